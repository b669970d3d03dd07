//! Ground states and the semantics of formulas and effects over them: the
//! one semantics the validator, the runtime's knowledge base and the
//! closed loop share.
//!
//! A [`World`] is a [`WorldModel`] made ready for evaluation (ids for
//! types, objects, predicates and functions; derived rules compiled and
//! stratified). Logic values are compiled against it once ([`Cond`],
//! [`Eff`]): names become ids, variables become slots of a binding, types
//! become the objects they range over. Evaluating is then lookups only.

use crate::logic::{Atom, Name};
use crate::types::TypeTable;
use crate::world::WorldModel;
use rustc_hash::{FxHashMap, FxHashSet};
use std::sync::Arc;

mod compile;
mod eval;

pub use compile::{CTerm, CompiledAction, Cond, Eff, Num, Quant};

/// A ground atom or fluent: `[predicate or function index, object ids...]`.
pub type Key = Box<[u32]>;

/// What is true (and what numbers hold) at one moment.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct State {
    pub facts: FxHashSet<Key>,
    pub fluents: FxHashMap<Key, f64>,
    /// Derived atoms, recomputed after every change.
    pub derived: FxHashSet<Key>,
}

/// Why a numeric effect could not be applied.
#[derive(Clone, Debug, PartialEq)]
pub struct NumericError {
    pub fluent: String,
}

/// The changes one effect makes, gathered before any is applied.
#[derive(Clone, Debug, Default)]
pub struct Changes {
    pub add: Vec<Key>,
    pub delete: Vec<Key>,
    pub numeric: Vec<(Key, f64)>,
    pub numeric_errors: Vec<NumericError>,
}

/// A world ready for evaluation.
pub struct World {
    model: WorldModel,
    types: TypeTable,
    objects: FxHashMap<Name, u32>,
    object_types: Vec<Vec<u32>>,
    predicates: FxHashMap<Name, u32>,
    predicate_params: Vec<Vec<Vec<u32>>>,
    derived_predicates: Vec<bool>,
    functions: FxHashMap<Name, u32>,
    function_params: Vec<Vec<Vec<u32>>>,
    /// Derived rules compiled over their heads' parameters, and their
    /// strata (each only negates predicates of earlier strata).
    rules: Vec<compile::Rule>,
    strata: Vec<Vec<usize>>,
    goal: Option<Cond>,
}

impl World {
    /// Makes a world model ready; the error names the first thing in it
    /// that does not fit (an undeclared type, predicate or object, a
    /// wrong arity, ...).
    pub fn new(model: WorldModel) -> Result<World, String> {
        compile::build(model)
    }

    /// The world of a checked domain and problem.
    pub fn of_checked(
        domain: &crate::ast::Domain,
        dix: &crate::check::DomainIndex,
        problem: &crate::ast::Problem,
        pix: &crate::check::ProblemIndex,
    ) -> Result<World, String> {
        World::new(WorldModel::from_checked(domain, dix, problem, pix))
    }

    pub fn model(&self) -> &WorldModel {
        &self.model
    }

    /// The problem's goal, compiled (`None`: the problem has none).
    pub fn goal(&self) -> Option<&Cond> {
        self.goal.as_ref()
    }

    pub fn types(&self) -> &TypeTable {
        &self.types
    }

    pub fn object_id(&self, name: &str) -> Option<u32> {
        self.objects.get(name).copied()
    }

    pub fn object_name(&self, id: u32) -> &str {
        &self.model.objects[id as usize].name
    }

    pub fn object_count(&self) -> usize {
        self.model.objects.len()
    }

    /// An object's types, as ids of [`World::types`].
    pub fn object_types(&self, id: u32) -> &[u32] {
        &self.object_types[id as usize]
    }

    pub fn predicate_id(&self, name: &str) -> Option<u32> {
        self.predicates.get(name).copied()
    }

    pub fn predicate_name(&self, id: u32) -> &str {
        &self.model.predicates[id as usize].name
    }

    pub fn is_derived(&self, pred: u32) -> bool {
        self.derived_predicates[pred as usize]
    }

    pub fn function_id(&self, name: &str) -> Option<u32> {
        self.functions.get(name).copied()
    }

    /// The objects whose types fit one of `types` (ids of [`World::types`]).
    pub fn objects_of(&self, types: &[u32]) -> Arc<[u32]> {
        (0..self.object_types.len() as u32)
            .filter(|&o| self.types.fits(&self.object_types[o as usize], types))
            .collect()
    }

    /// The initial state: the model's facts and values, derived atoms
    /// included.
    pub fn initial_state(&self) -> State {
        let mut s = State::default();
        for f in &self.model.init {
            match f {
                crate::logic::InitFact::Atom(a) => {
                    s.facts.extend(self.atom_key(a).ok());
                }
                crate::logic::InitFact::Value(a, v) => {
                    if let Ok(k) = self.fluent_key(a) {
                        s.fluents.insert(k, *v);
                    }
                }
            }
        }
        self.close_derived(&mut s);
        s
    }

    /// The key of a ground atom, e.g. `(on a b)`.
    pub fn atom_key(&self, a: &Atom) -> Result<Key, String> {
        compile::ground_key(self, a, false)
    }

    /// The key of a ground fluent, e.g. `(fuel truck1)`.
    pub fn fluent_key(&self, a: &Atom) -> Result<Key, String> {
        compile::ground_key(self, a, true)
    }

    /// `(pred a b)` for a ground atom key.
    pub fn show_atom(&self, k: &[u32]) -> String {
        self.show(&self.model.predicates[k[0] as usize].name, &k[1..])
    }

    /// `(f a b)` for a ground fluent key.
    pub fn show_fluent(&self, k: &[u32]) -> String {
        self.show(&self.model.functions[k[0] as usize].name, &k[1..])
    }

    fn show(&self, head: &str, args: &[u32]) -> String {
        let mut s = format!("({head}");
        for &o in args {
            s.push(' ');
            s.push_str(self.object_name(o));
        }
        s.push(')');
        s
    }

    /// A ground atom for its key (the inverse of [`World::atom_key`]).
    pub fn atom_of(&self, k: &[u32]) -> Atom {
        Atom {
            pred: self.model.predicates[k[0] as usize].name.clone(),
            args: self.args_of(k),
        }
    }

    /// A fluent's ground term for its key (the inverse of
    /// [`World::fluent_key`]).
    pub fn fluent_of(&self, k: &[u32]) -> Atom {
        Atom {
            pred: self.model.functions[k[0] as usize].name.clone(),
            args: self.args_of(k),
        }
    }

    fn args_of(&self, k: &[u32]) -> Vec<crate::logic::Term> {
        k[1..]
            .iter()
            .map(|&o| crate::logic::Term::Obj(self.model.objects[o as usize].name.clone()))
            .collect()
    }

    /// A state as `:init` facts: its true facts, then its fluents' values
    /// (derived atoms are not facts: they follow from the others), each
    /// group sorted.
    pub fn init_of(&self, s: &State) -> Vec<crate::logic::InitFact> {
        use crate::logic::InitFact;
        let mut facts: Vec<&Key> = s.facts.iter().collect();
        facts.sort();
        let mut values: Vec<(&Key, &f64)> = s.fluents.iter().collect();
        values.sort_by(|a, b| a.0.cmp(b.0));
        facts
            .into_iter()
            .map(|k| InitFact::Atom(self.atom_of(k)))
            .chain(
                values
                    .into_iter()
                    .map(|(k, v)| InitFact::Value(self.fluent_of(k), *v)),
            )
            .collect()
    }

    /// Applies changes: deletes first, then adds (an atom both deleted and
    /// added stays true), then numeric updates; derived atoms are recomputed.
    pub fn apply(&self, s: &mut State, mut changes: Changes) {
        self.apply_changes(s, &mut changes);
    }

    /// [`World::apply`], leaving `changes` empty but keeping its room for
    /// the next changes (a replay gathers every step's in the same one).
    pub fn apply_changes(&self, s: &mut State, changes: &mut Changes) {
        for k in changes.delete.drain(..) {
            s.facts.remove(&k);
        }
        // One at a time: changes are mostly a step's fact or two, for which
        // `extend`'s reservation costs more than it saves.
        for k in changes.add.drain(..) {
            s.facts.insert(k);
        }
        for (k, v) in changes.numeric.drain(..) {
            s.fluents.insert(k, v);
        }
        changes.numeric_errors.clear();
        self.close_derived(s);
    }
}

#[cfg(test)]
mod tests;

//! Ground states and the semantics of formulas and effects over them. The
//! validator replays plans with this; the runtime's simulated world uses the
//! same code as its knowledge base.

use crate::ast::*;
use crate::check::{DomainIndex, ProblemIndex};
use crate::source::Span;
use crate::types::TypeId;
use rustc_hash::{FxHashMap, FxHashSet};
use std::cell::RefCell;

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

/// Variable bindings: variable name to object id, innermost last.
pub type Env<'a> = Vec<(&'a str, u32)>;

/// A problem made ready for evaluation: the domain, its indexes and the
/// problem's objects.
pub struct World<'a> {
    pub domain: &'a Domain,
    pub dix: &'a DomainIndex,
    pub pix: &'a ProblemIndex,
    objects_by_type: RefCell<FxHashMap<Vec<TypeId>, std::rc::Rc<[u32]>>>,
}

/// Why a numeric effect could not be applied.
#[derive(Clone, Debug, PartialEq)]
pub struct NumericError {
    pub fluent: String,
}

impl<'a> World<'a> {
    pub fn new(domain: &'a Domain, dix: &'a DomainIndex, pix: &'a ProblemIndex) -> World<'a> {
        World {
            domain,
            dix,
            pix,
            objects_by_type: RefCell::default(),
        }
    }

    /// The initial state of a problem, derived atoms included.
    pub fn initial_state(&self, problem: &Problem) -> State {
        let mut s = State::default();
        let env = Env::new();
        for f in &problem.init {
            match f {
                InitFact::Atom { atom } => {
                    if let Some(k) = self.atom_key(atom, &env) {
                        s.facts.insert(k);
                    }
                }
                InitFact::Value { fluent, value, .. } => {
                    if let Some(k) = self.fluent_key(fluent, &env) {
                        s.fluents.insert(k, *value);
                    }
                }
            }
        }
        self.close_derived(&mut s);
        s
    }

    fn objects_of(&self, types: &[TypeId]) -> std::rc::Rc<[u32]> {
        if let Some(v) = self.objects_by_type.borrow().get(types) {
            return v.clone();
        }
        let v: std::rc::Rc<[u32]> = self.pix.objects_of(&self.dix.types, types).into();
        self.objects_by_type
            .borrow_mut()
            .insert(types.to_vec(), v.clone());
        v
    }

    fn term(&self, t: &Term, env: &Env) -> Option<u32> {
        match t {
            Term::Var { name } => env
                .iter()
                .rev()
                .find(|(v, _)| *v == name.name)
                .map(|(_, o)| *o),
            Term::Const { name } => self.pix.objects.get(name.as_str()).map(|o| o.id),
        }
    }

    fn key(&self, head: u32, args: &[Term], env: &Env) -> Option<Key> {
        let mut k = Vec::with_capacity(args.len() + 1);
        k.push(head);
        for a in args {
            k.push(self.term(a, env)?);
        }
        Some(k.into_boxed_slice())
    }

    pub fn atom_key(&self, atom: &Atom, env: &Env) -> Option<Key> {
        let sig = self.dix.predicates.get(atom.pred.as_str())?;
        self.key(sig.index as u32, &atom.args, env)
    }

    pub fn fluent_key(&self, app: &Atom, env: &Env) -> Option<Key> {
        let sig = self.dix.functions.get(app.pred.as_str())?;
        self.key(sig.index as u32, &app.args, env)
    }

    pub fn is_derived(&self, pred: u32) -> bool {
        self.dix
            .derived
            .contains(self.domain.predicates[pred as usize].name.as_str())
    }

    /// `(pred a b)` for a ground atom key.
    pub fn show_atom(&self, k: &[u32]) -> String {
        let mut s = format!("({}", self.domain.predicates[k[0] as usize].name.name);
        for &o in &k[1..] {
            s.push(' ');
            s.push_str(&self.pix.object_names[o as usize]);
        }
        s.push(')');
        s
    }

    pub fn show_fluent(&self, k: &[u32]) -> String {
        let mut s = format!("({}", self.domain.functions[k[0] as usize].name.name);
        for &o in &k[1..] {
            s.push(' ');
            s.push_str(&self.pix.object_names[o as usize]);
        }
        s.push(')');
        s
    }

    pub fn atom_holds(&self, s: &State, atom: &Atom, env: &Env) -> bool {
        let Some(sig) = self.dix.predicates.get(atom.pred.as_str()) else {
            return false;
        };
        let Some(k) = self.key(sig.index as u32, &atom.args, env) else {
            return false;
        };
        if self.dix.derived.contains(atom.pred.as_str()) {
            s.derived.contains(&k)
        } else {
            s.facts.contains(&k)
        }
    }

    /// Calls `f` with `env` extended by each binding of `vars`; stops when
    /// `f` returns `Some`.
    fn each_binding<'e, R>(
        &self,
        vars: &'e [Typed],
        env: &mut Env<'e>,
        f: &mut dyn FnMut(&mut Env<'e>) -> Option<R>,
    ) -> Option<R> {
        let Some((first, rest)) = vars.split_first() else {
            return f(env);
        };
        let types = self.dix.types.resolve(&first.ty, &mut Vec::new());
        for &o in self.objects_of(&types).iter() {
            env.push((first.name.as_str(), o));
            let r = self.each_binding(rest, env, f);
            env.pop();
            if r.is_some() {
                return r;
            }
        }
        None
    }

    pub fn holds<'e>(
        &self,
        s: &State,
        f: &'e Formula,
        env: &mut Env<'e>,
        duration: Option<f64>,
    ) -> bool {
        match f {
            Formula::Atom { atom } => self.atom_holds(s, atom, env),
            Formula::Equal { left, right, .. } => {
                self.term(left, env).is_some() && self.term(left, env) == self.term(right, env)
            }
            Formula::Not { formula, .. } => !self.holds(s, formula, env, duration),
            Formula::And { parts, .. } => parts.iter().all(|p| self.holds(s, p, env, duration)),
            Formula::Or { parts, .. } => parts.iter().any(|p| self.holds(s, p, env, duration)),
            Formula::Imply { left, right, .. } => {
                !self.holds(s, left, env, duration) || self.holds(s, right, env, duration)
            }
            Formula::Exists { vars, body, .. } => self
                .each_binding(vars, env, &mut |env| {
                    self.holds(s, body, env, duration).then_some(())
                })
                .is_some(),
            Formula::Forall { vars, body, .. } => self
                .each_binding(vars, env, &mut |env| {
                    (!self.holds(s, body, env, duration)).then_some(())
                })
                .is_none(),
            Formula::Compare {
                op, left, right, ..
            } => {
                match (
                    self.value(s, left, env, duration),
                    self.value(s, right, env, duration),
                ) {
                    (Some(a), Some(b)) => match op {
                        Comparison::Lt => a < b,
                        Comparison::Le => a <= b,
                        Comparison::Gt => a > b,
                        Comparison::Ge => a >= b,
                        Comparison::Eq => a == b,
                    },
                    _ => false,
                }
            }
        }
    }

    /// A numeric expression's value; `None` when a fluent is undefined.
    pub fn value(&self, s: &State, e: &NumExpr, env: &Env, duration: Option<f64>) -> Option<f64> {
        Some(match e {
            NumExpr::Number { value, .. } => *value,
            NumExpr::Fluent { app } => {
                if app.pred.name == "total-time"
                    && app.args.is_empty()
                    && !self.dix.functions.contains_key("total-time")
                {
                    return None;
                }
                *s.fluents.get(&self.fluent_key(app, env)?)?
            }
            NumExpr::Duration { .. } => duration?,
            NumExpr::Binary {
                op, left, right, ..
            } => {
                let (a, b) = (
                    self.value(s, left, env, duration)?,
                    self.value(s, right, env, duration)?,
                );
                match op {
                    NumOp::Add => a + b,
                    NumOp::Sub => a - b,
                    NumOp::Mul => a * b,
                    NumOp::Div => a / b,
                }
            }
            NumExpr::Neg { expr, .. } => -self.value(s, expr, env, duration)?,
        })
    }

    /// Why a formula that does not hold fails, in the user's terms: the
    /// first failing literal with its arguments filled in, and its span.
    pub fn why_not<'e>(
        &self,
        s: &State,
        f: &'e Formula,
        env: &mut Env<'e>,
        duration: Option<f64>,
    ) -> (String, Span) {
        let span = f.span();
        let text = match f {
            Formula::Atom { atom } => format!("`{}` is false", self.show_ground(atom, env)),
            Formula::Equal { left, right, .. } => format!(
                "`{}` and `{}` are different objects",
                self.show_term(left, env),
                self.show_term(right, env)
            ),
            Formula::Not { formula, .. } => match &**formula {
                Formula::Atom { atom } => format!(
                    "`{}` is true, but must be false",
                    self.show_ground(atom, env)
                ),
                Formula::Equal { left, right, .. } => format!(
                    "`{}` and `{}` are the same object, but must differ",
                    self.show_term(left, env),
                    self.show_term(right, env)
                ),
                _ => "a negated condition holds".to_owned(),
            },
            Formula::And { parts, .. } => {
                return match parts.iter().find(|p| !self.holds(s, p, env, duration)) {
                    Some(p) => self.why_not(s, p, env, duration),
                    None => (String::new(), span),
                }
            }
            Formula::Or { .. } => "none of the alternatives of an `or` holds".to_owned(),
            Formula::Imply { right, .. } => {
                let (why, _) = self.why_not(s, right, env, duration);
                format!("the condition of an `imply` holds, but {why}")
            }
            Formula::Exists { vars, .. } => {
                let vs: Vec<String> = vars.iter().map(|v| format!("?{}", v.name.name)).collect();
                format!("no choice of {} satisfies an `exists`", vs.join(" "))
            }
            Formula::Forall { vars, body, .. } => {
                return self
                    .each_binding(vars, env, &mut |env| {
                        if self.holds(s, body, env, duration) {
                            return None;
                        }
                        let bound: Vec<String> = env[env.len() - vars.len()..]
                            .iter()
                            .map(|(v, o)| format!("?{v} = {}", self.pix.object_names[*o as usize]))
                            .collect();
                        let (why, at) = self.why_not(s, body, env, duration);
                        Some((format!("for {}: {why}", bound.join(", ")), at))
                    })
                    .unwrap_or((String::new(), span))
            }
            Formula::Compare { .. } => "a numeric comparison does not hold".to_owned(),
        };
        (text, span)
    }

    fn show_term(&self, t: &Term, env: &Env) -> String {
        match self.term(t, env) {
            Some(o) => self.pix.object_names[o as usize].clone(),
            None => t.to_string(),
        }
    }

    pub fn show_ground(&self, atom: &Atom, env: &Env) -> String {
        let mut s = format!("({}", atom.pred.name);
        for a in &atom.args {
            s.push(' ');
            s.push_str(&self.show_term(a, env));
        }
        s.push(')');
        s
    }

    /// Collects the changes of an effect, evaluated in `s` (the state before).
    pub fn collect_effect<'e>(
        &self,
        s: &State,
        e: &'e Effect,
        env: &mut Env<'e>,
        duration: Option<f64>,
        changes: &mut Changes,
    ) {
        match e {
            Effect::Add { atom } => changes.add.extend(self.atom_key(atom, env)),
            Effect::Delete { atom, .. } => changes.delete.extend(self.atom_key(atom, env)),
            Effect::And { parts, .. } => {
                for p in parts {
                    self.collect_effect(s, p, env, duration, changes);
                }
            }
            Effect::Forall { vars, body, .. } => {
                self.each_binding(vars, env, &mut |env| {
                    self.collect_effect(s, body, env, duration, changes);
                    None::<()>
                });
            }
            Effect::When {
                condition, body, ..
            } => {
                if self.holds(s, condition, env, duration) {
                    self.collect_effect(s, body, env, duration, changes);
                }
            }
            Effect::Numeric {
                op, fluent, value, ..
            } => {
                let key = self.fluent_key(fluent, env);
                let old = key.as_ref().and_then(|k| s.fluents.get(k)).copied();
                let v = self.value(s, value, env, duration);
                let new = match (op, old, v) {
                    (AssignOp::Assign, _, Some(v)) => Some(v),
                    (AssignOp::Increase, Some(o), Some(v)) => Some(o + v),
                    (AssignOp::Decrease, Some(o), Some(v)) => Some(o - v),
                    (AssignOp::ScaleUp, Some(o), Some(v)) => Some(o * v),
                    (AssignOp::ScaleDown, Some(o), Some(v)) => Some(o / v),
                    _ => None,
                };
                match (key, new) {
                    (Some(k), Some(n)) => changes.numeric.push((k, n)),
                    _ => changes.numeric_errors.push(NumericError {
                        fluent: self.show_ground(fluent, env),
                    }),
                }
            }
        }
    }

    /// Applies changes: deletes first, then adds (an atom both deleted and
    /// added stays true), then numeric updates; derived atoms are recomputed.
    pub fn apply(&self, s: &mut State, changes: Changes) {
        for k in &changes.delete {
            s.facts.remove(k);
        }
        s.facts.extend(changes.add);
        for (k, v) in changes.numeric {
            s.fluents.insert(k, v);
        }
        self.close_derived(s);
    }

    /// Recomputes every derived atom, stratum by stratum, to a fixpoint.
    pub fn close_derived(&self, s: &mut State) {
        if self.dix.derived_strata.is_empty() {
            return;
        }
        s.derived.clear();
        for stratum in &self.dix.derived_strata {
            loop {
                let mut found: Vec<Key> = Vec::new();
                for &r in stratum {
                    let rule = &self.domain.derived[r];
                    let Some(sig) = self.dix.predicates.get(rule.head.name.as_str()) else {
                        continue;
                    };
                    let mut env = Env::new();
                    self.each_binding(&rule.head.params, &mut env, &mut |env| {
                        let mut k = Vec::with_capacity(env.len() + 1);
                        k.push(sig.index as u32);
                        k.extend(env.iter().map(|(_, o)| *o));
                        let k = k.into_boxed_slice();
                        if !s.derived.contains(&k) && self.holds(s, &rule.body, env, None) {
                            found.push(k);
                        }
                        None::<()>
                    });
                }
                if found.is_empty() {
                    break;
                }
                s.derived.extend(found);
            }
        }
    }
}

/// The changes one effect makes, gathered before any is applied.
#[derive(Clone, Debug, Default)]
pub struct Changes {
    pub add: Vec<Key>,
    pub delete: Vec<Key>,
    pub numeric: Vec<(Key, f64)>,
    pub numeric_errors: Vec<NumericError>,
}

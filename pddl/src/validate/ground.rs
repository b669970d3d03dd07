//! What a ground action (an action with its arguments) does regardless of
//! the state, worked out the first time a step uses it: its condition
//! literals and its unconditional add and delete effects, as atoms of
//! [`TrackedFacts`]. Long plans repeat few ground actions, so a replay
//! then tests and sets a handful of table entries per step.
//!
//! A phase is cached only when that is exact: conditions that are
//! conjunctions of (negated) atoms and equalities, effects that are
//! conjunctions of adds, deletes and numeric updates (which read fluents
//! only, never facts, and are still evaluated at each step). Anything
//! else (`or`, quantifiers, comparisons, `when`, `forall`) is left to the
//! general path.

use super::tracked::{Literal, TrackedFacts};
use crate::state::{CTerm, CompiledAction, Cond, Eff, State};
use rustc_hash::FxHashMap;
use std::marker::PhantomData;

/// A phase's conditions.
pub(super) enum GroundConds {
    /// All of these must hold.
    Literals(Box<[Literal]>),
    /// Evaluated by the general path at each step.
    General,
}

/// A phase's effects.
pub(super) enum GroundEffects {
    Cached {
        delete: Box<[u32]>,
        add: Box<[u32]>,
        /// The phase's numeric effects, in their written order.
        numeric: Box<[Eff]>,
    },
    /// Collected by the general path at each step.
    General,
}

pub(super) struct GroundAction {
    pub pre_start: GroundConds,
    pub pre_over_all: GroundConds,
    pub pre_end: GroundConds,
    pub eff_start: GroundEffects,
    pub eff_end: GroundEffects,
}

/// The ground actions of one replay, and the atoms they mention; `'s` is
/// the life of the steps' argument lists.
#[derive(Default)]
pub(super) struct GroundActions<'s> {
    /// `[action index, args...]` to an index of `actions`.
    index: FxHashMap<Box<[u32]>, usize>,
    /// The same by the address and length of an argument list: plan steps
    /// that make the same call share theirs, and looking up an address
    /// hashes three words. An address stands for the arguments it holds
    /// because the lists outlive this table (`'s`).
    by_address: FxHashMap<(usize, *const u32, usize), usize>,
    lists: PhantomData<&'s [u32]>,
    actions: Vec<GroundAction>,
    /// Room for the key of the step being looked up.
    key: Vec<u32>,
    pub facts: TrackedFacts,
}

impl<'s> GroundActions<'s> {
    /// The ground action `action` of the domain with `args`, grounded on
    /// first use; `state` gives the truth of atoms first seen.
    pub fn get(
        &mut self,
        action: usize,
        compiled: &CompiledAction,
        args: &'s [u32],
        state: &State,
    ) -> (&GroundAction, &mut TrackedFacts) {
        let i = self.id(action, compiled, args, state);
        self.parts(i)
    }

    /// [`GroundActions::get`]'s ground action as an id for
    /// [`GroundActions::parts`]: a replay that meets a step several times
    /// (a durative action's start, end and `over all`) looks it up once.
    pub fn id(
        &mut self,
        action: usize,
        compiled: &CompiledAction,
        args: &'s [u32],
        state: &State,
    ) -> usize {
        let address = (action, args.as_ptr(), args.len());
        match self.by_address.get(&address) {
            Some(&i) => i,
            None => {
                let i = self.by_content(action, compiled, args, state);
                self.by_address.insert(address, i);
                i
            }
        }
    }

    /// Ground action `id` and the atoms' table.
    pub fn parts(&mut self, id: usize) -> (&GroundAction, &mut TrackedFacts) {
        (&self.actions[id], &mut self.facts)
    }

    fn by_content(
        &mut self,
        action: usize,
        compiled: &CompiledAction,
        args: &[u32],
        state: &State,
    ) -> usize {
        self.key.clear();
        self.key
            .push(u32::try_from(action).expect("fewer than 2^32 actions"));
        self.key.extend_from_slice(args);
        match self.index.get(&self.key[..]) {
            Some(&i) => i,
            None => {
                let g = ground(compiled, args, &mut self.facts, state);
                self.actions.push(g);
                let i = self.actions.len() - 1;
                self.index.insert(self.key.as_slice().into(), i);
                i
            }
        }
    }
}

fn ground(
    c: &CompiledAction,
    args: &[u32],
    facts: &mut TrackedFacts,
    state: &State,
) -> GroundAction {
    let mut g = Grounder { args, facts, state };
    GroundAction {
        pre_start: g.conds(&c.pre_start),
        pre_over_all: g.conds(&c.pre_over_all),
        pre_end: g.conds(&c.pre_end),
        eff_start: g.effects(&c.eff_start),
        eff_end: g.effects(&c.eff_end),
    }
}

struct Grounder<'a> {
    args: &'a [u32],
    facts: &'a mut TrackedFacts,
    state: &'a State,
}

/// Returned when a part cannot be cached.
struct NotCached;

impl Grounder<'_> {
    fn conds(&mut self, conds: &[Cond]) -> GroundConds {
        let mut out = Vec::new();
        match conds.iter().try_for_each(|c| self.literals(c, &mut out)) {
            Ok(()) => GroundConds::Literals(out.into()),
            Err(NotCached) => GroundConds::General,
        }
    }

    fn literals(&mut self, c: &Cond, out: &mut Vec<Literal>) -> Result<(), NotCached> {
        match c {
            Cond::And(parts) => parts.iter().try_for_each(|p| self.literals(p, out)),
            Cond::Not(inner) => match &**inner {
                Cond::Atom { .. } => {
                    out.push(self.literal(inner, false)?);
                    Ok(())
                }
                Cond::Eq(l, r) if self.object(*l)? != self.object(*r)? => Ok(()),
                _ => Err(NotCached),
            },
            Cond::Atom { .. } => {
                out.push(self.literal(c, true)?);
                Ok(())
            }
            Cond::Eq(l, r) if self.object(*l)? == self.object(*r)? => Ok(()),
            // A false equality, like any other condition, is for the general
            // path: it fails there with its message.
            _ => Err(NotCached),
        }
    }

    fn literal(&mut self, atom: &Cond, positive: bool) -> Result<Literal, NotCached> {
        let Cond::Atom {
            pred,
            derived: false,
            args,
        } = atom
        else {
            return Err(NotCached);
        };
        Ok(Literal {
            atom: self.atom(*pred, args)?,
            positive,
        })
    }

    fn effects(&mut self, effects: &[Eff]) -> GroundEffects {
        let (mut delete, mut add, mut numeric) = (Vec::new(), Vec::new(), Vec::new());
        let mut sort = |e: &Eff| -> Result<(), NotCached> {
            self.effect(e, &mut delete, &mut add, &mut numeric)
        };
        match effects.iter().try_for_each(&mut sort) {
            Ok(()) => GroundEffects::Cached {
                delete: delete.into(),
                add: add.into(),
                numeric: numeric.into(),
            },
            Err(NotCached) => GroundEffects::General,
        }
    }

    fn effect(
        &mut self,
        e: &Eff,
        delete: &mut Vec<u32>,
        add: &mut Vec<u32>,
        numeric: &mut Vec<Eff>,
    ) -> Result<(), NotCached> {
        match e {
            Eff::Add { pred, args } => add.push(self.atom(*pred, args)?),
            Eff::Del { pred, args } => delete.push(self.atom(*pred, args)?),
            Eff::And(parts) => {
                for p in parts {
                    self.effect(p, delete, add, numeric)?;
                }
            }
            Eff::Numeric { .. } => numeric.push(e.clone()),
            Eff::Forall(..) | Eff::When(..) => return Err(NotCached),
        }
        Ok(())
    }

    fn atom(&mut self, pred: u32, args: &[CTerm]) -> Result<u32, NotCached> {
        let mut key = Vec::with_capacity(args.len() + 1);
        key.push(pred);
        for &a in args {
            key.push(self.object(a)?);
        }
        Ok(self.facts.intern(&key, self.state))
    }

    /// Outside quantifiers every slot is a parameter.
    fn object(&self, t: CTerm) -> Result<u32, NotCached> {
        match t {
            CTerm::Obj(o) => Ok(o),
            CTerm::Slot(s) => self.args.get(s as usize).copied().ok_or(NotCached),
        }
    }
}

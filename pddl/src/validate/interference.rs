//! What one event of a timed plan (an action's start, its end, or an
//! instantaneous action) reads and writes, and whether two events at the
//! same happening interfere.
//!
//! PDDL 2.1 lets events happen at the same time only when their order
//! cannot matter. As VAL decides it: two events interfere when one adds
//! an atom the other deletes, when one changes an atom or a fluent the
//! other reads (in a condition, a `when` or a numeric expression), or when
//! one assigns a fluent the other updates. Two events adding (or deleting)
//! the same atom, or both increasing or decreasing the same fluent, do not.

use crate::ast::AssignOp;
use crate::state::{CTerm, Cond, Eff, EffectVisitor, Key, Num, State, World};
use rustc_hash::FxHashSet;

/// The atoms and fluents an event touches.
#[derive(Default)]
pub(super) struct Footprint {
    pub reads: FxHashSet<Key>,
    pub fluent_reads: FxHashSet<Key>,
    pub adds: FxHashSet<Key>,
    pub deletes: FxHashSet<Key>,
    /// Fluents it updates; `true` when only by `increase`/`decrease`.
    pub updates: Vec<(Key, bool)>,
}

/// Why two events interfere, in the user's terms.
pub(super) struct Clash {
    /// What the first event does, e.g. "deletes `(at r2d2 wp1)`".
    pub first: String,
    /// What the second does with it, e.g. "needs it".
    pub second: &'static str,
}

impl Footprint {
    /// The footprint of conditions `conds` and effects `effects` under
    /// binding `b` in state `s` (a `when` counts as read whether or not it
    /// holds; its effect as written only when it does, as VAL has it).
    pub fn of(
        world: &World,
        s: &State,
        conds: &[Cond],
        effects: &[Eff],
        b: &mut Vec<u32>,
        duration: Option<f64>,
    ) -> Footprint {
        let mut f = Footprint::default();
        for c in conds {
            f.read_cond(c, b);
        }
        for e in effects {
            world.walk_effect(s, e, b, duration, &mut f);
        }
        f
    }

    fn read_cond(&mut self, c: &Cond, b: &mut Vec<u32>) {
        match c {
            Cond::Atom { pred, args, .. } => {
                self.reads.insert(key(*pred, args, b));
            }
            Cond::Eq(..) => {}
            Cond::Not(x) => self.read_cond(x, b),
            Cond::And(ps) | Cond::Or(ps) => ps.iter().for_each(|p| self.read_cond(p, b)),
            Cond::Imply(l, r) => {
                self.read_cond(l, b);
                self.read_cond(r, b);
            }
            Cond::Exists(q, body) | Cond::Forall(q, body) => {
                World::any_binding(q, b, &mut |b| {
                    self.read_cond(body, b);
                    false
                });
            }
            Cond::Compare(_, l, r) => {
                self.read_num(l, b);
                self.read_num(r, b);
            }
        }
    }

    fn read_num(&mut self, n: &Num, b: &[u32]) {
        match n {
            Num::Fluent { func, args } => {
                self.fluent_reads.insert(key(*func, args, b));
            }
            Num::Bin(_, l, r) => {
                self.read_num(l, b);
                self.read_num(r, b);
            }
            Num::Neg(x) => self.read_num(x, b),
            Num::Const(_) | Num::Undefined | Num::Duration => {}
        }
    }

    /// How `self` and `other` (two different events at the same
    /// happening) interfere, if they do.
    pub fn clash(&self, other: &Footprint, world: &World) -> Option<Clash> {
        let atom = |k: &Key| format!("`{}`", world.show_atom(k));
        let fluent = |k: &Key| format!("`{}`", world.show_fluent(k));
        if let Some(k) = self.deletes.intersection(&other.adds).next() {
            return Some(Clash {
                first: format!("deletes {}", atom(k)),
                second: "adds it",
            });
        }
        if let Some(k) = self.adds.intersection(&other.deletes).next() {
            return Some(Clash {
                first: format!("adds {}", atom(k)),
                second: "deletes it",
            });
        }
        for (mine, theirs, what) in [
            (&self.deletes, &other.reads, "deletes"),
            (&self.adds, &other.reads, "adds"),
        ] {
            if let Some(k) = mine.intersection(theirs).next() {
                return Some(Clash {
                    first: format!("{what} {}", atom(k)),
                    second: "needs it",
                });
            }
        }
        for (mine, theirs, what) in [
            (&other.deletes, &self.reads, "needs"),
            (&other.adds, &self.reads, "needs"),
        ] {
            if let Some(k) = mine.intersection(theirs).next() {
                let second = if other.adds.contains(k) {
                    "adds it"
                } else {
                    "deletes it"
                };
                return Some(Clash {
                    first: format!("{what} {}", atom(k)),
                    second,
                });
            }
        }
        for (k, additive) in &self.updates {
            if other.fluent_reads.contains(k) {
                return Some(Clash {
                    first: format!("updates {}", fluent(k)),
                    second: "reads it",
                });
            }
            if let Some((_, theirs)) = other.updates.iter().find(|(o, _)| o == k) {
                if !(*additive && *theirs) {
                    return Some(Clash {
                        first: format!("assigns {}", fluent(k)),
                        second: "updates it too",
                    });
                }
            }
        }
        for (k, _) in &other.updates {
            if self.fluent_reads.contains(k) {
                return Some(Clash {
                    first: format!("reads {}", fluent(k)),
                    second: "updates it",
                });
            }
        }
        None
    }

    /// Whether any change of `self` touches what `reads` reads: an atom it
    /// adds or deletes, or a fluent it updates.
    pub fn changes_any(&self, reads: &Footprint) -> bool {
        self.adds
            .iter()
            .chain(&self.deletes)
            .any(|k| reads.reads.contains(k))
            || self
                .updates
                .iter()
                .any(|(k, _)| reads.fluent_reads.contains(k))
    }
}

/// A `when` counts as read whether or not it holds; its effect as
/// written only when it does, as VAL has it.
impl EffectVisitor for Footprint {
    fn atom(&mut self, positive: bool, atom: Key) {
        if positive {
            self.adds.insert(atom);
        } else {
            self.deletes.insert(atom);
        }
    }

    fn numeric(&mut self, op: AssignOp, fluent: Key, value: &Num, b: &mut Vec<u32>) {
        self.read_num(value, b);
        let additive = matches!(op, AssignOp::Increase | AssignOp::Decrease);
        self.updates.push((fluent, additive));
    }

    fn condition(&mut self, c: &Cond, b: &mut Vec<u32>) {
        self.read_cond(c, b);
    }
}

fn key(head: u32, args: &[CTerm], b: &[u32]) -> Key {
    std::iter::once(head)
        .chain(args.iter().map(|a| match *a {
            CTerm::Slot(i) => b[i as usize],
            CTerm::Obj(o) => o,
        }))
        .collect()
}

//! How each schema takes part in the relaxed-reachability fixpoint: the
//! joins that find its bindings (semi-naive, or naive for preconditions
//! that are more than literals) and what a binding must still satisfy.

use super::*;

/// How a schema takes part in the reachability fixpoint.
pub(super) struct Joins {
    /// Semi-naive: one join per atom of the precondition, led by it, over
    /// the atoms new in the round before. Naive: one join over all atoms,
    /// run again every round, for schemas whose precondition is more than
    /// a conjunction of atoms and (in)equalities or whose effects have
    /// conditions (which may become reachable for an old binding).
    pub(super) steps: Vec<Vec<Step>>,
    pub(super) naive: bool,
    pub(super) conditional: bool,
    pub(super) allowed: Vec<Vec<bool>>,
    /// What a binding the join finds must still satisfy: the whole
    /// precondition when naive, only its non-atom literals otherwise.
    pub(super) check: LF,
}

impl Joins {
    pub(super) fn new(reach: &mut Reach, s: &Schema, nobj: usize, fixpoint: Fixpoint) -> Joins {
        let mut atoms = Vec::new();
        necessary_atoms(&s.pre_start, &mut atoms);
        let all = atoms.len();
        atoms.retain(|(_, args)| {
            args.len() <= MAX_ARITY
                && args.iter().all(|a| {
                    matches!(a, LTerm::Obj(_))
                        || matches!(a, LTerm::Slot(x) if (*x as usize) < s.params.len())
                })
        });
        let conditional = has_when(&s.eff_start) || has_when(&s.eff_end);
        let naive = fixpoint == Fixpoint::Naive
            || atoms.len() < all
            || conditional
            || !literal_conjunction(&s.pre_start);
        let slots = s.slots.max(s.params.len());
        let steps = if naive || atoms.is_empty() {
            let order = join_order(&atoms, slots, None);
            let ordered: Vec<_> = order.iter().map(|&i| atoms[i].clone()).collect();
            vec![reach.plan(&ordered, &vec![Part::All; atoms.len()], slots)]
        } else {
            (0..atoms.len())
                .map(|lead| {
                    let order = join_order(&atoms, slots, Some(lead));
                    let ordered: Vec<_> = order.iter().map(|&i| atoms[i].clone()).collect();
                    let parts: Vec<Part> = order
                        .iter()
                        .map(|&i| match i.cmp(&lead) {
                            std::cmp::Ordering::Less => Part::Old,
                            std::cmp::Ordering::Equal => Part::New,
                            std::cmp::Ordering::Greater => Part::All,
                        })
                        .collect();
                    reach.plan(&ordered, &parts, slots)
                })
                .collect()
        };
        let allowed = s
            .params
            .iter()
            .map(|objs| {
                let mut v = vec![false; nobj];
                for &o in objs.iter() {
                    v[o as usize] = true;
                }
                v
            })
            .collect();
        let check = if naive {
            s.pre_start.clone()
        } else {
            let mut rest = Vec::new();
            non_atoms(&s.pre_start, &mut rest);
            LF::And(rest)
        };
        Joins {
            steps,
            naive,
            conditional,
            allowed,
            check,
        }
    }
}

/// Whether `f` is a conjunction of atoms, negated atoms and (in)equalities.
pub(super) fn literal_conjunction(f: &LF) -> bool {
    match f {
        LF::And(ps) => ps.iter().all(literal_conjunction),
        LF::Atom { .. } | LF::Eq(..) => true,
        LF::Not(g) => matches!(**g, LF::Atom { .. } | LF::Eq(..)),
        _ => false,
    }
}

/// The conjuncts of a literal conjunction other than positive atoms.
pub(super) fn non_atoms(f: &LF, out: &mut Vec<LF>) {
    match f {
        LF::And(ps) => ps.iter().for_each(|p| non_atoms(p, out)),
        LF::Atom { .. } => {}
        f => out.push(f.clone()),
    }
}

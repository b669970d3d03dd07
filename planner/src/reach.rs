//! The reachable atoms of the relaxed-reachability fixpoint and the joins
//! over them. Atoms of a predicate are kept in the order they were found,
//! with hash indexes on the argument positions that joins look them up by,
//! so a join step costs the matching atoms, not all atoms of the predicate.
//! The fixpoint is semi-naive: a round joins each schema only on bindings
//! that use at least one atom found in the round before, so every binding
//! is enumerated once over the whole fixpoint instead of once per round.

use crate::lifted::{LTerm, MAX_ARITY};
use rustc_hash::{FxHashMap, FxHashSet};

/// Values at some argument positions -> the atoms (indexes into
/// `Relation::atoms`, ascending) with them.
type Index = FxHashMap<Box<[u32]>, Vec<u32>>;

/// Reachable atoms of one predicate, with indexes by bound positions.
#[derive(Default)]
struct Relation {
    atoms: Vec<Box<[u32]>>,
    /// A bit mask of argument positions, and the index on them.
    indexes: Vec<(u32, Index)>,
}

/// The values of `atom` (a key `[pred, args...]`) at the positions of `mask`.
fn project(atom: &[u32], mask: u32, buf: &mut [u32; MAX_ARITY]) -> usize {
    let mut n = 0;
    for (i, &o) in atom[1..].iter().enumerate() {
        if mask >> i & 1 == 1 {
            buf[n] = o;
            n += 1;
        }
    }
    n
}

impl Relation {
    fn index(&mut self, mask: u32) -> usize {
        if let Some(i) = self.indexes.iter().position(|(m, _)| *m == mask) {
            return i;
        }
        let mut map = Index::default();
        let mut buf = [0; MAX_ARITY];
        for (i, a) in self.atoms.iter().enumerate() {
            let n = project(a, mask, &mut buf);
            map.entry(buf[..n].into()).or_default().push(i as u32);
        }
        self.indexes.push((mask, map));
        self.indexes.len() - 1
    }

    fn push(&mut self, atom: Box<[u32]>) {
        let id = self.atoms.len() as u32;
        let mut buf = [0; MAX_ARITY];
        for (mask, map) in &mut self.indexes {
            let n = project(&atom, *mask, &mut buf);
            match map.get_mut(&buf[..n]) {
                Some(v) => v.push(id),
                None => {
                    map.insert(buf[..n].into(), vec![id]);
                }
            }
        }
        self.atoms.push(atom);
    }
}

/// The set of reachable atoms (static ones included), per predicate.
pub(crate) struct Reach {
    all: FxHashSet<Box<[u32]>>,
    rels: Vec<Relation>,
}

/// Which atoms of its predicate a join step ranges over in a round: those
/// found before the previous round (`Old`), in it (`New`), or either.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Part {
    Old,
    New,
    All,
}

/// One atom of a join, with what is bound when it is reached.
#[derive(Clone, Debug)]
pub(crate) struct Step {
    pred: u32,
    args: Vec<LTerm>,
    /// Positions bound by constants or earlier steps (0: scan the atoms).
    mask: u32,
    index: usize,
    part: Part,
}

/// How many atoms each predicate had at the start of the previous round
/// and of this one.
pub(crate) struct Round<'a> {
    pub before: &'a [usize],
    pub now: &'a [usize],
}

impl Reach {
    pub fn new(preds: usize) -> Reach {
        Reach {
            all: FxHashSet::default(),
            rels: (0..preds).map(|_| Relation::default()).collect(),
        }
    }

    pub fn contains(&self, key: &[u32]) -> bool {
        self.all.contains(key)
    }

    pub fn len(&self) -> usize {
        self.all.len()
    }

    pub fn iter(&self) -> impl Iterator<Item = &Box<[u32]>> {
        self.all.iter()
    }

    /// Adds an atom; whether it is new.
    pub fn insert(&mut self, key: Box<[u32]>) -> bool {
        if self.all.contains(&key) {
            return false;
        }
        self.rels[key[0] as usize].push(key.clone());
        self.all.insert(key);
        true
    }

    /// The number of atoms of each predicate.
    pub fn sizes(&self) -> Vec<usize> {
        self.rels.iter().map(|r| r.atoms.len()).collect()
    }

    /// A join of `atoms` (in this order) where step `i` ranges over
    /// `parts[i]`; indexes for its lookups are made here.
    pub fn plan(&mut self, atoms: &[(u32, Vec<LTerm>)], parts: &[Part], slots: usize) -> Vec<Step> {
        let mut bound = vec![false; slots];
        let mut out = Vec::with_capacity(atoms.len());
        for ((pred, args), &part) in atoms.iter().zip(parts) {
            let mut mask = 0u32;
            for (i, a) in args.iter().enumerate() {
                let known = match a {
                    LTerm::Obj(_) => true,
                    LTerm::Slot(s) => bound[*s as usize],
                };
                if known {
                    mask |= 1 << i;
                }
            }
            for a in args {
                if let LTerm::Slot(s) = a {
                    bound[*s as usize] = true;
                }
            }
            let index = if mask == 0 {
                0
            } else {
                self.rels[*pred as usize].index(mask)
            };
            out.push(Step {
                pred: *pred,
                args: args.clone(),
                mask,
                index,
                part,
            });
        }
        out
    }

    /// Calls `leaf` for each assignment of the slots of `steps` (written
    /// into `env`) under which every step's atom is reachable, within the
    /// parts of the round. `allowed[s]` says which objects slot `s` may
    /// take. Stops early when `stop` says so.
    pub fn join(
        &self,
        steps: &[Step],
        round: &Round,
        allowed: &[Vec<bool>],
        env: &mut [Option<u32>],
        stop: &dyn Fn() -> bool,
        leaf: &mut dyn FnMut(&mut [Option<u32>]),
    ) {
        let Some((step, rest)) = steps.split_first() else {
            return leaf(env);
        };
        if stop() {
            return;
        }
        let p = step.pred as usize;
        let (lo, hi) = match step.part {
            Part::Old => (0, round.before[p]),
            Part::New => (round.before[p], round.now[p]),
            Part::All => (0, round.now[p]),
        };
        if lo >= hi {
            return;
        }
        let rel = &self.rels[p];
        let mut visit = |atom: &[u32], env: &mut [Option<u32>]| {
            let mut newly = [0usize; MAX_ARITY];
            let mut nb = 0;
            let mut ok = true;
            for (i, a) in step.args.iter().enumerate() {
                let o = atom[i + 1];
                ok = match *a {
                    LTerm::Obj(c) => c == o,
                    LTerm::Slot(s) => match env[s as usize] {
                        Some(v) => v == o,
                        None if allowed[s as usize]
                            .get(o as usize)
                            .copied()
                            .unwrap_or(false) =>
                        {
                            env[s as usize] = Some(o);
                            newly[nb] = s as usize;
                            nb += 1;
                            true
                        }
                        None => false,
                    },
                };
                if !ok {
                    break;
                }
            }
            if ok {
                self.join(rest, round, allowed, env, stop, leaf);
            }
            for &s in &newly[..nb] {
                env[s] = None;
            }
        };
        if step.mask == 0 {
            for atom in &rel.atoms[lo..hi] {
                visit(atom, env);
            }
            return;
        }
        let mut key = [0u32; MAX_ARITY];
        let mut n = 0;
        for (i, a) in step.args.iter().enumerate() {
            if step.mask >> i & 1 == 1 {
                key[n] = match *a {
                    LTerm::Obj(o) => o,
                    LTerm::Slot(s) => env[s as usize].unwrap_or(u32::MAX),
                };
                n += 1;
            }
        }
        let Some(ids) = rel.indexes[step.index].1.get(&key[..n]) else {
            return;
        };
        let from = ids.partition_point(|&id| (id as usize) < lo);
        for &id in &ids[from..] {
            if id as usize >= hi {
                break;
            }
            visit(&rel.atoms[id as usize], env);
        }
    }
}

/// Orders a join: `first` (if any) leads, then each next atom shares the
/// most variables with those before it (so no cross products are built
/// when a chain exists), with fewer new variables breaking ties. Returns
/// the original positions in join order.
pub(crate) fn join_order(
    atoms: &[(u32, Vec<LTerm>)],
    slots: usize,
    first: Option<usize>,
) -> Vec<usize> {
    let mut bound = vec![false; slots];
    let mut left: Vec<usize> = (0..atoms.len()).collect();
    let mut out = Vec::with_capacity(atoms.len());
    let mut take = |i: usize, left: &mut Vec<usize>, bound: &mut Vec<bool>| {
        left.retain(|&j| j != i);
        for t in &atoms[i].1 {
            if let LTerm::Slot(s) = t {
                bound[*s as usize] = true;
            }
        }
        out.push(i);
    };
    if let Some(f) = first {
        take(f, &mut left, &mut bound);
    }
    while !left.is_empty() {
        let score = |i: usize| {
            let args = &atoms[i].1;
            let known = args
                .iter()
                .filter(|a| match a {
                    LTerm::Obj(_) => true,
                    LTerm::Slot(s) => bound[*s as usize],
                })
                .count();
            (known, usize::MAX - (args.len() - known), usize::MAX - i)
        };
        let best = left
            .iter()
            .copied()
            .max_by_key(|&i| score(i))
            .unwrap_or(left[0]);
        take(best, &mut left, &mut bound);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn atom(pred: u32, args: &[u32]) -> Box<[u32]> {
        std::iter::once(pred).chain(args.iter().copied()).collect()
    }

    #[test]
    fn joins_follow_shared_variables() {
        // (at ?p ?a) (road ?x ?y) (link ?a ?x): the link comes second.
        let at = (0, vec![LTerm::Slot(0), LTerm::Slot(1)]);
        let road = (1, vec![LTerm::Slot(2), LTerm::Slot(3)]);
        let link = (2, vec![LTerm::Slot(1), LTerm::Slot(2)]);
        let atoms = [at, road, link];
        assert_eq!(join_order(&atoms, 4, None), [0, 2, 1]);
        assert_eq!(join_order(&atoms, 4, Some(1)), [1, 2, 0]);
    }

    /// All bindings of `(edge ?a ?b) (edge ?b ?c)` over a chain 0-1-2-3.
    fn paths(reach: &mut Reach, parts: &[Part], round: &Round) -> Vec<[u32; 3]> {
        let atoms = [
            (0, vec![LTerm::Slot(0), LTerm::Slot(1)]),
            (0, vec![LTerm::Slot(1), LTerm::Slot(2)]),
        ];
        let steps = reach.plan(&atoms, parts, 3);
        let allowed = vec![vec![true; 4]; 3];
        let mut env = vec![None; 3];
        let mut out = Vec::new();
        reach.join(&steps, round, &allowed, &mut env, &|| false, &mut |e| {
            out.push([e[0].unwrap(), e[1].unwrap(), e[2].unwrap()])
        });
        out.sort();
        out
    }

    #[test]
    fn indexed_joins_find_every_binding_and_semi_naive_rounds_find_each_once() {
        let mut reach = Reach::new(1);
        reach.insert(atom(0, &[0, 1]));
        reach.insert(atom(0, &[1, 2]));
        let first = reach.sizes();
        assert!(!reach.insert(atom(0, &[0, 1])), "stored once");
        reach.insert(atom(0, &[2, 3]));
        let second = reach.sizes();
        let all = paths(
            &mut reach,
            &[Part::All, Part::All],
            &Round {
                before: &[0],
                now: &second,
            },
        );
        assert_eq!(all, [[0, 1, 2], [1, 2, 3]]);
        // Round 1 saw the first two edges; round 2 only what uses the new one.
        let r1 = paths(
            &mut reach,
            &[Part::New, Part::All],
            &Round {
                before: &[0],
                now: &first,
            },
        );
        assert_eq!(r1, [[0, 1, 2]]);
        let round = Round {
            before: &first,
            now: &second,
        };
        let mut r2 = paths(&mut reach, &[Part::New, Part::All], &round);
        r2.extend(paths(&mut reach, &[Part::Old, Part::New], &round));
        assert_eq!(r2, [[1, 2, 3]]);
    }
}

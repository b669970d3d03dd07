//! The state space every search walks: the operators applicable in a state
//! ([`Successors`]) and the states met so far, stored once ([`Registry`]).

use crate::task::{holds, test, Task};
use hashbrown::HashTable;
use std::hash::BuildHasher;

/// The applicable operators of a state, found through one trigger fact per
/// operator instead of a scan of all operators.
pub struct Successors {
    by_fact: Vec<Vec<u32>>,
    always: Vec<u32>,
}

impl Successors {
    pub fn new(task: &Task) -> Successors {
        let mut by_fact = vec![Vec::new(); task.num_facts()];
        let mut always = Vec::new();
        for (i, o) in task.operators.iter().enumerate() {
            // Prefer a condition that is false initially: it is more often
            // false, so the operator is looked at less often.
            let pos = o.pre.iter().filter(|l| l.positive);
            let trigger = pos
                .clone()
                .find(|l| !test(&task.init, l.fact))
                .or_else(|| pos.clone().next());
            match trigger {
                Some(l) => by_fact[l.fact as usize].push(i as u32),
                None => always.push(i as u32),
            }
        }
        Successors { by_fact, always }
    }

    pub fn applicable(&self, task: &Task, s: &[u64], out: &mut Vec<u32>) {
        out.clear();
        for &o in &self.always {
            if holds(s, &task.operators[o as usize].pre) {
                out.push(o);
            }
        }
        for (w, &word) in s.iter().enumerate() {
            let mut bits = word;
            while bits != 0 {
                let f = w * 64 + bits.trailing_zeros() as usize;
                bits &= bits - 1;
                if let Some(ops) = self.by_fact.get(f) {
                    for &o in ops {
                        if holds(s, &task.operators[o as usize].pre) {
                            out.push(o);
                        }
                    }
                }
            }
        }
    }
}

/// States stored once in an arena, found by hash.
pub(crate) struct Registry {
    words: usize,
    arena: Vec<u64>,
    table: HashTable<u32>,
    hasher: rustc_hash::FxBuildHasher,
}

impl Registry {
    pub(crate) fn new(words: usize) -> Registry {
        Registry {
            words,
            arena: Vec::new(),
            table: HashTable::new(),
            hasher: rustc_hash::FxBuildHasher,
        }
    }

    pub(crate) fn get(&self, id: u32) -> &[u64] {
        let i = id as usize * self.words;
        &self.arena[i..i + self.words]
    }

    fn hash(&self, s: &[u64]) -> u64 {
        self.hasher.hash_one(s)
    }

    /// The state's id, and whether it is new.
    pub(crate) fn insert(&mut self, s: &[u64]) -> (u32, bool) {
        let h = self.hash(s);
        let (arena, words) = (&self.arena, self.words);
        let at = |id: u32| &arena[id as usize * words..(id as usize + 1) * words];
        if let Some(&id) = self.table.find(h, |&id| at(id) == s) {
            return (id, false);
        }
        let id = (self.arena.len() / self.words) as u32;
        self.arena.extend_from_slice(s);
        let (arena, hasher) = (&self.arena, &self.hasher);
        self.table.insert_unique(h, id, |&id| {
            hasher.hash_one(&arena[id as usize * words..(id as usize + 1) * words])
        });
        (id, true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::task::AxiomScratch;
    use crate::test_util::rooms;

    #[test]
    fn the_registry_stores_each_state_once() {
        let mut r = Registry::new(2);
        assert_eq!(r.insert(&[1, 2]), (0, true));
        assert_eq!(r.insert(&[3, 4]), (1, true));
        assert_eq!(r.insert(&[1, 2]), (0, false));
        assert_eq!(r.get(1), &[3, 4]);
    }

    #[test]
    fn successors_are_the_applicable_operators() {
        let t = rooms();
        let succ = Successors::new(&t);
        let mut ax = AxiomScratch::default();
        let (mut s, mut next, mut app) = (t.init.clone(), Vec::new(), Vec::new());
        for _ in 0..3 {
            succ.applicable(&t, &s, &mut app);
            app.sort_unstable();
            let scan: Vec<u32> = (0..t.operators.len() as u32)
                .filter(|&o| holds(&s, &t.operators[o as usize].pre))
                .collect();
            assert_eq!(app, scan);
            let Some(&o) = app.first() else { break };
            t.apply(&t.operators[o as usize], &s, &mut next, &mut ax);
            std::mem::swap(&mut s, &mut next);
        }
    }
}

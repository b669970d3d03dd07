//! The truth of the ground atoms that cached ground actions mention, kept
//! in a dense table so that a replayed step tests and sets them by index
//! instead of hashing a key into the state's fact set.
//!
//! The table runs ahead of the [`State`]: a cached step changes only the
//! table and remembers which atoms it changed; [`TrackedFacts::flush`]
//! writes those into the state before anything reads the state's facts
//! (the general path, the goal). Atoms the table does not know are always
//! up to date in the state.

use crate::state::{Changes, Key, State};
use rustc_hash::FxHashMap;

/// One atom a cached condition tests: `atom` must be `positive`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Literal {
    pub atom: u32,
    pub positive: bool,
}

#[derive(Default)]
pub(super) struct TrackedFacts {
    ids: FxHashMap<Key, u32>,
    keys: Vec<Key>,
    truth: Vec<bool>,
    /// Whether the state may disagree with `truth` (set by cached steps,
    /// cleared by a flush); `unflushed` lists those atoms.
    stale: Vec<bool>,
    unflushed: Vec<u32>,
}

impl TrackedFacts {
    /// The id of a ground atom, tracked from now on. Its truth is read from
    /// `state`, which is up to date for an atom the table did not know.
    pub fn intern(&mut self, key: &[u32], state: &State) -> u32 {
        if let Some(&id) = self.ids.get(key) {
            return id;
        }
        let id = u32::try_from(self.keys.len()).expect("fewer than 2^32 tracked atoms");
        let key: Key = key.into();
        self.truth.push(state.facts.contains(&key));
        self.stale.push(false);
        self.ids.insert(key.clone(), id);
        self.keys.push(key);
        id
    }

    pub fn all_hold(&self, literals: &[Literal]) -> bool {
        literals
            .iter()
            .all(|l| self.truth[l.atom as usize] == l.positive)
    }

    /// Makes `atoms` true or false, leaving the state to the next flush.
    pub fn set(&mut self, atoms: &[u32], value: bool) {
        for &a in atoms {
            let i = a as usize;
            if self.truth[i] != value {
                self.truth[i] = value;
                if !self.stale[i] {
                    self.stale[i] = true;
                    self.unflushed.push(a);
                }
            }
        }
    }

    /// Writes every change since the last flush into `state`.
    pub fn flush(&mut self, state: &mut State) {
        for a in self.unflushed.drain(..) {
            let i = a as usize;
            self.stale[i] = false;
            let key = &self.keys[i];
            // An atom set and reset since the last flush is as the state
            // has it: test before inserting a copy of its key.
            if !self.truth[i] {
                state.facts.remove(key);
            } else if !state.facts.contains(key) {
                state.facts.insert(key.clone());
            }
        }
    }

    /// Follows changes the general path is about to apply to a flushed
    /// state, in the order [`crate::state::World::apply_changes`] applies
    /// them: deletes, then adds.
    pub fn note(&mut self, changes: &Changes) {
        debug_assert!(self.unflushed.is_empty(), "changes to a stale state");
        for (keys, value) in [(&changes.delete, false), (&changes.add, true)] {
            for k in keys {
                if let Some(&id) = self.ids.get(k) {
                    self.truth[id as usize] = value;
                }
            }
        }
    }
}

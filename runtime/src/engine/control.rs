//! Control nodes: the ordered families (Sequence, SequenceWithMemory,
//! Fallback and their reactive forms), written once, and Parallel.

use super::state::NodeState;
use super::{Engine, NodeDef, Status};

impl<'w> Engine<'w> {
    /// The ordered-children loop. `FALLBACK`: a child's success ends the
    /// node (else its failure does). `REACTIVE`: every tick starts from the
    /// first child, and a RUNNING child halts all the others. `MEMORY`: the
    /// child that ended the node is where the next tick starts
    /// (SequenceWithMemory). SKIPPED children are passed over; when all
    /// were, the node is SKIPPED.
    #[inline(never)]
    pub(super) fn tick_ordered<const FALLBACK: bool, const REACTIVE: bool, const MEMORY: bool>(
        &mut self,
        iu: usize,
        def: NodeDef,
    ) -> Status {
        let (stop, done) = if FALLBACK {
            (Status::Success, Status::Failure)
        } else {
            (Status::Failure, Status::Success)
        };
        let active = self.status[iu] == Status::Running;
        self.set(iu, Status::Running);
        let (mut idx, mut skipped) = if REACTIVE {
            (0, 0)
        } else {
            self.state[iu].child()
        };
        if !active {
            // BT.CPP counts the skipped children of this run only (a halted
            // SequenceWithMemory keeps its index, not its count).
            skipped = 0;
        }
        loop {
            if idx >= def.len {
                self.reset_children(def, 0);
                self.state[iu] = NodeState::Fresh;
                return if skipped == def.len {
                    Status::Skipped
                } else {
                    done
                };
            }
            let c = self.kid(def, idx);
            let fresh = MEMORY && self.status[c as usize] == Status::Idle;
            let s = self.tick_node(c);
            if s == Status::Running {
                if REACTIVE {
                    for k in (0..def.len).filter(|&k| k != idx) {
                        let o = self.kid(def, k);
                        self.reset(o);
                    }
                } else {
                    self.state[iu] = NodeState::Child { next: idx, skipped };
                }
                return Status::Running;
            }
            if s == stop {
                if MEMORY {
                    // The index is kept: the child that ended it runs again.
                    self.reset_children(def, idx);
                    self.state[iu] = NodeState::Child { next: idx, skipped };
                } else {
                    self.reset_children(def, 0);
                    self.state[iu] = NodeState::Fresh;
                }
                return stop;
            }
            if s == Status::Skipped {
                skipped += 1;
                if REACTIVE {
                    // So that it can be skipped again.
                    self.reset(c);
                }
            }
            idx += 1;
            // BT.CPP 4.10: a SequenceWithMemory child that started and
            // succeeded in this tick hands the flow back (RUNNING); the next
            // one runs at the next tick.
            if fresh && s == done && idx < def.len {
                self.state[iu] = NodeState::Child { next: idx, skipped };
                return Status::Running;
            }
        }
    }

    #[inline(never)]
    pub(super) fn tick_parallel(
        &mut self,
        iu: usize,
        def: NodeDef,
        success: i32,
        failure: i32,
    ) -> Status {
        self.set(iu, Status::Running);
        let n = def.len as i64;
        let need_s = threshold(success, n);
        let need_f = threshold(failure, n);
        let (s0, f0) = self.state[iu].tally();
        let (mut succ, mut fail) = (s0 as i64, f0 as i64);
        let mut skipped = 0;
        let mut out = Status::Running;
        for j in 0..def.len {
            let c = self.kid(def, j);
            if !self.status[c as usize].is_done() {
                match self.tick_node(c) {
                    Status::Success => succ += 1,
                    Status::Failure => fail += 1,
                    Status::Skipped => skipped += 1,
                    _ => {}
                }
            }
            // With a threshold counted from the end, SKIPPED children count
            // as successes (BT.CPP 4.10).
            if succ >= need_s || (success < 0 && succ + skipped as i64 >= need_s) {
                out = Status::Success;
                break;
            }
            if n - fail < need_s || fail == need_f {
                out = Status::Failure;
                break;
            }
        }
        if out == Status::Running {
            self.state[iu] = NodeState::Tally {
                success: succ as u32,
                failure: fail as u32,
            };
            if skipped == def.len {
                return Status::Skipped;
            }
        } else {
            self.state[iu] = NodeState::Fresh;
            self.reset_children(def, 0);
        }
        out
    }
}

/// A Parallel threshold over `n` children: negative counts from the end
/// (`-1`: all of them).
pub(super) fn threshold(t: i32, n: i64) -> i64 {
    if t < 0 {
        (n + t as i64 + 1).max(0)
    } else {
        t as i64
    }
}

#[cfg(test)]
mod tests {
    use super::threshold;

    #[test]
    fn parallel_thresholds_count_from_the_end_when_negative() {
        assert_eq!(threshold(-1, 5), 5);
        assert_eq!(threshold(-2, 5), 4);
        assert_eq!(threshold(2, 5), 2);
        assert_eq!(threshold(-9, 5), 0);
    }
}

//! The ground task the search runs on: facts numbered densely, states as
//! packed bitsets, operators with literal preconditions and (conditional)
//! effects, and layered axioms that compute derived facts in every state.

/// A fact index with a sign.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Lit {
    pub fact: u32,
    pub positive: bool,
}

impl Lit {
    pub fn pos(fact: u32) -> Lit {
        Lit {
            fact,
            positive: true,
        }
    }
}

/// One add or delete, made when its condition holds in the state before.
#[derive(Clone, Debug, PartialEq)]
pub struct GroundEffect {
    pub cond: Vec<Lit>,
    pub fact: u32,
    pub add: bool,
}

#[derive(Clone, Debug)]
pub struct Operator {
    /// Index into `domain.actions`.
    pub action: usize,
    pub args: Vec<u32>,
    pub pre: Vec<Lit>,
    pub effects: Vec<GroundEffect>,
    pub cost: u64,
}

/// `head` holds when every literal of `body` does; axioms of one layer only
/// negate facts of earlier layers.
#[derive(Clone, Debug)]
pub struct Axiom {
    pub head: u32,
    pub body: Vec<Lit>,
    pub layer: u32,
}

#[derive(Clone, Debug, Default)]
pub struct Task {
    /// Each fact's text, e.g. `(on a b)`.
    pub fact_names: Vec<String>,
    /// Each fact's predicate (an index into the domain's predicates);
    /// `u32::MAX` for auxiliary facts.
    pub fact_preds: Vec<u32>,
    /// Whether a fact is computed by axioms rather than set by operators.
    pub derived: Vec<bool>,
    pub operators: Vec<Operator>,
    /// Sorted by layer.
    pub axioms: Vec<Axiom>,
    pub layers: u32,
    /// The initial state, derived facts included.
    pub init: Vec<u64>,
    pub goal: Vec<Lit>,
    /// `total-cost` before the first step (0 unless the problem says otherwise).
    pub base_cost: f64,
    /// Whether every operator costs 1.
    pub unit_cost: bool,
    pub words: usize,
}

#[inline]
pub fn test(s: &[u64], f: u32) -> bool {
    s[(f >> 6) as usize] >> (f & 63) & 1 == 1
}

#[inline]
pub fn set(s: &mut [u64], f: u32) {
    s[(f >> 6) as usize] |= 1 << (f & 63);
}

#[inline]
pub fn clear(s: &mut [u64], f: u32) {
    s[(f >> 6) as usize] &= !(1 << (f & 63));
}

#[inline]
pub fn holds(s: &[u64], l: &[Lit]) -> bool {
    l.iter().all(|l| test(s, l.fact) == l.positive)
}

impl Task {
    pub fn num_facts(&self) -> usize {
        self.fact_names.len()
    }

    pub fn is_goal(&self, s: &[u64]) -> bool {
        holds(s, &self.goal)
    }

    /// The state after applying `op` in `s` (which it must be applicable
    /// in): conditions are read in `s`, deletes go first, then adds.
    pub fn apply(&self, op: &Operator, s: &[u64], out: &mut Vec<u64>, ax: &mut AxiomScratch) {
        out.clear();
        out.extend_from_slice(s);
        for e in &op.effects {
            if !e.add && holds(s, &e.cond) {
                clear(out, e.fact);
            }
        }
        for e in &op.effects {
            if e.add && holds(s, &e.cond) {
                set(out, e.fact);
            }
        }
        self.close(out, ax);
    }

    /// Recomputes the derived facts of a state, layer by layer.
    pub fn close(&self, s: &mut [u64], ax: &mut AxiomScratch) {
        if self.axioms.is_empty() {
            return;
        }
        ax.prepare(self);
        for (w, m) in s.iter_mut().zip(&ax.derived_mask) {
            *w &= !m;
        }
        let mut start = 0;
        while start < self.axioms.len() {
            let layer = self.axioms[start].layer;
            let mut end = start;
            while end < self.axioms.len() && self.axioms[end].layer == layer {
                end += 1;
            }
            ax.queue.clear();
            for i in start..end {
                let a = &self.axioms[i];
                let mut waiting = 0u32;
                let mut ok = true;
                for l in &a.body {
                    if l.positive && ax.layer_of[l.fact as usize] == layer as i64 {
                        waiting += 1;
                    } else if test(s, l.fact) != l.positive {
                        ok = false;
                        break;
                    }
                }
                ax.waiting[i] = if ok { waiting } else { u32::MAX };
                if ok && waiting == 0 && !test(s, a.head) {
                    set(s, a.head);
                    ax.queue.push(a.head);
                }
            }
            while let Some(f) = ax.queue.pop() {
                for &i in &ax.uses[f as usize] {
                    let i = i as usize;
                    if i < start || i >= end || ax.waiting[i] == u32::MAX {
                        continue;
                    }
                    ax.waiting[i] -= 1;
                    let h = self.axioms[i].head;
                    if ax.waiting[i] == 0 && !test(s, h) {
                        set(s, h);
                        ax.queue.push(h);
                    }
                }
            }
            start = end;
        }
    }
}

/// Work arrays for axiom evaluation, built once per task.
#[derive(Default, Debug)]
pub struct AxiomScratch {
    ready: bool,
    derived_mask: Vec<u64>,
    /// A derived fact's layer; -1 for facts operators set.
    layer_of: Vec<i64>,
    /// Axioms whose body has the fact positively in the same layer.
    uses: Vec<Vec<u32>>,
    waiting: Vec<u32>,
    queue: Vec<u32>,
}

impl AxiomScratch {
    fn prepare(&mut self, t: &Task) {
        if self.ready {
            return;
        }
        self.ready = true;
        self.derived_mask = vec![0; t.words];
        self.layer_of = vec![-1; t.num_facts()];
        for (f, &d) in t.derived.iter().enumerate() {
            if d {
                set(&mut self.derived_mask, f as u32);
            }
        }
        for a in &t.axioms {
            self.layer_of[a.head as usize] = a.layer as i64;
        }
        self.uses = vec![Vec::new(); t.num_facts()];
        for (i, a) in t.axioms.iter().enumerate() {
            for l in &a.body {
                if l.positive && self.layer_of[l.fact as usize] == a.layer as i64 {
                    self.uses[l.fact as usize].push(i as u32);
                }
            }
        }
        self.waiting = vec![0; t.axioms.len()];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::{fact, rooms};

    #[test]
    fn bits_set_clear_and_test() {
        let mut s = vec![0u64; 2];
        set(&mut s, 3);
        set(&mut s, 70);
        assert!(test(&s, 3) && test(&s, 70) && !test(&s, 4));
        clear(&mut s, 70);
        assert!(!test(&s, 70));
        assert!(holds(
            &s,
            &[
                Lit::pos(3),
                Lit {
                    fact: 4,
                    positive: false
                }
            ]
        ));
        assert!(!holds(&s, &[Lit::pos(4)]));
    }

    #[test]
    fn deletes_go_first_and_conditions_read_the_state_before() {
        let t = Task {
            fact_names: vec!["(a)".into(), "(b)".into(), "(c)".into()],
            derived: vec![false; 3],
            words: 1,
            ..Task::default()
        };
        let o = Operator {
            action: 0,
            args: Vec::new(),
            pre: Vec::new(),
            effects: vec![
                // (a) deleted and added: stays true.
                GroundEffect {
                    cond: vec![],
                    fact: 0,
                    add: false,
                },
                GroundEffect {
                    cond: vec![],
                    fact: 0,
                    add: true,
                },
                // (b) is deleted; (c) is added when (b) held before.
                GroundEffect {
                    cond: vec![],
                    fact: 1,
                    add: false,
                },
                GroundEffect {
                    cond: vec![Lit::pos(1)],
                    fact: 2,
                    add: true,
                },
            ],
            cost: 1,
        };
        let mut out = Vec::new();
        let mut ax = AxiomScratch::default();
        t.apply(&o, &[0b011], &mut out, &mut ax);
        assert_eq!(out, [0b101]);
    }

    #[test]
    fn derived_facts_follow_the_state() {
        let t = rooms();
        let reach_vault = fact(&t, "(reachable vault)");
        let at_hall = fact(&t, "(at hall)");
        assert!(test(&t.init, reach_vault), "the doors lead on to the vault");
        let mut s = t.init.clone();
        clear(&mut s, at_hall);
        let mut ax = AxiomScratch::default();
        t.close(&mut s, &mut ax);
        assert!(!test(&s, reach_vault), "nowhere to start from");
        set(&mut s, fact(&t, "(at lab)"));
        t.close(&mut s, &mut ax);
        assert!(test(&s, reach_vault));
        assert!(!test(&s, fact(&t, "(reachable hall)")));
    }
}

//! What one attempt leaves the next: the world's state, the faults' run-time
//! state, the tick, and the goal's adjustments (goals faults added, parts
//! replaced by spares, priority orders to reach first).

use super::LoopError;
use crate::faults::Faults;
use btc_pddl::diagnostic::codes;
use btc_pddl::logic::{Formula, Name, Terms};
use btc_pddl::state::{State, World};
use btc_runtime::error::LoadError;
use btc_runtime::Kb;

/// What carries from one attempt to the next.
#[derive(Default)]
pub(super) struct Carry {
    pub state: Option<State>,
    pub faults: Option<Faults>,
    pub tick: u64,
    /// Goals faults added (high-priority orders).
    pub extra_goals: Vec<Formula>,
    /// Parts in the goal replaced by spares: (part, spare).
    pub substitutions: Vec<(Name, Name)>,
    /// Goals of high-priority orders that preempted a plan, to be reached
    /// before the rest of the goal.
    pub priority: Vec<Formula>,
}

impl Carry {
    /// The KB of the problem, in the carried state.
    pub fn kb<'w>(&self, w: &'w World) -> Kb<'w> {
        let mut kb = Kb::new(w);
        if let Some(s) = &self.state {
            kb.state = s.clone();
        }
        kb
    }

    /// The goal: the problem's with spares for discarded parts, and the
    /// goals faults added.
    pub fn goal(&self, base: &Formula) -> Formula {
        let g = base.replace_objects(&self.substitutions);
        if self.extra_goals.is_empty() {
            return g;
        }
        let mut parts = vec![g];
        parts.extend(
            self.extra_goals
                .iter()
                .map(|e| e.replace_objects(&self.substitutions)),
        );
        Formula::And(parts)
    }

    /// The goals of the priority orders still to do, with spares for
    /// discarded parts.
    pub fn priority_goal(&self) -> Formula {
        let parts: Vec<Formula> = self
            .priority
            .iter()
            .map(|g| g.replace_objects(&self.substitutions))
            .collect();
        Formula::conjunction(parts).unwrap_or_else(Formula::truth)
    }

    /// A spare for a discarded part: an object of the same types, named
    /// `PART_...`, that is somewhere in the KB, not itself discarded and
    /// not already named by the goal.
    pub fn spare(&self, kb: &Kb<'_>, part: &Name, named: &[Name]) -> Option<Name> {
        let w = kb.world;
        let id = w.object_id(part)?;
        let prefix = format!("{part}_");
        let mut cands: Vec<(&str, u32)> = (0..w.object_count() as u32)
            .map(|o| (w.object_name(o), o))
            .filter(|(n, o)| n.starts_with(&prefix) && w.object_types(*o) == w.object_types(id))
            .collect();
        cands.sort();
        cands
            .into_iter()
            .find(|(n, o)| {
                !kb.facts_mentioning(*o).is_empty()
                    && !named.iter().any(|x| &**x == *n)
                    && !self
                        .substitutions
                        .iter()
                        .any(|(p, s)| &**p == *n || &**s == *n)
            })
            .map(|(n, _)| btc_pddl::logic::name(n))
    }
}

/// `goal` made a condition of the KB's world, for `Kb::set_goal`.
pub(super) fn goal_formula(kb: &mut Kb<'_>, goal: &Formula) -> Result<u32, LoopError> {
    kb.formula(goal).map_err(|m| {
        LoopError::Tree(LoadError::new(
            codes::X_KB,
            format!("the adjusted goal `{goal}` is not a condition of this problem: {m}"),
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use btc_pddl::logic::{decode, name};

    #[test]
    fn spares_replace_objects_not_words() {
        let base = decode::formula("(and (on battery_red agv1) (on battery_red_2 tray))").unwrap();
        let mut c = Carry::default();
        c.substitutions.push((name("battery_red"), name("b2")));
        c.extra_goals
            .push(decode::formula("(on battery_red agv2)").unwrap());
        assert_eq!(
            c.goal(&base).to_string(),
            "(and (and (on b2 agv1) (on battery_red_2 tray)) (on b2 agv2))"
        );
        assert!(base.objects().contains(&name("battery_red")));
        assert!(!decode::formula("(on p10 agv1)")
            .unwrap()
            .objects()
            .contains(&name("p1")));
    }
}

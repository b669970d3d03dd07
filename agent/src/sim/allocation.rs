//! The paper's allocation rules (Liu et al. 2024, section 3.2) as pure
//! functions over what the task manager knows: which tasks an idle agent
//! looks at and in what order, whether a combined task is split or
//! converted, and whether a running agent is preempted for a high-priority
//! order. The task manager gathers the facts; the rules decide.

use super::tasks::TaskId;
use crate::trial::OrderType;

/// Rule 1, with high priority first: the (priority, queue) pairs an agent
/// looks at, in order. An agent serves only its robot's queues, in the
/// order the cell lists them; every high-priority task of them comes before
/// any regular one.
pub fn visit_order(queues: &[OrderType]) -> impl Iterator<Item = (bool, OrderType)> + '_ {
    [true, false]
        .into_iter()
        .flat_map(move |prio| queues.iter().map(move |&q| (prio, q)))
}

/// What the ranking of a queued task reads.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    pub task: TaskId,
    /// A part of its kind lies on the conveyor now.
    pub on_conveyor: bool,
    /// The tick it was created.
    pub created: u64,
}

/// Rule 3: within a queue, tasks whose part is on the conveyor first (the
/// belt carries it away), then the oldest, then by id.
pub fn rank(cands: &mut [Candidate]) {
    cands.sort_by_key(|c| (!c.on_conveyor, c.created, c.task));
}

/// Rule 2's decision for a combined task.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Combine {
    /// A kitting half onto this AGV's quadrant, and an assembly half that
    /// takes the part from it.
    Split { agv: u8, quadrant: u8 },
    /// One assembly task that takes its part from the bins or the belt.
    Convert,
}

/// Rule 2: a combined task is split into a kitting and an assembly task
/// when every other agent is idle (and can kit) and an AGV has room for the
/// kitting half (`place`, asked only then); converted to an assembly task
/// otherwise.
pub fn split_or_convert(
    agents: usize,
    others_idle: bool,
    place: impl FnOnce() -> Option<(u8, u8)>,
) -> Combine {
    if others_idle && agents > 1 {
        if let Some((agv, quadrant)) = place() {
            return Combine::Split { agv, quadrant };
        }
    }
    Combine::Convert
}

/// Preemption: an agent on a regular task stops it for a high-priority
/// order when it could do one of the order's queued tasks and no other
/// idle agent could.
pub fn preempts(running_priority: bool, can_do: bool, an_idle_other_can: bool) -> bool {
    !running_priority && can_do && !an_idle_other_can
}

#[cfg(test)]
mod tests {
    use super::*;
    use OrderType::{Assembly, Combined, Kitting};

    #[test]
    fn rule_1_an_agent_looks_at_its_own_queues_in_order_high_priority_first() {
        let floor: Vec<_> = visit_order(&[Kitting]).collect();
        assert_eq!(floor, [(true, Kitting), (false, Kitting)]);
        let ceiling: Vec<_> = visit_order(&[Assembly, Combined, Kitting]).collect();
        assert_eq!(
            ceiling,
            [
                (true, Assembly),
                (true, Combined),
                (true, Kitting),
                (false, Assembly),
                (false, Combined),
                (false, Kitting)
            ]
        );
        assert_eq!(visit_order(&[]).count(), 0);
    }

    #[test]
    fn rule_2_split_when_the_others_are_idle_and_an_agv_has_room_else_convert() {
        let room = || Some((2, 3));
        assert_eq!(
            split_or_convert(2, true, room),
            Combine::Split {
                agv: 2,
                quadrant: 3
            }
        );
        assert_eq!(split_or_convert(2, false, room), Combine::Convert);
        assert_eq!(split_or_convert(2, true, || None), Combine::Convert);
        // One agent alone never splits: nobody would take the other half.
        assert_eq!(split_or_convert(1, true, room), Combine::Convert);
        // The AGV is looked for only when a split is possible.
        let asked = std::cell::Cell::new(false);
        split_or_convert(2, false, || {
            asked.set(true);
            None
        });
        assert!(!asked.get());
    }

    #[test]
    fn rule_3_conveyor_parts_first_then_the_oldest() {
        let c = |task, on_conveyor, created| Candidate {
            task,
            on_conveyor,
            created,
        };
        let mut cands = vec![c(0, false, 1), c(1, true, 5), c(2, false, 0), c(3, true, 5)];
        rank(&mut cands);
        let order: Vec<TaskId> = cands.iter().map(|c| c.task).collect();
        assert_eq!(order, [1, 3, 2, 0]);
    }

    #[test]
    fn preemption_stops_a_regular_task_only_for_an_agent_that_is_needed() {
        assert!(preempts(false, true, false));
        assert!(!preempts(true, true, false), "a priority task is kept");
        assert!(!preempts(false, false, false), "it could not help");
        assert!(!preempts(false, true, true), "an idle agent takes it");
    }
}

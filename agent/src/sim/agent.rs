//! One agent per robot (the paper's execution level): the queues its
//! robot serves, the task it runs with its tree, the resources it holds,
//! and its figures for the report.

use super::tasks::{Attempt, Resource, TaskId};
use crate::trial::{OrderType, Robot};
use btc_lang::db::CompileJob;
use btc_pddl::state::State;
use btc_runtime::{Engine, Status};

pub struct AgentRt<'w> {
    pub robot: Robot,
    pub obj: u32,
    pub queues: Vec<OrderType>,
    pub job: CompileJob,
    pub plan_path: String,
    pub task: Option<TaskId>,
    pub engine: Option<Engine<'w>>,
    pub resources: Vec<Resource>,
    pub attempt: Option<Attempt>,
    pub busy: u64,
    pub done: usize,
    pub failed: usize,
    pub plans: usize,
    pub planning_ms: f64,
}

impl<'w> AgentRt<'w> {
    pub fn new(
        robot: Robot,
        obj: u32,
        queues: Vec<OrderType>,
        job: CompileJob,
        plan_path: String,
    ) -> AgentRt<'w> {
        AgentRt {
            robot,
            obj,
            queues,
            job,
            plan_path,
            task: None,
            engine: None,
            resources: Vec::new(),
            attempt: None,
            busy: 0,
            done: 0,
            failed: 0,
            plans: 0,
            planning_ms: 0.0,
        }
    }

    pub fn idle(&self) -> bool {
        self.task.is_none()
    }
}

/// Runs `f` on an engine acting on the shared world's state: the engine
/// owns its KB, so the state is lent to it for the call and taken back.
/// The one place the world changes hands.
fn in_world<T>(
    engine: &mut Engine<'_>,
    world: &mut State,
    f: impl FnOnce(&mut Engine<'_>) -> T,
) -> T {
    let ekb = engine.kb.as_mut().expect("built with a KB");
    std::mem::swap(&mut ekb.state, world);
    let out = f(engine);
    let ekb = engine.kb.as_mut().expect("built with a KB");
    std::mem::swap(&mut ekb.state, world);
    out
}

/// One tick of a tree in the shared world: its status and whether its
/// goal holds.
pub fn step(engine: &mut Engine<'_>, world: &mut State) -> (Status, bool) {
    in_world(engine, world, |e| {
        let status = e.step();
        (status, e.goal().is_none_or(|g| g.0))
    })
}

/// Halts a tree in the shared world.
pub fn halt(engine: &mut Engine<'_>, world: &mut State) {
    in_world(engine, world, |e| e.halt_all());
}

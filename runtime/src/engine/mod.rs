//! The engine: a loaded tree compiled into a flat arena (nodes in preorder,
//! children as index ranges into one array, an enum per node), ticked with
//! BehaviorTree.CPP v4 semantics. Per-node state is one typed value per
//! node ([`NodeState`]); ports are resolved to constants or blackboard
//! slots when the tree is built, so a tick neither allocates nor looks
//! anything up by name.
//!
//! The parts: `build` compiles a [`TreeDoc`](crate::spec::TreeDoc) into the
//! arena; `control`, `decorator`, `leaf` and `step` are the tick semantics
//! of each family of nodes; `record` is why nodes fail and the fault
//! records; the tick's observers and hooks are `observe` (status changes
//! and events go to the caller's observers), `inject` (the caller's fault
//! injector: before a tick, when a step starts, when an action leaf is
//! ticked, when a condition is read) and the controller (commands of
//! action leaves).

mod build;
mod control;
mod decorator;
mod flow;
mod guard;
mod handled;
mod inject;
mod leaf;
mod observe;
pub(crate) mod port;
mod record;
mod state;
pub(crate) mod status;
mod step;
pub(crate) mod value;

pub use inject::{ActionLeaf, FaultOutcome, Injection, Injector, Interference};
pub use observe::{Observer, RunView, TickEvent};
pub(crate) use port::{PortBind, Src};
pub use record::FaultRecord;
pub(crate) use record::Reason;
pub use status::Status;
pub use value::Value;

use crate::controller::Controller;
use crate::handler::{ActionHandler, HaltHandler};
use crate::kb::{ConditionId, EffectId, FormulaId, Kb};
use serde::Serialize;
use state::NodeState;
use step::StepRt;

/// Deepest nesting of nodes (subtrees expanded) the engine runs.
pub const MAX_DEPTH: usize = 256;
/// Deepest chain of SubTree calls.
pub const MAX_CALLS: usize = 32;

/// What a node of the arena does, with what it was built with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Op {
    Sequence,
    ReactiveSequence,
    SequenceWithMemory,
    Fallback,
    ReactiveFallback,
    Parallel {
        success: i32,
        failure: i32,
    },
    Inverter,
    ForceSuccess,
    ForceFailure,
    KeepRunningUntilFailure,
    Retry(Arg<i32>),
    Repeat(Arg<i32>),
    Timeout(Arg<u64>),
    IfThenElse,
    WhileDoElse,
    /// The variable is port `variable`; the cases are the `cases` ports
    /// after `first_case`.
    Switch {
        variable: u32,
        first_case: u32,
        cases: u32,
    },
    Delay(Arg<u64>),
    RunOnce {
        then_skip: bool,
    },
    Precondition {
        script: u32,
        otherwise: Status,
    },
    SubTree,
    Step(u32),
    AlwaysSuccess,
    AlwaysFailure,
    Sleep(u32),
    SetBlackboard {
        value: u32,
        slot: u32,
    },
    KbHolds(FormulaId),
    KbApply(EffectId),
    WaitForStep(u32),
    Script(u32),
    ScriptCondition(u32),
    Condition(u32),
    Action(u32),
}

/// A decorator's count or duration: fixed, or read from a blackboard slot
/// when the node is ticked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Arg<T> {
    Fixed(T),
    Slot(u32),
}

#[derive(Clone, Copy, Debug)]
pub(crate) struct NodeDef {
    pub op: Op,
    pub first: u32,
    pub len: u32,
    /// Its pre- and post-condition scripts (an index into
    /// `Engine::guards`), or [`NO_GUARD`].
    pub guard: u32,
}

/// A node without pre- or post-conditions.
pub(crate) const NO_GUARD: u32 = u32::MAX;

/// What the trace and the reports say about a node.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NodeMeta {
    /// The registration ID (`Sequence`, `MoveTo`, `SubTree`...).
    pub id: String,
    /// Its `name`, or the ID.
    pub name: String,
    /// The plan step (0-based) the node belongs to.
    pub step: Option<u32>,
    pub parent: Option<u32>,
}

pub(crate) struct ActionInfo {
    pub id: Box<str>,
    pub ports: (u32, u32),
    /// The embedder's implementation ([`Engine::set_action_handler`]).
    pub handler: Option<u32>,
    /// What hears of its halts ([`Engine::set_halt_handler`]).
    pub on_halt: Option<u32>,
}

pub(crate) struct CondInfo {
    /// The model's formula, compiled over the ports it names (`None`: a
    /// condition the executor implements, simulated as SUCCESS).
    pub formula: Option<ConditionId>,
    /// For each slot of the formula, the port (an index into
    /// `Engine::ports`) whose object fills it.
    pub slot_ports: Box<[u32]>,
    /// The ports' objects at blackboard generation `generation`, or why a
    /// port names no object.
    pub objects: Result<Vec<u32>, String>,
    pub generation: u64,
}

#[derive(Clone, Debug)]
pub struct Options {
    /// Ticks an action leaf stays RUNNING before it succeeds.
    pub ticks_per_action: u32,
    /// Simulated milliseconds per tick (`Sleep`, `Timeout`).
    pub ms_per_tick: u64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            ticks_per_action: 1,
            ms_per_tick: 10,
        }
    }
}

pub struct Engine<'w> {
    pub(crate) nodes: Vec<NodeDef>,
    pub(crate) kids: Vec<u32>,
    pub meta: Vec<NodeMeta>,
    pub(crate) ports: Vec<PortBind>,
    pub(crate) actions: Vec<ActionInfo>,
    pub(crate) conds: Vec<CondInfo>,
    pub(crate) scripts: Vec<guard::CompiledScript>,
    pub(crate) guards: Vec<guard::Guard>,
    /// Blackboard entry names (`Tree#instance/key`) and values.
    pub slot_names: Vec<String>,
    pub(crate) bb: Vec<Value>,
    pub(crate) bb_gen: u64,
    pub(crate) status: Vec<Status>,
    pub(crate) state: Vec<NodeState>,
    pub kb: Option<Kb<'w>>,
    pub(crate) steps: Vec<StepRt>,
    pub(crate) opts: Options,
    pub tick: u64,
    pub(crate) now_ms: u64,
    /// Told of every event ([`Engine::observe`]).
    pub(crate) observers: Vec<Box<dyn Observer>>,
    pub(crate) last_failure: Option<(u32, Reason)>,
    pub records: Vec<FaultRecord>,
    /// The caller's fault injector ([`Engine::inject`]).
    pub(crate) injector: Option<Box<dyn Injector>>,
    /// Some injected fault may happen or is in effect: leaves consult the
    /// injector.
    pub(crate) inject_live: bool,
    pub(crate) controller: Option<Controller>,
    pub(crate) handlers: Vec<ActionHandler<'w>>,
    pub(crate) halt_handlers: Vec<HaltHandler<'w>>,
    pub(crate) record_slots: [u32; 4],
    /// The step that started last, while it has not finished.
    pub(crate) step_running: Option<u32>,
}

impl<'w> Engine<'w> {
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    pub fn status_of(&self, node: u32) -> Status {
        self.status[node as usize]
    }

    pub fn root_status(&self) -> Status {
        self.status.first().copied().unwrap_or(Status::Idle)
    }

    /// A blackboard entry by its full name (`MainTree/fault_reason`).
    pub fn blackboard(&self, name: &str) -> Option<&Value> {
        let i = self.slot_names.iter().position(|n| n == name)?;
        self.bb.get(i)
    }

    /// The IDs of the tree's action leaves (what a fault's `on_action`
    /// can name), each once.
    pub fn action_ids(&self) -> Vec<&str> {
        let mut ids: Vec<&str> = self.actions.iter().map(|a| &*a.id).collect();
        ids.sort_unstable();
        ids.dedup();
        ids
    }

    pub fn steps_total(&self) -> usize {
        self.steps.iter().filter(|s| !s.skipped).count()
    }

    pub fn steps_done(&self) -> usize {
        self.steps.iter().filter(|s| s.finished).count()
    }

    pub fn step_label(&self, step: usize) -> Option<&str> {
        self.steps.get(step).map(|s| s.label.as_str())
    }

    pub fn attach_controller(&mut self, c: Controller) {
        self.controller = Some(c);
    }

    pub fn take_controller(&mut self) -> Option<Controller> {
        self.controller.take()
    }

    /// Whether the problem's goal holds in the KB (`None` without a KB).
    pub fn goal(&self) -> Option<(bool, Option<String>)> {
        self.kb.as_ref().map(Kb::goal)
    }

    /// One tick of the whole tree.
    pub fn tick_once(&mut self) -> Status {
        self.tick += 1;
        self.now_ms = self.tick.saturating_mul(self.opts.ms_per_tick);
        if let Some(c) = self.controller.as_mut() {
            c.poll();
        }
        if self.injector.is_some() {
            self.inject_before_tick();
        }
        if self.nodes.is_empty() {
            return Status::Success;
        }
        self.tick_node(0)
    }

    /// Ticks until the root is no longer RUNNING, or `max_ticks` have run
    /// (then the tree is halted). `each` sees the engine after every tick.
    pub fn run(&mut self, max_ticks: u64, mut each: impl FnMut(&mut Engine<'w>)) -> Status {
        if max_ticks == 0 {
            self.finish(Status::Running);
            return Status::Running;
        }
        loop {
            let s = self.tick_once();
            each(self);
            if s != Status::Running {
                self.finish(s);
                return s;
            }
            if self.tick >= max_ticks {
                self.halt_all();
                self.finish(Status::Running);
                return Status::Running;
            }
            if let Some(c) = self.controller.as_mut() {
                c.wait_any(std::time::Duration::from_secs(1));
            }
        }
    }

    /// One tick as [`Engine::run`] makes it: once the root is done, the
    /// failure that ended it (or the goal that does not hold) is recorded.
    /// The task level (`btc trial`) ticks several engines on one clock this
    /// way.
    pub fn step(&mut self) -> Status {
        let s = self.tick_once();
        if s != Status::Running {
            self.finish(s);
        }
        s
    }

    /// Ticks like [`Engine::run`], but halts the tree and returns
    /// `(Status::Running, true)` as soon as `stop` says so after a tick
    /// (replanning preempts a plan this way).
    pub fn run_until(
        &mut self,
        max_ticks: u64,
        mut stop: impl FnMut(&mut Engine<'w>) -> bool,
    ) -> (Status, bool) {
        if max_ticks == 0 {
            self.finish(Status::Running);
            return (Status::Running, false);
        }
        loop {
            let s = self.tick_once();
            if s != Status::Running {
                self.finish(s);
                return (s, false);
            }
            if stop(self) {
                self.halt_all();
                return (Status::Running, true);
            }
            if self.tick >= max_ticks {
                self.halt_all();
                self.finish(Status::Running);
                return (Status::Running, false);
            }
            if let Some(c) = self.controller.as_mut() {
                c.wait_any(std::time::Duration::from_secs(1));
            }
        }
    }

    /// Halts the whole tree (every running node, leaves first).
    pub fn halt_all(&mut self) {
        if !self.nodes.is_empty() {
            self.reset(0);
        }
    }

    #[inline]
    pub(crate) fn kid(&self, def: NodeDef, j: u32) -> u32 {
        self.kids[(def.first + j) as usize]
    }

    /// A node's status changes; the observers are told.
    #[inline]
    pub(crate) fn set(&mut self, i: usize, s: Status) {
        let old = self.status[i];
        if old != s {
            self.status[i] = s;
            if self.observed() {
                self.observe_status(i as u32, old, s);
            }
        }
    }

    pub(crate) fn reset_children(&mut self, def: NodeDef, from: u32) {
        for j in from..def.len {
            let c = self.kid(def, j);
            self.reset(c);
        }
    }

    /// BT.CPP's `haltChild`: a RUNNING node is halted (its own state
    /// cleared, its children reset), then the node goes back to IDLE. A
    /// node that finished only goes back to IDLE: what is below it, and its
    /// own state, stay as they are (BT.CPP's `resetStatus`).
    #[inline]
    pub(crate) fn reset(&mut self, i: u32) {
        let iu = i as usize;
        match self.status[iu] {
            Status::Idle => return,
            Status::Running => self.halt(i),
            _ => {}
        }
        self.set(iu, Status::Idle);
    }

    /// BT.CPP's `halt()` of a RUNNING node: its children are reset, its
    /// state is cleared (but what BT.CPP keeps), its `_onHalted` runs.
    #[inline(never)]
    fn halt(&mut self, i: u32) {
        let iu = i as usize;
        let def = self.nodes[iu];
        self.reset_children(def, 0);
        let keep = match (def.op, self.state[iu]) {
            // BT.CPP v4 keeps the index of a halted SequenceWithMemory.
            (Op::SequenceWithMemory, _) => true,
            // RunOnce remembers for good that it ran, and Precondition that
            // its child was let in (neither resets on halt in BT.CPP).
            (Op::RunOnce { .. } | Op::Precondition { .. }, _) => true,
            // A halted action's command still runs; its completion is moot.
            (Op::Action(_), NodeState::Commanded(seq)) => {
                if let Some(c) = self.controller.as_mut() {
                    c.forget(seq);
                }
                false
            }
            _ => false,
        };
        if !keep {
            self.state[iu] = NodeState::Fresh;
        }
        if let Op::Action(a) = def.op {
            if let Some(h) = self.actions[a as usize].on_halt {
                self.halt_handled(i, a, h);
            }
        }
        if def.guard != NO_GUARD {
            self.on_halted(i, def.guard);
        }
    }

    /// Ticks node `i`: its pre-conditions, the family's semantics, its
    /// post-conditions, then the status is set (a SKIPPED node keeps its
    /// own, as in BT.CPP).
    ///
    /// `tick_node` and `tick_op` are inlined into every family's loop, and
    /// with them the common leaves (built-ins, actions, conditions), so
    /// that ticking a leaf costs no call; the control and decorator
    /// families are `#[inline(never)]`, which ends the recursion there and
    /// keeps their frames off a leaf's path (this halved the time per leaf
    /// tick).
    #[inline(always)]
    pub(crate) fn tick_node(&mut self, i: u32) -> Status {
        let iu = i as usize;
        let def = self.nodes[iu];
        if def.guard != NO_GUARD {
            return self.tick_guarded(i, def);
        }
        let s = self.tick_op(i, def);
        if s != Status::Skipped {
            self.set(iu, s);
        }
        s
    }

    #[inline(always)]
    pub(crate) fn tick_op(&mut self, i: u32, def: NodeDef) -> Status {
        let iu = i as usize;
        match def.op {
            Op::Sequence => self.tick_ordered::<false, false, false>(iu, def),
            Op::SequenceWithMemory => self.tick_ordered::<false, false, true>(iu, def),
            Op::Fallback => self.tick_ordered::<true, false, false>(iu, def),
            Op::ReactiveSequence => self.tick_ordered::<false, true, false>(iu, def),
            Op::ReactiveFallback => self.tick_ordered::<true, true, false>(iu, def),
            Op::Parallel { success, failure } => self.tick_parallel(iu, def, success, failure),
            Op::Inverter
            | Op::ForceSuccess
            | Op::ForceFailure
            | Op::KeepRunningUntilFailure
            | Op::SubTree => self.tick_wrapper(i, def),
            Op::Retry(n) => self.tick_loop::<true>(i, def, n),
            Op::Repeat(n) => self.tick_loop::<false>(i, def, n),
            Op::Timeout(msec) => self.tick_timeout(i, def, msec),
            Op::IfThenElse => self.tick_if_then_else(i, def),
            Op::WhileDoElse => self.tick_while_do_else(i, def),
            Op::Switch {
                variable,
                first_case,
                cases,
            } => self.tick_switch(iu, def, variable, first_case, cases),
            Op::Delay(msec) => self.tick_delay(i, def, msec),
            Op::RunOnce { then_skip } => self.tick_run_once(iu, def, then_skip),
            Op::Precondition { script, otherwise } => {
                self.tick_precondition(i, def, script, otherwise)
            }
            Op::Step(k) => self.tick_step(i, def, k),
            Op::AlwaysSuccess => Status::Success,
            Op::AlwaysFailure => self.fail(i, "AlwaysFailure"),
            Op::Sleep(p) => self.tick_sleep(iu, p),
            Op::SetBlackboard { value, slot } => self.tick_set_blackboard(value, slot),
            Op::KbHolds(f) => self.tick_kb_holds(i, f),
            Op::KbApply(e) => self.tick_kb_apply(e),
            Op::WaitForStep(k) => self.tick_wait_for_step(i, k),
            Op::Script(k) => self.tick_script(i, k),
            Op::ScriptCondition(k) => self.tick_script_condition(i, k),
            Op::Condition(c) => self.tick_condition(i, c),
            Op::Action(a) => self.tick_action(i, a),
        }
    }
}

#[cfg(test)]
mod tests;

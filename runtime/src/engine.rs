//! The engine: a loaded tree compiled into a flat arena (nodes in preorder,
//! children as index ranges into one array, an enum per node), ticked with
//! BehaviorTree.CPP v4 semantics. Per-node state lives in parallel vectors;
//! ports are resolved to constants or blackboard slots when the tree is
//! built, so a tick neither allocates nor looks anything up by name.

use crate::controller::{Command, Controller};
use crate::error::LoadError;
use crate::faults::FaultRt;
use crate::kb::{ConditionId, EffectId, FormulaId, Kb};
use crate::spec::{default_name, Amount, Kind, SNode, StepConditions, TreeDoc};
use btc_ir::{LeafKind, NodeModel, PortValue};
use btc_pddl::diagnostic::{codes, did_you_mean};
use btc_pddl::logic::{self, Binding, Effect, Formula, Name, Terms};
use rustc_hash::FxHashMap;
use serde::Serialize;
use std::rc::Rc;

/// Deepest nesting of nodes (subtrees expanded) the engine runs.
pub const MAX_DEPTH: usize = 256;
/// Deepest chain of SubTree calls.
pub const MAX_CALLS: usize = 32;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "UPPERCASE")]
pub enum Status {
    Idle,
    Running,
    Success,
    Failure,
}

impl Status {
    pub fn name(self) -> &'static str {
        match self {
            Status::Idle => "IDLE",
            Status::Running => "RUNNING",
            Status::Success => "SUCCESS",
            Status::Failure => "FAILURE",
        }
    }

    pub fn is_done(self) -> bool {
        matches!(self, Status::Success | Status::Failure)
    }
}

/// A blackboard value. Text from XML is converted when a typed port reads it.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Empty,
    Text(Rc<str>),
    Int(i64),
    Float(f64),
    Bool(bool),
}

impl Value {
    fn from_port(v: &PortValue) -> Value {
        match v {
            PortValue::Text(s) => Value::Text(s.as_str().into()),
            PortValue::Int(n) => Value::Int(*n),
            PortValue::Float(f) => Value::Float(*f),
            PortValue::Bool(b) => Value::Bool(*b),
            PortValue::Param(p) => Value::Text(format!("{{{p}}}").into()),
            PortValue::Formula(_) | PortValue::Effect(_) => Value::Text(v.to_text().into()),
        }
    }

    pub fn as_int(&self) -> Option<i64> {
        match self {
            Value::Int(n) => Some(*n),
            Value::Float(f) if f.fract() == 0.0 => Some(*f as i64),
            Value::Text(s) => s.trim().parse().ok(),
            _ => None,
        }
    }

    pub fn text(&self) -> String {
        match self {
            Value::Empty => String::new(),
            Value::Text(s) => s.to_string(),
            Value::Int(n) => n.to_string(),
            Value::Float(f) => btc_ir::format_float(*f),
            Value::Bool(b) => b.to_string(),
        }
    }

    /// Converts text to a port's declared type (`int`, `float`, `bool`;
    /// anything else stays text).
    fn typed(self, ty: &str) -> Result<Value, String> {
        let Value::Text(s) = &self else {
            return Ok(self);
        };
        let t = s.trim();
        Ok(match ty {
            "int" => Value::Int(t.parse().map_err(|_| format!("`{s}` is not an int"))?),
            "float" => Value::Float(t.parse().map_err(|_| format!("`{s}` is not a float"))?),
            "bool" => match t {
                "true" | "1" => Value::Bool(true),
                "false" | "0" => Value::Bool(false),
                _ => return Err(format!("`{s}` is not a bool")),
            },
            _ => self,
        })
    }
}

/// A decorator's count or duration: fixed, or read from a blackboard slot
/// when the node is ticked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Arg<T> {
    Fixed(T),
    Slot(u32),
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Op {
    Sequence,
    ReactiveSequence,
    SequenceWithMemory,
    Fallback,
    ReactiveFallback,
    Parallel { success: i32, failure: i32 },
    Inverter,
    ForceSuccess,
    ForceFailure,
    KeepRunningUntilFailure,
    Retry(Arg<i32>),
    Repeat(Arg<i32>),
    Timeout(Arg<u64>),
    SubTree,
    Step(u32),
    AlwaysSuccess,
    AlwaysFailure,
    Sleep(u32),
    SetBlackboard { value: u32, slot: u32 },
    KbHolds(FormulaId),
    KbApply(EffectId),
    WaitForStep(u32),
    Condition(u32),
    Action(u32),
}

#[derive(Clone, Copy, Debug)]
pub(crate) struct NodeDef {
    pub op: Op,
    pub first: u32,
    pub len: u32,
}

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

#[derive(Clone, Debug)]
pub(crate) enum Src {
    Const(Value),
    Slot(u32),
}

#[derive(Clone, Debug)]
pub(crate) struct PortBind {
    pub name: Box<str>,
    pub src: Src,
}

pub(crate) struct ActionInfo {
    pub id: Box<str>,
    pub ports: (u32, u32),
    /// The embedder's implementation ([`Engine::set_action_handler`]).
    pub handler: Option<u32>,
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

/// A plan step at run time.
#[derive(Clone, Debug, Default)]
pub(crate) struct StepRt {
    pub label: String,
    pub pre_start: Option<FormulaId>,
    pub pre_over_all: Option<FormulaId>,
    pub pre_end: Option<FormulaId>,
    pub eff_start: Option<EffectId>,
    pub eff_end: Option<EffectId>,
    pub skipped: bool,
    pub started: bool,
    pub finished: bool,
}

impl StepRt {
    /// What an action leaf of the step checks when it starts: the
    /// precondition, or (when at-start effects already changed the KB) the
    /// over-all condition.
    fn leaf_check(&self) -> Option<FormulaId> {
        if self.eff_start.is_some() {
            self.pre_over_all
        } else {
            self.pre_start.or(self.pre_over_all)
        }
    }
}

/// Why a node failed.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Reason {
    Precondition(FormulaId),
    EndCondition(FormulaId),
    ConditionFalse(FormulaId),
    /// A formula-defined condition with these objects in its ports.
    PortsFalse(ConditionId, Vec<u32>),
    Fault(usize, String),
    Plain(String),
}

/// A record of a failure: what failed, in which step, why, and the KB.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FaultRecord {
    pub tick: u64,
    pub node: u32,
    pub node_id: String,
    pub node_name: String,
    /// 1-based plan step: the failing node's, or for a node outside every
    /// step (a plan-level monitor), the step that was running.
    pub step: Option<usize>,
    pub action: Option<String>,
    pub reason: String,
    /// The injected faults the failure is attributed to.
    pub faults: Vec<String>,
    pub kb: Vec<String>,
}

/// One line of the trace.
#[derive(Clone, Debug, PartialEq)]
pub enum TraceItem {
    Status {
        tick: u64,
        node: u32,
        from: Status,
        to: Status,
    },
    StepStarted {
        tick: u64,
        step: u32,
    },
    StepFinished {
        tick: u64,
        step: u32,
    },
    Fault {
        tick: u64,
        fault: usize,
        ended: bool,
    },
    Record(usize),
    Command {
        tick: u64,
        seq: u64,
        node: u32,
    },
}

#[derive(Clone, Debug)]
pub struct Options {
    /// Ticks an action leaf stays RUNNING before it succeeds.
    pub ticks_per_action: u32,
    /// Simulated milliseconds per tick (`Sleep`, `Timeout`).
    pub ms_per_tick: u64,
    /// Record every status change.
    pub trace: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            ticks_per_action: 1,
            ms_per_tick: 10,
            trace: false,
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
    /// Blackboard entry names (`Tree#instance/key`) and values.
    pub slot_names: Vec<String>,
    pub(crate) bb: Vec<Value>,
    pub(crate) bb_gen: u64,
    pub(crate) status: Vec<Status>,
    pub(crate) cur: Vec<u32>,
    pub(crate) aux: Vec<u64>,
    pub kb: Option<Kb<'w>>,
    pub(crate) steps: Vec<StepRt>,
    pub(crate) opts: Options,
    pub tick: u64,
    pub(crate) now_ms: u64,
    pub trace: Vec<TraceItem>,
    pub(crate) last_failure: Option<(u32, Reason)>,
    pub records: Vec<FaultRecord>,
    pub(crate) faults: Vec<FaultRt>,
    /// Some fault is pending or in effect: leaves consult the faults.
    pub(crate) faults_live: bool,
    pub(crate) controller: Option<Controller>,
    pub(crate) handlers: Vec<crate::handler::ActionHandler<'w>>,
    pub(crate) record_slots: [u32; 4],
    /// The step that started last, while it has not finished.
    pub(crate) step_running: Option<u32>,
}

/// A blackboard scope: key to slot.
type Scope = FxHashMap<String, u32>;

struct Builder<'d, 'e, 'w> {
    doc: &'d TreeDoc,
    /// The document's trees and node models by ID: looking them up in the
    /// lists per node made loading quadratic.
    trees: FxHashMap<&'d str, &'d SNode>,
    models: FxHashMap<&'d str, &'d NodeModel>,
    e: &'e mut Engine<'w>,
    instances: FxHashMap<String, u32>,
    /// The tree instance being built (`Main`, `Check#1`): names new entries.
    tree: String,
    /// Children of the nodes being built, before they move to `kids`.
    pending: Vec<u32>,
}

impl<'w> Engine<'w> {
    /// Compiles a loaded document into an engine. `kb` is the simulated
    /// world; without it, trees that read or write the KB are refused.
    pub fn build(
        doc: &TreeDoc,
        kb: Option<Kb<'w>>,
        opts: Options,
    ) -> Result<Engine<'w>, LoadError> {
        let mut e = Engine {
            nodes: Vec::new(),
            kids: Vec::new(),
            meta: Vec::new(),
            ports: Vec::new(),
            actions: Vec::new(),
            conds: Vec::new(),
            slot_names: Vec::new(),
            bb: Vec::new(),
            bb_gen: 1,
            status: Vec::new(),
            cur: Vec::new(),
            aux: Vec::new(),
            kb,
            steps: Vec::new(),
            opts,
            tick: 0,
            now_ms: 0,
            trace: Vec::new(),
            last_failure: None,
            records: Vec::new(),
            faults: Vec::new(),
            faults_live: false,
            controller: None,
            handlers: Vec::new(),
            record_slots: [0; 4],
            step_running: None,
        };
        e.load_steps(doc)?;
        let main = doc.tree(&doc.main).ok_or_else(|| {
            LoadError::new(
                codes::X_SUBTREE,
                format!("the main tree `{}` is not defined", doc.main),
            )
        })?;
        let mut scope = Scope::default();
        for (k, key) in ["fault_node", "fault_step", "fault_reason", "fault_kb"]
            .iter()
            .enumerate()
        {
            let s = e.new_slot(format!("{}/{key}", doc.main), Value::Empty);
            scope.insert((*key).to_owned(), s);
            e.record_slots[k] = s;
        }
        let mut b = Builder {
            doc,
            // The first definition of an ID counts, as `TreeDoc::tree` has it.
            trees: doc
                .trees
                .iter()
                .rev()
                .map(|(id, n)| (id.as_str(), n))
                .collect(),
            models: doc
                .models
                .iter()
                .rev()
                .map(|m| (m.id.as_str(), m))
                .collect(),
            e: &mut e,
            instances: FxHashMap::default(),
            tree: doc.main.clone(),
            pending: Vec::new(),
        };
        b.node(main, &mut scope, None, None, 0, 0)?;
        let n = e.nodes.len();
        e.status = vec![Status::Idle; n];
        e.cur = vec![0; n];
        e.aux = vec![0; n];
        Ok(e)
    }

    fn load_steps(&mut self, doc: &TreeDoc) -> Result<(), LoadError> {
        for s in &doc.steps {
            let mut rt = StepRt {
                label: format!("step {}: {}", s.index + 1, s.display()),
                skipped: s.skipped,
                ..StepRt::default()
            };
            if !s.skipped {
                rt.pre_start = self.kb_formula(s.pre_start.as_ref(), &rt.label)?;
                rt.pre_over_all = self.kb_formula(s.pre_over_all.as_ref(), &rt.label)?;
                rt.pre_end = self.kb_formula(s.pre_end.as_ref(), &rt.label)?;
                rt.eff_start = self.kb_effect(s.eff_start.as_ref(), &rt.label)?;
                rt.eff_end = self.kb_effect(s.eff_end.as_ref(), &rt.label)?;
            }
            self.steps.push(rt);
        }
        Ok(())
    }

    fn need_kb(&mut self, what: &str) -> Result<&mut Kb<'w>, LoadError> {
        self.kb.as_mut().ok_or_else(|| no_kb(what))
    }

    fn kb_formula(
        &mut self,
        f: Option<&Formula>,
        what: &str,
    ) -> Result<Option<FormulaId>, LoadError> {
        let Some(f) = f else {
            return Ok(None);
        };
        let kb = self.need_kb(what)?;
        kb.formula(f).map(Some).map_err(|m| {
            LoadError::new(
                codes::X_KB,
                format!("{what}: `{f}` is not a condition of this problem: {m}"),
            )
        })
    }

    fn kb_effect(&mut self, e: Option<&Effect>, what: &str) -> Result<Option<EffectId>, LoadError> {
        let Some(e) = e else {
            return Ok(None);
        };
        let kb = self.need_kb(what)?;
        kb.effect(e).map(Some).map_err(|m| {
            LoadError::new(
                codes::X_KB,
                format!("{what}: `{e}` is not an effect of this problem: {m}"),
            )
        })
    }

    fn new_slot(&mut self, name: String, v: Value) -> u32 {
        self.slot_names.push(name);
        self.bb.push(v);
        (self.bb.len() - 1) as u32
    }

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

    #[inline]
    fn kid(&self, def: NodeDef, j: u32) -> u32 {
        self.kids[(def.first + j) as usize]
    }

    #[inline]
    fn set(&mut self, i: usize, s: Status) {
        let old = self.status[i];
        if old != s {
            self.status[i] = s;
            if self.opts.trace {
                self.trace.push(TraceItem::Status {
                    tick: self.tick,
                    node: i as u32,
                    from: old,
                    to: s,
                });
            }
        }
    }

    /// One tick of the whole tree.
    pub fn tick_once(&mut self) -> Status {
        self.tick += 1;
        self.now_ms = self.tick.saturating_mul(self.opts.ms_per_tick);
        if self.controller.is_some() {
            if let Some(c) = self.controller.as_mut() {
                c.poll();
            }
        }
        if !self.faults.is_empty() {
            self.faults_before_tick();
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

    fn reset_children(&mut self, def: NodeDef, from: u32) {
        for j in from..def.len {
            let c = self.kid(def, j);
            self.reset(c);
        }
    }

    /// BT.CPP's `haltChild`: a RUNNING node is halted (its own state
    /// cleared, its children reset), then the node goes back to IDLE. A
    /// node that finished only goes back to IDLE: what is below it, and its
    /// own counters, stay as they are (BT.CPP's `resetStatus`).
    fn reset(&mut self, i: u32) {
        let iu = i as usize;
        match self.status[iu] {
            Status::Idle => return,
            Status::Running => self.halt(i),
            _ => {}
        }
        self.set(iu, Status::Idle);
    }

    /// BT.CPP's `halt()` of a RUNNING node.
    fn halt(&mut self, i: u32) {
        let iu = i as usize;
        let def = self.nodes[iu];
        match def.op {
            // BT.CPP v4 keeps the index of a halted SequenceWithMemory.
            Op::SequenceWithMemory => {}
            // A halted action's command still runs; its completion is moot.
            Op::Action(_) if self.cur[iu] == 2 => {
                if let Some(c) = self.controller.as_mut() {
                    c.forget(self.aux[iu]);
                }
                self.cur[iu] = 0;
            }
            _ => self.cur[iu] = 0,
        }
        self.aux[iu] = 0;
        self.reset_children(def, 0);
    }

    fn tick_node(&mut self, i: u32) -> Status {
        let iu = i as usize;
        let def = self.nodes[iu];
        let s = match def.op {
            Op::Sequence => {
                self.set(iu, Status::Running);
                let mut idx = self.cur[iu];
                loop {
                    if idx >= def.len {
                        self.reset_children(def, 0);
                        self.cur[iu] = 0;
                        break Status::Success;
                    }
                    match self.tick_node(self.kid(def, idx)) {
                        Status::Running => {
                            self.cur[iu] = idx;
                            break Status::Running;
                        }
                        Status::Failure => {
                            self.reset_children(def, 0);
                            self.cur[iu] = 0;
                            break Status::Failure;
                        }
                        _ => idx += 1,
                    }
                }
            }
            Op::SequenceWithMemory => {
                self.set(iu, Status::Running);
                let mut idx = self.cur[iu];
                loop {
                    if idx >= def.len {
                        self.reset_children(def, 0);
                        self.cur[iu] = 0;
                        break Status::Success;
                    }
                    let c = self.kid(def, idx);
                    let fresh = self.status[c as usize] == Status::Idle;
                    match self.tick_node(c) {
                        Status::Running => {
                            self.cur[iu] = idx;
                            break Status::Running;
                        }
                        Status::Failure => {
                            // The index is kept: the failed child runs again.
                            self.reset_children(def, idx);
                            self.cur[iu] = idx;
                            break Status::Failure;
                        }
                        _ => {
                            idx += 1;
                            // BT.CPP 4.10: a child that started and finished
                            // in this tick hands the flow back (RUNNING);
                            // the next one runs at the next tick.
                            if fresh && idx < def.len {
                                self.cur[iu] = idx;
                                break Status::Running;
                            }
                        }
                    }
                }
            }
            Op::Fallback => {
                self.set(iu, Status::Running);
                let mut idx = self.cur[iu];
                loop {
                    if idx >= def.len {
                        self.reset_children(def, 0);
                        self.cur[iu] = 0;
                        break Status::Failure;
                    }
                    match self.tick_node(self.kid(def, idx)) {
                        Status::Running => {
                            self.cur[iu] = idx;
                            break Status::Running;
                        }
                        Status::Success => {
                            self.reset_children(def, 0);
                            self.cur[iu] = 0;
                            break Status::Success;
                        }
                        _ => idx += 1,
                    }
                }
            }
            Op::ReactiveSequence | Op::ReactiveFallback => {
                let seq = def.op == Op::ReactiveSequence;
                self.set(iu, Status::Running);
                let (stop, done) = if seq {
                    (Status::Failure, Status::Success)
                } else {
                    (Status::Success, Status::Failure)
                };
                let mut out = done;
                for j in 0..def.len {
                    let c = self.kid(def, j);
                    let s = self.tick_node(c);
                    if s == Status::Running {
                        // Every other child is halted (reset to IDLE).
                        for k in 0..def.len {
                            if k != j {
                                let o = self.kid(def, k);
                                self.reset(o);
                            }
                        }
                        out = Status::Running;
                        break;
                    }
                    if s == stop {
                        out = stop;
                        break;
                    }
                }
                if out != Status::Running {
                    self.reset_children(def, 0);
                }
                out
            }
            Op::Parallel { success, failure } => self.tick_parallel(iu, def, success, failure),
            Op::Inverter
            | Op::ForceSuccess
            | Op::ForceFailure
            | Op::KeepRunningUntilFailure
            | Op::SubTree => {
                self.set(iu, Status::Running);
                let c = self.kid(def, 0);
                let s = self.tick_node(c);
                if s.is_done() {
                    self.reset(c);
                }
                match (def.op, s) {
                    (_, Status::Running) => Status::Running,
                    (Op::Inverter, Status::Success) => {
                        self.note_failure(
                            i,
                            Reason::Plain("its child succeeded (Inverter)".into()),
                        );
                        Status::Failure
                    }
                    (Op::Inverter, _) => Status::Success,
                    (Op::ForceSuccess, _) => Status::Success,
                    (Op::ForceFailure, _) => {
                        self.note_failure(i, Reason::Plain("ForceFailure".into()));
                        Status::Failure
                    }
                    (Op::KeepRunningUntilFailure, Status::Success) => Status::Running,
                    (_, s) => s,
                }
            }
            Op::Retry(arg) | Op::Repeat(arg) => 'arm: {
                let retry = matches!(def.op, Op::Retry(_));
                let what = if retry { "num_attempts" } else { "num_cycles" };
                let n = match self.amount(arg, what, |n| i32::try_from(n).ok().filter(|n| *n >= -1))
                {
                    Ok(n) => n,
                    Err(r) => {
                        self.note_failure(i, r);
                        break 'arm Status::Failure;
                    }
                };
                self.set(iu, Status::Running);
                let c = self.kid(def, 0);
                // Retry counts failures and stops at a success; Repeat the
                // reverse.
                let (again, end) = if retry {
                    (Status::Failure, Status::Success)
                } else {
                    (Status::Success, Status::Failure)
                };
                let more = |done: u32| n < 0 || (done as i64) < n as i64;
                loop {
                    if !more(self.cur[iu]) {
                        self.cur[iu] = 0;
                        break again;
                    }
                    let fresh = self.status[c as usize] == Status::Idle;
                    let s = self.tick_node(c);
                    if s == Status::Running {
                        break Status::Running;
                    }
                    self.reset(c);
                    if s == end {
                        self.cur[iu] = 0;
                        break end;
                    }
                    self.cur[iu] = self.cur[iu].saturating_add(1);
                    if !more(self.cur[iu]) {
                        self.cur[iu] = 0;
                        break again;
                    }
                    // BT.CPP 4.10: an attempt that started and ended in this
                    // tick hands the flow back (RUNNING); the next attempt
                    // runs at the next tick. After a child that was RUNNING,
                    // the next attempt starts at once.
                    if fresh {
                        break Status::Running;
                    }
                }
            }
            Op::Timeout(arg) => 'arm: {
                let c = self.kid(def, 0);
                if self.status[iu] != Status::Running {
                    // Read when the timeout starts, as BT.CPP does.
                    let msec = match self.amount(arg, "msec", |n| u64::try_from(n).ok()) {
                        Ok(ms) => ms,
                        Err(r) => {
                            self.note_failure(i, r);
                            break 'arm Status::Failure;
                        }
                    };
                    self.set(iu, Status::Running);
                    self.aux[iu] = self.now_ms.saturating_add(msec);
                    self.cur[iu] = u32::try_from(msec).unwrap_or(u32::MAX);
                }
                let msec = self.cur[iu];
                if msec > 0
                    && self.now_ms >= self.aux[iu]
                    && self.status[c as usize] == Status::Running
                {
                    self.reset(c);
                    self.note_failure(i, Reason::Plain(format!("timed out after {msec} ms")));
                    Status::Failure
                } else {
                    let s = self.tick_node(c);
                    if s.is_done() {
                        self.reset(c);
                    }
                    s
                }
            }
            Op::Step(k) => self.tick_step(i, def, k),
            Op::AlwaysSuccess => Status::Success,
            Op::AlwaysFailure => {
                self.note_failure(i, Reason::Plain("AlwaysFailure".into()));
                Status::Failure
            }
            Op::Sleep(p) => {
                if self.status[iu] != Status::Running {
                    let ms = self.read(p).as_int().unwrap_or(0);
                    if ms <= 0 {
                        Status::Success
                    } else {
                        self.aux[iu] = self.now_ms.saturating_add(ms as u64);
                        Status::Running
                    }
                } else if self.now_ms >= self.aux[iu] {
                    Status::Success
                } else {
                    Status::Running
                }
            }
            Op::SetBlackboard { value, slot } => {
                let v = self.read(value).clone();
                if self.bb[slot as usize] != v {
                    self.bb[slot as usize] = v;
                    self.bb_gen += 1;
                }
                Status::Success
            }
            Op::KbHolds(f) => match self.blackout() {
                Some(s) => {
                    if s == Status::Failure {
                        self.note_blackout(i);
                    }
                    s
                }
                None => self.check(i, f),
            },
            Op::KbApply(e) => {
                if let Some(kb) = self.kb.as_mut() {
                    kb.apply(e);
                }
                Status::Success
            }
            Op::WaitForStep(k) => match self.steps.get(k as usize) {
                Some(s) if s.finished || s.skipped => Status::Success,
                Some(_) => Status::Running,
                None => {
                    self.note_failure(i, Reason::Plain(format!("there is no step {}", k + 1)));
                    Status::Failure
                }
            },
            Op::Condition(c) => self.tick_condition(i, c),
            Op::Action(a) => self.tick_action(i, a),
        };
        self.set(iu, s);
        s
    }

    fn tick_parallel(&mut self, iu: usize, def: NodeDef, success: i32, failure: i32) -> Status {
        self.set(iu, Status::Running);
        let n = def.len as i64;
        let need_s = threshold(success, n);
        let need_f = threshold(failure, n);
        let mut succ = self.cur[iu] as i64;
        let mut fail = self.aux[iu] as i64;
        let mut out = Status::Running;
        for j in 0..def.len {
            let c = self.kid(def, j);
            if !self.status[c as usize].is_done() {
                match self.tick_node(c) {
                    Status::Success => succ += 1,
                    Status::Failure => fail += 1,
                    _ => {}
                }
            }
            if succ >= need_s {
                out = Status::Success;
                break;
            }
            if n - fail < need_s || fail == need_f {
                out = Status::Failure;
                break;
            }
        }
        if out == Status::Running {
            self.cur[iu] = succ as u32;
            self.aux[iu] = fail as u64;
        } else {
            self.cur[iu] = 0;
            self.aux[iu] = 0;
            self.reset_children(def, 0);
        }
        out
    }

    fn tick_step(&mut self, i: u32, def: NodeDef, k: u32) -> Status {
        let iu = i as usize;
        let ku = k as usize;
        if self.status[iu] != Status::Running {
            self.set(iu, Status::Running);
            if !self.faults.is_empty() {
                self.faults_on_step(ku, i);
            }
            self.step_running = Some(k);
            if self.opts.trace {
                self.trace.push(TraceItem::StepStarted {
                    tick: self.tick,
                    step: k,
                });
            }
            if let Some(st) = self.steps.get(ku) {
                // With at-start effects, the precondition is checked before
                // they apply; otherwise the step's action leaves check it.
                if st.eff_start.is_some() {
                    if let (Some(pre), Some(kb)) = (st.pre_start, self.kb.as_ref()) {
                        if !kb.holds(pre) {
                            self.note_failure(i, Reason::Precondition(pre));
                            return Status::Failure;
                        }
                    }
                }
                if !st.started {
                    let eff = st.eff_start;
                    self.steps[ku].started = true;
                    if let (Some(e), Some(kb)) = (eff, self.kb.as_mut()) {
                        kb.apply(e);
                    }
                }
            }
        }
        let c = self.kid(def, 0);
        let s = self.tick_node(c);
        if !s.is_done() {
            return s;
        }
        self.reset(c);
        if s == Status::Failure {
            return s;
        }
        if let Some(st) = self.steps.get(ku) {
            if let (Some(pre), Some(kb)) = (st.pre_end, self.kb.as_ref()) {
                if !kb.holds(pre) {
                    self.note_failure(i, Reason::EndCondition(pre));
                    return Status::Failure;
                }
            }
            if !st.finished {
                let eff = st.eff_end;
                self.steps[ku].finished = true;
                if self.step_running == Some(k) {
                    self.step_running = None;
                }
                if let (Some(e), Some(kb)) = (eff, self.kb.as_mut()) {
                    kb.apply(e);
                }
                if self.opts.trace {
                    self.trace.push(TraceItem::StepFinished {
                        tick: self.tick,
                        step: k,
                    });
                }
            }
        }
        Status::Success
    }

    fn check(&mut self, i: u32, f: FormulaId) -> Status {
        match self.kb.as_ref() {
            Some(kb) if kb.holds(f) => Status::Success,
            Some(_) => {
                self.note_failure(i, Reason::ConditionFalse(f));
                Status::Failure
            }
            None => Status::Failure,
        }
    }

    fn tick_condition(&mut self, i: u32, c: u32) -> Status {
        let cu = c as usize;
        let Some(formula) = self.conds[cu].formula else {
            return Status::Success;
        };
        if let Some(s) = self.blackout() {
            if s == Status::Failure {
                self.note_blackout(i);
            }
            return s;
        }
        if self.conds[cu].generation != self.bb_gen {
            self.conds[cu].objects = self.port_objects(&self.conds[cu].slot_ports);
            self.conds[cu].generation = self.bb_gen;
        }
        let Some(kb) = self.kb.as_ref() else {
            return Status::Failure;
        };
        match &self.conds[cu].objects {
            Ok(objects) if kb.holds_with(formula, objects) => Status::Success,
            Ok(objects) => {
                let r = Reason::PortsFalse(formula, objects.clone());
                self.note_failure(i, r);
                Status::Failure
            }
            Err(m) => {
                let r = Reason::Plain(m.clone());
                self.note_failure(i, r);
                Status::Failure
            }
        }
    }

    /// The objects a formula-defined condition's ports name now.
    fn port_objects(&self, slot_ports: &[u32]) -> Result<Vec<u32>, String> {
        let kb = self.kb.as_ref().ok_or("no knowledge base")?;
        slot_ports
            .iter()
            .map(|&p| {
                let port = &self.ports[p as usize];
                // PDDL names are case-insensitive; a port's text keeps its case.
                let v = self.value(&port.src).text();
                kb.object(&v.to_lowercase()).ok_or_else(|| {
                    format!(
                        "port `{}` holds `{v}`, which is not an object of this problem",
                        port.name
                    )
                })
            })
            .collect()
    }

    fn tick_action(&mut self, i: u32, a: u32) -> Status {
        if let Some(h) = self.actions[a as usize].handler {
            return self.tick_handled(i, a, h);
        }
        let iu = i as usize;
        let started = self.status[iu] == Status::Running && self.cur[iu] != 0;
        if self.faults_live {
            let fresh = self.status[iu] != Status::Running;
            if let Some(s) = self.faults_on_action(i, a, fresh) {
                if s == Status::Failure {
                    self.cur[iu] = 0;
                }
                return s;
            }
        }
        if !started {
            let step = self.meta[iu].step;
            if let (Some(k), Some(kb)) = (step, self.kb.as_ref()) {
                if let Some(pre) = self.steps.get(k as usize).and_then(StepRt::leaf_check) {
                    if !kb.holds(pre) {
                        self.note_failure(i, Reason::Precondition(pre));
                        return Status::Failure;
                    }
                }
            }
            if self.controller.is_some() {
                let cmd = self.command(i, a);
                let seq = self.controller.as_mut().map_or(0, |c| c.submit(cmd));
                if self.opts.trace {
                    self.trace.push(TraceItem::Command {
                        tick: self.tick,
                        seq,
                        node: i,
                    });
                }
                self.cur[iu] = 2;
                self.aux[iu] = seq;
                return Status::Running;
            }
            if self.opts.ticks_per_action == 0 {
                return Status::Success;
            }
            self.cur[iu] = 1;
            self.aux[iu] = self.opts.ticks_per_action as u64;
            return Status::Running;
        }
        if self.cur[iu] == 2 {
            let seq = self.aux[iu];
            let done = self.controller.as_mut().is_some_and(|c| c.take_done(seq));
            if done {
                self.cur[iu] = 0;
                return Status::Success;
            }
            return Status::Running;
        }
        self.aux[iu] = self.aux[iu].saturating_sub(1);
        if self.aux[iu] == 0 {
            self.cur[iu] = 0;
            Status::Success
        } else {
            Status::Running
        }
    }

    fn command(&self, i: u32, a: u32) -> Command {
        let info = &self.actions[a as usize];
        let (p, q) = info.ports;
        Command {
            seq: 0,
            node: i,
            command: info.id.to_string(),
            args: self.ports[p as usize..q as usize]
                .iter()
                .map(|b| (b.name.to_string(), self.value(&b.src).text()))
                .collect(),
            step: self.meta[i as usize].step.map(|s| s as usize + 1),
        }
    }

    #[inline]
    pub(crate) fn value<'a>(&'a self, s: &'a Src) -> &'a Value {
        match s {
            Src::Const(v) => v,
            Src::Slot(k) => &self.bb[*k as usize],
        }
    }

    /// A decorator's count: fixed, or read from its blackboard slot (a fault
    /// reason when the entry holds no number the decorator takes).
    fn amount<T: Copy>(
        &self,
        a: Arg<T>,
        port: &str,
        fit: impl Fn(i64) -> Option<T>,
    ) -> Result<T, Reason> {
        match a {
            Arg::Fixed(n) => Ok(n),
            Arg::Slot(s) => {
                let v = &self.bb[s as usize];
                v.as_int().and_then(fit).ok_or_else(|| {
                    Reason::Plain(format!(
                        "`{port}` reads `{}` from the blackboard, which is not a number it takes",
                        v.text()
                    ))
                })
            }
        }
    }

    #[inline]
    fn read(&self, port: u32) -> &Value {
        let p = &self.ports[port as usize];
        self.value(&p.src)
    }

    /// Whether an action's ports name `object`.
    pub(crate) fn action_mentions(&self, a: u32, object: &str) -> bool {
        let (p, q) = self.actions[a as usize].ports;
        self.ports[p as usize..q as usize]
            .iter()
            .any(|b| matches!(self.value(&b.src), Value::Text(t) if &**t == object))
    }

    pub(crate) fn note_failure(&mut self, node: u32, r: Reason) {
        self.last_failure = Some((node, r));
    }

    pub(crate) fn reason_text(&self, r: &Reason) -> String {
        let kb = self.kb.as_ref();
        match r {
            Reason::Precondition(f) => kb.map_or_else(String::new, |kb| {
                format!("its step's precondition does not hold: {}", kb.why_not(*f))
            }),
            Reason::EndCondition(f) => kb.map_or_else(String::new, |kb| {
                format!(
                    "its step's at-end condition does not hold: {}",
                    kb.why_not(*f)
                )
            }),
            Reason::ConditionFalse(f) => kb.map_or_else(String::new, |kb| {
                format!("the condition does not hold: {}", kb.why_not(*f))
            }),
            Reason::PortsFalse(c, objects) => kb.map_or_else(String::new, |kb| {
                format!(
                    "the condition does not hold: {}",
                    kb.why_not_with(*c, objects)
                )
            }),
            Reason::Fault(_, s) | Reason::Plain(s) => s.clone(),
        }
    }

    /// Writes a fault record for a failure of `node` to the records, the
    /// blackboard and the trace.
    pub(crate) fn record(&mut self, node: u32, r: &Reason) {
        let reason = self.reason_text(r);
        let meta = &self.meta[node as usize];
        let step = meta.step.or(self.step_running).map(|s| s as usize);
        let faults = self.faults_related(r, &reason);
        let rec = FaultRecord {
            tick: self.tick,
            node,
            node_id: meta.id.clone(),
            node_name: meta.name.clone(),
            step: step.map(|s| s + 1),
            action: step
                .and_then(|s| self.steps.get(s))
                .map(|s| s.label.clone()),
            reason,
            faults,
            kb: self.kb.as_ref().map(Kb::snapshot).unwrap_or_default(),
        };
        let [n, s, why, kb] = self.record_slots;
        self.bb[n as usize] = Value::Text(format!("{} ({})", rec.node_name, rec.node_id).into());
        self.bb[s as usize] = rec.step.map_or(Value::Empty, |s| Value::Int(s as i64));
        self.bb[why as usize] = Value::Text(rec.reason.as_str().into());
        self.bb[kb as usize] = Value::Text(rec.kb.join(" ").into());
        self.bb_gen += 1;
        self.records.push(rec);
        if self.opts.trace {
            self.trace.push(TraceItem::Record(self.records.len() - 1));
        }
    }

    /// After the run: the record of the failure that ended it, or of the
    /// goal that does not hold.
    fn finish(&mut self, s: Status) {
        if s == Status::Failure {
            if let Some((node, r)) = self.last_failure.clone() {
                let dup = self.records.last().is_some_and(|rec| {
                    rec.node == node && rec.reason == self.reason_text(&r) && rec.tick == self.tick
                });
                if !dup {
                    self.record(node, &r);
                }
            }
        } else if s == Status::Success {
            if let Some((false, Some(why))) = self.kb.as_ref().map(Kb::goal) {
                self.record(
                    0,
                    &Reason::Plain(format!(
                        "the tree succeeded but the goal does not hold: {why}"
                    )),
                );
            }
        } else {
            let t = self.tick;
            self.record(
                0,
                &Reason::Plain(format!("the tree was still running after {t} ticks")),
            );
        }
    }

    /// Whether the problem's goal holds in the KB (`None` without a KB).
    pub fn goal(&self) -> Option<(bool, Option<String>)> {
        self.kb.as_ref().map(Kb::goal)
    }

    /// The trace as JSON Lines.
    pub fn trace_jsonl(&self) -> String {
        let mut out = String::new();
        for t in &self.trace {
            out.push_str(&self.trace_line(t).to_string());
            out.push('\n');
        }
        out
    }

    /// Writes the trace so far as JSON Lines and forgets it, so that a long
    /// run streams its trace in bounded memory (`btc run --trace` calls this
    /// after every tick).
    pub fn drain_trace(&mut self, out: &mut dyn std::io::Write) -> std::io::Result<()> {
        let items = std::mem::take(&mut self.trace);
        let mut line = Vec::new();
        for t in &items {
            line.clear();
            serde_json::to_writer(&mut line, &self.trace_line(t))?;
            line.push(b'\n');
            out.write_all(&line)?;
        }
        self.trace = items;
        self.trace.clear();
        Ok(())
    }

    fn trace_line(&self, t: &TraceItem) -> serde_json::Value {
        {
            match t {
                TraceItem::Status {
                    tick,
                    node,
                    from,
                    to,
                } => {
                    let m = &self.meta[*node as usize];
                    serde_json::json!({
                        "tick": tick, "node": node, "id": m.id, "name": m.name,
                        "from": from.name(), "to": to.name(),
                    })
                }
                TraceItem::StepStarted { tick, step } => serde_json::json!({
                    "tick": tick, "event": "step_started", "step": step + 1,
                    "action": self.step_label(*step as usize),
                }),
                TraceItem::StepFinished { tick, step } => serde_json::json!({
                    "tick": tick, "event": "step_finished", "step": step + 1,
                    "action": self.step_label(*step as usize),
                }),
                TraceItem::Fault { tick, fault, ended } => {
                    let f = &self.faults[*fault];
                    serde_json::json!({
                        "tick": tick, "event": if *ended { "fault_ended" } else { "fault_triggered" },
                        "fault": f.spec.label(), "kind": f.spec.kind.name(),
                    })
                }
                TraceItem::Record(k) => {
                    let mut v = serde_json::to_value(&self.records[*k]).unwrap_or_default();
                    if let Some(o) = v.as_object_mut() {
                        o.insert("event".into(), "fault_record".into());
                    }
                    v
                }
                TraceItem::Command { tick, seq, node } => serde_json::json!({
                    "tick": tick, "event": "command", "seq": seq, "node": node,
                    "command": self.meta[*node as usize].id,
                }),
            }
        }
    }
}

/// X005 for a KB node whose port holds something other than PDDL.
fn not_pddl(n: &SNode, id: &str, key: &str, v: &PortValue, what: &str) -> LoadError {
    LoadError::new(
        codes::X_KB,
        format!(
            "`{id}`: port `{key}` holds `{}`, which is not a PDDL {what} value",
            v.to_text()
        ),
    )
    .at_opt(n.at)
    .hint("trees written by `btc compile` carry PDDL values here; check the file was not edited by hand")
}

fn no_kb(what: &str) -> LoadError {
    LoadError::new(
        codes::X_KB,
        format!("{what} reads or writes the KB, and no PDDL problem was given"),
    )
    .hint("pass `--problem PROBLEM` (and `--domain DOMAIN` unless it is beside the problem)")
}

fn threshold(t: i32, n: i64) -> i64 {
    if t < 0 {
        (n + t as i64 + 1).max(0)
    } else {
        t as i64
    }
}

const BUILTIN_LEAVES: &[&str] = &[
    "AlwaysSuccess",
    "AlwaysFailure",
    "Sleep",
    "SetBlackboard",
    "KbHolds",
    "KbApply",
    "WaitForStep",
];

impl<'d, 'e, 'w> Builder<'d, 'e, 'w> {
    fn err(&self, code: btc_pddl::diagnostic::Code, n: &SNode, msg: String) -> LoadError {
        LoadError::new(code, msg).at_opt(n.at)
    }

    #[allow(clippy::too_many_arguments)]
    fn node(
        &mut self,
        n: &SNode,
        scope: &mut Scope,
        step: Option<u32>,
        parent: Option<u32>,
        depth: usize,
        calls: usize,
    ) -> Result<u32, LoadError> {
        if depth > MAX_DEPTH {
            return Err(self.err(
                codes::X_TOO_DEEP,
                n,
                format!("the tree is nested deeper than {MAX_DEPTH} levels"),
            ));
        }
        let me = self.e.nodes.len() as u32;
        let mut name = n
            .name
            .clone()
            .unwrap_or_else(|| default_name(&n.kind).to_owned());
        let mut id = default_name(&n.kind).to_owned();
        let mut my_step = step;
        self.e.nodes.push(NodeDef {
            op: Op::AlwaysSuccess,
            first: 0,
            len: 0,
        });
        self.e.meta.push(NodeMeta {
            id: String::new(),
            name: String::new(),
            step,
            parent,
        });
        let arity = |want: usize, b: &Self| -> Result<(), LoadError> {
            if n.children.len() != want {
                return Err(b.err(
                    codes::X_BAD_PORT,
                    n,
                    format!(
                        "`{}` takes exactly one child, and has {}",
                        default_name(&n.kind),
                        n.children.len()
                    ),
                ));
            }
            Ok(())
        };
        let op = match &n.kind {
            Kind::Sequence => Op::Sequence,
            Kind::ReactiveSequence => Op::ReactiveSequence,
            Kind::SequenceWithMemory => Op::SequenceWithMemory,
            Kind::Fallback => Op::Fallback,
            Kind::ReactiveFallback => Op::ReactiveFallback,
            Kind::Parallel { success, failure } => {
                let c = n.children.len() as i64;
                for (what, t) in [("success_count", *success), ("failure_count", *failure)] {
                    if threshold(t, c) > c {
                        return Err(self
                            .err(
                                codes::X_BAD_PORT,
                                n,
                                format!("Parallel has {c} children, fewer than its {what} {t}"),
                            )
                            .hint(
                                "BT.CPP refuses such a Parallel: it could never finish that way",
                            ));
                    }
                }
                Op::Parallel {
                    success: *success,
                    failure: *failure,
                }
            }
            Kind::Inverter => Op::Inverter,
            Kind::ForceSuccess => Op::ForceSuccess,
            Kind::ForceFailure => Op::ForceFailure,
            Kind::KeepRunningUntilFailure => Op::KeepRunningUntilFailure,
            Kind::Retry(k) => Op::Retry(self.arg(k, scope)),
            Kind::Repeat(k) => Op::Repeat(self.arg(k, scope)),
            Kind::Timeout(ms) => Op::Timeout(self.arg(ms, scope)),
            Kind::SubTree { .. } => {
                id = "SubTree".into();
                Op::SubTree
            }
            Kind::Step {
                step: k,
                start_effect,
                end_effect,
                conditions,
            } => {
                let k32 = u32::try_from(*k).unwrap_or(u32::MAX);
                while self.e.steps.len() <= *k && self.e.steps.len() < 100_000 {
                    let idx = self.e.steps.len();
                    // A step the tree file names but no plan describes:
                    // skipped until a KbStep refers to it.
                    self.e.steps.push(StepRt {
                        label: format!("step {}", idx + 1),
                        skipped: true,
                        ..StepRt::default()
                    });
                }
                if *k >= self.e.steps.len() {
                    return Err(self.err(
                        codes::X_BAD_PORT,
                        n,
                        format!("step {} is out of range", k + 1),
                    ));
                }
                if *k >= self.doc.steps.len() && self.e.steps[*k].skipped {
                    self.e.steps[*k].skipped = false;
                    if let Some(nm) = &n.name {
                        self.derive_step(*k, nm, conditions.is_none())
                            .map_err(|e| e.at_opt(n.at))?;
                    }
                    if let Some(c) = conditions {
                        self.given_conditions(*k, c).map_err(|e| e.at_opt(n.at))?;
                    }
                }
                let label = format!("`{}`", self.e.steps[*k].label);
                if let Some(f) = self
                    .e
                    .kb_effect(start_effect.as_ref(), &label)
                    .map_err(|e| e.at_opt(n.at))?
                {
                    self.e.steps[*k].eff_start = Some(f);
                }
                if let Some(f) = self
                    .e
                    .kb_effect(end_effect.as_ref(), &label)
                    .map_err(|e| e.at_opt(n.at))?
                {
                    self.e.steps[*k].eff_end = Some(f);
                }
                if n.name.is_none() {
                    name = self.e.steps[*k].label.clone();
                }
                my_step = Some(k32);
                self.e.meta[me as usize].step = my_step;
                Op::Step(k32)
            }
            Kind::Leaf {
                id: lid,
                kind,
                ports,
            } => self.leaf(n, lid, *kind, ports, scope)?,
        };
        if matches!(
            op,
            Op::Inverter
                | Op::ForceSuccess
                | Op::ForceFailure
                | Op::KeepRunningUntilFailure
                | Op::Retry(_)
                | Op::Repeat(_)
                | Op::Timeout(_)
                | Op::Step(_)
        ) {
            arity(1, self)?;
        }
        {
            let m = &mut self.e.meta[me as usize];
            m.name = name;
            m.id = id;
        }
        let mark = self.pending.len();
        if let Kind::SubTree {
            id: tid,
            ports,
            autoremap,
        } = &n.kind
        {
            if !n.children.is_empty() {
                return Err(self.err(
                    codes::X_BAD_PORT,
                    n,
                    "a SubTree has no children of its own".into(),
                ));
            }
            let Some(def) = self.trees.get(tid.as_str()).copied() else {
                let hint = did_you_mean(tid, self.doc.trees.iter().map(|(t, _)| t.as_str()));
                let mut e = self.err(
                    codes::X_SUBTREE,
                    n,
                    format!("SubTree `{tid}` is not defined"),
                );
                if let Some(h) = hint {
                    e = e.hint(h);
                }
                return Err(e);
            };
            if calls >= MAX_CALLS {
                return Err(self.err(
                    codes::X_SUBTREE,
                    n,
                    format!("SubTree `{tid}` calls itself (or nests more than {MAX_CALLS} calls)"),
                ));
            }
            let count = self.instances.entry(tid.clone()).or_insert(0);
            *count += 1;
            let inst = format!("{tid}#{count}");
            let mut child: Scope = if *autoremap {
                scope.clone()
            } else {
                Scope::default()
            };
            for (k, v) in ports {
                let slot = match v {
                    PortValue::Param(p) => {
                        let p = if p == "=" { k } else { p };
                        self.slot_in(scope, p)
                    }
                    other => self
                        .e
                        .new_slot(format!("{inst}/{k}"), Value::from_port(other)),
                };
                child.insert(k.clone(), slot);
            }
            let outer = std::mem::replace(&mut self.tree, inst);
            let c = self.node(def, &mut child, my_step, Some(me), depth + 1, calls + 1);
            self.tree = outer;
            if *autoremap {
                // BT.CPP creates an autoremapped subtree's new entries in
                // the parent's blackboard (all but `_private` ones and the
                // call's own ports): later nodes of the parent see them.
                for (k, slot) in child {
                    if !k.starts_with('_') && !ports.iter().any(|(p, _)| *p == k) {
                        scope.entry(k).or_insert(slot);
                    }
                }
            }
            self.pending.push(c?);
        } else {
            for c in &n.children {
                let k = self.node(c, scope, my_step, Some(me), depth + 1, calls)?;
                self.pending.push(k);
            }
        }
        let first = self.e.kids.len() as u32;
        let len = (self.pending.len() - mark) as u32;
        self.e.kids.extend(self.pending.drain(mark..));
        self.e.nodes[me as usize] = NodeDef { op, first, len };
        Ok(me)
    }

    /// A step's conditions as its `KbStep` gives them.
    fn given_conditions(&mut self, k: usize, c: &StepConditions) -> Result<(), LoadError> {
        let what = format!("`{}`", self.e.steps[k].label);
        let start = self.e.kb_formula(c.start.as_ref(), &what)?;
        let over_all = self.e.kb_formula(c.over_all.as_ref(), &what)?;
        let end = self.e.kb_formula(c.end.as_ref(), &what)?;
        let st = &mut self.e.steps[k];
        st.pre_start = start;
        st.pre_over_all = over_all;
        st.pre_end = end;
        Ok(())
    }

    /// A step known only from a tree file (`KbStep name="step 3: (grasp r
    /// p bin1)"`): its label, and unless the file gives them (`conditions`
    /// false), its conditions: the domain action's, grounded.
    fn derive_step(&mut self, k: usize, name: &str, conditions: bool) -> Result<(), LoadError> {
        let Some(open) = name.find('(') else {
            return Ok(());
        };
        let inner = name[open + 1..].trim_end().trim_end_matches(')');
        let mut words = inner.split_whitespace();
        let Some(act) = words.next().map(str::to_lowercase) else {
            return Ok(());
        };
        let args: Vec<Name> = words.map(|w| logic::name(&w.to_lowercase())).collect();
        let Some(a) = self.doc.actions.iter().find(|a| *a.name == *act) else {
            return Ok(());
        };
        if a.params.len() != args.len() {
            return Ok(());
        }
        let params = a.param_names();
        let binding = Binding {
            params: &params,
            objects: &args,
        };
        let ground = |parts: &[Formula]| {
            Formula::conjunction(parts.iter().map(|f| f.ground(&binding)).collect())
        };
        let (pre_start, over_all, pre_end) = (
            ground(&a.pre_start),
            ground(&a.pre_over_all),
            ground(&a.pre_end),
        );
        let label = format!(
            "step {}: ({})",
            k + 1,
            std::iter::once(act.as_str())
                .chain(args.iter().map(|a| &**a))
                .collect::<Vec<_>>()
                .join(" ")
        );
        if !conditions {
            self.e.steps[k].label = label;
            return Ok(());
        }
        let what = format!("`{label}`");
        let pre_start = self.e.kb_formula(pre_start.as_ref(), &what)?;
        let over_all = self.e.kb_formula(over_all.as_ref(), &what)?;
        let pre_end = self.e.kb_formula(pre_end.as_ref(), &what)?;
        let st = &mut self.e.steps[k];
        st.label = label;
        st.pre_start = pre_start;
        st.pre_over_all = over_all;
        st.pre_end = pre_end;
        Ok(())
    }

    /// A decorator's count: fixed, or the slot of the blackboard entry it reads.
    fn arg<T: Copy>(&mut self, a: &Amount<T>, scope: &mut Scope) -> Arg<T> {
        match a {
            Amount::Fixed(n) => Arg::Fixed(*n),
            Amount::Entry(key) => Arg::Slot(self.slot_in(scope, key)),
        }
    }

    fn slot_in(&mut self, scope: &mut Scope, key: &str) -> u32 {
        if let Some(&s) = scope.get(key) {
            return s;
        }
        let s = self
            .e
            .new_slot(format!("{}/{key}", self.tree), Value::Empty);
        scope.insert(key.to_owned(), s);
        s
    }

    fn bind_ports(
        &mut self,
        n: &SNode,
        ports: &[(String, PortValue)],
        types: &dyn Fn(&str) -> Option<String>,
        scope: &mut Scope,
    ) -> Result<(u32, u32), LoadError> {
        let start = self.e.ports.len() as u32;
        for (k, v) in ports {
            let src = match v {
                PortValue::Param(p) => {
                    let p = if p == "=" { k.as_str() } else { p.as_str() };
                    Src::Slot(self.slot_in(scope, p))
                }
                other => {
                    let val = Value::from_port(other);
                    let val = match types(k) {
                        Some(ty) => val.typed(&ty).map_err(|m| {
                            self.err(
                                codes::X_BAD_PORT,
                                n,
                                format!("port `{k}` of `{}`: {m}", default_name(&n.kind)),
                            )
                        })?,
                        None => val,
                    };
                    Src::Const(val)
                }
            };
            self.e.ports.push(PortBind {
                name: k.as_str().into(),
                src,
            });
        }
        Ok((start, self.e.ports.len() as u32))
    }

    /// A KB node's PDDL port: it must be written out.
    fn kb_port<'p>(
        &self,
        n: &SNode,
        ports: &'p [(String, PortValue)],
        key: &str,
    ) -> Result<&'p PortValue, LoadError> {
        match ports.iter().find(|(k, _)| k == key) {
            Some((_, PortValue::Param(p))) => Err(self.err(
                codes::X_BAD_PORT,
                n,
                format!("port `{key}` of `{}` must be written out, not read from the blackboard entry `{p}`", default_name(&n.kind)),
            )),
            Some((_, v)) => Ok(v),
            None => Err(self.err(
                codes::X_BAD_PORT,
                n,
                format!("`{}` needs the port `{key}`", default_name(&n.kind)),
            )),
        }
    }

    fn const_text(
        &self,
        n: &SNode,
        ports: &[(String, PortValue)],
        key: &str,
        need: bool,
    ) -> Result<Option<String>, LoadError> {
        match ports.iter().find(|(k, _)| k == key) {
            Some((_, PortValue::Param(p))) => Err(self
                .err(
                    codes::X_BAD_PORT,
                    n,
                    format!("port `{key}` of `{}` must be written out, not read from the blackboard entry `{p}`", default_name(&n.kind)),
                )),
            Some((_, v)) => Ok(Some(v.to_text())),
            None if need => Err(self.err(
                codes::X_BAD_PORT,
                n,
                format!("`{}` needs the port `{key}`", default_name(&n.kind)),
            )),
            None => Ok(None),
        }
    }

    /// A condition's formula compiled over the ports it names: its free
    /// variables are port names, each a slot filled from that port. With
    /// constant ports only, the objects are checked now.
    fn port_condition(
        &mut self,
        n: &SNode,
        id: &str,
        f: &Formula,
        range: (u32, u32),
    ) -> Result<(ConditionId, Box<[u32]>), LoadError> {
        let what = format!("the condition `{id}`");
        let vars = f.free_vars();
        let mut slots = Vec::with_capacity(vars.len());
        for v in &vars {
            let p = (range.0..range.1).find(|&p| *self.e.ports[p as usize].name == **v);
            match p {
                Some(p) => slots.push(p),
                None => {
                    return Err(self.err(
                        codes::X_KB,
                        n,
                        format!(
                            "{what}: its formula `{f}` reads `?{v}`, which is none of its ports"
                        ),
                    ))
                }
            }
        }
        let kb = self.e.need_kb(&what).map_err(|e| e.at_opt(n.at))?;
        let c = kb.condition(f, &vars).map_err(|m| {
            self.err(
                codes::X_KB,
                n,
                format!("{what}: `{f}` is not a condition of this problem: {m}"),
            )
        })?;
        let all_const = slots
            .iter()
            .all(|&p| matches!(self.e.ports[p as usize].src, Src::Const(_)));
        if all_const {
            if let Err(m) = self.e.port_objects(&slots) {
                return Err(self.err(codes::X_KB, n, format!("{what}: {m}")));
            }
        }
        Ok((c, slots.into()))
    }

    fn leaf(
        &mut self,
        n: &SNode,
        id: &str,
        kind: Option<LeafKind>,
        ports: &[(String, PortValue)],
        scope: &mut Scope,
    ) -> Result<Op, LoadError> {
        if !n.children.is_empty() {
            return Err(self.err(
                codes::X_UNKNOWN_NODE,
                n,
                format!("`{id}` has children, but it is not a control or decorator node the runtime knows"),
            ));
        }
        let what = format!("`{id}`");
        match id {
            "AlwaysSuccess" => return Ok(Op::AlwaysSuccess),
            "AlwaysFailure" => return Ok(Op::AlwaysFailure),
            "Sleep" => {
                self.const_text(n, ports, "msec", true)?;
                let (a, _) =
                    self.bind_ports(n, ports, &|k| (k == "msec").then(|| "int".into()), scope)?;
                let p = ports.iter().position(|(k, _)| k == "msec").unwrap_or(0) as u32;
                return Ok(Op::Sleep(a + p));
            }
            "SetBlackboard" => {
                let key = match ports.iter().find(|(k, _)| k == "output_key") {
                    Some((_, PortValue::Param(p))) => p.clone(),
                    Some((_, v)) => v.to_text(),
                    None => {
                        return Err(self.err(
                            codes::X_BAD_PORT,
                            n,
                            "`SetBlackboard` needs the port `output_key`".into(),
                        ));
                    }
                };
                let Some(vi) = ports.iter().position(|(k, _)| k == "value") else {
                    return Err(self.err(
                        codes::X_BAD_PORT,
                        n,
                        "`SetBlackboard` needs the port `value`".into(),
                    ));
                };
                let slot = self.slot_in(scope, &key);
                let (a, _) = self.bind_ports(n, ports, &|_| None, scope)?;
                return Ok(Op::SetBlackboard {
                    value: a + vi as u32,
                    slot,
                });
            }
            "KbHolds" => {
                let f = match self.kb_port(n, ports, "formula")? {
                    PortValue::Formula(f) => self.e.kb_formula(Some(f), &what),
                    other => Err(not_pddl(n, id, "formula", other, "condition")),
                }
                .map_err(|e| e.at_opt(n.at))?;
                return match f {
                    Some(f) => Ok(Op::KbHolds(f)),
                    None => Ok(Op::AlwaysSuccess),
                };
            }
            "KbApply" => {
                let e = match self.kb_port(n, ports, "effect")? {
                    PortValue::Effect(e) => self.e.kb_effect(Some(e), &what),
                    other => Err(not_pddl(n, id, "effect", other, "effect")),
                }
                .map_err(|e| e.at_opt(n.at))?;
                return match e {
                    Some(e) => Ok(Op::KbApply(e)),
                    None => Ok(Op::AlwaysSuccess),
                };
            }
            "WaitForStep" => {
                let t = self.const_text(n, ports, "step", true)?.unwrap_or_default();
                let k: u32 = t.trim().parse().ok().filter(|k| *k >= 1).ok_or_else(|| {
                    self.err(
                        codes::X_BAD_PORT,
                        n,
                        format!("port `step` of `WaitForStep`: `{t}` is not a step number"),
                    )
                })?;
                return Ok(Op::WaitForStep(k - 1));
            }
            _ => {}
        }
        let model = self.models.get(id).copied();
        let kind = kind.or(model.map(|m| m.kind)).ok_or_else(|| {
            let known = self.doc.models.iter().map(|m| m.id.as_str()).chain(BUILTIN_LEAVES.iter().copied());
            let mut e = self.err(
                codes::X_UNKNOWN_NODE,
                n,
                format!("`{id}` is not a node the runtime knows: it is not built in and not declared in the tree's node models"),
            );
            e = e.hint(match did_you_mean(id, known) {
                Some(h) => h,
                None => "declare it in <TreeNodesModel> as an <Action> or a <Condition>".into(),
            });
            e
        })?;
        let types = |k: &str| -> Option<String> {
            model.and_then(|m| m.ports.iter().find(|p| p.name == k).map(|p| p.ty.clone()))
        };
        let range = self.bind_ports(n, ports, &types, scope)?;
        Ok(match kind {
            LeafKind::Condition => {
                let formula = model.and_then(|m| m.formula.clone());
                let c = self.e.conds.len() as u32;
                let (compiled, slot_ports) = match &formula {
                    Some(f) => {
                        let (c, slots) = self.port_condition(n, id, f, range)?;
                        (Some(c), slots)
                    }
                    None => (None, Box::default()),
                };
                self.e.conds.push(CondInfo {
                    formula: compiled,
                    slot_ports,
                    objects: Ok(Vec::new()),
                    generation: 0,
                });
                Op::Condition(c)
            }
            LeafKind::Action => {
                let a = self.e.actions.len() as u32;
                self.e.actions.push(ActionInfo {
                    id: id.into(),
                    ports: range,
                    handler: None,
                });
                Op::Action(a)
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parallel_thresholds_count_from_the_end_when_negative() {
        assert_eq!(threshold(-1, 5), 5);
        assert_eq!(threshold(-2, 5), 4);
        assert_eq!(threshold(2, 5), 2);
        assert_eq!(threshold(-9, 5), 0);
    }

    #[test]
    fn text_converts_to_the_declared_port_type() {
        let t = |s: &str| Value::Text(s.into());
        assert_eq!(t(" 42 ").typed("int"), Ok(Value::Int(42)));
        assert_eq!(t("2.5").typed("float"), Ok(Value::Float(2.5)));
        assert_eq!(t("true").typed("bool"), Ok(Value::Bool(true)));
        assert_eq!(t("bin1").typed("container"), Ok(t("bin1")));
        assert!(t("three").typed("int").is_err());
        assert_eq!(Value::Int(3).typed("int"), Ok(Value::Int(3)));
    }

    fn leaf(id: &str) -> SNode {
        SNode::leaf(id)
    }

    #[test]
    fn a_failure_made_by_a_decorator_is_recorded_as_its_own() {
        // An earlier, recovered failure must not be blamed.
        let fallback = SNode {
            kind: Kind::Fallback,
            name: None,
            children: vec![leaf("AlwaysFailure"), leaf("AlwaysSuccess")],
            at: None,
        };
        let inverter = SNode {
            kind: Kind::Inverter,
            name: Some("not done".into()),
            children: vec![leaf("AlwaysSuccess")],
            at: None,
        };
        let root = SNode {
            kind: Kind::Sequence,
            name: None,
            children: vec![fallback, inverter],
            at: None,
        };
        let doc = TreeDoc {
            main: "M".into(),
            trees: vec![("M".into(), root)],
            ..TreeDoc::default()
        };
        let mut e = Engine::build(&doc, None, Options::default()).unwrap();
        assert_eq!(e.run(10, |_| {}), Status::Failure);
        assert_eq!(e.records.len(), 1);
        assert_eq!(e.records[0].node_name, "not done");
        assert_eq!(e.records[0].reason, "its child succeeded (Inverter)");
    }

    #[test]
    fn an_empty_tree_of_one_leaf_runs() {
        let doc = TreeDoc {
            main: "M".into(),
            trees: vec![(
                "M".into(),
                SNode {
                    kind: Kind::Leaf {
                        id: "AlwaysFailure".into(),
                        kind: None,
                        ports: Vec::new(),
                    },
                    name: None,
                    children: Vec::new(),
                    at: None,
                },
            )],
            ..TreeDoc::default()
        };
        let mut e = Engine::build(&doc, None, Options::default()).unwrap();
        assert_eq!(e.run(10, |_| {}), Status::Failure);
        assert_eq!(e.records.len(), 1);
        assert_eq!(e.records[0].reason, "AlwaysFailure");
    }
}

//! One trial, tick by tick: the world's events, the task manager, the two
//! agents and the scoring of submitted orders.

use super::challenges::{ChallengeRt, Kind};
use super::facts::{Facts, Place};
use super::report::{AgentReport, Breakdown, ChallengeReport, FaultMet, OrderReport, TrialReport};
use super::scoring;
use super::tasks::{Attempt, Resource, Task, TaskId, TaskState, Work};
use crate::cell::{conjunction, Cell, Literal, Origin, PartInfo, TrialProblem, Var};
use crate::trial::{
    Behavior, ChallengeKind, Condition, Destination, OrderType, PartKind, Robot, SpawnOrder,
    Task as OrderTask, Trial,
};
use btc_lang::db::{self, CompileJob, Database, SourceFile};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::pipeline::{self, ProblemUnit};
use btc_pddl::source::Span;
use btc_pddl::state::Key;
use btc_planner::Outcome;
use btc_runtime::faults::{Blackout, FaultKind, FaultSpec, Trigger};
use btc_runtime::{Engine, Kb, Options, Scenario, Status, TreeDoc};
use rustc_hash::{FxHashMap, FxHashSet};
use std::time::Instant;

/// How a trial runs.
#[derive(Clone, Debug)]
pub struct TrialOptions {
    /// Seeds what ARIAC leaves to chance: a random conveyor order, the
    /// human's moves.
    pub seed: u64,
    /// Record the trace (task events and every tree's status changes).
    pub trace: bool,
    /// Check the world after every tick: each part in one place, no
    /// resource held by two tasks, no robot holding two things (the soak
    /// test's invariants). A violation stops the trial with an error.
    pub check: bool,
    /// Attempts at one part task before it is given up.
    pub max_attempts: u32,
    /// Trial seconds to stop at when the trial has no time limit.
    pub max_seconds: f64,
    pub planner: btc_planner::Options,
}

impl Default for TrialOptions {
    fn default() -> Self {
        TrialOptions {
            seed: 1,
            trace: false,
            check: false,
            max_attempts: 4,
            max_seconds: 3600.0,
            // An agent replans on line, between ticks: it takes LAMA's
            // first plan (no restarts) rather than spend the default
            // improvement budget on every part task.
            planner: btc_planner::Options {
                timeout: Some(std::time::Duration::from_secs(10)),
                improve: 0,
                ..btc_planner::Options::default()
            },
        }
    }
}

#[derive(Debug)]
pub enum TrialError {
    /// The cell's rules or its problem for this trial do not check.
    Cell(Vec<Diagnostic>),
    /// The world broke an invariant (a bug in the simulation or the cell's
    /// domain): what, and at which tick.
    Inconsistent { tick: u64, what: String },
}

/// A cell's rules database, reused across trials: each trial only sets the
/// problem file and the plans.
pub struct Runner<'c> {
    cell: &'c Cell,
    db: Database,
    jobs: Vec<(Robot, CompileJob, String)>,
    problem: SourceFile,
}

const PROBLEM_PATH: &str = "(trial).pddl";

impl<'c> Runner<'c> {
    /// The database with the cell's domain and rules; the rules must check.
    pub fn new(cell: &'c Cell) -> Result<Runner<'c>, TrialError> {
        Runner::with_db(cell, Database::new())
    }

    /// The same, in a database that holds other files already (the cell
    /// and trial files the CLI renders diagnostics for).
    pub fn with_db(cell: &'c Cell, mut db: Database) -> Result<Runner<'c>, TrialError> {
        let domain = db.set_file(&cell.domain_path, cell.domain_text.clone());
        let problem = db.set_file(PROBLEM_PATH, String::new());
        let mut jobs = Vec::new();
        let mut errors = Vec::new();
        for (robot, path, text) in &cell.rules {
            let rules = db.set_file(path, text.clone());
            let plan_path = format!("({}).sas_plan", robot.name());
            let plan = db.set_file(&plan_path, String::new());
            let job = CompileJob::new(&db, rules, plan, Some(problem), Some(domain));
            errors.extend(
                db::rules_diagnostics(&db, rules)
                    .iter()
                    .filter(|d| d.is_error())
                    .cloned(),
            );
            jobs.push((*robot, job, plan_path));
        }
        if !errors.is_empty() {
            return Err(TrialError::Cell(errors));
        }
        Ok(Runner {
            cell,
            db,
            jobs,
            problem,
        })
    }

    /// The database (to render diagnostics with its sources).
    pub fn db(&self) -> &Database {
        &self.db
    }

    pub fn db_mut(&mut self) -> &mut Database {
        &mut self.db
    }

    /// Runs one trial to its end.
    pub fn run(
        &mut self,
        trial: &Trial,
        name: &str,
        opts: &TrialOptions,
    ) -> Result<TrialReport, TrialError> {
        let t0 = Instant::now();
        let tp = TrialProblem::build(self.cell, trial, "trial");
        self.db.set_file(PROBLEM_PATH, tp.text.clone());
        let pid = db::file_id(&self.db, self.problem);
        let pu = pipeline::problem_unit_from(
            &tp.text,
            pid,
            self.cell.domain.domain.as_ref(),
            &self.cell.domain.index,
        );
        let errors: Vec<Diagnostic> = pu
            .diagnostics
            .iter()
            .filter(|d| d.is_error())
            .cloned()
            .collect();
        if !errors.is_empty() || pu.problem.is_none() {
            let first = errors
                .first()
                .map_or("it does not parse".to_owned(), |d| d.message.clone());
            return Err(TrialError::Cell(vec![Diagnostic::error(
                codes::CELL_MAPPING,
                Span::new(pid, 0, 0),
                format!("the trial's PDDL problem, built with the cell's mapping, does not fit the cell's domain: {first}"),
            )
            .with_hint("check the cell's `[names]`, `[types]` and `[always]` against its domain")]));
        }
        let world = btc_pddl::state::World::of_checked(
            self.cell.domain.domain.as_ref().expect("checked"),
            &self.cell.domain.index,
            pu.problem.as_ref().expect("checked"),
            &pu.index,
        )
        .map_err(|m| {
            TrialError::Cell(vec![Diagnostic::error(
                codes::CELL_MAPPING,
                Span::new(pid, 0, 0),
                format!("the trial's PDDL problem cannot be evaluated: {m}"),
            )])
        })?;
        let mut sim = Sim::new(
            self.cell,
            trial,
            &tp,
            (&pu, &world),
            opts,
            &mut self.db,
            &self.jobs,
        )?;
        sim.run()?;
        let mut report = sim.report(name);
        report.elapsed_ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok(report)
    }
}

struct PartRt {
    info: PartInfo,
    obj: u32,
    /// Conveyor parts: the ticks they arrive on and leave the belt.
    spawn: Option<u64>,
    leave: Option<u64>,
    /// Why it is out of the cell (fell off the belt, dropped on the floor).
    gone: Option<String>,
    faulty: bool,
    /// The task that holds it.
    reserved: Option<TaskId>,
}

#[derive(Default)]
struct OrderRt {
    announced: Option<u64>,
    submitted: Option<u64>,
    tasks: Vec<TaskId>,
    qc_done: bool,
    /// Combined orders: the AGV their kitting halves go on, and whether it
    /// has left for the station.
    agv: Option<u8>,
    committed: bool,
    submitting: bool,
    score: i64,
    breakdown: Option<Breakdown>,
}

struct Travel {
    agv: u8,
    to: u32,
    arrive: u64,
    /// The order it submits on arrival.
    order: Option<usize>,
}

struct AgentRt<'w> {
    robot: Robot,
    obj: u32,
    queues: Vec<OrderType>,
    job: CompileJob,
    plan_path: String,
    task: Option<TaskId>,
    engine: Option<Engine<'w>>,
    resources: Vec<Resource>,
    attempt: Option<Attempt>,
    busy: u64,
    done: usize,
    failed: usize,
    plans: usize,
    planning_ms: f64,
}

/// What choosing a task's part and resources came to.
enum Resolve {
    Go {
        part: Option<usize>,
        resources: Vec<Resource>,
        goal: Vec<Literal>,
    },
    /// Its goal already holds.
    Done,
    /// Not now (a part still to come, a resource held).
    Wait,
    /// Never: the cause.
    Never(String),
}

const TRAVEL: usize = usize::MAX;

struct Sim<'w, 'd> {
    cell: &'w Cell,
    trial: &'w Trial,
    opts: &'w TrialOptions,
    pu: &'w ProblemUnit,
    world: &'w btc_pddl::state::World,
    db: &'d mut Database,
    kb: Kb<'w>,
    facts: Facts,
    tick: u64,
    rng: fastrand::Rng,
    parts: Vec<PartRt>,
    part_of: FxHashMap<u32, usize>,
    orders: Vec<OrderRt>,
    tasks: Vec<Task>,
    agents: Vec<AgentRt<'w>>,
    challenges: Vec<ChallengeRt>,
    travels: Vec<Travel>,
    held: Vec<(Resource, TaskId)>,
    prev_kit: FxHashSet<Key>,
    prev_holding: FxHashSet<Key>,
    /// This tick's events: parts placed on AGVs (part, agv), orders
    /// submitted.
    placed: Vec<(usize, u8)>,
    submitted_now: Vec<usize>,
    limit: u64,
    time_limited: bool,
    /// What the last tick left: stopping needs two quiet ticks alike.
    last: (usize, usize, usize, usize),
    stopped: String,
    trace: Vec<(u64, String)>,
    obj: Objects,
}

/// Object ids of the cell's places and things.
struct Objects {
    conveyor: u32,
    agv: [u32; 4],
    kitting_station: [u32; 4],
    station: [u32; 4],
    quadrant: [u32; 4],
    warehouse: u32,
    bins: [u32; 8],
}

fn id(pix: &btc_pddl::ProblemIndex, name: &str) -> Result<u32, TrialError> {
    pix.objects.get(name).map(|o| o.id).ok_or_else(|| {
        TrialError::Cell(vec![Diagnostic::error(
            codes::CELL_MAPPING,
            Span::new(0, 0, 0),
            format!("the trial's problem has no object `{name}`"),
        )])
    })
}

impl<'w, 'd> Sim<'w, 'd> {
    fn new(
        cell: &'w Cell,
        trial: &'w Trial,
        tp: &TrialProblem,
        (pu, world): (&'w ProblemUnit, &'w btc_pddl::state::World),
        opts: &'w TrialOptions,
        db: &'d mut Database,
        jobs: &[(Robot, CompileJob, String)],
    ) -> Result<Sim<'w, 'd>, TrialError> {
        let pix = &pu.index;
        let kb = Kb::new(world);
        let facts = Facts::new(cell, pix).map_err(|m| {
            TrialError::Cell(vec![Diagnostic::error(
                codes::CELL_MAPPING,
                Span::new(0, 0, 0),
                m,
            )])
        })?;
        let time = &cell.spec.time;
        let mut rng = fastrand::Rng::with_seed(opts.seed);
        let mut parts: Vec<PartRt> = Vec::new();
        for p in &tp.parts {
            parts.push(PartRt {
                obj: id(pix, &p.name)?,
                info: p.clone(),
                spawn: None,
                leave: None,
                gone: None,
                faulty: false,
                reserved: None,
            });
        }
        // The belt's schedule: one part every `spawn_rate` seconds from the
        // start, in the file's order or shuffled.
        if let Some(c) = trial.conveyor.as_ref().filter(|c| c.active) {
            let mut order: Vec<usize> = (0..parts.len())
                .filter(|&k| matches!(parts[k].info.origin, Origin::Conveyor { .. }))
                .collect();
            if c.order == SpawnOrder::Random {
                rng.shuffle(&mut order);
            }
            for (n, k) in order.into_iter().enumerate() {
                let at = time.ticks(n as f64 * c.spawn_rate) + 1;
                parts[k].spawn = Some(at);
                parts[k].leave = Some(at + time.ticks(time.conveyor_seconds).max(1));
            }
        }
        let part_of = parts.iter().enumerate().map(|(k, p)| (p.obj, k)).collect();
        let mut agents = Vec::new();
        for (robot, job, plan_path) in jobs {
            let spec = cell.robot(*robot);
            agents.push(AgentRt {
                robot: *robot,
                obj: id(pix, &spec.object)?,
                queues: spec.queues.clone(),
                job: *job,
                plan_path: plan_path.clone(),
                task: None,
                engine: None,
                resources: Vec::new(),
                attempt: None,
                busy: 0,
                done: 0,
                failed: 0,
                plans: 0,
                planning_ms: 0.0,
            });
        }
        let mut challenges: Vec<ChallengeRt> = Vec::new();
        for (k, c) in trial.challenges.iter().enumerate() {
            let kind = Kind::Trial(c.kind.clone());
            challenges.push(ChallengeRt::new(format!("{}#{}", kind.name(), k + 1), kind));
        }
        for (k, o) in trial.orders.iter().enumerate() {
            if o.priority {
                challenges.push(ChallengeRt::new(
                    format!("high_priority_order({})", o.id),
                    Kind::HighPriorityOrder { order: k },
                ));
            }
        }
        let mut flipped_lots: Vec<(PartKind, String)> = Vec::new();
        for p in &parts {
            if p.info.flipped {
                let place = match p.info.origin {
                    Origin::Bin { bin, .. } => cell.bin(bin),
                    Origin::Agv { agv, .. } => cell.agv(agv),
                    Origin::Conveyor { .. } => cell.conveyor(),
                };
                if !flipped_lots.contains(&(p.info.kind, place.clone())) {
                    flipped_lots.push((p.info.kind, place));
                }
            }
        }
        for (kind, place) in flipped_lots {
            challenges.push(ChallengeRt::new(
                format!("flipped_part({kind} in {place})"),
                Kind::FlippedParts { kind, place },
            ));
        }
        let obj = Objects {
            conveyor: id(pix, &cell.conveyor())?,
            agv: [
                id(pix, &cell.agv(1))?,
                id(pix, &cell.agv(2))?,
                id(pix, &cell.agv(3))?,
                id(pix, &cell.agv(4))?,
            ],
            kitting_station: [
                id(pix, &cell.kitting_station(1))?,
                id(pix, &cell.kitting_station(2))?,
                id(pix, &cell.kitting_station(3))?,
                id(pix, &cell.kitting_station(4))?,
            ],
            station: [
                id(pix, &cell.station(1))?,
                id(pix, &cell.station(2))?,
                id(pix, &cell.station(3))?,
                id(pix, &cell.station(4))?,
            ],
            quadrant: [
                id(pix, &cell.quadrant(1))?,
                id(pix, &cell.quadrant(2))?,
                id(pix, &cell.quadrant(3))?,
                id(pix, &cell.quadrant(4))?,
            ],
            warehouse: id(pix, &cell.warehouse())?,
            bins: {
                let mut b = [0; 8];
                for (k, slot) in b.iter_mut().enumerate() {
                    *slot = id(pix, &cell.bin(k as u8 + 1))?;
                }
                b
            },
        };
        let (limit, time_limited) = match trial.time_limit {
            Some(s) => (time.ticks(s), true),
            None => (time.ticks(opts.max_seconds), false),
        };
        let mut sim = Sim {
            cell,
            trial,
            opts,
            pu,
            world,
            db,
            kb,
            facts,
            tick: 0,
            rng,
            parts,
            part_of,
            orders: (0..trial.orders.len())
                .map(|_| OrderRt::default())
                .collect(),
            tasks: Vec::new(),
            agents,
            challenges,
            travels: Vec::new(),
            held: Vec::new(),
            prev_kit: FxHashSet::default(),
            prev_holding: FxHashSet::default(),
            placed: Vec::new(),
            submitted_now: Vec::new(),
            limit: limit.max(1),
            time_limited,
            last: (0, 0, 0, 0),
            stopped: String::new(),
            trace: Vec::new(),
            obj,
        };
        sim.prev_kit = sim.kit_facts();
        sim.prev_holding = sim.holding_facts();
        Ok(sim)
    }

    fn secs(&self, t: u64) -> f64 {
        self.cell.spec.time.seconds(t)
    }

    fn name(&self, o: u32) -> &str {
        &self.pu.index.object_names[o as usize]
    }

    fn event(&mut self, v: serde_json::Value) {
        if self.opts.trace {
            let mut v = v;
            if let Some(o) = v.as_object_mut() {
                o.insert("tick".into(), self.tick.into());
            }
            self.trace.push((self.tick, v.to_string()));
        }
    }

    // ---- the main loop ----

    fn run(&mut self) -> Result<(), TrialError> {
        loop {
            self.tick += 1;
            self.placed.clear();
            self.submitted_now.clear();
            self.world_events();
            self.announce_orders();
            self.allocate();
            self.tick_agents();
            self.after_tick();
            if self.opts.check {
                self.check()?;
            }
            if let Some(why) = self.should_stop() {
                self.stopped = why;
                break;
            }
            self.last = self.signature();
        }
        self.close();
        Ok(())
    }

    fn should_stop(&self) -> Option<String> {
        let all_in = self.orders.iter().all(|o| o.submitted.is_some());
        if all_in && !self.orders.is_empty() {
            return Some("every order was submitted".into());
        }
        if self.tick >= self.limit {
            return Some(if self.time_limited {
                format!(
                    "the trial's time limit ({} s) was reached",
                    self.secs(self.limit)
                )
            } else {
                format!(
                    "the trial has no time limit and btc stops at {} s",
                    self.secs(self.limit)
                )
            });
        }
        if self.quiet() && self.signature() == self.last {
            return Some(
                "nothing more could happen: no agent has work it can do and no event is to come"
                    .into(),
            );
        }
        None
    }

    fn signature(&self) -> (usize, usize, usize, usize) {
        (
            self.tasks.len() + self.tasks.iter().map(|t| t.attempts.len()).sum::<usize>(),
            self.tasks.iter().filter(|t| t.is_open()).count(),
            self.tasks
                .iter()
                .filter(|t| t.state == TaskState::Blocked)
                .count()
                + 1000
                    * self
                        .tasks
                        .iter()
                        .filter(|t| matches!(t.state, TaskState::Running { .. }))
                        .count(),
            self.orders.iter().filter(|o| o.announced.is_some()).count()
                + self.orders.iter().filter(|o| o.submitted.is_some()).count(),
        )
    }

    /// No agent busy, no task that could start, nothing scheduled.
    fn quiet(&self) -> bool {
        if self.agents.iter().any(|a| a.task.is_some()) || !self.travels.is_empty() {
            return false;
        }
        if self.parts.iter().any(|p| {
            p.spawn.is_some_and(|s| s > self.tick)
                || p.leave.is_some_and(|l| l > self.tick) && p.gone.is_none()
        }) {
            return false;
        }
        let pending_time = |c: &Condition| matches!(c, Condition::Time(t) if self.cell.spec.time.ticks(*t) >= self.tick);
        if self
            .trial
            .orders
            .iter()
            .zip(&self.orders)
            .any(|(o, rt)| rt.announced.is_none() && pending_time(&o.announcement))
        {
            return false;
        }
        if self.challenges.iter().any(|c| {
            (c.met_at.is_none() && c.kind.condition().is_some_and(pending_time))
                || c.in_effect(self.tick) && c.until.is_some()
                || c.drop.is_some()
        }) {
            return false;
        }
        // Submissions waiting only for their order's tasks to end.
        !self.orders.iter().enumerate().any(|(k, o)| {
            o.announced.is_some() && o.submitted.is_none() && !o.submitting && self.order_ended(k)
        })
    }

    // ---- the world ----

    fn apply(&mut self, add: Vec<Key>, del: Vec<Key>) {
        self.kb.apply_keys(add, del);
    }

    fn world_events(&mut self) {
        let tick = self.tick;
        // The conveyor.
        for k in 0..self.parts.len() {
            if self.parts[k].spawn == Some(tick) {
                let p = self.parts[k].obj;
                let mut add = vec![self
                    .facts
                    .part_at
                    .key(&[(Var::Part, p), (Var::Place, self.obj.conveyor)])];
                if self.parts[k].info.flipped {
                    add.push(self.facts.flipped.key(&[(Var::Part, p)]));
                }
                self.apply(add, Vec::new());
                let name = self.parts[k].info.name.clone();
                self.event(
                    serde_json::json!({"event": "conveyor", "part": name, "what": "arrives"}),
                );
            }
            // A part a task has reserved is tracked by its robot and does
            // not ride off the belt (the symbolic world has no belt speed).
            if self.parts[k].leave == Some(tick) && self.parts[k].reserved.is_some() {
                self.parts[k].leave = Some(tick + 1);
            } else if self.parts[k].leave == Some(tick) {
                let p = self.parts[k].obj;
                let on = self
                    .facts
                    .part_at
                    .key(&[(Var::Part, p), (Var::Place, self.obj.conveyor)]);
                if self.kb.state.facts.contains(&on) {
                    let mut del = vec![on];
                    del.push(self.facts.flipped.key(&[(Var::Part, p)]));
                    self.apply(Vec::new(), del);
                    self.parts[k].gone = Some("it rode off the end of the conveyor belt".into());
                    let name = self.parts[k].info.name.clone();
                    self.event(serde_json::json!({"event": "conveyor", "part": name, "what": "falls off the end"}));
                }
            }
        }
        // AGVs arriving.
        let arrived: Vec<usize> = (0..self.travels.len())
            .filter(|&k| self.travels[k].arrive <= tick)
            .collect();
        for k in arrived.into_iter().rev() {
            let t = self.travels.remove(k);
            let agv = self.obj.agv[t.agv as usize - 1];
            if let Some(from) = self.facts.agv_place(&self.kb.state, agv) {
                let del = vec![self
                    .facts
                    .agv_at
                    .key(&[(Var::Agv, agv), (Var::Place, from)])];
                let add = vec![self
                    .facts
                    .agv_at
                    .key(&[(Var::Agv, agv), (Var::Place, t.to)])];
                self.apply(add, del);
            }
            self.held
                .retain(|(r, who)| !(*who == TRAVEL && *r == Resource::Agv(t.agv)));
            let to = self.name(t.to).to_owned();
            self.event(
                serde_json::json!({"event": "agv", "agv": format!("agv{}", t.agv), "arrives": to}),
            );
            if let Some(o) = t.order {
                self.submit(o);
            }
        }
        // Challenges: time triggers, ends, drops.
        for c in 0..self.challenges.len() {
            let ch = &self.challenges[c];
            if ch.met_at.is_some() && !ch.ended && ch.until.is_some_and(|u| tick >= u) {
                self.end_challenge(c);
                continue;
            }
            if let Some((at, part)) = ch.drop {
                if at <= tick {
                    self.drop_part(c, part);
                }
            }
            let ch = &self.challenges[c];
            if ch.met_at.is_none() {
                if let Some(Condition::Time(t)) = ch.kind.condition() {
                    if self.cell.spec.time.ticks(*t) < tick {
                        self.trigger(c);
                    }
                }
            }
        }
        self.human();
    }

    fn announce_orders(&mut self) {
        for k in 0..self.orders.len() {
            if self.orders[k].announced.is_some() {
                continue;
            }
            let go = match &self.trial.orders[k].announcement {
                Condition::Time(t) => self.cell.spec.time.ticks(*t) < self.tick,
                // Placements and submissions of the previous tick.
                Condition::PartPlace { .. } | Condition::Submission(_) => false,
            };
            if go {
                self.announce(k);
            }
        }
    }

    fn announce(&mut self, k: usize) {
        let o = &self.trial.orders[k];
        self.orders[k].announced = Some(self.tick);
        let prio = o.priority;
        let ty = o.task.order_type();
        self.event(serde_json::json!({"event": "order", "order": o.id, "what": "announced", "type": ty.name(), "priority": prio}));
        let mut ids = Vec::new();
        match &o.task {
            OrderTask::Kitting {
                agv,
                tray_id,
                products,
                ..
            } => {
                let tray = self.new_task(
                    k,
                    OrderType::Kitting,
                    Work::Tray {
                        agv: *agv,
                        tray: *tray_id,
                    },
                    Vec::new(),
                );
                ids.push(tray);
                for p in products {
                    ids.push(self.new_task(
                        k,
                        OrderType::Kitting,
                        Work::Kit {
                            part: p.kind,
                            agv: *agv,
                            quadrant: p.quadrant,
                        },
                        vec![tray],
                    ));
                }
            }
            OrderTask::Assembly {
                agvs,
                station,
                products,
            } => {
                for p in products {
                    ids.push(self.new_task(
                        k,
                        OrderType::Assembly,
                        Work::Assemble {
                            part: p.kind,
                            station: *station,
                            agvs: agvs.clone(),
                            from_task: None,
                        },
                        Vec::new(),
                    ));
                }
            }
            OrderTask::Combined { station, products } => {
                for p in products {
                    ids.push(self.new_task(
                        k,
                        OrderType::Combined,
                        Work::Combined {
                            part: p.kind,
                            station: *station,
                        },
                        Vec::new(),
                    ));
                }
            }
        }
        let _ = ids;
        if prio {
            if let Some(c) = self
                .challenges
                .iter()
                .position(|c| c.kind == Kind::HighPriorityOrder { order: k })
            {
                self.challenges[c].met_at = Some(self.tick);
                self.challenges[c].touch(k);
                self.preempt_for_priority(c);
            }
        }
    }

    fn new_task(
        &mut self,
        order: usize,
        queue: OrderType,
        work: Work,
        after: Vec<TaskId>,
    ) -> TaskId {
        let id = self.tasks.len();
        let priority = self.trial.orders[order].priority;
        self.event(serde_json::json!({"event": "task", "task": id, "order": self.trial.orders[order].id, "what": "created", "work": work.describe(), "queue": queue.name()}));
        self.tasks.push(Task {
            id,
            order,
            queue,
            work,
            priority,
            state: if after.is_empty() {
                TaskState::Queued
            } else {
                TaskState::Blocked
            },
            after,
            part: None,
            attempts: Vec::new(),
            reassignments: 0,
            created: self.tick,
        });
        self.orders[order].tasks.push(id);
        id
    }

    // ---- the task manager ----

    fn normal(&self, a: usize) -> bool {
        let r = self.agents[a].robot;
        !self
            .challenges
            .iter()
            .any(|c| c.disables(r) && c.in_effect(self.tick))
    }

    fn idle(&self, a: usize) -> bool {
        self.agents[a].task.is_none()
    }

    /// Blocked tasks whose tasks before them are done become queued.
    fn unblock(&mut self) {
        for t in 0..self.tasks.len() {
            if self.tasks[t].state != TaskState::Blocked {
                continue;
            }
            let ready = self.tasks[t]
                .after
                .iter()
                .all(|&d| !self.tasks[d].is_open())
                && self.assembly_half_ready(t);
            if ready {
                self.tasks[t].state = TaskState::Queued;
            }
        }
    }

    /// An assembly half waits until no kitting half of its order is still
    /// to go on the same AGV and its order's quality check is done.
    fn assembly_half_ready(&self, t: TaskId) -> bool {
        let Work::Assemble {
            from_task: Some(_), ..
        } = &self.tasks[t].work
        else {
            return true;
        };
        let o = self.tasks[t].order;
        let Some(agv) = self.orders[o].agv else {
            return true;
        };
        let open_kits = self.orders[o].tasks.iter().any(|&k| {
            self.tasks[k].is_open()
                && matches!(&self.tasks[k].work, Work::Kit { agv: a, .. } | Work::Replace { agv: a, .. } if *a == agv)
        });
        !open_kits && self.orders[o].qc_done
    }

    fn allocate(&mut self) {
        self.unblock();
        // Passes until nothing changes: a split in one pass gives the floor
        // agent work in the next.
        for _ in 0..8 {
            let mut changed = false;
            for a in 0..self.agents.len() {
                if !self.idle(a) || !self.normal(a) {
                    continue;
                }
                changed |= self.take(a);
            }
            if !changed {
                break;
            }
        }
    }

    /// The paper's rules: the agent's queues in its order, high-priority
    /// tasks first, tasks whose part is on the conveyor first within them.
    fn take(&mut self, a: usize) -> bool {
        let queues = self.agents[a].queues.clone();
        for prio in [true, false] {
            for &q in &queues {
                let mut cands: Vec<TaskId> = (0..self.tasks.len())
                    .filter(|&t| {
                        let task = &self.tasks[t];
                        task.queue == q && task.priority == prio && task.state == TaskState::Queued
                    })
                    .collect();
                cands.sort_by_key(|&t| (!self.on_conveyor(t), self.tasks[t].created, t));
                for t in cands {
                    if q == OrderType::Combined {
                        if self.split_or_convert(a, t) {
                            return true;
                        }
                        continue;
                    }
                    match self.start(a, t) {
                        Some(true) => return true,
                        Some(false) => continue,
                        None => return true,
                    }
                }
            }
        }
        false
    }

    /// Whether a part of the task's kind is on the belt now.
    fn on_conveyor(&self, t: TaskId) -> bool {
        let Some(kind) = self.tasks[t].work.part_kind() else {
            return false;
        };
        self.parts.iter().any(|p| {
            p.info.kind == kind
                && p.reserved.is_none()
                && self.facts.place(&self.kb.state, p.obj) == Place::At(self.obj.conveyor)
        })
    }

    /// Rule 2: a combined task is split into a kitting and an assembly task
    /// when both agents are idle, and converted to an assembly task
    /// otherwise. True when the agent got work (or the queue changed).
    fn split_or_convert(&mut self, a: usize, t: TaskId) -> bool {
        let Work::Combined { part, station } = self.tasks[t].work.clone() else {
            return false;
        };
        let o = self.tasks[t].order;
        let others_idle = (0..self.agents.len()).all(|b| {
            b == a
                || (self.idle(b)
                    && self.normal(b)
                    && self.agents[b].queues.contains(&OrderType::Kitting))
        });
        if others_idle && self.agents.len() > 1 {
            if let Some((agv, quadrant)) = self.split_place(o, station) {
                let kit = self.new_task(
                    o,
                    OrderType::Kitting,
                    Work::Kit {
                        part,
                        agv,
                        quadrant,
                    },
                    Vec::new(),
                );
                let asm = self.new_task(
                    o,
                    OrderType::Assembly,
                    Work::Assemble {
                        part,
                        station,
                        agvs: vec![agv],
                        from_task: Some(kit),
                    },
                    vec![kit],
                );
                self.orders[o].agv = Some(agv);
                self.tasks[t].state = TaskState::Split {
                    into: vec![kit, asm],
                };
                let oid = self.trial.orders[o].id.clone();
                self.event(serde_json::json!({"event": "task", "task": t, "order": oid, "what": "split", "into": [kit, asm]}));
                return true;
            }
        }
        let asm = self.new_task(
            o,
            OrderType::Assembly,
            Work::Assemble {
                part,
                station,
                agvs: Vec::new(),
                from_task: None,
            },
            Vec::new(),
        );
        self.tasks[t].state = TaskState::Split { into: vec![asm] };
        let oid = self.trial.orders[o].id.clone();
        self.event(serde_json::json!({"event": "task", "task": t, "order": oid, "what": "converted", "into": [asm]}));
        self.start(a, asm);
        true
    }

    /// The AGV and quadrant for a split's kitting half: the order's AGV if
    /// it has one still at its kitting station, else a free AGV that serves
    /// the station.
    fn split_place(&self, o: usize, station: u8) -> Option<(u8, u8)> {
        let st = self.obj.station[station as usize - 1];
        let free_quadrant = |agv: u8| -> Option<u8> {
            let aobj = self.obj.agv[agv as usize - 1];
            (1..=4u8).find(|&q| {
                let k = self
                    .facts
                    .kit_free
                    .key(&[(Var::Agv, aobj), (Var::Quadrant, self.obj.quadrant[q as usize - 1])]);
                self.kb.state.facts.contains(&k)
                    && !self.tasks.iter().any(|t| {
                        t.is_open() && matches!(t.work, Work::Kit { agv: a, quadrant: qq, .. } if a == agv && qq == q)
                    })
            })
        };
        let at_home = |agv: u8| {
            let aobj = self.obj.agv[agv as usize - 1];
            self.facts.agv_place(&self.kb.state, aobj)
                == Some(self.obj.kitting_station[agv as usize - 1])
        };
        if let Some(agv) = self.orders[o].agv {
            if self.orders[o].committed || !at_home(agv) {
                return None;
            }
            return free_quadrant(agv).map(|q| (agv, q));
        }
        for agv in 1..=4u8 {
            let aobj = self.obj.agv[agv as usize - 1];
            let serves = self.kb.state.facts.contains(
                &self
                    .facts
                    .agv_goes
                    .key(&[(Var::Agv, aobj), (Var::Place, st)]),
            );
            let used = self
                .orders
                .iter()
                .enumerate()
                .any(|(k, r)| k != o && r.agv == Some(agv) && r.submitted.is_none())
                || self.tasks.iter().any(|t| {
                    t.is_open()
                        && match &t.work {
                            Work::Tray { agv: a, .. }
                            | Work::Kit { agv: a, .. }
                            | Work::Replace { agv: a, .. } => *a == agv,
                            Work::Assemble { agvs, .. } => agvs.contains(&agv),
                            Work::Combined { .. } => false,
                        }
                })
                || self.trial.orders.iter().zip(&self.orders).any(|(ord, r)| {
                    r.submitted.is_none()
                        && match &ord.task {
                            OrderTask::Kitting { agv: a, .. } => *a == agv,
                            OrderTask::Assembly { agvs, .. } => agvs.contains(&agv),
                            OrderTask::Combined { .. } => false,
                        }
                });
            if serves && at_home(agv) && !used {
                if let Some(q) = free_quadrant(agv) {
                    return Some((agv, q));
                }
            }
        }
        None
    }

    /// A part for the task, by the paper's preferences: the one the agent's
    /// robot holds (what the fault record kept), then one on the conveyor,
    /// then one lying the right way up, then any.
    fn pick_part(
        &self,
        a: usize,
        t: TaskId,
        kind: PartKind,
        from_agvs: &[u8],
    ) -> Result<Option<usize>, ()> {
        let robot = self.agents[a].obj;
        let s = &self.kb.state;
        // The part the task's last attempt used, wherever it lies now (the
        // fault record keeps it), unless another robot holds it.
        if let Some(k) = self.tasks[t].part {
            let p = &self.parts[k];
            let usable = match self.facts.place(s, p.obj) {
                Place::Held(r) => r == robot,
                Place::At(_) | Place::InKit { .. } => true,
                _ => false,
            };
            if usable
                && p.gone.is_none()
                && !p.faulty
                && p.reserved.is_none()
                && p.info.kind == kind
            {
                return Ok(Some(k));
            }
        }
        let mut best: Option<(u8, usize)> = None;
        let mut someone_has = false;
        for (k, p) in self.parts.iter().enumerate() {
            if p.info.kind != kind || p.gone.is_some() || p.faulty {
                continue;
            }
            let place = self.facts.place(s, p.obj);
            let rank = match place {
                Place::Held(r) if r == robot => 0,
                Place::At(l) if from_agvs.is_empty() && l == self.obj.conveyor => 1,
                Place::At(l) if from_agvs.is_empty() && self.obj.bins.contains(&l) => {
                    if s.facts
                        .contains(&self.facts.flipped.key(&[(Var::Part, p.obj)]))
                    {
                        3
                    } else {
                        2
                    }
                }
                Place::InKit { agv, .. }
                    if from_agvs
                        .iter()
                        .any(|&n| self.obj.agv[n as usize - 1] == agv) =>
                {
                    2
                }
                _ => {
                    if p.spawn.is_some_and(|t| t > self.tick) && from_agvs.is_empty() {
                        someone_has = true;
                    }
                    continue;
                }
            };
            if p.reserved.is_some() {
                someone_has = true;
                continue;
            }
            if best.is_none_or(|(r, _)| rank < r) {
                best = Some((rank, k));
            }
        }
        match best {
            Some((_, k)) => Ok(Some(k)),
            None if someone_has => Ok(None),
            None => Err(()),
        }
    }

    fn lits_kit(&self, part: u32, agv: u32, q: u32) -> Vec<Literal> {
        let f = &self.cell.spec.facts;
        let (p, a, qq) = (self.name(part), self.name(agv), self.name(q));
        vec![
            Literal {
                positive: true,
                atom: f
                    .in_kit
                    .ground(&[(Var::Part, p), (Var::Agv, a), (Var::Quadrant, qq)]),
            },
            Literal {
                positive: false,
                atom: f.flipped.ground(&[(Var::Part, p)]),
            },
        ]
    }

    fn lit(&self, t: &crate::cell::AtomTemplate, vals: &[(Var, u32)], positive: bool) -> Literal {
        let named: Vec<(Var, &str)> = vals.iter().map(|(v, o)| (*v, self.name(*o))).collect();
        Literal {
            positive,
            atom: t.ground(&named),
        }
    }

    fn resolve(&self, a: usize, t: TaskId) -> Resolve {
        let s = &self.kb.state;
        let f = &self.cell.spec.facts;
        match self.tasks[t].work.clone() {
            Work::Tray { agv, tray } => {
                let aobj = self.obj.agv[agv as usize - 1];
                let tname = self.cell.tray(tray);
                let Some(tobj) = self.pu.index.objects.get(&tname).map(|o| o.id) else {
                    return Resolve::Never(format!("the cell has no tray {tray}"));
                };
                match self.facts.tray_of(s, aobj) {
                    Some(x) if x == tobj => return Resolve::Done,
                    Some(x) => {
                        return Resolve::Never(format!(
                            "agv{agv} carries {} already, not tray {tray}",
                            self.name(x)
                        ))
                    }
                    None => {}
                }
                let on_table = s
                    .facts
                    .iter()
                    .any(|k| self.facts.tray_at.get(k, Var::Tray) == Some(tobj));
                let holder = s
                    .facts
                    .iter()
                    .find(|k| self.facts.holding_tray.get(k, Var::Tray) == Some(tobj))
                    .and_then(|k| self.facts.holding_tray.get(k, Var::Robot));
                match holder {
                    Some(r) if r != self.agents[a].obj => return Resolve::Wait,
                    Some(_) => {}
                    None if !on_table => {
                        return Resolve::Never(format!(
                            "tray {tray} is on neither tray table (the trial's `kitting_trays` do not have it)"
                        ))
                    }
                    None => {}
                }
                if self.facts.agv_place(s, aobj) != Some(self.obj.kitting_station[agv as usize - 1])
                {
                    return Resolve::Wait;
                }
                Resolve::Go {
                    part: None,
                    resources: vec![Resource::Agv(agv), Resource::Tray(tray)],
                    goal: vec![Literal {
                        positive: true,
                        atom: f
                            .tray_on
                            .ground(&[(Var::Tray, &tname), (Var::Agv, self.name(aobj))]),
                    }],
                }
            }
            Work::Kit {
                part,
                agv,
                quadrant,
            }
            | Work::Replace {
                part,
                agv,
                quadrant,
                ..
            } => {
                let aobj = self.obj.agv[agv as usize - 1];
                let qobj = self.obj.quadrant[quadrant as usize - 1];
                if self.facts.agv_place(s, aobj) != Some(self.obj.kitting_station[agv as usize - 1])
                {
                    return Resolve::Wait;
                }
                let mut goal = Vec::new();
                let mut resources = vec![Resource::Quadrant(agv, quadrant)];
                let occupant = self
                    .facts
                    .kit(s, aobj)
                    .into_iter()
                    .find(|(q, _)| *q == qobj)
                    .and_then(|(_, p)| self.part_of.get(&p).copied());
                if let Work::Replace { faulty, .. } = self.tasks[t].work {
                    goal.push(self.lit(&f.discarded, &[(Var::Part, self.parts[faulty].obj)], true));
                    resources.push(Resource::Part(faulty));
                }
                if let Some(occ) = occupant {
                    let is_replace =
                        matches!(self.tasks[t].work, Work::Replace { faulty, .. } if faulty == occ);
                    if !is_replace {
                        if self.parts[occ].info.kind == part && !self.parts[occ].faulty {
                            // The part is there: turned over if need be.
                            if !s.facts.contains(
                                &self.facts.flipped.key(&[(Var::Part, self.parts[occ].obj)]),
                            ) {
                                return Resolve::Done;
                            }
                            resources.push(Resource::Part(occ));
                            goal.extend(self.lits_kit(self.parts[occ].obj, aobj, qobj));
                            return Resolve::Go {
                                part: Some(occ),
                                resources,
                                goal,
                            };
                        }
                        goal.push(self.lit(
                            &f.discarded,
                            &[(Var::Part, self.parts[occ].obj)],
                            true,
                        ));
                        resources.push(Resource::Part(occ));
                    }
                }
                match self.pick_part(a, t, part, &[]) {
                    Ok(Some(k)) => {
                        resources.push(Resource::Part(k));
                        goal.extend(self.lits_kit(self.parts[k].obj, aobj, qobj));
                        Resolve::Go {
                            part: Some(k),
                            resources,
                            goal,
                        }
                    }
                    Ok(None) => Resolve::Wait,
                    Err(()) => Resolve::Never(format!(
                        "insufficient parts: no {part} is left in the bins or on the conveyor, nor still to come"
                    )),
                }
            }
            Work::Assemble {
                part,
                station,
                agvs,
                from_task,
            } => {
                let st = self.obj.station[station as usize - 1];
                let taken = self
                    .facts
                    .insert(s, st)
                    .into_iter()
                    .filter_map(|p| self.part_of.get(&p))
                    .any(|&k| self.parts[k].info.kind.ty == part.ty);
                if taken {
                    return Resolve::Never(format!(
                        "the insert at as{station} has a {} in its slot already",
                        part.ty.name()
                    ));
                }
                let k = match from_task {
                    Some(kt) => match self.tasks[kt].part {
                        Some(k) if self.parts[k].gone.is_none() => k,
                        _ => return Resolve::Never("the part its kitting half placed is gone".into()),
                    },
                    None => match self.pick_part(a, t, part, &agvs) {
                        Ok(Some(k)) => k,
                        Ok(None) => return Resolve::Wait,
                        Err(()) if agvs.is_empty() => {
                            return Resolve::Never(format!(
                                "insufficient parts: no {part} is left in the bins or on the conveyor, nor still to come"
                            ))
                        }
                        Err(()) => {
                            return Resolve::Never(format!(
                                "insufficient parts: no {part} is on {}",
                                agvs.iter().map(|n| format!("agv{n}")).collect::<Vec<_>>().join(" or ")
                            ))
                        }
                    },
                };
                let mut resources = vec![Resource::Part(k), Resource::Station(station)];
                if let Place::InKit { agv, .. } = self.facts.place(s, self.parts[k].obj) {
                    if let Some(n) = self.obj.agv.iter().position(|&x| x == agv) {
                        resources.push(Resource::Agv(n as u8 + 1));
                    }
                }
                let p = self.parts[k].obj;
                Resolve::Go {
                    part: Some(k),
                    resources,
                    goal: vec![
                        self.lit(&f.installed, &[(Var::Part, p), (Var::Station, st)], true),
                        self.lit(&f.flipped, &[(Var::Part, p)], false),
                    ],
                }
            }
            Work::Combined { .. } => Resolve::Wait,
        }
    }

    fn free(&self, res: &[Resource]) -> bool {
        res.iter()
            .all(|r| !self.held.iter().any(|(h, _)| h.conflicts(*r)))
    }

    /// Starts task `t` on agent `a`: `Some(true)` started (or finished at
    /// once), `Some(false)` not now, `None` the task ended without running.
    fn start(&mut self, a: usize, t: TaskId) -> Option<bool> {
        match self.resolve(a, t) {
            Resolve::Wait => Some(false),
            Resolve::Done => {
                self.tasks[t].state = TaskState::Done { tick: self.tick };
                let oid = self.trial.orders[self.tasks[t].order].id.clone();
                self.event(serde_json::json!({"event": "task", "task": t, "order": oid, "what": "done", "how": "its goal already held"}));
                None
            }
            Resolve::Never(cause) => {
                self.fail_task(t, cause);
                None
            }
            Resolve::Go {
                part,
                resources,
                goal,
            } => {
                if !self.free(&resources) {
                    return Some(false);
                }
                self.launch(a, t, part, resources, goal);
                Some(true)
            }
        }
    }

    fn fail_task(&mut self, t: TaskId, cause: String) {
        if cause.starts_with("insufficient parts") {
            if let Some(kind) = self.tasks[t].work.part_kind() {
                let c = match self
                    .challenges
                    .iter()
                    .position(|c| c.kind == Kind::InsufficientParts { kind })
                {
                    Some(c) => c,
                    None => {
                        self.challenges.push(ChallengeRt::new(
                            format!("insufficient_parts({kind})"),
                            Kind::InsufficientParts { kind },
                        ));
                        self.challenges.len() - 1
                    }
                };
                let o = self.tasks[t].order;
                let ch = &mut self.challenges[c];
                ch.met_at.get_or_insert(self.tick);
                ch.touch(o);
                ch.ended = true;
                ch.note(format!("task {t}: {cause}"));
            }
        }
        let oid = self.trial.orders[self.tasks[t].order].id.clone();
        self.event(serde_json::json!({"event": "task", "task": t, "order": oid, "what": "failed", "cause": cause}));
        self.tasks[t].state = TaskState::Failed {
            tick: self.tick,
            cause,
        };
        // What waited for it can go on without it.
        for d in 0..self.tasks.len() {
            if self.tasks[d].after.contains(&t) && self.tasks[d].state == TaskState::Blocked {
                if let Work::Assemble {
                    from_task: Some(k), ..
                } = self.tasks[d].work
                {
                    if k == t {
                        // The kitting half failed: the assembly half is
                        // converted (its part comes from the bins).
                        if let Work::Assemble {
                            from_task, agvs, ..
                        } = &mut self.tasks[d].work
                        {
                            *from_task = None;
                            agvs.clear();
                        }
                    }
                }
            }
        }
    }

    /// Plans, compiles and builds the tree of a task on agent `a`.
    fn launch(
        &mut self,
        a: usize,
        t: TaskId,
        part: Option<usize>,
        resources: Vec<Resource>,
        mut goal: Vec<Literal>,
    ) {
        // A part in the robot's hand that the task does not use is put back,
        // not thrown away.
        if let Some(h) = self.facts.held_by(&self.kb.state, self.agents[a].obj) {
            let named = goal
                .iter()
                .any(|l| l.atom.args.iter().any(|x| x == self.name(h)));
            if !named {
                let lit = self.lit(&self.cell.spec.facts.discarded, &[(Var::Part, h)], false);
                goal.push(lit);
            }
        }
        let goal_f = conjunction(&goal);
        let goal_text = goal_f.to_string();
        let robot = self.agents[a].robot;
        let robot_name = self.cell.robot(robot).object.clone();
        let mut attempt = Attempt {
            agent: robot_name.clone(),
            start_tick: self.tick,
            end_tick: self.tick,
            part: part.map(|k| self.parts[k].info.name.clone()),
            goal: goal_text.clone(),
            plan: Vec::new(),
            planning_ms: 0.0,
            outcome: String::new(),
            challenges: Vec::new(),
        };
        // The goal must fit the domain (it is checked as the KB compiles it).
        match self.kb.formula(&goal_f) {
            Ok(_) => {}
            Err(m) => {
                attempt.outcome = format!("failed: the goal does not fit the domain: {m}");
                self.tasks[t].attempts.push(attempt);
                self.fail_task(
                    t,
                    format!("its goal `{goal_text}` does not fit the cell's domain: {m}"),
                );
                return;
            }
        };
        // The agent plans for its own robot: the other robots are left out,
        // and so are the kit quadrants and insert slots its goal does not
        // name (a part in hand goes back to a bin, not into another kit).
        let mut state = self.kb.state.clone();
        for b in &self.agents {
            if b.robot != robot {
                state
                    .facts
                    .remove(&self.facts.enabled.key(&[(Var::Robot, b.obj)]));
            }
        }
        let keep: Vec<Key> = goal.iter().filter_map(|l| self.kit_or_slot_of(l)).collect();
        state.facts.retain(|k| {
            !(self.facts.kit_free.is(k) || self.facts.insert_free.is(k)) || keep.contains(k)
        });
        let tp = Instant::now();
        let domain = self.cell.domain.domain.as_ref().expect("checked");
        let report = btc_planner::plan_from(
            domain,
            &self.cell.domain.index,
            &self.pu.index,
            &state,
            Some(&goal_f.to_ast(Span::new(0, 0, 0))),
            &self.opts.planner,
        );
        let ms = tp.elapsed().as_secs_f64() * 1e3;
        attempt.planning_ms = ms;
        self.agents[a].plans += 1;
        self.agents[a].planning_ms += ms;
        let sas = match report {
            Ok(r) => match r.outcome {
                Outcome::Plan(p) => btc_planner::to_sas_plan(domain, &self.pu.index, &p),
                Outcome::Unsolvable => {
                    attempt.outcome = format!(
                        "no plan: no plan reaches `{goal_text}` from the state at {} s",
                        self.secs(self.tick)
                    );
                    return self.attempt_failed(t, attempt, None);
                }
                Outcome::Timeout => {
                    attempt.outcome = "no plan: the planner's time limit stopped it".into();
                    return self.attempt_failed(t, attempt, None);
                }
            },
            Err(d) => {
                attempt.outcome = format!(
                    "no plan: {}",
                    d.first()
                        .map_or("the planner refused the task", |d| d.message.as_str())
                );
                return self.attempt_failed(t, attempt, None);
            }
        };
        if sas.lines().all(|l| l.starts_with(';')) {
            // The goal holds already (a plan of no steps).
            self.tasks[t].state = TaskState::Done { tick: self.tick };
            return;
        }
        let path = self.agents[a].plan_path.clone();
        self.db.set_file(&path, sas);
        let job = self.agents[a].job;
        let doc = match db::compile(self.db, job) {
            Ok(ir) => {
                attempt.plan = ir.steps.iter().map(|s| s.display()).collect();
                TreeDoc::from_ir(ir)
            }
            Err(e) => {
                attempt.outcome = format!(
                    "failed: the plan does not compile with the rules: {}",
                    e.first().map_or("(no detail)", |d| d.message.as_str())
                );
                return self.attempt_failed(t, attempt, None);
            }
        };
        let mut kb = Kb::new(self.world);
        if let Ok(g) = kb.formula(&goal_f) {
            kb.set_goal(g);
        }
        let time = &self.cell.spec.time;
        let eopts = Options {
            ticks_per_action: time.ticks_per_action,
            ms_per_tick: (time.seconds_per_tick * 1000.0).round().max(1.0) as u64,
            trace: self.opts.trace,
        };
        let mut engine = match Engine::build(&doc, Some(kb), eopts) {
            Ok(e) => e,
            Err(e) => {
                attempt.outcome = format!("failed: the tree cannot run: {}", e.message);
                return self.attempt_failed(t, attempt, None);
            }
        };
        engine.tick = self.tick - 1;
        // Challenges in effect reach the new tree too.
        let specs = self.faults_for(robot, self.tick);
        if !specs.is_empty() {
            let _ = engine.add_faults(&Scenario {
                description: None,
                faults: specs,
            });
        }
        if let Some(k) = part {
            self.note_flipped_use(k, t);
        }
        for r in &resources {
            if let Resource::Part(k) = r {
                self.parts[*k].reserved = Some(t);
            }
            self.held.push((*r, t));
        }
        let oid = self.trial.orders[self.tasks[t].order].id.clone();
        self.event(serde_json::json!({"event": "attempt", "task": t, "order": oid, "agent": robot_name, "goal": goal_text, "plan": attempt.plan}));
        self.tasks[t].part = part;
        self.tasks[t].state = TaskState::Running { agent: a };
        let ag = &mut self.agents[a];
        ag.task = Some(t);
        ag.engine = Some(engine);
        ag.resources = resources;
        ag.attempt = Some(attempt);
    }

    /// The free quadrant or insert slot a goal literal needs.
    fn kit_or_slot_of(&self, l: &Literal) -> Option<Key> {
        let f = &self.cell.spec.facts;
        let args: Vec<&str> = l.atom.args.iter().map(String::as_str).collect();
        let obj = |n: &str| self.pu.index.objects.get(n).map(|o| o.id);
        if let Some(m) = f.in_kit.matches(&l.atom.pred, &args) {
            let get = |v: Var| m.iter().find(|(w, _)| *w == v).and_then(|(_, n)| obj(n));
            return Some(self.facts.kit_free.key(&[
                (Var::Agv, get(Var::Agv)?),
                (Var::Quadrant, get(Var::Quadrant)?),
            ]));
        }
        if let Some(m) = f.installed.matches(&l.atom.pred, &args) {
            let get = |v: Var| m.iter().find(|(w, _)| *w == v).and_then(|(_, n)| obj(n));
            let kind = self.kind_of(get(Var::Part)?)?;
            let slot = obj(&self.cell.insert_slot(kind.ty))?;
            return Some(
                self.facts
                    .insert_free
                    .key(&[(Var::Station, get(Var::Station)?), (Var::Slot, slot)]),
            );
        }
        None
    }

    fn note_flipped_use(&mut self, k: usize, t: TaskId) {
        let s = &self.kb.state;
        if !s
            .facts
            .contains(&self.facts.flipped.key(&[(Var::Part, self.parts[k].obj)]))
        {
            return;
        }
        let kind = self.parts[k].info.kind;
        let o = self.tasks[t].order;
        let tick = self.tick;
        let name = self.parts[k].info.name.clone();
        if let Some(c) = self
            .challenges
            .iter_mut()
            .find(|c| matches!(&c.kind, Kind::FlippedParts { kind: kk, .. } if *kk == kind))
        {
            c.met_at.get_or_insert(tick);
            c.touch(o);
            c.note(format!(
                "{name} lies flipped: the plan of task {t} turns it over"
            ));
        }
    }

    /// A failed attempt: the task goes back to its queue for reassignment,
    /// or is given up after its last attempt.
    fn attempt_failed(&mut self, t: TaskId, mut attempt: Attempt, record: Option<String>) {
        attempt.end_tick = self.tick;
        let why = record.unwrap_or_else(|| attempt.outcome.clone());
        self.tasks[t].attempts.push(attempt);
        let n = self.tasks[t].attempts.len() as u32;
        if n >= self.opts.max_attempts {
            self.fail_task(t, format!("gave up after {n} attempts; the last: {why}"));
        } else {
            self.tasks[t].state = TaskState::Queued;
            self.tasks[t].reassignments += 1;
            let oid = self.trial.orders[self.tasks[t].order].id.clone();
            self.event(serde_json::json!({"event": "task", "task": t, "order": oid, "what": "requeued", "why": why}));
        }
    }

    fn release(&mut self, a: usize) {
        let Some(t) = self.agents[a].task.take() else {
            return;
        };
        self.held.retain(|(_, who)| *who != t);
        for r in std::mem::take(&mut self.agents[a].resources) {
            if let Resource::Part(k) = r {
                if self.parts[k].reserved == Some(t) {
                    self.parts[k].reserved = None;
                }
            }
        }
        self.agents[a].engine = None;
    }

    /// The runtime faults a challenge in effect means for a robot's tree.
    fn faults_for(&self, robot: Robot, from: u64) -> Vec<FaultSpec> {
        let name = self.cell.robot(robot).object.clone();
        let mut out = Vec::new();
        for c in &self.challenges {
            if !c.in_effect(from) {
                continue;
            }
            let left = c.until.map(|u| u.saturating_sub(from).max(1));
            let kind = match &c.kind {
                Kind::Trial(ChallengeKind::RobotMalfunction { robots, .. })
                    if robots.contains(&robot) =>
                {
                    FaultKind::RobotMalfunction
                }
                Kind::Trial(ChallengeKind::SensorBlackout { .. }) => FaultKind::SensorBlackout,
                Kind::Trial(ChallengeKind::Human { .. })
                    if robot == Robot::CeilingRobot
                        && c.window.is_some_and(|(s, e)| s <= from && from < e) =>
                {
                    FaultKind::HumanTooClose
                }
                _ => continue,
            };
            let duration = if kind == FaultKind::HumanTooClose {
                c.window.map(|(_, e)| e.saturating_sub(from).max(1))
            } else {
                left
            };
            out.push(spec(kind, &c.label, &name, from, duration));
        }
        out
    }

    fn tick_agents(&mut self) {
        for a in 0..self.agents.len() {
            let Some(mut engine) = self.agents[a].engine.take() else {
                continue;
            };
            self.agents[a].busy += 1;
            let ekb = engine.kb.as_mut().expect("built with a KB");
            std::mem::swap(&mut ekb.state, &mut self.kb.state);
            let status = engine.step();
            let goal_ok = engine.goal().is_none_or(|g| g.0);
            let ekb = engine.kb.as_mut().expect("built with a KB");
            std::mem::swap(&mut ekb.state, &mut self.kb.state);
            if status == Status::Running {
                self.agents[a].engine = Some(engine);
                continue;
            }
            self.finish_attempt(a, engine, status == Status::Success && goal_ok);
        }
    }

    fn finish_attempt(&mut self, a: usize, engine: Engine<'w>, ok: bool) {
        let Some(t) = self.agents[a].task else {
            return;
        };
        let mut attempt = self.agents[a]
            .attempt
            .take()
            .expect("a running task has an attempt");
        attempt.end_tick = self.tick;
        let record = engine.records.last().cloned();
        if self.opts.trace {
            let agent = attempt.agent.clone();
            for line in engine.trace_jsonl().lines() {
                if let Ok(mut v) = serde_json::from_str::<serde_json::Value>(line) {
                    let tick = v
                        .get("tick")
                        .and_then(serde_json::Value::as_u64)
                        .unwrap_or(self.tick);
                    if let Some(o) = v.as_object_mut() {
                        o.insert("agent".into(), agent.clone().into());
                        o.insert("task".into(), t.into());
                    }
                    self.trace.push((tick, v.to_string()));
                }
            }
        }
        let faults: Vec<String> = record
            .as_ref()
            .map(|r| r.faults.clone())
            .unwrap_or_default();
        attempt.challenges = faults.clone();
        let o = self.tasks[t].order;
        for f in &faults {
            if let Some(c) = self.challenges.iter_mut().find(|c| c.label == *f) {
                c.touch(o);
                c.note(format!("task {t} failed and went back to its queue"));
            }
        }
        self.release(a);
        if ok {
            attempt.outcome = "done".into();
            self.tasks[t].attempts.push(attempt);
            self.tasks[t].state = TaskState::Done { tick: self.tick };
            self.agents[a].done += 1;
            let oid = self.trial.orders[o].id.clone();
            self.event(
                serde_json::json!({"event": "task", "task": t, "order": oid, "what": "done"}),
            );
        } else {
            let why = record.map_or_else(
                || "the tree failed".to_owned(),
                |r| format!("`{}` failed: {}", r.node_name, r.reason),
            );
            attempt.outcome = format!("failed: {why}");
            self.agents[a].failed += 1;
            self.attempt_failed(t, attempt, Some(why));
        }
    }

    /// A high-priority order: agents on regular tasks that could do its
    /// tasks stop them (the tasks go back to their queues).
    fn preempt_for_priority(&mut self, c: usize) {
        let order = match self.challenges[c].kind {
            Kind::HighPriorityOrder { order } => order,
            _ => return,
        };
        self.unblock();
        for a in 0..self.agents.len() {
            let Some(t) = self.agents[a].task else {
                continue;
            };
            if self.tasks[t].priority {
                continue;
            }
            let can = self.orders[order].tasks.iter().any(|&pt| {
                self.tasks[pt].state == TaskState::Queued
                    && self.agents[a].queues.contains(&self.tasks[pt].queue)
            });
            let idle_other = (0..self.agents.len()).any(|b| {
                b != a
                    && self.idle(b)
                    && self.normal(b)
                    && self.orders[order].tasks.iter().any(|&pt| {
                        self.tasks[pt].state == TaskState::Queued
                            && self.agents[b].queues.contains(&self.tasks[pt].queue)
                    })
            });
            if !can || idle_other {
                continue;
            }
            let Some(mut engine) = self.agents[a].engine.take() else {
                continue;
            };
            let ekb = engine.kb.as_mut().expect("built with a KB");
            std::mem::swap(&mut ekb.state, &mut self.kb.state);
            engine.halt_all();
            let ekb = engine.kb.as_mut().expect("built with a KB");
            std::mem::swap(&mut ekb.state, &mut self.kb.state);
            let mut attempt = self.agents[a].attempt.take().expect("running");
            attempt.end_tick = self.tick;
            let id = self.trial.orders[order].id.clone();
            attempt.outcome = format!("preempted by high-priority order `{id}`");
            attempt.challenges = vec![self.challenges[c].label.clone()];
            self.release(a);
            self.tasks[t].attempts.push(attempt);
            self.tasks[t].state = TaskState::Queued;
            self.tasks[t].reassignments += 1;
            let robot = self.cell.robot(self.agents[a].robot).object.clone();
            let to = self.tasks[t].order;
            self.challenges[c].touch(to);
            self.challenges[c].note(format!("{robot} stopped task {t} for it"));
            let oid = self.trial.orders[to].id.clone();
            self.event(serde_json::json!({"event": "task", "task": t, "order": oid, "what": "preempted", "by": id}));
        }
    }

    // ---- challenges ----

    fn trigger(&mut self, c: usize) {
        let tick = self.tick;
        let time = self.cell.spec.time.clone();
        self.challenges[c].met_at = Some(tick);
        let label = self.challenges[c].label.clone();
        self.event(
            serde_json::json!({"event": "challenge", "challenge": label, "what": "triggered"}),
        );
        match self.challenges[c].kind.clone() {
            Kind::Trial(ChallengeKind::RobotMalfunction {
                duration, robots, ..
            }) => {
                self.challenges[c].until = Some(tick + time.ticks(duration).max(1));
                for r in robots {
                    let a = self.agents.iter().position(|x| x.robot == r);
                    let Some(a) = a else { continue };
                    let obj = self.agents[a].obj;
                    self.apply(
                        Vec::new(),
                        vec![self.facts.enabled.key(&[(Var::Robot, obj)])],
                    );
                    let name = self.cell.robot(r).object.clone();
                    self.challenges[c].note(format!("{name} disabled for {duration} s"));
                    self.inject(a);
                }
            }
            Kind::Trial(ChallengeKind::SensorBlackout {
                duration, sensors, ..
            }) => {
                self.challenges[c].until = Some(tick + time.ticks(duration).max(1));
                self.challenges[c].note(format!(
                    "{} silent for {duration} s: the monitors wait, the agents work from their world model",
                    sensors.join(", ")
                ));
                for a in 0..self.agents.len() {
                    self.inject(a);
                }
            }
            Kind::Trial(ChallengeKind::Human { behavior, .. }) => {
                // The human walks in; whether and when it comes close to the
                // ceiling robot depends on its behaviour (seeded).
                let (start, len) = match behavior {
                    Behavior::Antagonistic => (
                        self.rng.u64(0..=time.ticks(10.0)),
                        time.ticks(5.0 + self.rng.f64() * 10.0).max(1),
                    ),
                    Behavior::Indifferent => (
                        self.rng.u64(0..=time.ticks(60.0)),
                        time.ticks(3.0 + self.rng.f64() * 4.0).max(1),
                    ),
                    Behavior::Helpful => (0, 0),
                };
                if len > 0 {
                    self.challenges[c].window = Some((tick + start, tick + start + len));
                    self.challenges[c].until = Some(tick + start + len);
                } else {
                    self.challenges[c].ended = true;
                    self.challenges[c].note(
                        "the helpful human stops short of the ceiling robot: nothing to avoid",
                    );
                }
            }
            _ => {}
        }
    }

    /// The human's approach: the ceiling robot keeps its distance (pauses)
    /// while the human is close.
    fn human(&mut self) {
        let tick = self.tick;
        for c in 0..self.challenges.len() {
            let Some((s, e)) = self.challenges[c].window else {
                continue;
            };
            if tick == s && !self.challenges[c].ended {
                let secs = self.secs(e - s);
                self.challenges[c].note(format!(
                    "the human came close to the ceiling robot; it kept its distance for {secs} s"
                ));
                if let Some(a) = self
                    .agents
                    .iter()
                    .position(|x| x.robot == Robot::CeilingRobot)
                {
                    self.inject(a);
                }
            }
        }
    }

    /// Puts the faults now in effect into agent `a`'s running tree.
    fn inject(&mut self, a: usize) {
        let robot = self.agents[a].robot;
        let specs = self.faults_for(robot, self.tick);
        if let Some(e) = self.agents[a].engine.as_mut() {
            // Only faults the tree does not have yet.
            let fresh: Vec<FaultSpec> = specs
                .into_iter()
                .filter(|s| {
                    !e.fault_outcomes(false)
                        .iter()
                        .any(|o| Some(&o.fault) == s.name.as_ref() && o.met_at.is_none())
                })
                .collect();
            let _ = e.add_faults(&Scenario {
                description: None,
                faults: fresh,
            });
        }
    }

    fn end_challenge(&mut self, c: usize) {
        self.challenges[c].ended = true;
        let label = self.challenges[c].label.clone();
        self.event(serde_json::json!({"event": "challenge", "challenge": label, "what": "ended"}));
        if let Kind::Trial(ChallengeKind::RobotMalfunction { robots, .. }) =
            self.challenges[c].kind.clone()
        {
            for r in robots {
                // Another malfunction may still hold it.
                let still = self
                    .challenges
                    .iter()
                    .enumerate()
                    .any(|(d, x)| d != c && x.disables(r) && x.in_effect(self.tick));
                if still {
                    continue;
                }
                if let Some(a) = self.agents.iter().position(|x| x.robot == r) {
                    let obj = self.agents[a].obj;
                    self.apply(
                        vec![self.facts.enabled.key(&[(Var::Robot, obj)])],
                        Vec::new(),
                    );
                    let name = self.cell.robot(r).object.clone();
                    self.challenges[c].note(format!("{name} repaired"));
                }
            }
        }
    }

    /// The gripper lets go of the part (if it still holds it).
    fn drop_part(&mut self, c: usize, k: usize) {
        self.challenges[c].drop = None;
        self.challenges[c].ended = true;
        let Kind::Trial(ChallengeKind::DroppedPart { robot, .. }) = self.challenges[c].kind.clone()
        else {
            return;
        };
        let Some(a) = self.agents.iter().position(|x| x.robot == robot) else {
            return;
        };
        let robj = self.agents[a].obj;
        let p = self.parts[k].obj;
        let holds = self
            .facts
            .holding
            .key(&[(Var::Robot, robj), (Var::Part, p)]);
        let name = self.parts[k].info.name.clone();
        if !self.kb.state.facts.contains(&holds) {
            self.challenges[c].note(format!(
                "{name} was already placed when the gripper failed: nothing dropped"
            ));
            return;
        }
        self.challenges[c].met_at = Some(self.tick);
        self.apply(
            vec![self.facts.hand_empty.key(&[(Var::Robot, robj)])],
            vec![holds, self.facts.flipped.key(&[(Var::Part, p)])],
        );
        self.parts[k].gone = Some("the gripper dropped it on the floor".into());
        let rname = self.cell.robot(robot).object.clone();
        self.challenges[c].note(format!("{rname}'s gripper dropped {name}"));
        if let Some(t) = self.parts[k].reserved {
            let o = self.tasks[t].order;
            self.challenges[c].touch(o);
        }
        let label = self.challenges[c].label.clone();
        if let Some(e) = self.agents[a].engine.as_mut() {
            let _ = e.add_faults(&Scenario {
                description: None,
                faults: vec![spec(
                    FaultKind::FaultyGripper,
                    &label,
                    &rname,
                    self.tick,
                    None,
                )],
            });
        }
        self.event(serde_json::json!({"event": "challenge", "challenge": label, "what": "dropped", "part": name}));
    }

    // ---- after the agents' tick ----

    fn kit_facts(&self) -> FxHashSet<Key> {
        self.kb
            .state
            .facts
            .iter()
            .filter(|k| self.facts.in_kit.is(k))
            .cloned()
            .collect()
    }

    fn holding_facts(&self) -> FxHashSet<Key> {
        self.kb
            .state
            .facts
            .iter()
            .filter(|k| self.facts.holding.is(k))
            .cloned()
            .collect()
    }

    fn after_tick(&mut self) {
        // Placements on AGVs.
        let kit = self.kit_facts();
        let new_kit: Vec<Key> = kit.difference(&self.prev_kit).cloned().collect();
        self.prev_kit = kit;
        for k in new_kit {
            let (Some(p), Some(agv), Some(q)) = (
                self.facts.in_kit.get(&k, Var::Part),
                self.facts.in_kit.get(&k, Var::Agv),
                self.facts.in_kit.get(&k, Var::Quadrant),
            ) else {
                continue;
            };
            let (Some(&part), Some(n), Some(qn)) = (
                self.part_of.get(&p),
                self.obj.agv.iter().position(|&x| x == agv),
                self.obj.quadrant.iter().position(|&x| x == q),
            ) else {
                continue;
            };
            self.placed.push((part, n as u8 + 1));
            self.faulty_on_place(part, n as u8 + 1, qn as u8 + 1);
        }
        // Picks.
        let holding = self.holding_facts();
        let picks: Vec<Key> = holding.difference(&self.prev_holding).cloned().collect();
        self.prev_holding = holding;
        for k in picks {
            let (Some(r), Some(p)) = (
                self.facts.holding.get(&k, Var::Robot),
                self.facts.holding.get(&k, Var::Part),
            ) else {
                continue;
            };
            if let (Some(a), Some(&part)) = (
                self.agents.iter().position(|x| x.obj == r),
                self.part_of.get(&p),
            ) {
                self.on_pick(a, part);
            }
        }
        // Orders: quality checks and submissions.
        for o in 0..self.orders.len() {
            self.progress_order(o);
        }
        // Conditions on placements and submissions.
        let placed = std::mem::take(&mut self.placed);
        let submitted = std::mem::take(&mut self.submitted_now);
        for k in 0..self.orders.len() {
            if self.orders[k].announced.is_some() {
                continue;
            }
            if self.condition_met(
                &self.trial.orders[k].announcement.clone(),
                &placed,
                &submitted,
            ) {
                self.announce(k);
            }
        }
        for c in 0..self.challenges.len() {
            if self.challenges[c].met_at.is_some() {
                continue;
            }
            if let Some(cond) = self.challenges[c].kind.condition().cloned() {
                if !matches!(cond, Condition::Time(_))
                    && self.condition_met(&cond, &placed, &submitted)
                {
                    self.trigger(c);
                }
            }
        }
        self.placed = placed;
        self.submitted_now = submitted;
    }

    fn condition_met(&self, c: &Condition, placed: &[(usize, u8)], submitted: &[usize]) -> bool {
        match c {
            Condition::Time(_) => false,
            Condition::PartPlace { agv, kind } => placed
                .iter()
                .any(|(p, a)| a == agv && self.parts[*p].info.kind == *kind),
            Condition::Submission(id) => submitted.iter().any(|&o| self.trial.orders[o].id == *id),
        }
    }

    /// ARIAC's faulty parts: the first part placed in a flagged quadrant of
    /// the order's kit is faulty.
    fn faulty_on_place(&mut self, part: usize, agv: u8, q: u8) {
        for c in 0..self.challenges.len() {
            let Kind::Trial(ChallengeKind::FaultyPart {
                order_id,
                quadrants,
            }) = &self.challenges[c].kind
            else {
                continue;
            };
            let Some(o) = self.trial.orders.iter().position(|x| x.id == *order_id) else {
                continue;
            };
            if self.orders[o].announced.is_none() || self.orders[o].submitted.is_some() {
                continue;
            }
            let order_agv = match &self.trial.orders[o].task {
                OrderTask::Kitting { agv, .. } => Some(*agv),
                OrderTask::Combined { .. } => self.orders[o].agv,
                OrderTask::Assembly { .. } => None,
            };
            if order_agv != Some(agv)
                || !quadrants[q as usize - 1]
                || self.challenges[c].consumed[q as usize - 1]
            {
                continue;
            }
            self.challenges[c].consumed[q as usize - 1] = true;
            self.challenges[c].met_at.get_or_insert(self.tick);
            self.challenges[c].touch(o);
            self.parts[part].faulty = true;
            let name = self.parts[part].info.name.clone();
            self.challenges[c].note(format!("{name}, the first part in quadrant {q}, is faulty"));
        }
    }

    /// ARIAC's faulty gripper: the (drop_after + 1)-th pick of the kind by
    /// the robot is dropped `delay` seconds later.
    fn on_pick(&mut self, a: usize, part: usize) {
        let robot = self.agents[a].robot;
        let kind = self.parts[part].info.kind;
        let time = self.cell.spec.time.clone();
        for c in 0..self.challenges.len() {
            let ch = &mut self.challenges[c];
            let Kind::Trial(ChallengeKind::DroppedPart {
                robot: r,
                kind: k,
                drop_after,
                delay,
            }) = &ch.kind
            else {
                continue;
            };
            if *r != robot || *k != kind || ch.ended || ch.drop.is_some() {
                continue;
            }
            ch.picks += 1;
            if ch.picks == drop_after + 1 {
                ch.drop = Some((self.tick + time.ticks(*delay).max(1), part));
            }
        }
    }

    /// Every task of the order ended (done or given up).
    fn order_ended(&self, o: usize) -> bool {
        self.orders[o]
            .tasks
            .iter()
            .all(|&t| !self.tasks[t].is_open())
    }

    fn has_faulty_challenge(&self, o: usize) -> bool {
        let id = &self.trial.orders[o].id;
        self.challenges
            .iter()
            .any(|c| matches!(&c.kind, Kind::Trial(ChallengeKind::FaultyPart { order_id, .. }) if order_id == id))
    }

    fn progress_order(&mut self, o: usize) {
        if self.orders[o].announced.is_none()
            || self.orders[o].submitted.is_some()
            || self.orders[o].submitting
        {
            return;
        }
        let ty = self.trial.orders[o].task.order_type();
        // Combined: the quality check of the split AGV before it leaves.
        if ty == OrderType::Combined && !self.orders[o].qc_done {
            if let Some(agv) = self.orders[o].agv {
                let open_kits = self.orders[o].tasks.iter().any(|&k| {
                    self.tasks[k].is_open()
                        && matches!(&self.tasks[k].work, Work::Kit { agv: a, .. } if *a == agv)
                });
                if !open_kits {
                    self.quality_check(o, agv);
                }
            }
        }
        if ty == OrderType::Combined {
            // Assembly halves start only after the AGV's kit is checked.
            if self.orders[o].tasks.iter().any(|&t| {
                matches!(self.tasks[t].state, TaskState::Running { .. })
                    && matches!(
                        &self.tasks[t].work,
                        Work::Assemble {
                            from_task: Some(_),
                            ..
                        }
                    )
            }) {
                self.orders[o].committed = true;
            }
        }
        if !self.order_ended(o) {
            return;
        }
        // ARIAC: a high-priority order is submitted before the regular ones.
        let priority_open = self.trial.orders.iter().zip(&self.orders).any(|(x, r)| {
            x.priority && r.announced.is_some() && r.submitted.is_none() && !r.submitting
        });
        if !self.trial.orders[o].priority && priority_open {
            return;
        }
        match &self.trial.orders[o].task {
            OrderTask::Kitting {
                agv, destination, ..
            } => {
                let agv = *agv;
                if !self.orders[o].qc_done {
                    self.quality_check(o, agv);
                    if !self.order_ended(o) {
                        return;
                    }
                }
                // Ship the kit: the AGV to its destination.
                let aobj = self.obj.agv[agv as usize - 1];
                let to = match destination {
                    Destination::Warehouse => self.obj.warehouse,
                    Destination::Kitting => self.obj.kitting_station[agv as usize - 1],
                    Destination::Station(n) => self.obj.station[*n as usize - 1],
                };
                if !self.free(&[Resource::Agv(agv)]) {
                    return;
                }
                let goes = self.kb.state.facts.contains(
                    &self
                        .facts
                        .agv_goes
                        .key(&[(Var::Agv, aobj), (Var::Place, to)]),
                );
                self.orders[o].submitting = true;
                if goes && self.facts.agv_place(&self.kb.state, aobj) != Some(to) {
                    self.held.push((Resource::Agv(agv), TRAVEL));
                    let arrive = self.tick + u64::from(self.cell.spec.time.ticks_per_action);
                    self.travels.push(Travel {
                        agv,
                        to,
                        arrive,
                        order: Some(o),
                    });
                    let id = self.trial.orders[o].id.clone();
                    let dest = self.name(to).to_owned();
                    self.event(serde_json::json!({"event": "agv", "agv": format!("agv{agv}"), "order": id, "leaves_for": dest}));
                } else {
                    self.submit(o);
                }
            }
            _ => {
                self.orders[o].submitting = true;
                self.submit(o);
            }
        }
    }

    /// ARIAC's quality check (once per order): faulty parts in the kit are
    /// found and replaced; the new parts are good.
    fn quality_check(&mut self, o: usize, agv: u8) {
        self.orders[o].qc_done = true;
        if !self.has_faulty_challenge(o)
            && self.trial.orders[o].task.order_type() == OrderType::Combined
        {
            return;
        }
        let aobj = self.obj.agv[agv as usize - 1];
        let kit = self.facts.kit(&self.kb.state, aobj);
        for (q, p) in kit {
            let Some(&k) = self.part_of.get(&p) else {
                continue;
            };
            if !self.parts[k].faulty {
                continue;
            }
            let Some(qn) = self.obj.quadrant.iter().position(|&x| x == q) else {
                continue;
            };
            let quadrant = qn as u8 + 1;
            let kind = self.parts[k].info.kind;
            let ty = self.trial.orders[o].task.order_type();
            let r = self.new_task(
                o,
                OrderType::Kitting,
                Work::Replace {
                    part: kind,
                    agv,
                    quadrant,
                    faulty: k,
                },
                Vec::new(),
            );
            let _ = ty;
            let name = self.parts[k].info.name.clone();
            if let Some(c) = self.challenges.iter_mut().find(|c| {
                matches!(&c.kind, Kind::Trial(ChallengeKind::FaultyPart { .. }))
                    && c.orders.contains(&o)
            }) {
                c.note(format!(
                    "the quality check found {name} faulty: task {r} replaces it"
                ));
            }
            // An assembly half that was to take the faulty part takes the
            // replacement instead.
            for t in 0..self.tasks.len() {
                if let Work::Assemble {
                    from_task: Some(ft),
                    ..
                } = &self.tasks[t].work
                {
                    if self.tasks[*ft].part == Some(k) && self.tasks[t].is_open() {
                        if let Work::Assemble { from_task, .. } = &mut self.tasks[t].work {
                            *from_task = Some(r);
                        }
                        self.tasks[t].after.push(r);
                        self.tasks[t].state = TaskState::Blocked;
                    }
                }
            }
        }
    }

    // ---- scoring ----

    fn submit(&mut self, o: usize) {
        self.orders[o].submitted = Some(self.tick);
        self.submitted_now.push(o);
        let (score, breakdown) = self.score(o);
        self.orders[o].score = score;
        self.orders[o].breakdown = Some(breakdown);
        let id = self.trial.orders[o].id.clone();
        self.event(
            serde_json::json!({"event": "order", "order": id, "what": "submitted", "score": score}),
        );
        // A high-priority order submitted while regular ones were still open.
        if let Some(c) = self
            .challenges
            .iter()
            .position(|c| c.kind == Kind::HighPriorityOrder { order: o })
        {
            let before = self
                .orders
                .iter()
                .enumerate()
                .filter(|(k, r)| {
                    *k != o
                        && !self.trial.orders[*k].priority
                        && r.announced.is_some()
                        && r.submitted.is_none()
                })
                .count();
            let note = format!(
                "submitted at {} s{}",
                self.secs(self.tick),
                if before > 0 {
                    format!(", before {before} regular order(s) still open")
                } else {
                    String::new()
                }
            );
            self.challenges[c].ended = true;
            self.challenges[c].note(note);
        }
    }

    fn kind_of(&self, p: u32) -> Option<PartKind> {
        self.part_of.get(&p).map(|&k| self.parts[k].info.kind)
    }

    fn score(&self, o: usize) -> (i64, Breakdown) {
        let s = &self.kb.state;
        match &self.trial.orders[o].task {
            OrderTask::Kitting {
                agv,
                tray_id,
                destination,
                products,
            } => {
                let aobj = self.obj.agv[*agv as usize - 1];
                let tray = self.facts.tray_of(s, aobj).map(|t| self.name(t).to_owned());
                let correct_tray = tray.as_deref() == Some(self.cell.tray(*tray_id).as_str());
                let kit = self.facts.kit(s, aobj);
                let quadrants: Vec<scoring::Quadrant> = products
                    .iter()
                    .map(|p| {
                        let q = self.obj.quadrant[p.quadrant as usize - 1];
                        let there = kit.iter().find(|(qq, _)| *qq == q).map(|(_, part)| *part);
                        let kind = there.and_then(|x| self.kind_of(x));
                        scoring::Quadrant {
                            quadrant: p.quadrant,
                            present: there.is_some(),
                            correct_type: kind.is_some_and(|k| k.ty == p.kind.ty),
                            correct_color: kind.is_some_and(|k| k.color == p.kind.color),
                            flipped: there.is_some_and(|x| {
                                s.facts.contains(&self.facts.flipped.key(&[(Var::Part, x)]))
                            }),
                            faulty: there
                                .and_then(|x| self.part_of.get(&x))
                                .is_some_and(|&k| self.parts[k].faulty),
                        }
                    })
                    .collect();
                let want = match destination {
                    Destination::Warehouse => self.obj.warehouse,
                    Destination::Kitting => self.obj.kitting_station[*agv as usize - 1],
                    Destination::Station(n) => self.obj.station[*n as usize - 1],
                };
                let at_dest = self.facts.agv_place(s, aobj) == Some(want);
                let k = scoring::kitting(
                    correct_tray && tray.is_some(),
                    &quadrants,
                    kit.len(),
                    at_dest,
                );
                (k.score, Breakdown::Kit(k))
            }
            OrderTask::Assembly {
                station, products, ..
            }
            | OrderTask::Combined { station, products } => {
                let st = self.obj.station[*station as usize - 1];
                let insert = self.facts.insert(s, st);
                let slots: Vec<scoring::Slot> = products
                    .iter()
                    .map(|p| {
                        let there = insert
                            .iter()
                            .find(|x| self.kind_of(**x).is_some_and(|k| k.ty == p.kind.ty));
                        scoring::Slot {
                            assembled: there.is_some(),
                            correct_color: there
                                .and_then(|x| self.kind_of(*x))
                                .is_some_and(|k| k.color == p.kind.color),
                            correct_pose: there.is_some_and(|x| {
                                !s.facts
                                    .contains(&self.facts.flipped.key(&[(Var::Part, *x)]))
                            }),
                        }
                    })
                    .collect();
                let kind = if self.trial.orders[o].task.order_type() == OrderType::Assembly {
                    scoring::Insert::Assembly
                } else {
                    scoring::Insert::Combined
                };
                let r = scoring::insert(kind, &slots, true);
                (r.score, Breakdown::Insert(r))
            }
        }
    }

    // ---- invariants ----

    fn check(&self) -> Result<(), TrialError> {
        let s = &self.kb.state;
        let bad = |what: String| TrialError::Inconsistent {
            tick: self.tick,
            what,
        };
        for p in &self.parts {
            let places = self.facts.places(s, p.obj);
            let in_cell = p.gone.is_none() && p.spawn.is_none_or(|t| t <= self.tick);
            let expect = usize::from(in_cell);
            if places.len() != expect {
                return Err(bad(format!(
                    "{} is in {} places ({:?}); it should be in {expect}",
                    p.info.name,
                    places.len(),
                    places
                )));
            }
        }
        for a in &self.agents {
            let held = s
                .facts
                .iter()
                .filter(|k| self.facts.holding.get(k, Var::Robot) == Some(a.obj))
                .count();
            let empty = s
                .facts
                .contains(&self.facts.hand_empty.key(&[(Var::Robot, a.obj)]));
            if held > 1 || (held == 1 && empty) {
                return Err(bad(format!(
                    "{} holds {held} parts and its hand is {}empty",
                    self.name(a.obj),
                    if empty { "" } else { "not " }
                )));
            }
        }
        for (i, (r, t)) in self.held.iter().enumerate() {
            for (r2, t2) in &self.held[i + 1..] {
                if t != t2 && r.conflicts(*r2) {
                    return Err(bad(format!(
                        "{r:?} is held by task {t} and {r2:?} by task {t2}"
                    )));
                }
            }
        }
        for (k, p) in self.parts.iter().enumerate() {
            if let Some(t) = p.reserved {
                if !matches!(self.tasks[t].state, TaskState::Running { .. }) {
                    return Err(bad(format!(
                        "part {k} is reserved by task {t}, which is not running"
                    )));
                }
            }
        }
        Ok(())
    }

    /// The end: open tasks end with the trial's cause, open orders stay
    /// unsubmitted (they score 0).
    fn close(&mut self) {
        for a in 0..self.agents.len() {
            if let (Some(t), Some(mut engine)) = (self.agents[a].task, self.agents[a].engine.take())
            {
                let ekb = engine.kb.as_mut().expect("built with a KB");
                std::mem::swap(&mut ekb.state, &mut self.kb.state);
                engine.halt_all();
                let ekb = engine.kb.as_mut().expect("built with a KB");
                std::mem::swap(&mut ekb.state, &mut self.kb.state);
                if let Some(mut att) = self.agents[a].attempt.take() {
                    att.end_tick = self.tick;
                    att.outcome = format!("stopped: {}", self.stopped);
                    self.tasks[t].attempts.push(att);
                }
                self.release(a);
            }
        }
        let why = self.stopped.clone();
        for t in 0..self.tasks.len() {
            if self.tasks[t].is_open() {
                self.fail_task(t, format!("not done when the trial stopped ({why})"));
            }
        }
    }

    // ---- the report ----

    fn report(&mut self, name: &str) -> TrialReport {
        let mut orders = Vec::new();
        for (k, o) in self.trial.orders.iter().enumerate() {
            let rt = &self.orders[k];
            let tasks: Vec<&Task> = rt
                .tasks
                .iter()
                .map(|&t| &self.tasks[t])
                .filter(|t| !matches!(t.state, TaskState::Split { .. }))
                .collect();
            let faults: Vec<FaultMet> = self
                .challenges
                .iter()
                .filter(|c| c.orders.contains(&k) && c.met_at.is_some())
                .map(|c| FaultMet {
                    challenge: c.label.clone(),
                    at: self.secs(c.met_at.unwrap_or(1) - 1),
                    ended: challenge_end(
                        c,
                        Some(
                            self.orders[k].score
                                == scoring::best(o.task.order_type(), o.task.kinds().len()),
                        ),
                    ),
                })
                .collect();
            orders.push(OrderReport {
                id: o.id.clone(),
                ty: o.task.order_type(),
                priority: o.priority,
                state: match (rt.announced, rt.submitted) {
                    (None, _) => "not announced".into(),
                    (Some(_), None) => "not submitted".into(),
                    (Some(_), Some(_)) => "submitted".into(),
                },
                announced: rt.announced.map(|t| self.secs(t - 1)),
                submitted: rt.submitted.map(|t| self.secs(t)),
                time: match (rt.announced, rt.submitted) {
                    (Some(a), Some(s)) => Some(self.secs(s + 1 - a)),
                    _ => None,
                },
                score: if rt.submitted.is_some() { rt.score } else { 0 },
                best: scoring::best(o.task.order_type(), o.task.kinds().len()),
                breakdown: rt.breakdown.clone(),
                part_tasks: tasks.len(),
                done: tasks.iter().filter(|t| t.is_done()).count(),
                failed: tasks
                    .iter()
                    .filter(|t| matches!(t.state, TaskState::Failed { .. }))
                    .count(),
                reassignments: tasks.iter().map(|t| t.reassignments).sum(),
                faults,
            });
        }
        let agents = self
            .agents
            .iter()
            .map(|a| AgentReport {
                robot: self.cell.robot(a.robot).object.clone(),
                busy: self.secs(a.busy),
                tasks_done: a.done,
                tasks_failed: self
                    .tasks
                    .iter()
                    .filter(|t| {
                        matches!(t.state, TaskState::Failed { .. })
                            && t.attempts
                                .last()
                                .is_some_and(|x| x.agent == self.cell.robot(a.robot).object)
                    })
                    .count(),
                plans: a.plans,
                planning_ms: a.planning_ms,
            })
            .collect();
        let challenges = self
            .challenges
            .iter()
            .map(|c| ChallengeReport {
                challenge: c.label.clone(),
                kind: c.kind.name().to_owned(),
                met: c.met_at.map(|t| self.secs(t - 1)),
                ended: challenge_end(c, None),
            })
            .collect();
        let mut trace = String::new();
        if self.opts.trace {
            self.trace.sort_by_key(|(t, _)| *t);
            for (_, l) in &self.trace {
                trace.push_str(l);
                trace.push('\n');
            }
        }
        let score = orders.iter().map(|o| o.score).sum();
        let best = orders.iter().map(|o| o.best).sum();
        TrialReport {
            trial: name.to_owned(),
            seed: self.opts.seed,
            seconds: self.secs(self.tick),
            ticks: self.tick,
            score,
            best,
            orders,
            agents,
            challenges,
            tasks: self.tasks.clone(),
            stopped: self.stopped.clone(),
            elapsed_ms: 0.0,
            trace,
        }
    }
}

fn challenge_end(c: &ChallengeRt, full: Option<bool>) -> String {
    if c.met_at.is_none() {
        return match c.effects.first() {
            Some(e) => format!("not met: {e}"),
            None => "not met".into(),
        };
    }
    let what = c.effects.join("; ");
    let head = match full {
        Some(true) => "recovered",
        Some(false) => "cost points",
        None => "met",
    };
    if what.is_empty() {
        head.into()
    } else {
        format!("{head}: {what}")
    }
}

fn spec(kind: FaultKind, label: &str, robot: &str, at: u64, duration: Option<u64>) -> FaultSpec {
    FaultSpec {
        kind,
        name: Some(label.to_owned()),
        trigger: Trigger::Tick(at.max(1)),
        robot: Some(robot.to_owned()),
        part: None,
        duration,
        retract: Some(Vec::new()),
        add: Vec::new(),
        goal: None,
        blackout: Blackout::Running,
    }
}

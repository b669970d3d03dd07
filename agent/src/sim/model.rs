//! The model of one trial (Mesa's model/agent split): the cell's world,
//! the task manager, one agent per robot, the challenges and the trace,
//! stepped on one clock. A step is the paper's Figure 2 read top to
//! bottom: world events, the task manager, the agents, the challenges and
//! orders their tick set off, the observers.
//!
//! What each part of a step does lives beside it: `allocate` (the task
//! manager handing out tasks), `resolve` (a task's part, resources and
//! goal), `execute` (the agents' attempts), `agility` (the challenges in
//! the world), `orders` (quality checks and submissions), `invariants`
//! (the checking mode), `report`.

use super::agent::AgentRt;
use super::challenges::{self, Challenge, Kind};
use super::events::{Event, Trace};
use super::options::{TrialError, TrialOptions};
use super::task_manager::TaskManager;
use super::world::{id, CellWorld, PartId};
use crate::cell::{Cell, TrialProblem};
use crate::trial::{Condition, Robot, Trial};
use btc_lang::db::{CompileJob, Database};
use btc_pddl::pipeline::ProblemUnit;
use btc_pddl::state::Key;
use btc_runtime::Kb;
use rustc_hash::FxHashSet;

pub(super) struct Sim<'w, 'd> {
    pub cell: &'w Cell,
    pub trial: &'w Trial,
    pub opts: &'w TrialOptions,
    pub pu: &'w ProblemUnit,
    pub world: &'w btc_pddl::state::World,
    pub db: &'d mut Database,
    pub w: CellWorld<'w>,
    pub tm: TaskManager<'w>,
    pub agents: Vec<AgentRt<'w>>,
    pub challenges: Vec<Challenge>,
    pub trace: Trace,
    pub tick: u64,
    pub rng: fastrand::Rng,
    pub prev_kit: FxHashSet<Key>,
    pub prev_holding: FxHashSet<Key>,
    /// This tick's events: parts placed on AGVs (part, agv), orders
    /// submitted.
    pub placed: Vec<(PartId, u8)>,
    pub submitted_now: Vec<usize>,
    pub limit: u64,
    pub time_limited: bool,
    /// What the last tick left: stopping needs two quiet ticks alike.
    pub last: (usize, usize, usize, usize),
    pub stopped: String,
}

impl<'w, 'd> Sim<'w, 'd> {
    pub fn new(
        cell: &'w Cell,
        trial: &'w Trial,
        tp: &TrialProblem,
        (pu, world): (&'w ProblemUnit, &'w btc_pddl::state::World),
        opts: &'w TrialOptions,
        db: &'d mut Database,
        jobs: &[(Robot, CompileJob, String)],
    ) -> Result<Sim<'w, 'd>, TrialError> {
        let pix = &pu.index;
        let mut rng = fastrand::Rng::with_seed(opts.seed);
        let agents = || {
            let mut agents = Vec::new();
            for (robot, job, plan_path) in jobs {
                let spec = cell.robot(*robot);
                agents.push(AgentRt::new(
                    *robot,
                    id(pix, &spec.object)?,
                    spec.queues.clone(),
                    *job,
                    plan_path.clone(),
                ));
            }
            Ok(agents)
        };
        let (w, agents) = CellWorld::new((cell, trial, tp), Kb::new(world), pix, &mut rng, agents)?;
        let time = &cell.spec.time;
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
            w,
            tm: TaskManager::new(trial),
            agents,
            challenges: challenges::at_start(cell, trial, &tp.parts),
            trace: Trace::new(opts.trace),
            tick: 0,
            rng,
            prev_kit: FxHashSet::default(),
            prev_holding: FxHashSet::default(),
            placed: Vec::new(),
            submitted_now: Vec::new(),
            limit: limit.max(1),
            time_limited,
            last: (0, 0, 0, 0),
            stopped: String::new(),
        };
        sim.prev_kit = sim.w.facts_of(&sim.w.facts.in_kit);
        sim.prev_holding = sim.w.facts_of(&sim.w.facts.holding);
        Ok(sim)
    }

    pub fn secs(&self, t: u64) -> f64 {
        self.cell.spec.time.seconds(t)
    }

    pub fn event(&mut self, e: Event) {
        self.trace.event(self.tick, &e);
    }

    /// The trial to its end.
    pub fn run(&mut self) -> Result<(), TrialError> {
        loop {
            self.step();
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

    /// One tick, as the paper's figure reads: the world, the task manager,
    /// the agents, then what their tick set off. The trace observes each
    /// as it happens.
    fn step(&mut self) {
        self.tick += 1;
        self.placed.clear();
        self.submitted_now.clear();
        self.world_events();
        self.announce_orders();
        self.allocate();
        self.tick_agents();
        self.placements_and_picks();
        self.progress_orders();
        self.conditions();
    }

    /// The belt, the AGVs arriving (and submitting), the challenges' times.
    fn world_events(&mut self) {
        self.w.belt(self.tick, &mut self.trace);
        for t in self.w.arrivals(self.tick) {
            self.w.arrive(&t, self.tick, &mut self.trace);
            if let Some(o) = t.order {
                self.submit(o);
            }
        }
        self.challenge_times();
    }

    fn should_stop(&self) -> Option<String> {
        let all_in = self.tm.orders.iter().all(|o| o.submitted.is_some());
        if all_in && !self.tm.orders.is_empty() {
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
        self.tm.signature()
    }

    /// No agent busy, no task that could start, nothing scheduled.
    fn quiet(&self) -> bool {
        if self.agents.iter().any(|a| a.task.is_some()) || !self.w.travels.is_empty() {
            return false;
        }
        if self.w.parts.iter().any(|p| {
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
            .zip(&self.tm.orders)
            .any(|(o, rt)| rt.announced.is_none() && pending_time(&o.announcement))
        {
            return false;
        }
        if self.challenges.iter().any(|c| {
            (c.met_at.is_none() && c.kind.condition().is_some_and(pending_time))
                || c.in_effect(self.tick) && c.until.is_some()
                || matches!(&c.kind, Kind::DroppedPart(d) if d.drop.is_some())
        }) {
            return false;
        }
        // Submissions waiting only for their order's tasks to end.
        !self.tm.orders.iter().enumerate().any(|(k, o)| {
            o.announced.is_some()
                && o.submitted.is_none()
                && !o.submitting
                && self.tm.order_ended(k)
        })
    }

    /// The end: open tasks end with the trial's cause, open orders stay
    /// unsubmitted (they score 0).
    fn close(&mut self) {
        let why = self.stopped.clone();
        for a in 0..self.agents.len() {
            let Some((t, Some(mut attempt))) = self.halt(a) else {
                continue;
            };
            attempt.end_tick = self.tick;
            attempt.outcome = format!("stopped: {why}");
            self.tm.tasks[t].attempts.push(attempt);
        }
        for t in 0..self.tm.tasks.len() {
            if self.tm.tasks[t].is_open() {
                self.fail_task(t, super::events::Cause::TrialStopped { why: why.clone() });
            }
        }
    }
}

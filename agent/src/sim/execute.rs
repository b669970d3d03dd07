//! The agents' step (the paper's execution level, as the trial runs it):
//! an agent plans its task from the shared world's state for its own
//! robot, compiles the plan with its robot's rules, runs the tree with the
//! challenges in effect, and on failure hands the task back with its fault
//! record; an agent on a regular task is preempted for a high-priority
//! order.

use super::agent;
use super::allocation;
use super::challenges::Kind;
use super::events::{Cause, Event};
use super::model::Sim;
use super::tasks::{Attempt, PartId, Resource, TaskId, TaskState};
use crate::cell::{conjunction, Literal, Var};
use crate::execution::{self, Planning, PlanningWorld};
use crate::faults::{FaultsOnEngine, Scenario};
use btc_pddl::source::Span;
use btc_pddl::state::Key;
use btc_runtime::observers::JsonlTrace;
use btc_runtime::{Engine, Kb, Options, Status, TreeDoc};

impl<'w> Sim<'w, '_> {
    /// Plans, compiles and builds the tree of a task on agent `a`.
    pub(super) fn launch(
        &mut self,
        a: usize,
        t: TaskId,
        part: Option<PartId>,
        resources: Vec<Resource>,
        mut goal: Vec<Literal>,
    ) {
        // A part in the robot's hand that the task does not use is put back,
        // not thrown away.
        if let Some(h) = self.w.facts.held_by(&self.w.kb.state, self.agents[a].obj) {
            let named = goal
                .iter()
                .any(|l| l.atom.args.iter().any(|x| x == self.w.name(h)));
            if !named {
                let lit = self
                    .w
                    .lit(&self.cell.spec.facts.discarded, &[(Var::Part, h)], false);
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
            part: part.map(|k| self.w.parts[k].info.name.clone()),
            goal: goal_text.clone(),
            plan: Vec::new(),
            planning_ms: 0.0,
            outcome: String::new(),
            challenges: Vec::new(),
        };
        // The goal must fit the domain (it is checked as the KB compiles it).
        match self.w.kb.formula(&goal_f) {
            Ok(_) => {}
            Err(m) => {
                attempt.outcome = format!("failed: the goal does not fit the domain: {m}");
                self.tm.tasks[t].attempts.push(attempt);
                self.fail_task(
                    t,
                    Cause::GoalDoesNotFit {
                        goal: goal_text,
                        why: m.to_string(),
                    },
                );
                return;
            }
        };
        // The agent plans for its own robot: the other robots are left out,
        // and so are the kit quadrants and insert slots its goal does not
        // name (a part in hand goes back to a bin, not into another kit).
        let mut state = self.w.kb.state.clone();
        for b in &self.agents {
            if b.robot != robot {
                state
                    .facts
                    .remove(&self.w.facts.enabled.key(&[(Var::Robot, b.obj)]));
            }
        }
        let keep: Vec<Key> = goal.iter().filter_map(|l| self.kit_or_slot_of(l)).collect();
        state.facts.retain(|k| {
            !(self.w.facts.kit_free.is(k) || self.w.facts.insert_free.is(k)) || keep.contains(k)
        });
        let domain = self.cell.domain.domain.as_ref().expect("checked");
        let w = PlanningWorld {
            domain,
            dix: &self.cell.domain.index,
            pix: &self.pu.index,
        };
        let planning = execution::plan(w, &state, &goal_f, Span::new(0, 0, 0), &self.opts.planner);
        let ms = match &planning {
            Ok(
                Planning::Made { ms, .. } | Planning::Unsolvable { ms } | Planning::Timeout { ms },
            ) => *ms,
            Err(_) => 0.0,
        };
        attempt.planning_ms = ms;
        self.agents[a].plans += 1;
        self.agents[a].planning_ms += ms;
        let plan = match planning {
            Ok(Planning::Made { plan, .. }) => plan,
            Ok(Planning::Unsolvable { .. }) => {
                attempt.outcome = format!(
                    "no plan: no plan reaches `{goal_text}` from the state at {} s",
                    self.secs(self.tick)
                );
                return self.attempt_failed(t, attempt, None);
            }
            Ok(Planning::Timeout { .. }) => {
                attempt.outcome = "no plan: the planner's time limit stopped it".into();
                return self.attempt_failed(t, attempt, None);
            }
            Err(d) => {
                attempt.outcome = format!(
                    "no plan: {}",
                    d.first()
                        .map_or("the planner refused the task", |d| d.message.as_str())
                );
                return self.attempt_failed(t, attempt, None);
            }
        };
        if plan.is_empty() {
            // The goal holds already (a plan of no steps).
            self.tm.tasks[t].state = TaskState::Done { tick: self.tick };
            return;
        }
        let path = self.agents[a].plan_path.clone();
        let job = self.agents[a].job;
        let doc = match execution::compile(self.db, job, &path, Some(plan)) {
            Ok(ir) => {
                attempt.plan = ir.steps.iter().map(|s| s.display()).collect();
                TreeDoc::from_ir(&ir)
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
        };
        let mut engine = match execution::start(&doc, kb, eopts, self.tick - 1, self.opts.trace) {
            Ok(e) => e,
            Err(e) => {
                attempt.outcome = format!("failed: the tree cannot run: {}", e.message);
                return self.attempt_failed(t, attempt, None);
            }
        };
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
        self.w.hold(t, &resources);
        let order = self.trial.orders[self.tm.tasks[t].order].id.clone();
        self.event(Event::Attempt {
            task: t,
            order,
            agent: robot_name,
            goal: goal_text,
            plan: attempt.plan.clone(),
        });
        self.tm.tasks[t].part = part;
        self.tm.tasks[t].state = TaskState::Running { agent: a };
        let ag = &mut self.agents[a];
        ag.task = Some(t);
        ag.engine = Some(engine);
        ag.resources = resources;
        ag.attempt = Some(attempt);
    }

    /// The free quadrant or insert slot a goal literal needs.
    pub(super) fn kit_or_slot_of(&self, l: &Literal) -> Option<Key> {
        let f = &self.cell.spec.facts;
        let args: Vec<&str> = l.atom.args.iter().map(String::as_str).collect();
        let obj = |n: &str| self.pu.index.objects.get(n).map(|o| o.id);
        if let Some(m) = f.in_kit.matches(&l.atom.pred, &args) {
            let get = |v: Var| m.iter().find(|(w, _)| *w == v).and_then(|(_, n)| obj(n));
            return Some(self.w.facts.kit_free.key(&[
                (Var::Agv, get(Var::Agv)?),
                (Var::Quadrant, get(Var::Quadrant)?),
            ]));
        }
        if let Some(m) = f.installed.matches(&l.atom.pred, &args) {
            let get = |v: Var| m.iter().find(|(w, _)| *w == v).and_then(|(_, n)| obj(n));
            let kind = self.w.kind_of(get(Var::Part)?)?;
            let slot = obj(&self.cell.insert_slot(kind.ty))?;
            return Some(
                self.w
                    .facts
                    .insert_free
                    .key(&[(Var::Station, get(Var::Station)?), (Var::Slot, slot)]),
            );
        }
        None
    }

    /// A failed attempt (`record`: what failed, else its outcome): the task
    /// goes back to its queue for reassignment, or is given up after its
    /// last attempt.
    pub(super) fn attempt_failed(
        &mut self,
        t: TaskId,
        mut attempt: Attempt,
        record: Option<String>,
    ) {
        attempt.end_tick = self.tick;
        let why = record.unwrap_or_else(|| attempt.outcome.clone());
        let max = self.opts.max_attempts;
        if let Some(cause) =
            self.tm
                .attempt_failed(t, attempt, why, max, self.tick, &mut self.trace)
        {
            self.fail_task(t, cause);
        }
    }

    /// Agent `a` lets go of its task, its resources and its tree.
    fn release(&mut self, a: usize) {
        let Some(t) = self.agents[a].task.take() else {
            return;
        };
        let res = std::mem::take(&mut self.agents[a].resources);
        self.w.release(t, res);
        self.agents[a].engine = None;
    }

    /// Stops agent `a`'s running tree in the world and releases it: its
    /// task and attempt.
    pub(super) fn halt(&mut self, a: usize) -> Option<(TaskId, Option<Attempt>)> {
        let t = self.agents[a].task?;
        let mut engine = self.agents[a].engine.take()?;
        agent::halt(&mut engine, &mut self.w.kb.state);
        let attempt = self.agents[a].attempt.take();
        self.release(a);
        Some((t, attempt))
    }

    pub(super) fn tick_agents(&mut self) {
        for a in 0..self.agents.len() {
            let Some(mut engine) = self.agents[a].engine.take() else {
                continue;
            };
            self.agents[a].busy += 1;
            let (status, goal_ok) = agent::step(&mut engine, &mut self.w.kb.state);
            if status == Status::Running {
                self.agents[a].engine = Some(engine);
                continue;
            }
            self.finish_attempt(a, engine, status == Status::Success && goal_ok);
        }
    }

    fn finish_attempt(&mut self, a: usize, mut engine: Engine<'w>, ok: bool) {
        let Some(t) = self.agents[a].task else {
            return;
        };
        let mut attempt = self.agents[a]
            .attempt
            .take()
            .expect("a running task has an attempt");
        attempt.end_tick = self.tick;
        let record = engine.records.last().cloned();
        if let Some(tree) = engine.take_observer::<JsonlTrace>() {
            self.trace.tree(tree.text(), &attempt.agent, t, self.tick);
        }
        let faults: Vec<String> = record
            .as_ref()
            .map(|r| r.faults.clone())
            .unwrap_or_default();
        attempt.challenges = faults.clone();
        let o = self.tm.tasks[t].order;
        for f in &faults {
            if let Some(c) = self.challenges.iter_mut().find(|c| c.label == *f) {
                c.touch(o);
                c.note(format!("task {t} failed and went back to its queue"));
            }
        }
        self.release(a);
        if ok {
            attempt.outcome = "done".into();
            self.agents[a].done += 1;
            self.tm.done(t, attempt, self.tick, &mut self.trace);
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

    /// A high-priority order (challenge `c`): agents on regular tasks that
    /// could do its tasks, and that no idle agent would spare, stop them
    /// (the tasks go back to their queues).
    pub(super) fn preempt_for_priority(&mut self, c: usize) {
        let order = match self.challenges[c].kind {
            Kind::HighPriorityOrder { order } => order,
            _ => return,
        };
        self.tm.unblock();
        for a in 0..self.agents.len() {
            let Some(t) = self.agents[a].task else {
                continue;
            };
            let can = self.tm.has_queued_for(order, &self.agents[a].queues);
            let idle_other = (0..self.agents.len()).any(|b| {
                b != a
                    && self.agents[b].idle()
                    && self.normal(b)
                    && self.tm.has_queued_for(order, &self.agents[b].queues)
            });
            if !allocation::preempts(self.tm.tasks[t].priority, can, idle_other) {
                continue;
            }
            let Some((_, attempt)) = self.halt(a) else {
                continue;
            };
            let mut attempt = attempt.expect("running");
            attempt.end_tick = self.tick;
            let id = self.trial.orders[order].id.clone();
            attempt.outcome = format!("preempted by high-priority order `{id}`");
            attempt.challenges = vec![self.challenges[c].label.clone()];
            let robot = self.cell.robot(self.agents[a].robot).object.clone();
            let to = self.tm.tasks[t].order;
            self.challenges[c].touch(to);
            self.challenges[c].note(format!("{robot} stopped task {t} for it"));
            self.tm
                .preempted(t, attempt, id, self.tick, &mut self.trace);
        }
    }
}

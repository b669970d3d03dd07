//! The closed loop (`btc run --replan`): plan, compile the plan with the
//! rules, run the tree in the simulated world, and when it fails turn the
//! fault record into a new initial state and goal, plan again from there
//! with `btc_planner::plan_from`, and so on, up to a number of replans.
//!
//! One KB lives through the whole loop: the state the failed attempt left
//! (after the faults with a duration ended) is the next plan's initial
//! state. Faults are events in time: their run-time state moves from one
//! attempt's engine to the next and the tick count goes on, so a fault that
//! fired never fires again, and one that lasts N ticks lasts N ticks of the
//! loop. Nothing here prints or reads files; the CLI loads the files into
//! the database and renders the result.

use btc_lang::db::{self, CompileJob, Database, JobWorld};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::logic::{Formula, Name, Terms};
use btc_pddl::source::Span;
use btc_pddl::state::{State, World};
use btc_planner::Outcome;
use btc_runtime::engine::{Engine, FaultRecord, Options, Status};
use btc_runtime::error::LoadError;
use btc_runtime::faults::{FaultOutcome, FaultRt, Scenario};
use btc_runtime::{Kb, TreeDoc};
use serde::Serialize;
use std::time::Instant;

/// How the loop runs.
#[derive(Clone, Debug)]
pub struct LoopOptions {
    pub engine: Options,
    pub planner: btc_planner::Options,
    /// Plans made after a failure, at most (the first plan does not count).
    pub max_replans: usize,
    /// Ticks in all, across attempts and waits.
    pub max_ticks: u64,
}

impl Default for LoopOptions {
    fn default() -> Self {
        LoopOptions {
            engine: Options::default(),
            planner: btc_planner::Options::default(),
            max_replans: 5,
            max_ticks: 100_000,
        }
    }
}

/// One plan and its run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Attempt {
    /// 1-based.
    pub attempt: usize,
    /// `given` (the `--plan` file) or `planned`.
    pub source: &'static str,
    /// The goal this plan was made for.
    pub goal: String,
    /// The plan's steps, `(action arg ...)`.
    pub plan: Vec<String>,
    /// Planning time (0 for a given plan) and states the search expanded.
    pub planning_ms: f64,
    pub expanded: usize,
    pub compile_ms: f64,
    pub run_ms: f64,
    /// The ticks the attempt ran: from `start_tick + 1` to `end_tick`.
    pub start_tick: u64,
    pub end_tick: u64,
    pub status: Status,
    pub steps_done: usize,
    pub steps_total: usize,
    pub records: Vec<FaultRecord>,
    /// Ticks waited after the failure for faults with a duration to end.
    pub waited_ticks: u64,
    /// A high-priority order halted the tree (its status is then RUNNING).
    pub preempted: bool,
}

/// Why the loop planned again, and what changed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Replan {
    /// The attempt that failed (1-based).
    pub after_attempt: usize,
    /// The tick the new plan starts from.
    pub tick: u64,
    /// The failing node and reason, from the fault record.
    pub why: String,
    /// The 1-based plan step that failed, and its action.
    pub from_step: Option<usize>,
    pub action: Option<String>,
    pub faults: Vec<String>,
    /// Changes to the goal (a replaced part, an added order).
    pub adjustments: Vec<String>,
}

/// What the loop came to.
#[derive(Clone, Debug, Serialize)]
pub struct LoopSummary {
    pub attempts: Vec<Attempt>,
    pub replans: Vec<Replan>,
    pub faults: Vec<FaultOutcome>,
    /// The final goal (the problem's, adjusted).
    pub goal: String,
    pub goal_reached: bool,
    pub goal_failure: Option<String>,
    pub ticks: u64,
    /// Why the loop stopped short of the goal.
    pub stopped: Option<String>,
    /// Goal literals no plan reaches from the state the loop stopped in,
    /// each with the faults that name it.
    pub unreachable: Vec<Unreachable>,
    /// Wall-clock time of the whole loop.
    pub elapsed_ms: f64,
    /// The stop as a diagnostic (X008, X009, S004), on the problem's goal.
    #[serde(skip)]
    pub diagnostics: Vec<Diagnostic>,
    /// Every attempt's trace and the loop's events, as JSON Lines (when
    /// `engine.trace` is set).
    #[serde(skip)]
    pub trace: String,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Unreachable {
    pub literal: String,
    pub faults: Vec<String>,
}

impl LoopSummary {
    pub fn success(&self) -> bool {
        self.goal_reached
    }
}

/// Inputs the loop cannot work with.
#[derive(Debug)]
pub enum LoopError {
    /// The rules, domain, problem or a plan do not compile.
    Compile(Vec<Diagnostic>),
    /// The compiled tree cannot be run.
    Tree(LoadError),
    /// The fault scenario does not fit the problem or the plan.
    Scenario(LoadError),
}

/// What carries from one attempt to the next.
struct Carry {
    state: Option<State>,
    faults: Option<Vec<FaultRt>>,
    tick: u64,
    /// Goals faults added (high-priority orders).
    extra_goals: Vec<Formula>,
    /// Parts in the goal replaced by spares: (part, spare).
    substitutions: Vec<(Name, Name)>,
    /// Goals of high-priority orders that preempted a plan, to be reached
    /// before the rest of the goal.
    priority: Vec<Formula>,
}

/// Runs the loop on a compile job whose plan file is `job.plan`: with
/// `given_plan`, that file's text is the first plan; otherwise (and for
/// every replan) the planner writes the plan into it (sas_plan text) and the
/// job is compiled again, as `btc compile` would compile that file.
pub fn run_loop(
    db: &mut Database,
    job: CompileJob,
    given_plan: bool,
    scenario: Option<&Scenario>,
    opts: &LoopOptions,
) -> Result<LoopSummary, LoopError> {
    let mut trace = Vec::new();
    let mut out = run_loop_traced(db, job, given_plan, scenario, opts, &mut trace)?;
    out.trace = String::from_utf8_lossy(&trace).into_owned();
    Ok(out)
}

/// [`run_loop`] with the trace (when `opts.engine.trace` is set) written to
/// `trace` as it happens, tick by tick, instead of kept in the summary: a
/// long loop holds bounded memory and a killed one leaves its trace so far.
/// Write errors are the writer's to keep (`btc_files::Stream` does).
pub fn run_loop_traced(
    db: &mut Database,
    job: CompileJob,
    given_plan: bool,
    scenario: Option<&Scenario>,
    opts: &LoopOptions,
    trace_out: &mut dyn std::io::Write,
) -> Result<LoopSummary, LoopError> {
    let t0 = Instant::now();
    let plan_path = job.plan(db).path(db).clone();
    let goal_span = world(db, job)?.problem.goal.as_ref().map_or(
        Span::new(problem_file_id(db, job), 0, 0),
        btc_pddl::ast::Formula::span,
    );
    // The world does not change from plan to plan: only the plan file does.
    let the_world = world(db, job)?
        .world()
        .map_err(|m| LoopError::Tree(LoadError::new(codes::X_KB, m)))?;
    let base_goal = the_world
        .model()
        .goal
        .clone()
        .unwrap_or_else(Formula::truth);
    let mut carry = Carry {
        state: None,
        faults: None,
        tick: 0,
        extra_goals: Vec::new(),
        substitutions: Vec::new(),
        priority: Vec::new(),
    };
    let mut out = LoopSummary {
        attempts: Vec::new(),
        replans: Vec::new(),
        faults: Vec::new(),
        goal: base_goal.to_string(),
        goal_reached: false,
        goal_failure: None,
        ticks: 0,
        stopped: None,
        unreachable: Vec::new(),
        elapsed_ms: 0.0,
        diagnostics: Vec::new(),
        trace: String::new(),
    };
    let trace = opts.engine.trace;
    loop {
        let attempt = out.attempts.len() + 1;
        let whole = goal_of(&base_goal, &carry);
        out.goal = whole.to_string();
        // This attempt's goal: a priority order's first, then the whole.
        let for_priority = !carry.priority.is_empty();
        let goal = if for_priority {
            priority_goal(&carry)
        } else {
            whole
        };
        let goal_text = goal.to_string();
        // Plan (unless the first plan is given) from the carried state.
        let (plan_text, planning_ms, expanded) = if attempt == 1 && given_plan {
            (None, 0.0, 0)
        } else {
            let w = world(db, job)?;
            let mut kb = kb_at(&the_world, &carry);
            let g = goal_formula(&mut kb, &goal)?;
            kb.set_goal(g);
            if let (true, _) = kb.goal() {
                if for_priority {
                    // The order is done (e.g. by its own effect).
                    carry.priority.clear();
                    continue;
                }
                // Nothing left to do.
                out.goal_reached = true;
                out.goal_failure = None;
                break;
            }
            let tp = Instant::now();
            let report = btc_planner::plan_from(
                w.domain,
                w.dix,
                w.pix,
                &kb.state,
                Some(&goal.to_ast(goal_span)),
                &opts.planner,
            )
            .map_err(LoopError::Compile)?;
            let planning_ms = tp.elapsed().as_secs_f64() * 1e3;
            match report.outcome {
                Outcome::Plan(p) => (
                    Some(btc_planner::to_sas_plan(w.domain, w.pix, &p)),
                    planning_ms,
                    report.search.expanded,
                ),
                Outcome::Unsolvable => {
                    let un = unreachable(&w, &kb, &goal, goal_span, &carry, opts)?;
                    let lits: Vec<String> = un.iter().map(|u| format!("`{}`", u.literal)).collect();
                    let by: Vec<String> = un.iter().flat_map(|u| u.faults.clone()).collect();
                    // Faults still in effect (a malfunction that outlasted
                    // the tick limit) count too.
                    let in_effect = carry
                        .faults
                        .iter()
                        .flatten()
                        .filter(|rt| rt.met_at.is_some() && !rt.ended)
                        .map(|rt| rt.spec.label());
                    let mut by_u: Vec<String> = Vec::new();
                    for f in by.into_iter().chain(in_effect) {
                        if !by_u.contains(&f) {
                            by_u.push(f);
                        }
                    }
                    let msg = format!(
                        "no plan reaches the goal from the state after {}: {} {} unreachable{}",
                        if out.attempts.is_empty() {
                            "the start".to_owned()
                        } else {
                            format!("tick {}", carry.tick)
                        },
                        if lits.is_empty() {
                            "the goal as a whole".to_owned()
                        } else {
                            lits.join(", ")
                        },
                        if lits.len() > 1 { "are" } else { "is" },
                        if by_u.is_empty() {
                            String::new()
                        } else {
                            format!(" (made so by fault {})", quoted(&by_u))
                        }
                    );
                    out.diagnostics.push(
                        Diagnostic::error(codes::X_REPLAN_UNSOLVABLE, goal_span, msg.clone())
                            .with_hint(
                                "a fault removed what the goal needs and nothing in the problem \
                                 replaces it; a discarded part is replaced by a spare of the same \
                                 kind (an object of its type named `PART_...`, e.g. `battery_red_2`)",
                            ),
                    );
                    out.unreachable = un;
                    out.stopped = Some(msg);
                    out.goal_failure = kb.goal().1;
                    break;
                }
                Outcome::Timeout => {
                    let limit = opts.planner.timeout.unwrap_or_default();
                    let msg = format!(
                        "planning from the state at tick {} found no plan within {} s",
                        carry.tick,
                        limit.as_secs_f64()
                    );
                    out.diagnostics.push(
                        Diagnostic::error(codes::PLAN_TIMEOUT, goal_span, msg.clone())
                            .with_hint("raise the planner's time limit"),
                    );
                    out.stopped = Some(msg);
                    out.goal_failure = kb.goal().1;
                    break;
                }
            }
        };
        if let Some(text) = &plan_text {
            db.set_file(&plan_path, text.clone());
        }
        // Compile, exactly as `btc compile` compiles the plan file.
        let tc = Instant::now();
        let ir = db::compile(db, job).as_ref().map_err(|e| {
            let mut e = e.clone();
            if e.is_empty() {
                e = db::job_diagnostics(db, job)
                    .iter()
                    .filter(|d| d.is_error())
                    .cloned()
                    .collect();
            }
            LoopError::Compile(e)
        })?;
        let doc = TreeDoc::from_ir(ir);
        let compile_ms = tc.elapsed().as_secs_f64() * 1e3;
        let plan: Vec<String> = ir.steps.iter().map(|s| s.display()).collect();
        if trace {
            push_event(
                trace_out,
                serde_json::json!({
                    "event": "plan", "attempt": attempt, "tick": carry.tick,
                    "source": if plan_text.is_some() { "planned" } else { "given" },
                    "goal": goal_text, "steps": plan,
                }),
            );
        }
        // Run, in the carried world.
        let mut kb = kb_at(&the_world, &carry);
        let g = goal_formula(&mut kb, &goal)?;
        kb.set_goal(g);
        let mut engine =
            Engine::build(&doc, Some(kb), opts.engine.clone()).map_err(LoopError::Tree)?;
        engine.tick = carry.tick;
        match carry.faults.take() {
            Some(f) => engine.restore_faults(f),
            None => {
                if let Some(s) = scenario {
                    engine.add_faults(s).map_err(LoopError::Scenario)?;
                }
            }
        }
        let start_tick = engine.tick;
        let tr = Instant::now();
        // A high-priority order whose goal does not hold preempts the plan.
        let (status, preempted) = engine.run_until(opts.max_ticks, |e| {
            if trace {
                let _ = e.drain_trace(trace_out);
            }
            e.kb.as_ref()
                .is_some_and(|kb| !kb.unmet_extra_goals().is_empty())
        });
        let run_ms = tr.elapsed().as_secs_f64() * 1e3;
        let sum = engine.summary(status);
        let done = !preempted && sum.success();
        let end_tick = engine.tick;
        let waited = if done || (status == Status::Running && !preempted) {
            0
        } else {
            engine.wait_for_faults(opts.max_ticks)
        };
        let preempting: Vec<Formula> = if preempted {
            engine
                .kb
                .as_ref()
                .map(Kb::unmet_extra_goals)
                .unwrap_or_default()
        } else {
            Vec::new()
        };
        let order_faults: Vec<String> = sum
            .faults
            .iter()
            .filter(|f| {
                f.kind == btc_runtime::faults::FaultKind::HighPriorityOrder
                    && f.met_at == Some(end_tick)
            })
            .map(|f| f.fault.clone())
            .collect();
        out.faults = engine.fault_outcomes(done);
        if trace {
            let _ = engine.drain_trace(trace_out);
        }
        let discarded = engine.discarded_parts();
        let kb = engine.kb.as_mut().expect("built with a KB");
        let mut added = kb.extra_goals();
        added.retain(|a| !carry.extra_goals.contains(a));
        carry.extra_goals.extend(added.iter().cloned());
        let (goal_ok, goal_why) = kb.goal();
        carry.state = Some(std::mem::take(&mut kb.state));
        carry.tick = engine.tick;
        carry.faults = Some(engine.take_faults());
        out.ticks = carry.tick;
        out.goal_reached = goal_ok && done && !for_priority;
        out.goal_failure = goal_why;
        out.attempts.push(Attempt {
            attempt,
            source: if plan_text.is_some() {
                "planned"
            } else {
                "given"
            },
            goal: goal_text.clone(),
            plan,
            planning_ms,
            expanded,
            compile_ms,
            run_ms,
            start_tick,
            end_tick,
            status,
            steps_done: sum.steps_done,
            steps_total: sum.steps_total,
            records: sum.records.clone(),
            waited_ticks: waited,
            preempted,
        });
        if done && for_priority {
            // The priority order is done: back to the whole goal.
            carry.priority.clear();
            out.goal_reached = false;
            continue;
        }
        if done {
            break;
        }
        if status == Status::Running && !preempted {
            out.stopped = Some(format!(
                "the loop ran out of ticks ({} in all)",
                opts.max_ticks
            ));
            out.diagnostics.push(
                Diagnostic::error(
                    codes::X_REPLAN_LIMIT,
                    goal_span,
                    out.stopped.clone().unwrap_or_default(),
                )
                .with_hint("raise `--max-ticks`"),
            );
            break;
        }
        if out.replans.len() >= opts.max_replans {
            let msg = format!(
                "the goal was not reached after {} (the limit)",
                plural(opts.max_replans, "replan")
            );
            out.diagnostics.push(
                Diagnostic::error(codes::X_REPLAN_LIMIT, goal_span, msg.clone())
                    .with_hint("raise `--max-replans`, or look at the fault records"),
            );
            out.stopped = Some(msg);
            break;
        }
        // The goal adjustments: orders that added a goal, parts replaced.
        let mut adjustments = Vec::new();
        for a in added {
            adjustments.push(format!("a fault added the goal `{a}`"));
        }
        {
            let kb = kb_at(&the_world, &carry);
            let named = goal.objects();
            for (part, fault) in discarded {
                let part = btc_pddl::logic::name(&part);
                if carry.substitutions.iter().any(|(p, _)| *p == part) || !named.contains(&part) {
                    continue;
                }
                match spare(&kb, &part, &carry, &named) {
                    Some(s) => {
                        adjustments.push(format!(
                            "`{part}` is gone (fault `{fault}`): the goal uses `{s}` instead"
                        ));
                        carry.substitutions.push((part, s));
                    }
                    None => adjustments.push(format!(
                        "`{part}` is gone (fault `{fault}`) and the problem has no spare `{part}_...`"
                    )),
                }
            }
        }
        let rp = if preempted {
            for g in &preempting {
                adjustments.push(format!("`{g}` comes first: the order preempted the plan"));
            }
            carry.priority = preempting.clone();
            Replan {
                after_attempt: attempt,
                tick: carry.tick,
                why: format!(
                    "a high-priority order preempted the plan at tick {end_tick}: {}",
                    quoted(&preempting.iter().map(|g| g.to_string()).collect::<Vec<_>>())
                ),
                from_step: None,
                action: None,
                faults: order_faults,
                adjustments,
            }
        } else {
            let last = sum.records.last();
            let why = last.map_or_else(
                || "the tree failed".to_owned(),
                |r| format!("`{}` ({}) failed: {}", r.node_name, r.node_id, r.reason),
            );
            Replan {
                after_attempt: attempt,
                tick: carry.tick,
                why,
                from_step: last.and_then(|r| r.step),
                action: last.and_then(|r| r.action.clone()),
                faults: last.map(|r| r.faults.clone()).unwrap_or_default(),
                adjustments,
            }
        };
        if trace {
            let mut v = serde_json::to_value(&rp).unwrap_or_default();
            if let Some(o) = v.as_object_mut() {
                o.insert("event".into(), "replan".into());
            }
            push_event(trace_out, v);
        }
        out.replans.push(rp);
    }
    out.goal = goal_of(&base_goal, &carry).to_string();
    out.elapsed_ms = t0.elapsed().as_secs_f64() * 1e3;
    if trace {
        push_event(
            trace_out,
            serde_json::json!({
                "event": "goal_check", "tick": out.ticks, "goal": out.goal,
                "reached": out.goal_reached, "replans": out.replans.len(),
            }),
        );
    }
    Ok(out)
}

fn push_event(out: &mut dyn std::io::Write, v: serde_json::Value) {
    let _ = writeln!(out, "{v}");
}

fn plural(n: usize, what: &str) -> String {
    if n == 1 {
        format!("1 {what}")
    } else {
        format!("{n} {what}s")
    }
}

fn quoted(v: &[String]) -> String {
    v.iter()
        .map(|s| format!("`{s}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn problem_file_id(db: &Database, job: CompileJob) -> u32 {
    db::job_problem(db, job).map_or(0, |p| db::file_id(db, p))
}

fn world(db: &Database, job: CompileJob) -> Result<JobWorld<'_>, LoopError> {
    JobWorld::of(db, job).ok_or_else(|| {
        LoopError::Compile(
            db::job_diagnostics(db, job)
                .iter()
                .filter(|d| d.is_error())
                .cloned()
                .collect(),
        )
    })
}

/// The KB of the problem, in the carried state.
fn kb_at<'w>(w: &'w World, carry: &Carry) -> Kb<'w> {
    let mut kb = Kb::new(w);
    if let Some(s) = &carry.state {
        kb.state = s.clone();
    }
    kb
}

/// The goal: the problem's with spares for discarded parts, and the goals
/// faults added.
fn goal_of(base: &Formula, carry: &Carry) -> Formula {
    let g = base.replace_objects(&carry.substitutions);
    if carry.extra_goals.is_empty() {
        return g;
    }
    let mut parts = vec![g];
    parts.extend(
        carry
            .extra_goals
            .iter()
            .map(|e| e.replace_objects(&carry.substitutions)),
    );
    Formula::And(parts)
}

/// The goals of the priority orders still to do, with spares for
/// discarded parts.
fn priority_goal(carry: &Carry) -> Formula {
    let parts: Vec<Formula> = carry
        .priority
        .iter()
        .map(|g| g.replace_objects(&carry.substitutions))
        .collect();
    Formula::conjunction(parts).unwrap_or_else(Formula::truth)
}

fn goal_formula(kb: &mut Kb<'_>, goal: &Formula) -> Result<u32, LoopError> {
    kb.formula(goal).map_err(|m| {
        LoopError::Tree(LoadError::new(
            codes::X_KB,
            format!("the adjusted goal `{goal}` is not a condition of this problem: {m}"),
        ))
    })
}

/// A spare for a discarded part: an object of the same types, named
/// `PART_...`, that is somewhere in the KB, not itself discarded and not
/// already named by the goal.
fn spare(kb: &Kb<'_>, part: &Name, carry: &Carry, named: &[Name]) -> Option<Name> {
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
                && !carry
                    .substitutions
                    .iter()
                    .any(|(p, s)| &**p == *n || &**s == *n)
        })
        .map(|(n, _)| btc_pddl::logic::name(n))
}

/// The goal's conjuncts (nested conjunctions split too) that no plan
/// reaches from the KB's state, with the faults that name them.
fn unreachable(
    w: &JobWorld<'_>,
    kb: &Kb<'_>,
    goal: &Formula,
    span: Span,
    carry: &Carry,
    opts: &LoopOptions,
) -> Result<Vec<Unreachable>, LoopError> {
    let mut literals = Vec::new();
    for part in goal.conjuncts() {
        literals.extend(part.conjuncts().iter().cloned());
    }
    let faults = carry.faults.as_deref().unwrap_or(&[]);
    let mut out = Vec::new();
    for lit in literals {
        let r = btc_planner::plan_from(
            w.domain,
            w.dix,
            w.pix,
            &kb.state,
            Some(&lit.to_ast(span)),
            &opts.planner,
        )
        .map_err(LoopError::Compile)?;
        if r.outcome == Outcome::Unsolvable {
            out.push(Unreachable {
                literal: lit.to_string(),
                faults: btc_runtime::faults::naming(faults, &lit),
            });
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use btc_pddl::logic::{decode, name};

    fn carry() -> Carry {
        Carry {
            state: None,
            faults: None,
            tick: 0,
            extra_goals: Vec::new(),
            substitutions: Vec::new(),
            priority: Vec::new(),
        }
    }

    #[test]
    fn spares_replace_objects_not_words() {
        let base = decode::formula("(and (on battery_red agv1) (on battery_red_2 tray))").unwrap();
        let mut c = carry();
        c.substitutions.push((name("battery_red"), name("b2")));
        c.extra_goals
            .push(decode::formula("(on battery_red agv2)").unwrap());
        assert_eq!(
            goal_of(&base, &c).to_string(),
            "(and (and (on b2 agv1) (on battery_red_2 tray)) (on b2 agv2))"
        );
        assert!(base.objects().contains(&name("battery_red")));
        assert!(!decode::formula("(on p10 agv1)")
            .unwrap()
            .objects()
            .contains(&name("p1")));
    }
}

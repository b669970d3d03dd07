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
use btc_pddl::ast::Formula;
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::source::Span;
use btc_pddl::state::State;
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
    /// Goals faults added (high-priority orders), as texts.
    extra_goals: Vec<String>,
    /// Parts in the goal replaced by spares: (part, spare).
    substitutions: Vec<(String, String)>,
    /// Goals of high-priority orders that preempted a plan, to be reached
    /// before the rest of the goal.
    priority: Vec<String>,
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
    let goal_span = world(db, job)?
        .problem
        .goal
        .as_ref()
        .map_or(Span::new(problem_file_id(db, job), 0, 0), Formula::span);
    let base_goal = {
        let text = db::job_problem(db, job)
            .map(|p| p.text(db).clone())
            .unwrap_or_default();
        text.get(goal_span.start as usize..goal_span.end as usize)
            .filter(|g| !g.trim().is_empty())
            .unwrap_or("(and)")
            .to_owned()
    };
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
        goal: base_goal.clone(),
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
        out.goal = goal_text(&base_goal, &carry);
        // This attempt's goal: a priority order's first, then the whole.
        let for_priority = !carry.priority.is_empty();
        let goal_text = if for_priority {
            priority_text(&carry)
        } else {
            out.goal.clone()
        };
        // Plan (unless the first plan is given) from the carried state.
        let (plan_text, planning_ms, expanded) = if attempt == 1 && given_plan {
            (None, 0.0, 0)
        } else {
            let w = world(db, job)?;
            let mut kb = kb_at(&w, &carry);
            let g = goal_formula(&mut kb, &goal_text)?;
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
                Some(kb.formula_ast(g)),
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
                    let un = unreachable(&w, &mut kb, &goal_text, g, &carry, opts)?;
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
        let w = world(db, job)?;
        let mut kb = kb_at(&w, &carry);
        let g = goal_formula(&mut kb, &goal_text)?;
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
        let preempting: Vec<String> = if preempted {
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
        let mut added = kb.extra_goal_texts();
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
            let w = world(db, job)?;
            let kb = kb_at(&w, &carry);
            for (part, fault) in discarded {
                if carry.substitutions.iter().any(|(p, _)| *p == part)
                    || !mentions(&goal_text, &part)
                {
                    continue;
                }
                match spare(&w, &kb, &part, &carry, &goal_text) {
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
                    quoted(&preempting)
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
    out.goal = goal_text(&base_goal, &carry);
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
fn kb_at<'w>(w: &JobWorld<'w>, carry: &Carry) -> Kb<'w> {
    let mut kb = Kb::new(w.domain, w.dix, w.problem, w.pix);
    if let Some(s) = &carry.state {
        kb.state = s.clone();
    }
    kb
}

/// The goal text: the problem's with spares for discarded parts, and the
/// goals faults added.
fn goal_text(base: &str, carry: &Carry) -> String {
    let mut g = base.to_owned();
    for (p, s) in &carry.substitutions {
        g = replace_word(&g, p, s);
    }
    if carry.extra_goals.is_empty() {
        g
    } else {
        format!("(and {g} {})", carry.extra_goals.join(" "))
    }
}

/// The goals of the priority orders still to do, with spares for
/// discarded parts.
fn priority_text(carry: &Carry) -> String {
    let mut parts: Vec<String> = carry.priority.clone();
    for (p, s) in &carry.substitutions {
        for g in &mut parts {
            *g = replace_word(g, p, s);
        }
    }
    if parts.len() == 1 {
        parts.remove(0)
    } else {
        format!("(and {})", parts.join(" "))
    }
}

fn goal_formula(kb: &mut Kb<'_>, text: &str) -> Result<u32, LoopError> {
    kb.formula(text).map_err(|m| {
        LoopError::Tree(LoadError::new(
            codes::X_KB,
            format!("the adjusted goal `{text}` is not a condition of this problem: {m}"),
        ))
    })
}

fn is_word(c: char) -> bool {
    c.is_alphanumeric() || c == '_' || c == '-'
}

/// `text` with every whole-word `from` replaced by `to`.
pub fn replace_word(text: &str, from: &str, to: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(k) = rest.find(from) {
        let before = rest[..k].chars().next_back();
        let after = rest[k + from.len()..].chars().next();
        out.push_str(&rest[..k]);
        if before.is_some_and(is_word) || after.is_some_and(is_word) {
            out.push_str(from);
        } else {
            out.push_str(to);
        }
        rest = &rest[k + from.len()..];
    }
    out.push_str(rest);
    out
}

fn mentions(text: &str, word: &str) -> bool {
    replace_word(text, word, "\u{0}") != text
}

/// A spare for a discarded part: an object of the same types, named
/// `PART_...`, that is somewhere in the KB, not itself discarded and not
/// already in the goal.
fn spare(w: &JobWorld<'_>, kb: &Kb<'_>, part: &str, carry: &Carry, goal: &str) -> Option<String> {
    let info = w.pix.objects.get(part)?;
    let prefix = format!("{part}_");
    let mut cands: Vec<(&String, u32)> = w
        .pix
        .objects
        .iter()
        .filter(|(n, o)| n.starts_with(&prefix) && o.types == info.types)
        .map(|(n, o)| (n, o.id))
        .collect();
    cands.sort();
    cands
        .into_iter()
        .find(|(n, id)| {
            !kb.facts_mentioning(*id).is_empty()
                && !mentions(goal, n)
                && !carry.substitutions.iter().any(|(p, s)| p == *n || s == *n)
        })
        .map(|(n, _)| n.clone())
}

/// The goal's top-level conjuncts that no plan reaches from the KB's
/// state, with the faults that name them.
fn unreachable(
    w: &JobWorld<'_>,
    kb: &mut Kb<'_>,
    goal_text: &str,
    g: u32,
    carry: &Carry,
    opts: &LoopOptions,
) -> Result<Vec<Unreachable>, LoopError> {
    let parts: Vec<String> = match kb.formula_ast(g) {
        Formula::And { parts, .. } => parts
            .iter()
            .filter_map(|p| {
                let s = p.span();
                goal_text
                    .get(s.start as usize..s.end as usize)
                    .map(str::to_owned)
            })
            .collect(),
        _ => vec![goal_text.to_owned()],
    };
    let shown =
        |lit: &str| btc_runtime::faults::naming(carry.faults.as_deref().unwrap_or(&[]), lit);
    let mut out = Vec::new();
    for lit in parts {
        // A nested `(and ...)` (added goals) is split too.
        let id = goal_formula(kb, &lit)?;
        let sub: Vec<String> = match kb.formula_ast(id) {
            Formula::And { parts, .. } => parts
                .iter()
                .filter_map(|p| {
                    let s = p.span();
                    lit.get(s.start as usize..s.end as usize).map(str::to_owned)
                })
                .collect(),
            _ => vec![lit.clone()],
        };
        for l in sub {
            let id = goal_formula(kb, &l)?;
            let r = btc_planner::plan_from(
                w.domain,
                w.dix,
                w.pix,
                &kb.state,
                Some(kb.formula_ast(id)),
                &opts.planner,
            )
            .map_err(LoopError::Compile)?;
            if r.outcome == Outcome::Unsolvable {
                let faults = shown(&l);
                out.push(Unreachable { literal: l, faults });
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_are_replaced_whole() {
        assert_eq!(
            replace_word(
                "(on battery_red agv1) (on battery_red_2 x)",
                "battery_red",
                "b2"
            ),
            "(on b2 agv1) (on battery_red_2 x)"
        );
        assert!(mentions("(on p1 agv1)", "p1"));
        assert!(!mentions("(on p10 agv1)", "p1"));
    }
}

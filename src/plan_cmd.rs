//! `btc plan DOMAIN PROBLEM`: ground and search; the plan goes to stdout
//! (or atomically to `-o`), statistics to stderr.

use crate::stdout::{out, outln};
use crate::{files, report, Format};
use btc_pddl::diagnostic::has_errors;
use btc_pddl::pipeline::{domain_unit, problem_unit};
use btc_pddl::source::Sources;
use btc_planner::{Heuristic, Options, Outcome};
use std::path::Path;
use std::process::ExitCode;

pub struct PlanArgs<'a> {
    pub domain: &'a Path,
    pub problem: &'a Path,
    pub output: Option<&'a Path>,
    pub options: Options,
    pub quiet: bool,
    pub format: Format,
}

pub fn run(args: &PlanArgs) -> anyhow::Result<ExitCode> {
    let mut sources = Sources::new();
    let mut diags = Vec::new();
    let d = files::load(&mut sources, args.domain, &mut diags)?;
    let p = files::load(&mut sources, args.problem, &mut diags)?;
    let du = domain_unit(&sources, d);
    let pu = problem_unit(&sources, p, &du);
    diags.extend(du.diagnostics.iter().cloned());
    diags.extend(pu.diagnostics.iter().cloned());
    let (Some(domain), Some(problem)) = (&du.domain, &pu.problem) else {
        return finish(&diags, &sources, args.format, None);
    };
    if has_errors(&diags) {
        return finish(&diags, &sources, args.format, None);
    }
    let report = match btc_planner::plan(domain, &du.index, problem, &pu.index, &args.options) {
        Ok(r) => r,
        Err(ds) => {
            diags.extend(ds);
            return finish(&diags, &sources, args.format, None);
        }
    };
    let base_cost = match &report.outcome {
        Outcome::Plan(p) => p.base_cost,
        _ => 0.0,
    };
    let stats = serde_json::json!({
        "heuristic": report
            .search
            .heuristic
            .map_or_else(|| "ff+landmarks".to_owned(), |h| format!("{h:?}").to_lowercase()),
        "searches": report.search.iterations,
        "first_cost": report.search.first_cost.map(|c| base_cost + c as f64),
        "proved_optimal": report.search.proved_optimal,
        "work": report.search.work,
        "reachable_atoms": report.ground.reachable_atoms,
        "operators": report.ground.operators,
        "axioms": report.ground.axioms,
        "facts": report.ground.facts,
        "ground_ms": report.ground_time.as_secs_f64() * 1e3,
        "expanded": report.search.expanded,
        "generated": report.search.generated,
        "evaluated": report.search.evaluated,
        "search_ms": report.search.time.as_secs_f64() * 1e3,
    });
    let mut plan_json = None;
    match &report.outcome {
        Outcome::Plan(plan) => {
            let schedule = btc_planner::schedule_plan(domain, &du.index, problem, &pu.index, plan)
                .map_err(anyhow::Error::msg)?;
            let text = match &schedule {
                Some(s) => btc_planner::to_timed_plan(domain, &pu.index, plan, s),
                None => btc_planner::to_sas_plan(domain, &pu.index, plan),
            };
            if let (Some(s), Format::Text, false) = (&schedule, args.format, args.quiet) {
                eprintln!(
                    "schedule: makespan {:.3}, against {:.3} for the steps one after another{}",
                    s.makespan,
                    s.sequential,
                    if s.serialized {
                        " (laid one after another: the deordered schedule did not validate)"
                    } else {
                        ""
                    }
                );
            }
            match args.output {
                Some(path) => files::write_atomically(path, &text)?,
                None if args.format == Format::Text => out!("{text}")?,
                None => {}
            }
            plan_json = Some(serde_json::json!({
                "steps": plan.steps.len(),
                "cost": plan.base_cost + plan.cost as f64,
                "makespan": schedule.as_ref().map(|s| s.makespan),
                "sequential_duration": schedule.as_ref().map(|s| s.sequential),
                "plan": text,
            }));
        }
        Outcome::Unsolvable => diags.push(btc_planner::unsolvable(problem)),
        Outcome::Timeout => diags.push(btc_planner::timeout(
            problem,
            args.options.timeout.unwrap_or_default(),
        )),
    }
    if args.format == Format::Text && !args.quiet {
        let r = &report;
        if args.options.heuristic == Heuristic::LmCut && r.search.heuristic == Some(Heuristic::Max)
        {
            eprintln!("note: LM-cut needs a task without conditional effects and derived predicates; h_max was used");
        }
        let found = match &r.outcome {
            Outcome::Plan(p) => format!(
                "plan: {}, cost {}",
                report::plural(p.steps.len(), "step"),
                p.base_cost + p.cost as f64
            ),
            Outcome::Unsolvable => "no plan exists".to_owned(),
            Outcome::Timeout => "time limit reached".to_owned(),
        };
        let restarts = match (r.search.iterations, r.search.first_cost) {
            (n, Some(c)) if n > 1 => format!(
                "; {} searches from a first plan of cost {}{}",
                n,
                base_cost + c as f64,
                if r.search.proved_optimal {
                    ", proved optimal"
                } else {
                    ""
                }
            ),
            _ => String::new(),
        };
        eprintln!(
            "{found}{restarts}; {} ground actions, {} facts, {} axioms; {} expanded, {} generated; grounding {:.3} ms, search {:.3} ms",
            r.ground.operators,
            r.ground.facts,
            r.ground.axioms,
            r.search.expanded,
            r.search.generated,
            r.ground_time.as_secs_f64() * 1e3,
            r.search.time.as_secs_f64() * 1e3,
        );
    }
    finish(&diags, &sources, args.format, Some((stats, plan_json)))
}

fn finish(
    diags: &[btc_pddl::diagnostic::Diagnostic],
    sources: &Sources,
    format: Format,
    result: Option<(serde_json::Value, Option<serde_json::Value>)>,
) -> anyhow::Result<ExitCode> {
    let json = report::diagnostics(diags, sources, format);
    let solved = result.as_ref().is_some_and(|(_, p)| p.is_some()) && !has_errors(diags);
    if format == Format::Json {
        let (stats, plan) = result.unwrap_or((serde_json::Value::Null, None));
        let doc = serde_json::json!({
            "solved": solved,
            "plan": plan,
            "statistics": stats,
            "diagnostics": json,
        });
        outln!("{}", serde_json::to_string_pretty(&doc)?)?;
    }
    Ok(if solved {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

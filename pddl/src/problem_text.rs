//! A problem written back as PDDL with another initial state and goal: the
//! knowledge base an agent holds now, as a problem any planner reads. The
//! problem's name, domain, requirements, objects and metric stay as they
//! were declared.

use crate::ast::{Problem, TypeSpec};
use crate::logic::{Formula, InitFact};
use std::fmt::Write;

/// `problem` with `init` as its initial state and `goal` as its goal.
pub fn problem_text(problem: &Problem, init: &[InitFact], goal: Option<&Formula>) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "(define (problem {})", problem.name.name);
    let _ = writeln!(o, "  (:domain {})", problem.domain.name);
    if !problem.requirements.is_empty() {
        // The parser keeps a requirement's name without its colon.
        let reqs: Vec<String> = problem
            .requirements
            .iter()
            .map(|r| format!(":{}", r.name.trim_start_matches(':')))
            .collect();
        let _ = writeln!(o, "  (:requirements {})", reqs.join(" "));
    }
    if !problem.objects.is_empty() {
        o.push_str("  (:objects");
        // Consecutive objects of one type share a line, as people write them.
        // (Types compare as text: their spans differ.)
        let mut line: Vec<&str> = Vec::new();
        let mut ty: Option<String> = None;
        let flush = |o: &mut String, line: &mut Vec<&str>, ty: &Option<String>| {
            if line.is_empty() {
                return;
            }
            let _ = write!(o, "\n    {}", line.join(" "));
            if let Some(t) = ty {
                let _ = write!(o, " - {t}");
            }
            line.clear();
        };
        for obj in &problem.objects {
            let this = match obj.ty {
                TypeSpec::Object => None,
                ref t => Some(t.to_string()),
            };
            if line.is_empty() || ty != this {
                flush(&mut o, &mut line, &ty);
                ty = this;
            }
            line.push(&obj.name.name);
        }
        flush(&mut o, &mut line, &ty);
        o.push_str(")\n");
    }
    o.push_str("  (:init");
    for f in init {
        let _ = write!(o, "\n    {f}");
    }
    o.push_str(")\n");
    if let Some(g) = goal {
        let _ = writeln!(o, "  (:goal {g})");
    }
    if let Some(m) = &problem.metric {
        let how = match m.optimize {
            crate::ast::Optimize::Minimize => "minimize",
            crate::ast::Optimize::Maximize => "maximize",
        };
        let _ = writeln!(o, "  (:metric {how} {})", m.expr);
    }
    o.push(')');
    o.push('\n');
    o
}

//! A problem made as a value (by a program that knows its world: the
//! trial's cell, an embedding host), with the text it reads as. The
//! compiler takes the value as it is; the text is the problem file btc
//! would write for it, which a diagnostic on the problem shows, and every
//! span points into it as if the text had been read.

use crate::ast::{Atom, Formula, InitFact, Name, Problem, SmolStr, Term, TypeSpec, Typed};
use crate::source::{FileId, Span};
use std::fmt::Write as _;

/// A problem value and its text; [`WrittenProblem::problem`] places it in
/// a file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WrittenProblem {
    text: String,
    name: Written,
    domain: Written,
    objects: Vec<(Written, Written)>,
    facts: Vec<WrittenFact>,
    goal: (u32, u32),
    whole: (u32, u32),
}

/// A name and where it stands in the text.
#[derive(Clone, Debug, Default, PartialEq)]
struct Written {
    name: SmolStr,
    start: u32,
    end: u32,
}

#[derive(Clone, Debug, PartialEq)]
struct WrittenFact {
    pred: Written,
    args: Vec<Written>,
    start: u32,
    end: u32,
}

/// Writes a problem: its objects, then its initial facts. The goal is
/// empty, `(and)`: a problem written this way is a world to plan from, and
/// each planning call states its own goal.
pub struct ProblemWriter {
    problem: WrittenProblem,
    in_init: bool,
}

impl ProblemWriter {
    /// Starts `(define (problem NAME) (:domain DOMAIN)`, after a `;` line
    /// that says who wrote it.
    pub fn new(comment: &str, name: &str, domain: &str) -> ProblemWriter {
        let mut p = WrittenProblem::default();
        for line in comment.lines() {
            let _ = writeln!(p.text, "; {line}");
        }
        let whole = p.text.len() as u32;
        p.text.push_str("(define (problem ");
        p.name = name_at(&mut p.text, name);
        p.text.push_str(")\n  (:domain ");
        p.domain = name_at(&mut p.text, domain);
        p.text.push_str(")\n  (:objects");
        p.whole.0 = whole;
        ProblemWriter {
            problem: p,
            in_init: false,
        }
    }

    /// Declares `names` as objects of type `ty` (one line of the list).
    ///
    /// # Panics
    /// When a fact was written before: objects come first.
    pub fn objects<S: AsRef<str>>(&mut self, ty: &str, names: &[S]) -> &mut Self {
        assert!(!self.in_init, "objects are written before the facts");
        if names.is_empty() {
            return self;
        }
        let text = &mut self.problem.text;
        text.push_str("\n   ");
        let mut written = Vec::with_capacity(names.len());
        for n in names {
            text.push(' ');
            written.push(name_at(text, n.as_ref()));
        }
        text.push_str(" - ");
        let ty = name_at(text, ty);
        self.problem
            .objects
            .extend(written.into_iter().map(|n| (n, ty.clone())));
        self
    }

    /// States the initial fact `(pred args...)`.
    pub fn fact<S: AsRef<str>>(&mut self, pred: &str, args: &[S]) -> &mut Self {
        let text = &mut self.problem.text;
        if !self.in_init {
            text.push_str(")\n  (:init");
            self.in_init = true;
        }
        text.push_str("\n    ");
        let start = text.len() as u32;
        text.push('(');
        let pred = name_at(text, pred);
        let args = args
            .iter()
            .map(|a| {
                text.push(' ');
                name_at(text, a.as_ref())
            })
            .collect();
        text.push(')');
        let end = text.len() as u32;
        self.problem.facts.push(WrittenFact {
            pred,
            args,
            start,
            end,
        });
        self
    }

    /// Ends the problem with the empty goal.
    pub fn finish(mut self) -> WrittenProblem {
        let text = &mut self.problem.text;
        if !self.in_init {
            text.push_str(")\n  (:init");
        }
        text.push_str(")\n  (:goal ");
        let goal = text.len() as u32;
        text.push_str("(and)");
        self.problem.goal = (goal, text.len() as u32);
        text.push_str("))");
        self.problem.whole.1 = text.len() as u32;
        text.push('\n');
        self.problem
    }
}

/// Writes a name (lower-cased, as PDDL is read) and returns it with its
/// place in the text.
fn name_at(text: &mut String, name: &str) -> Written {
    let start = text.len();
    text.extend(name.chars().flat_map(char::to_lowercase));
    Written {
        name: SmolStr::new(&text[start..]),
        start: start as u32,
        end: text.len() as u32,
    }
}

impl WrittenProblem {
    /// The problem file's text.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The problem, its spans in `file` (which holds
    /// [`WrittenProblem::text`]).
    pub fn problem(&self, file: FileId) -> Problem {
        let span = |start: u32, end: u32| Span::new(file, start as usize, end as usize);
        let name = |w: &Written| Name {
            name: w.name.clone(),
            span: span(w.start, w.end),
        };
        Problem {
            name: name(&self.name),
            domain: name(&self.domain),
            requirements: Vec::new(),
            objects: self
                .objects
                .iter()
                .map(|(n, ty)| Typed {
                    name: name(n),
                    ty: TypeSpec::Named { name: name(ty) },
                })
                .collect(),
            init: self
                .facts
                .iter()
                .map(|f| InitFact::Atom {
                    atom: Atom {
                        pred: name(&f.pred),
                        args: f
                            .args
                            .iter()
                            .map(|a| Term::Const { name: name(a) })
                            .collect(),
                        span: span(f.start, f.end),
                    },
                })
                .collect(),
            goal: Some(Formula::And {
                parts: Vec::new(),
                span: span(self.goal.0, self.goal.1),
            }),
            metric: None,
            span: span(self.whole.0, self.whole.1),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The value is what reading its text gives.
    fn reads_back(w: &WrittenProblem) {
        let (read, diags) = crate::parse_problem(w.text(), 3);
        assert!(diags.is_empty(), "{diags:?}\n{}", w.text());
        assert_eq!(read.as_ref(), Some(&w.problem(3)), "\n{}", w.text());
    }

    #[test]
    fn a_world_reads_back_as_written() {
        let mut w = ProblemWriter::new("written by a test", "cell", "Kitting");
        w.objects("robot", &["floor", "ceiling"])
            .objects("part", &["Red-Pump-1"])
            .fact("at", &["floor", "bin1"])
            .fact("handempty", &["ceiling"])
            .fact("ready", &[] as &[&str]);
        let w = w.finish();
        assert!(w
            .text()
            .starts_with("; written by a test\n(define (problem cell)"));
        assert!(w.text().contains("red-pump-1 - part"), "{}", w.text());
        reads_back(&w);
    }

    #[test]
    fn an_empty_world_reads_back() {
        reads_back(&ProblemWriter::new("", "p", "d").finish());
        let mut w = ProblemWriter::new("", "p", "d");
        w.objects("t", &["a"]).objects("t", &[] as &[&str]);
        reads_back(&w.finish());
    }
}

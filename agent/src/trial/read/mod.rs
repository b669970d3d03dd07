//! The trial reader: YAML text to a [`Trial`], with a diagnostic (and its
//! line and column) for everything that does not fit the ARIAC 2023 trial
//! configuration format. It never stops at the first problem: each part of
//! the file is read on its own, and a part that does not fit is left out.

mod cell;
mod challenges;
mod fields;
mod orders;
mod rules;

use super::model::*;
use super::yaml::{self, Node, Range, ScalarKind};
use btc_pddl::diagnostic::{codes, did_you_mean, Code, Diagnostic};
use btc_pddl::source::{FileId, Span};
use fields::{Fields, Reader};
use rules::{check_rules, check_supply};
use std::collections::BTreeMap;

/// The fields that say when an announcement or a challenge happens; one of
/// them is given.
const CONDITION_FIELDS: [&str; 3] = [
    "time_condition",
    "part_place_condition",
    "submission_condition",
];

/// Reads a trial file's text. `None` when it is not YAML or its top level
/// is not a mapping; otherwise the trial with whatever could be read, and
/// the diagnostics (errors mean the trial should not run).
pub fn read(text: &str, file: FileId) -> (Option<Trial>, Vec<Diagnostic>) {
    let mut r = Reader {
        file,
        diags: Vec::new(),
        unsimulated: BTreeMap::new(),
    };
    let root = match yaml::parse(text) {
        Ok(n) => n,
        Err(e) => {
            let end = text[e.at.min(text.len())..]
                .char_indices()
                .nth(1)
                .map_or(text.len(), |(k, _)| e.at + k);
            r.diags.push(
                Diagnostic::error(
                    codes::TRIAL_SYNTAX,
                    Span::new(file, e.at.min(text.len()), end.min(text.len())),
                    format!("this trial file is not YAML btc reads: {}", e.message),
                )
                .with_hint("trial files are YAML in the ARIAC 2023 format; see docs/trial.md"),
            );
            return (None, r.diags);
        }
    };
    let trial = r.trial(&root);
    r.report_unsimulated();
    if let Some(t) = &trial {
        check_rules(t, &mut r);
        check_supply(t, &mut r);
    }
    (trial, r.diags)
}

impl Reader {
    pub(super) fn trial(&mut self, root: &Node) -> Option<Trial> {
        if root.is_null() {
            self.error(
                codes::TRIAL_MISSING,
                root.range,
                "this trial file is empty: it needs at least `orders`",
            );
            return None;
        }
        let mut f = self.fields(root, "a trial file")?;
        let time_limit = match f.get("time_limit") {
            None => {
                let at = Range { start: 0, end: 0 };
                self.warn(
                    codes::TRIAL_MISSING,
                    at,
                    "this trial has no `time_limit`; as ARIAC does, btc runs it without one (-1)",
                );
                None
            }
            Some(n) => match self.number(n, "`time_limit`") {
                Some(-1.0) => None,
                Some(x) if x > 0.0 => Some(x),
                Some(_) => {
                    self.wrong(
                        n,
                        "`time_limit`",
                        "-1 (no limit) or a number of seconds above 0",
                    );
                    None
                }
                None => None,
            },
        };
        let trays = match self.need(&mut f, "kitting_trays") {
            Some(n) => self.trays(n),
            None => Vec::new(),
        };
        if let Some(n) = f.get("assembly_inserts") {
            self.inserts(n);
        }
        let (mut bins, mut agvs, mut conveyor) = (Vec::new(), Vec::new(), None);
        if let Some(n) = self.need(&mut f, "parts") {
            if let Some(mut p) = self.fields(n, "`parts`") {
                if let Some(b) = p.get("bins") {
                    bins = self.bins(b);
                }
                if let Some(a) = p.get("agvs") {
                    agvs = self.agvs(a);
                }
                if let Some(c) = p.get("conveyor_belt") {
                    conveyor = self.conveyor(c);
                }
                self.done(p, &["bins", "agvs", "conveyor_belt"]);
            }
        }
        let challenges = match f.get("challenges") {
            Some(n) if n.is_null() => Vec::new(),
            Some(n) => self.challenges(n),
            None => Vec::new(),
        };
        let orders = match self.need(&mut f, "orders") {
            Some(n) => self.orders(n),
            None => Vec::new(),
        };
        self.done(
            f,
            &[
                "time_limit",
                "kitting_trays",
                "assembly_inserts",
                "parts",
                "challenges",
                "orders",
            ],
        );
        Some(Trial {
            time_limit,
            trays,
            bins,
            agvs,
            conveyor,
            orders,
            challenges,
        })
    }
}

/// `prefixN` with N in range.
fn numbered(s: &str, prefix: &str, lo: u8, hi: u8) -> Option<u8> {
    let n: u8 = s.strip_prefix(prefix)?.parse().ok()?;
    (lo..=hi).contains(&n).then_some(n)
}

/// `pi`, `-pi/2`, `2*pi/3`, `0.5`, `'0.0'`.
fn is_angle(t: &str) -> bool {
    let t = t.trim();
    let t = t.strip_prefix('-').unwrap_or(t);
    if t.parse::<f64>().is_ok() {
        return true;
    }
    let (num, den) = match t.split_once('/') {
        Some((a, b)) => (a, Some(b)),
        None => (t, None),
    };
    let num_ok = num == "pi"
        || num
            .strip_suffix("*pi")
            .is_some_and(|k| k.parse::<f64>().is_ok());
    num_ok && den.is_none_or(|d| d.parse::<f64>().is_ok_and(|d| d != 0.0))
}

fn describe(n: &Node) -> String {
    match n.as_text() {
        Some(t) if !t.is_empty() => format!("`{t}`"),
        _ => n.kind().to_owned(),
    }
}

fn quote_all(v: &[&str]) -> String {
    v.iter()
        .map(|s| format!("`{s}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles() {
        for ok in ["pi", "-pi/2", "pi/6", "2*pi/3", "0", "0.0", "-1.5"] {
            assert!(is_angle(ok), "{ok}");
        }
        for bad in ["p1/2", "pi/0", "half", ""] {
            assert!(!is_angle(bad), "{bad}");
        }
    }
}

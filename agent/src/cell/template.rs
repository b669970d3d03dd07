//! PDDL atoms with holes: the cell's spelling of a fact (`(part_at {part}
//! {place})`) or an object name (`{color}_{type}_{k}`), parsed once and then
//! filled in (to write a fact) or matched (to read one back).

use btc_pddl::logic::{Atom, Formula};
use serde::Serialize;
use std::fmt;

/// What a hole stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Var {
    Robot,
    Place,
    Part,
    Agv,
    Quadrant,
    Station,
    Slot,
    Tray,
}

impl Var {
    pub const ALL: [Var; 8] = [
        Var::Robot,
        Var::Place,
        Var::Part,
        Var::Agv,
        Var::Quadrant,
        Var::Station,
        Var::Slot,
        Var::Tray,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Var::Robot => "robot",
            Var::Place => "place",
            Var::Part => "part",
            Var::Agv => "agv",
            Var::Quadrant => "quadrant",
            Var::Station => "station",
            Var::Slot => "slot",
            Var::Tray => "tray",
        }
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Arg {
    Const(String),
    Var(Var),
}

/// `(pred arg ...)` with holes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AtomTemplate {
    pub pred: String,
    pub args: Vec<Arg>,
}

/// A ground atom: the one structured form facts and goals take until they
/// are printed (once) into a problem file or a goal.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct GroundAtom {
    pub pred: String,
    pub args: Vec<String>,
}

impl fmt::Display for GroundAtom {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({}", self.pred)?;
        for a in &self.args {
            write!(f, " {a}")?;
        }
        f.write_str(")")
    }
}

/// A literal of a goal.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct Literal {
    pub positive: bool,
    pub atom: GroundAtom,
}

impl fmt::Display for Literal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.positive {
            write!(f, "{}", self.atom)
        } else {
            write!(f, "(not {})", self.atom)
        }
    }
}

impl Literal {
    /// The literal as a logic value, for the KB and the planner.
    pub fn formula(&self) -> Formula {
        let args: Vec<&str> = self.atom.args.iter().map(String::as_str).collect();
        let atom = Formula::Atom(Atom::ground(&self.atom.pred, &args));
        if self.positive {
            atom
        } else {
            Formula::Not(Box::new(atom))
        }
    }
}

/// A conjunction of literals as one formula (the literal itself for one).
pub fn conjunction(lits: &[Literal]) -> Formula {
    Formula::conjunction(lits.iter().map(Literal::formula).collect()).unwrap_or_else(Formula::truth)
}

impl AtomTemplate {
    /// Parses `(pred a {var} ...)`; names are lower-cased as PDDL's are.
    pub fn parse(text: &str) -> Result<AtomTemplate, String> {
        let t = text.trim();
        let inner = t
            .strip_prefix('(')
            .and_then(|s| s.strip_suffix(')'))
            .ok_or_else(|| format!("`{t}` is not one PDDL atom `(predicate arg ...)`"))?;
        if inner.contains(['(', ')']) {
            return Err(format!("`{t}` is not one PDDL atom `(predicate arg ...)`"));
        }
        let mut words = inner.split_whitespace();
        let pred = words
            .next()
            .ok_or_else(|| format!("`{t}` has no predicate"))?
            .to_lowercase();
        let mut args = Vec::new();
        for w in words {
            if let Some(v) = w.strip_prefix('{').and_then(|s| s.strip_suffix('}')) {
                let var = Var::ALL
                    .into_iter()
                    .find(|x| x.name() == v)
                    .ok_or_else(|| {
                        format!(
                            "`{{{v}}}` is not a hole btc fills; the holes are {}",
                            Var::ALL.map(|x| format!("`{{{}}}`", x.name())).join(", ")
                        )
                    })?;
                args.push(Arg::Var(var));
            } else if w.contains(['{', '}']) {
                return Err(format!("`{w}` in `{t}`: write a hole as `{{part}}`"));
            } else {
                args.push(Arg::Const(w.to_lowercase()));
            }
        }
        Ok(AtomTemplate { pred, args })
    }

    pub fn vars(&self) -> impl Iterator<Item = Var> + '_ {
        self.args.iter().filter_map(|a| match a {
            Arg::Var(v) => Some(*v),
            Arg::Const(_) => None,
        })
    }

    /// The atom with its holes filled from `vals`; a hole without a value
    /// is a bug in btc (the cell check makes sure every hole is known).
    pub fn ground(&self, vals: &[(Var, &str)]) -> GroundAtom {
        GroundAtom {
            pred: self.pred.clone(),
            args: self
                .args
                .iter()
                .map(|a| match a {
                    Arg::Const(c) => c.clone(),
                    Arg::Var(v) => vals
                        .iter()
                        .find(|(w, _)| w == v)
                        .map(|(_, s)| (*s).to_owned())
                        .unwrap_or_else(|| format!("?{}", v.name())),
                })
                .collect(),
        }
    }

    /// The values of the holes when `pred args` is an instance, in the
    /// order of the template's holes.
    pub fn matches<'a>(&self, pred: &str, args: &[&'a str]) -> Option<Vec<(Var, &'a str)>> {
        if pred != self.pred || args.len() != self.args.len() {
            return None;
        }
        let mut out = Vec::new();
        for (t, a) in self.args.iter().zip(args) {
            match t {
                Arg::Const(c) if c != a => return None,
                Arg::Const(_) => {}
                Arg::Var(v) => out.push((*v, *a)),
            }
        }
        Some(out)
    }
}

/// A name with `{n}`, `{type}`, `{color}`, `{k}` holes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NameTemplate(pub String);

impl NameTemplate {
    pub fn fill(
        &self,
        n: Option<u32>,
        ty: Option<&str>,
        color: Option<&str>,
        k: Option<u32>,
    ) -> String {
        let mut s = self.0.clone();
        if let Some(n) = n {
            s = s.replace("{n}", &n.to_string());
        }
        if let Some(t) = ty {
            s = s.replace("{type}", t);
        }
        if let Some(c) = color {
            s = s.replace("{color}", c);
        }
        if let Some(k) = k {
            s = s.replace("{k}", &k.to_string());
        }
        s.to_lowercase()
    }

    /// The holes it has, of those in `allowed`, and any other it has.
    pub fn holes(&self) -> Vec<String> {
        let mut out = Vec::new();
        let mut rest = self.0.as_str();
        while let Some(a) = rest.find('{') {
            let after = &rest[a + 1..];
            match after.find('}') {
                Some(b) => {
                    out.push(after[..b].to_owned());
                    rest = &after[b + 1..];
                }
                None => {
                    out.push(after.to_owned());
                    break;
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn templates_fill_and_match() {
        let t = AtomTemplate::parse("(In_Kit {part} {agv} {quadrant})").unwrap();
        assert_eq!(t.pred, "in_kit");
        let g = t.ground(&[
            (Var::Part, "red_pump_1"),
            (Var::Agv, "agv2"),
            (Var::Quadrant, "q3"),
        ]);
        assert_eq!(g.to_string(), "(in_kit red_pump_1 agv2 q3)");
        let m = t.matches("in_kit", &["red_pump_1", "agv2", "q3"]).unwrap();
        assert_eq!(m[1], (Var::Agv, "agv2"));
        let c = AtomTemplate::parse("(gripper_is {robot} parts_gripper)").unwrap();
        assert!(c.matches("gripper_is", &["r", "trays_gripper"]).is_none());
        assert!(AtomTemplate::parse("(at {thing})")
            .unwrap_err()
            .contains("not a hole"));
        assert!(AtomTemplate::parse("(and (a) (b))").is_err());
        let n = NameTemplate("{color}_{type}_{k}".into());
        assert_eq!(
            n.fill(None, Some("pump"), Some("red"), Some(2)),
            "red_pump_2"
        );
        assert_eq!(n.holes(), ["color", "type", "k"]);
    }
}

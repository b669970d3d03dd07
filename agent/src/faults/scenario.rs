//! A fault scenario: the faults of a run, each with its kind, its
//! trigger and what it changes, read from a TOML file (the format is in
//! `docs/runtime.md`). Its PDDL text is read here, once.

use super::FaultKind;
use btc_pddl::diagnostic::codes;
use btc_pddl::logic::{decode, Atom, Formula};
use btc_pddl::state::Key;
use btc_runtime::{Kb, LoadError};
use serde::Deserialize;

#[derive(Clone, Debug, PartialEq)]
pub enum Trigger {
    /// At the start of tick N (1-based).
    Tick(u64),
    /// When plan step N (0-based here) starts.
    Step(usize),
    /// When an action leaf with this ID starts for the `occurrence`-th time.
    /// `at`: where the ID is written in the scenario file (a byte offset).
    Action {
        id: String,
        occurrence: u32,
        at: Option<usize>,
    },
}

/// What a blackout makes conditions return.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blackout {
    Running,
    Failure,
}

#[derive(Clone, Debug, PartialEq)]
pub struct FaultSpec {
    pub kind: FaultKind,
    pub name: Option<String>,
    pub trigger: Trigger,
    pub robot: Option<String>,
    pub part: Option<String>,
    pub duration: Option<u64>,
    pub retract: Option<Vec<Atom>>,
    pub add: Vec<Atom>,
    pub goal: Option<Formula>,
    pub blackout: Blackout,
}

impl FaultSpec {
    pub fn label(&self) -> String {
        self.name
            .clone()
            .unwrap_or_else(|| self.kind.name().to_owned())
    }

    /// The facts the fault adds to and retracts from `kb`'s state when it
    /// happens: its `add` and `retract` facts, or for a faulty or missing
    /// part without a `retract`, every fact naming the part (it is gone).
    /// Only changes: facts already true are not added again, facts not
    /// true are not retracted.
    pub fn changes(&self, kb: &Kb<'_>) -> (Vec<Key>, Vec<Key>) {
        let mut retract: Vec<Key> = match &self.retract {
            Some(list) => list.iter().filter_map(|t| kb.atom_key(t).ok()).collect(),
            None if matches!(
                self.kind,
                FaultKind::FaultyPart | FaultKind::InsufficientParts
            ) =>
            {
                self.part
                    .as_deref()
                    .and_then(|p| kb.object(p))
                    .map(|o| kb.facts_mentioning(o))
                    .unwrap_or_default()
            }
            None => Vec::new(),
        };
        retract.retain(|k| kb.state.facts.contains(k));
        let mut add: Vec<Key> = self
            .add
            .iter()
            .filter_map(|t| kb.atom_key(t).ok())
            .collect();
        add.retain(|k| !kb.state.facts.contains(k));
        (add, retract)
    }

    /// What a fault of this kind must say and does not, in words (`None`:
    /// nothing is missing). A scenario file and a fault an embedder
    /// reports are held to the same needs.
    pub fn missing(&self) -> Option<&'static str> {
        match self.kind {
            FaultKind::RobotMalfunction | FaultKind::HumanTooClose if self.robot.is_none() => {
                Some("this kind needs `robot`")
            }
            FaultKind::RobotMalfunction | FaultKind::HumanTooClose if self.duration.is_none() => {
                Some("this kind needs `duration` (ticks)")
            }
            FaultKind::FaultyGripper if self.robot.is_none() => Some("this kind needs `robot`"),
            FaultKind::FaultyPart | FaultKind::InsufficientParts if self.part.is_none() => {
                Some("this kind needs `part`")
            }
            FaultKind::FlippedPart
                if self.retract.as_ref().is_none_or(Vec::is_empty) || self.add.is_empty() =>
            {
                Some("say how the part lies flipped: `retract` and `add` facts")
            }
            FaultKind::SensorBlackout if self.duration.is_none() => {
                Some("this kind needs `duration` (ticks)")
            }
            FaultKind::HighPriorityOrder if self.goal.is_none() => Some("this kind needs `goal`"),
            _ => None,
        }
    }
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scenario {
    pub description: Option<String>,
    pub faults: Vec<FaultSpec>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileScenario {
    description: Option<String>,
    #[serde(default)]
    fault: Vec<FileFault>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileFault {
    kind: toml::Spanned<String>,
    name: Option<String>,
    at_tick: Option<u64>,
    on_step: Option<usize>,
    on_action: Option<toml::Spanned<String>>,
    occurrence: Option<u32>,
    robot: Option<String>,
    part: Option<String>,
    duration: Option<u64>,
    retract: Option<Vec<String>>,
    #[serde(default)]
    add: Vec<String>,
    goal: Option<String>,
    conditions: Option<String>,
}

pub(super) fn bad(msg: impl Into<String>) -> LoadError {
    LoadError::new(codes::X_SCENARIO, msg)
}

impl Scenario {
    /// Reads a scenario file's text.
    pub fn parse(text: &str) -> Result<Scenario, LoadError> {
        let file: FileScenario = toml::from_str(text).map_err(|e| {
            let mut err = bad(format!(
                "this fault scenario is not valid: {}",
                e.message().trim()
            ))
            .hint("see the scenario format in docs/runtime.md");
            if let Some(sp) = e.span() {
                err = err.at(sp.start);
            }
            err
        })?;
        let mut faults = Vec::new();
        for (k, f) in file.fault.into_iter().enumerate() {
            let at = f.kind.span().start;
            Self::fault(k, f, &mut faults).map_err(|e| e.at_opt(Some(at)))?;
        }
        Ok(Scenario {
            description: file.description,
            faults,
        })
    }

    /// A warning (X011) for each `on_action` that names none of `actions`
    /// (the action IDs of the tree the scenario runs on): such a fault can
    /// never happen.
    pub fn triggers_naming_nothing(&self, actions: &[&str]) -> Vec<LoadError> {
        let mut out = Vec::new();
        for f in &self.faults {
            let Trigger::Action { id, at, .. } = &f.trigger else {
                continue;
            };
            if actions.contains(&id.as_str()) {
                continue;
            }
            let hint = btc_pddl::diagnostic::did_you_mean(id, actions.iter().copied())
                .unwrap_or_else(|| {
                    let mut names = actions.to_vec();
                    names.sort_unstable();
                    names.dedup();
                    format!("the tree's actions are {}", names.join(", "))
                });
            out.push(
                LoadError::new(
                    codes::X_TRIGGER,
                    format!(
                        "fault `{}`: `on_action = \"{id}\"` names no action of the tree, so it never happens",
                        f.label()
                    ),
                )
                .hint(hint)
                .at_opt(*at),
            );
        }
        out
    }

    fn fault(k: usize, f: FileFault, faults: &mut Vec<FaultSpec>) -> Result<(), LoadError> {
        {
            let kind_name = f.kind.get_ref().clone();
            let which = format!("fault {} ({})", k + 1, kind_name);
            let kind = FaultKind::from_name(&kind_name).ok_or_else(|| {
                let names: Vec<&str> = FaultKind::ALL.iter().map(|k| k.name()).collect();
                let mut e = bad(format!(
                    "fault {}: `{}` is not a fault kind",
                    k + 1,
                    kind_name
                ));
                e = e.hint(
                    btc_pddl::diagnostic::did_you_mean(&kind_name, names.iter().copied())
                        .unwrap_or_else(|| format!("the kinds are {}", names.join(", "))),
                );
                e
            })?;
            let trigger = match (f.at_tick, f.on_step, f.on_action) {
                (Some(t), None, None) if t >= 1 => Trigger::Tick(t),
                (None, Some(s), None) if s >= 1 => Trigger::Step(s - 1),
                (None, None, Some(a)) => Trigger::Action {
                    at: Some(a.span().start),
                    id: a.into_inner(),
                    occurrence: f.occurrence.unwrap_or(1).max(1),
                },
                (Some(0), None, None) | (None, Some(0), None) => {
                    return Err(bad(format!("{which}: ticks and steps count from 1")))
                }
                _ => {
                    return Err(bad(format!(
                        "{which}: give exactly one trigger: `at_tick`, `on_step` or `on_action`"
                    )))
                }
            };
            let blackout = match f.conditions.as_deref() {
                None | Some("running") => Blackout::Running,
                Some("failure") => Blackout::Failure,
                Some(o) => {
                    return Err(bad(format!(
                        "{which}: `conditions = \"{o}\"`: say \"running\" or \"failure\""
                    )))
                }
            };
            // The scenario's PDDL text is read here, once.
            let atoms = |list: &[String]| -> Result<Vec<Atom>, LoadError> {
                list.iter()
                    .map(|t| {
                        decode::atom(t)
                            .map_err(|m| bad(format!("{which}: `{t}` is not a PDDL fact: {m}")))
                    })
                    .collect()
            };
            let goal = match &f.goal {
                Some(g) => Some(decode::formula(g).map_err(|m| {
                    bad(format!("{which}: goal `{g}` is not a PDDL condition: {m}"))
                })?),
                None => None,
            };
            let spec = FaultSpec {
                kind,
                name: f.name,
                trigger,
                robot: f.robot,
                part: f.part,
                duration: f.duration,
                retract: f.retract.as_deref().map(atoms).transpose()?,
                add: atoms(&f.add)?,
                goal,
                blackout,
            };
            if let Some(m) = spec.missing() {
                return Err(bad(format!("{which}: {m}")));
            }
            faults.push(spec);
        }
        Ok(())
    }
}

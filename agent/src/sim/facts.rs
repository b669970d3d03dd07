//! The cell's facts as atom keys of the shared world's state: each fact
//! template resolved once to its predicate index and argument positions,
//! so the simulation reads and writes the state without text.

use crate::cell::template::Arg;
use crate::cell::{AtomTemplate, Cell, Var};
use btc_pddl::state::{Key, State};
use btc_pddl::{DomainIndex, ProblemIndex};

/// A fact template over object ids.
#[derive(Clone, Debug)]
pub struct KeyTemplate {
    pub pred: u32,
    /// Per argument: a constant's id or a hole.
    pub args: Vec<KArg>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum KArg {
    Const(u32),
    Var(Var),
}

impl KeyTemplate {
    fn new(t: &AtomTemplate, dix: &DomainIndex, pix: &ProblemIndex) -> Option<KeyTemplate> {
        let pred = dix.predicates.get(&t.pred)?.index as u32;
        let mut args = Vec::new();
        for a in &t.args {
            args.push(match a {
                Arg::Const(c) => KArg::Const(pix.objects.get(c)?.id),
                Arg::Var(v) => KArg::Var(*v),
            });
        }
        Some(KeyTemplate { pred, args })
    }

    pub fn key(&self, vals: &[(Var, u32)]) -> Key {
        let mut k = Vec::with_capacity(self.args.len() + 1);
        k.push(self.pred);
        for a in &self.args {
            k.push(match a {
                KArg::Const(c) => *c,
                KArg::Var(v) => vals
                    .iter()
                    .find(|(w, _)| w == v)
                    .map_or(u32::MAX, |(_, o)| *o),
            });
        }
        k.into_boxed_slice()
    }

    /// The value of hole `v` in `k`, when `k` is an instance.
    pub fn get(&self, k: &[u32], v: Var) -> Option<u32> {
        if k.first() != Some(&self.pred) || k.len() != self.args.len() + 1 {
            return None;
        }
        let mut out = None;
        for (a, &o) in self.args.iter().zip(&k[1..]) {
            match a {
                KArg::Const(c) if *c != o => return None,
                KArg::Var(w) if *w == v => out = Some(o),
                _ => {}
            }
        }
        out
    }

    pub fn is(&self, k: &[u32]) -> bool {
        k.first() == Some(&self.pred)
            && k.len() == self.args.len() + 1
            && self
                .args
                .iter()
                .zip(&k[1..])
                .all(|(a, o)| !matches!(a, KArg::Const(c) if c != o))
    }
}

/// Where a part is, read from the state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Place {
    At(u32),
    InKit { agv: u32, quadrant: u32 },
    Held(u32),
    Installed(u32),
    Discarded,
    Nowhere,
}

pub struct Facts {
    pub enabled: KeyTemplate,
    pub robot_at: KeyTemplate,
    pub hand_empty: KeyTemplate,
    pub holding: KeyTemplate,
    pub part_at: KeyTemplate,
    pub flipped: KeyTemplate,
    pub in_kit: KeyTemplate,
    pub kit_free: KeyTemplate,
    pub installed: KeyTemplate,
    pub insert_free: KeyTemplate,
    pub discarded: KeyTemplate,
    pub tray_at: KeyTemplate,
    pub holding_tray: KeyTemplate,
    pub tray_on: KeyTemplate,
    pub agv_at: KeyTemplate,
    pub agv_goes: KeyTemplate,
}

impl Facts {
    /// `None` when a template names a constant the problem lacks (the cell
    /// check reports the rest).
    pub fn new(cell: &Cell, pix: &ProblemIndex) -> Result<Facts, String> {
        let dix = &cell.domain.index;
        let f = &cell.spec.facts;
        let k = |name: &str, t: &AtomTemplate| {
            KeyTemplate::new(t, dix, pix).ok_or_else(|| {
                format!(
                    "the `{name}` fact `{}` names an object the trial's problem does not have",
                    show(t)
                )
            })
        };
        Ok(Facts {
            enabled: k("enabled", &f.enabled)?,
            robot_at: k("robot_at", &f.robot_at)?,
            hand_empty: k("hand_empty", &f.hand_empty)?,
            holding: k("holding", &f.holding)?,
            part_at: k("part_at", &f.part_at)?,
            flipped: k("flipped", &f.flipped)?,
            in_kit: k("in_kit", &f.in_kit)?,
            kit_free: k("kit_free", &f.kit_free)?,
            installed: k("installed", &f.installed)?,
            insert_free: k("insert_free", &f.insert_free)?,
            discarded: k("discarded", &f.discarded)?,
            tray_at: k("tray_at", &f.tray_at)?,
            holding_tray: k("holding_tray", &f.holding_tray)?,
            tray_on: k("tray_on", &f.tray_on)?,
            agv_at: k("agv_at", &f.agv_at)?,
            agv_goes: k("agv_goes", &f.agv_goes)?,
        })
    }

    /// Every place the state has for `part` (exactly one when the world is
    /// consistent, none for a part not in the cell).
    pub fn places(&self, s: &State, part: u32) -> Vec<Place> {
        let mut out = Vec::new();
        for k in &s.facts {
            if self.part_at.get(k, Var::Part) == Some(part) {
                out.push(Place::At(self.part_at.get(k, Var::Place).unwrap_or(0)));
            } else if self.in_kit.get(k, Var::Part) == Some(part) {
                out.push(Place::InKit {
                    agv: self.in_kit.get(k, Var::Agv).unwrap_or(0),
                    quadrant: self.in_kit.get(k, Var::Quadrant).unwrap_or(0),
                });
            } else if self.holding.get(k, Var::Part) == Some(part) {
                out.push(Place::Held(self.holding.get(k, Var::Robot).unwrap_or(0)));
            } else if self.installed.get(k, Var::Part) == Some(part) {
                out.push(Place::Installed(
                    self.installed.get(k, Var::Station).unwrap_or(0),
                ));
            } else if self.discarded.get(k, Var::Part) == Some(part) {
                out.push(Place::Discarded);
            }
        }
        out
    }

    pub fn place(&self, s: &State, part: u32) -> Place {
        self.places(s, part)
            .first()
            .copied()
            .unwrap_or(Place::Nowhere)
    }

    /// The facts about `part` that say where it is (to remove it).
    pub fn location_facts(&self, s: &State, part: u32) -> Vec<Key> {
        s.facts
            .iter()
            .filter(|k| {
                [&self.part_at, &self.in_kit, &self.holding, &self.installed]
                    .iter()
                    .any(|t| t.get(k, Var::Part) == Some(part))
            })
            .cloned()
            .collect()
    }

    /// What a robot holds.
    pub fn held_by(&self, s: &State, robot: u32) -> Option<u32> {
        s.facts
            .iter()
            .find(|k| self.holding.get(k, Var::Robot) == Some(robot))
            .and_then(|k| self.holding.get(k, Var::Part))
    }

    pub fn robot_place(&self, s: &State, robot: u32) -> Option<u32> {
        s.facts
            .iter()
            .find(|k| self.robot_at.get(k, Var::Robot) == Some(robot))
            .and_then(|k| self.robot_at.get(k, Var::Place))
    }

    pub fn agv_place(&self, s: &State, agv: u32) -> Option<u32> {
        s.facts
            .iter()
            .find(|k| self.agv_at.get(k, Var::Agv) == Some(agv))
            .and_then(|k| self.agv_at.get(k, Var::Place))
    }

    pub fn tray_of(&self, s: &State, agv: u32) -> Option<u32> {
        s.facts
            .iter()
            .find(|k| self.tray_on.get(k, Var::Agv) == Some(agv))
            .and_then(|k| self.tray_on.get(k, Var::Tray))
    }

    /// Parts in the AGV's quadrants: (quadrant, part).
    pub fn kit(&self, s: &State, agv: u32) -> Vec<(u32, u32)> {
        let mut v: Vec<(u32, u32)> = s
            .facts
            .iter()
            .filter(|k| self.in_kit.get(k, Var::Agv) == Some(agv))
            .filter_map(|k| {
                Some((
                    self.in_kit.get(k, Var::Quadrant)?,
                    self.in_kit.get(k, Var::Part)?,
                ))
            })
            .collect();
        v.sort_unstable();
        v
    }

    /// Parts installed at a station.
    pub fn insert(&self, s: &State, station: u32) -> Vec<u32> {
        let mut v: Vec<u32> = s
            .facts
            .iter()
            .filter(|k| self.installed.get(k, Var::Station) == Some(station))
            .filter_map(|k| self.installed.get(k, Var::Part))
            .collect();
        v.sort_unstable();
        v
    }
}

fn show(t: &AtomTemplate) -> String {
    let args: Vec<String> = t
        .args
        .iter()
        .map(|a| match a {
            Arg::Const(c) => c.clone(),
            Arg::Var(v) => format!("{{{}}}", v.name()),
        })
        .collect();
    format!("({} {})", t.pred, args.join(" "))
}

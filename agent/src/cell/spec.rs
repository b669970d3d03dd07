//! The cell file (`cell.toml`): what a workcell is for `btc trial`. Read
//! from text (the CLI reads the files); every problem is a T010 diagnostic
//! at its place in the file.

use super::template::{AtomTemplate, GroundAtom, NameTemplate, Var};
use crate::trial::{OrderType, Robot};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::source::{FileId, Span};
use serde::Deserialize;
use std::collections::BTreeMap;

/// Simulated time.
#[derive(Clone, Debug, PartialEq)]
pub struct Time {
    pub seconds_per_tick: f64,
    pub ticks_per_action: u32,
    pub conveyor_seconds: f64,
}

impl Time {
    /// Trial seconds to ticks (rounded up: a challenge at 10.5 s happens in
    /// the tick that contains it).
    pub fn ticks(&self, seconds: f64) -> u64 {
        (seconds / self.seconds_per_tick).ceil().max(0.0) as u64
    }

    pub fn seconds(&self, ticks: u64) -> f64 {
        ticks as f64 * self.seconds_per_tick
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct RobotSpec {
    pub robot: Robot,
    /// The PDDL object (the ARIAC name).
    pub object: String,
    pub rules: String,
    pub start: String,
    pub queues: Vec<OrderType>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Names {
    pub bin: NameTemplate,
    pub conveyor: NameTemplate,
    pub tray_table: NameTemplate,
    pub kitting_station: NameTemplate,
    pub assembly_station: NameTemplate,
    pub warehouse: NameTemplate,
    pub disposal: NameTemplate,
    pub agv: NameTemplate,
    pub tray: NameTemplate,
    pub quadrant: NameTemplate,
    pub insert_slot: NameTemplate,
    pub part: NameTemplate,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Types {
    pub robot: String,
    pub place: String,
    pub agv: String,
    pub tray: String,
    pub quadrant: String,
    pub insert_slot: String,
    /// By part type: battery, pump, regulator, sensor.
    pub parts: [String; 4],
}

/// The facts btc reads and writes.
#[derive(Clone, Debug, PartialEq)]
pub struct Facts {
    pub enabled: AtomTemplate,
    pub robot_at: AtomTemplate,
    pub hand_empty: AtomTemplate,
    pub parts_gripper: AtomTemplate,
    pub holding: AtomTemplate,
    pub part_at: AtomTemplate,
    pub flipped: AtomTemplate,
    pub in_kit: AtomTemplate,
    pub kit_free: AtomTemplate,
    pub installed: AtomTemplate,
    pub insert_free: AtomTemplate,
    pub fits: AtomTemplate,
    pub discarded: AtomTemplate,
    pub tray_at: AtomTemplate,
    pub holding_tray: AtomTemplate,
    pub tray_on: AtomTemplate,
    pub no_tray: AtomTemplate,
    pub agv_at: AtomTemplate,
    pub agv_goes: AtomTemplate,
}

impl Facts {
    /// Each fact with its name and the holes it must have.
    pub fn each(&self) -> [(&'static str, &AtomTemplate, &'static [Var]); 19] {
        use Var::*;
        [
            ("enabled", &self.enabled, &[Robot]),
            ("robot_at", &self.robot_at, &[Robot, Place]),
            ("hand_empty", &self.hand_empty, &[Robot]),
            ("parts_gripper", &self.parts_gripper, &[Robot]),
            ("holding", &self.holding, &[Robot, Part]),
            ("part_at", &self.part_at, &[Part, Place]),
            ("flipped", &self.flipped, &[Part]),
            ("in_kit", &self.in_kit, &[Part, Agv, Quadrant]),
            ("kit_free", &self.kit_free, &[Agv, Quadrant]),
            ("installed", &self.installed, &[Part, Station]),
            ("insert_free", &self.insert_free, &[Station, Slot]),
            ("fits", &self.fits, &[Part, Slot]),
            ("discarded", &self.discarded, &[Part]),
            ("tray_at", &self.tray_at, &[Tray, Place]),
            ("holding_tray", &self.holding_tray, &[Robot, Tray]),
            ("tray_on", &self.tray_on, &[Tray, Agv]),
            ("no_tray", &self.no_tray, &[Agv]),
            ("agv_at", &self.agv_at, &[Agv, Place]),
            ("agv_goes", &self.agv_goes, &[Agv, Place]),
        ]
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct CellSpec {
    pub domain: String,
    pub time: Time,
    pub robots: Vec<RobotSpec>,
    pub names: Names,
    pub types: Types,
    pub facts: Facts,
    pub always: Vec<GroundAtom>,
    /// Where each fact (by name) and each `[always]` fact (by its text) is
    /// written in the cell file, for diagnostics.
    pub spans: BTreeMap<String, std::ops::Range<usize>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileCell {
    domain: String,
    time: FileTime,
    robots: BTreeMap<toml::Spanned<String>, FileRobot>,
    names: BTreeMap<toml::Spanned<String>, toml::Spanned<String>>,
    types: BTreeMap<toml::Spanned<String>, toml::Spanned<String>>,
    facts: BTreeMap<toml::Spanned<String>, toml::Spanned<String>>,
    always: FileAlways,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileTime {
    seconds_per_tick: toml::Spanned<f64>,
    ticks_per_action: toml::Spanned<i64>,
    conveyor_seconds: toml::Spanned<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileRobot {
    rules: String,
    start: String,
    queues: Vec<toml::Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileAlways {
    facts: Vec<toml::Spanned<String>>,
}

struct Errors {
    file: FileId,
    diags: Vec<Diagnostic>,
}

impl Errors {
    fn at(&mut self, span: std::ops::Range<usize>, msg: impl Into<String>) {
        self.diags.push(Diagnostic::error(
            codes::CELL_INVALID,
            Span::new(self.file, span.start, span.end),
            msg.into(),
        ));
    }
}

const NAME_KEYS: [(&str, &[&str]); 12] = [
    ("bin", &["n"]),
    ("conveyor", &[]),
    ("tray_table", &["n"]),
    ("kitting_station", &["n"]),
    ("assembly_station", &["n"]),
    ("warehouse", &[]),
    ("disposal", &[]),
    ("agv", &["n"]),
    ("tray", &["n"]),
    ("quadrant", &["n"]),
    ("insert_slot", &["type"]),
    ("part", &["color", "type", "k"]),
];

const FACT_KEYS: [&str; 19] = [
    "enabled",
    "robot_at",
    "hand_empty",
    "parts_gripper",
    "holding",
    "part_at",
    "flipped",
    "in_kit",
    "kit_free",
    "installed",
    "insert_free",
    "fits",
    "discarded",
    "tray_at",
    "holding_tray",
    "tray_on",
    "no_tray",
    "agv_at",
    "agv_goes",
];

const TYPE_KEYS: [&str; 10] = [
    "robot",
    "place",
    "agv",
    "tray",
    "quadrant",
    "insert_slot",
    "battery",
    "pump",
    "regulator",
    "sensor",
];

impl CellSpec {
    pub fn parse(text: &str, file: FileId) -> Result<CellSpec, Vec<Diagnostic>> {
        let mut e = Errors {
            file,
            diags: Vec::new(),
        };
        let f: FileCell = match toml::from_str(text) {
            Ok(f) => f,
            Err(err) => {
                let sp = err.span().unwrap_or(0..0);
                e.at(
                    sp,
                    format!("this cell file is not valid: {}", err.message().trim()),
                );
                if let Some(d) = e.diags.last_mut() {
                    d.hint = Some("see the cell format in docs/trial.md".into());
                }
                return Err(e.diags);
            }
        };
        let time = Time {
            seconds_per_tick: *f.time.seconds_per_tick.get_ref(),
            ticks_per_action: (*f.time.ticks_per_action.get_ref()).clamp(0, 1000) as u32,
            conveyor_seconds: *f.time.conveyor_seconds.get_ref(),
        };
        if !(time.seconds_per_tick > 0.0 && time.seconds_per_tick.is_finite()) {
            e.at(
                f.time.seconds_per_tick.span(),
                "`seconds_per_tick` must be a number above 0",
            );
        }
        if !(1..=1000).contains(f.time.ticks_per_action.get_ref()) {
            e.at(
                f.time.ticks_per_action.span(),
                "`ticks_per_action` must be a whole number from 1 to 1000",
            );
        }
        if !(time.conveyor_seconds > 0.0 && time.conveyor_seconds.is_finite()) {
            e.at(
                f.time.conveyor_seconds.span(),
                "`conveyor_seconds` must be a number above 0",
            );
        }
        let mut robots = Vec::new();
        for (k, r) in &f.robots {
            let Some(robot) = Robot::ALL.into_iter().find(|x| x.name() == k.get_ref()) else {
                e.at(
                    k.span(),
                    format!(
                        "`{}` is not an ARIAC robot: the robots are `floor_robot` and `ceiling_robot`",
                        k.get_ref()
                    ),
                );
                continue;
            };
            let mut queues = Vec::new();
            for q in &r.queues {
                match ["kitting", "assembly", "combined"]
                    .iter()
                    .position(|n| n == q.get_ref())
                {
                    Some(i) => queues.push(
                        [OrderType::Kitting, OrderType::Assembly, OrderType::Combined][i],
                    ),
                    None => e.at(
                        q.span(),
                        format!(
                            "`{}` is not a task queue: the queues are `kitting`, `assembly` and `combined`",
                            q.get_ref()
                        ),
                    ),
                }
            }
            robots.push(RobotSpec {
                robot,
                object: robot.name().to_owned(),
                rules: r.rules.clone(),
                start: r.start.to_lowercase(),
                queues,
            });
        }
        for r in Robot::ALL {
            if !robots.iter().any(|x| x.robot == r) {
                e.at(0..0, format!("the cell has no `[robots.{}]`", r.name()));
            }
        }
        let names = Self::names(&f, &mut e);
        let types = Self::types(&f, &mut e);
        let facts = Self::facts(&f, &mut e);
        let mut spans: BTreeMap<String, std::ops::Range<usize>> = f
            .facts
            .iter()
            .map(|(k, v)| (k.get_ref().clone(), v.span()))
            .collect();
        let mut always = Vec::new();
        for a in &f.always.facts {
            match AtomTemplate::parse(a.get_ref()) {
                Ok(t) if t.vars().next().is_none() => {
                    let g = t.ground(&[]);
                    spans.insert(g.to_string(), a.span());
                    always.push(g)
                }
                Ok(_) => e.at(
                    a.span(),
                    "facts in `[always]` are ground: they have no holes",
                ),
                Err(m) => e.at(a.span(), m),
            }
        }
        if !e.diags.is_empty() {
            return Err(e.diags);
        }
        let (Some(names), Some(types), Some(facts)) = (names, types, facts) else {
            return Err(e.diags);
        };
        Ok(CellSpec {
            domain: f.domain,
            time,
            robots,
            names,
            types,
            facts,
            always,
            spans,
        })
    }

    fn names(f: &FileCell, e: &mut Errors) -> Option<Names> {
        let mut got: BTreeMap<&str, NameTemplate> = BTreeMap::new();
        for (k, v) in &f.names {
            let Some((key, allowed)) = NAME_KEYS.iter().find(|(n, _)| n == k.get_ref()) else {
                e.at(
                    k.span(),
                    format!("`{}` is not a name btc needs", k.get_ref()),
                );
                continue;
            };
            let t = NameTemplate(v.get_ref().clone());
            let holes = t.holes();
            for h in &holes {
                if !allowed.contains(&h.as_str()) {
                    e.at(
                        v.span(),
                        format!("`{{{h}}}` is not a hole of the `{key}` name"),
                    );
                }
            }
            for a in *allowed {
                if !holes.iter().any(|h| h == a) {
                    e.at(
                        v.span(),
                        format!("the `{key}` name needs `{{{a}}}` to tell its objects apart"),
                    );
                }
            }
            got.insert(key, t);
        }
        for (k, _) in NAME_KEYS {
            if !got.contains_key(k) {
                e.at(0..0, format!("`[names]` has no `{k}`"));
            }
        }
        let mut take = |k: &str| got.remove(k);
        Some(Names {
            bin: take("bin")?,
            conveyor: take("conveyor")?,
            tray_table: take("tray_table")?,
            kitting_station: take("kitting_station")?,
            assembly_station: take("assembly_station")?,
            warehouse: take("warehouse")?,
            disposal: take("disposal")?,
            agv: take("agv")?,
            tray: take("tray")?,
            quadrant: take("quadrant")?,
            insert_slot: take("insert_slot")?,
            part: take("part")?,
        })
    }

    fn types(f: &FileCell, e: &mut Errors) -> Option<Types> {
        let mut got: BTreeMap<&str, String> = BTreeMap::new();
        for (k, v) in &f.types {
            match TYPE_KEYS.iter().find(|n| **n == k.get_ref()) {
                Some(key) => {
                    got.insert(key, v.get_ref().to_lowercase());
                }
                None => e.at(
                    k.span(),
                    format!("`{}` is not a type btc needs", k.get_ref()),
                ),
            }
        }
        for k in TYPE_KEYS {
            if !got.contains_key(k) {
                e.at(0..0, format!("`[types]` has no `{k}`"));
            }
        }
        let mut take = |k: &str| got.remove(k);
        Some(Types {
            robot: take("robot")?,
            place: take("place")?,
            agv: take("agv")?,
            tray: take("tray")?,
            quadrant: take("quadrant")?,
            insert_slot: take("insert_slot")?,
            parts: [
                take("battery")?,
                take("pump")?,
                take("regulator")?,
                take("sensor")?,
            ],
        })
    }

    fn facts(f: &FileCell, e: &mut Errors) -> Option<Facts> {
        let mut got: BTreeMap<String, AtomTemplate> = BTreeMap::new();
        let mut spans: BTreeMap<String, std::ops::Range<usize>> = BTreeMap::new();
        for (k, v) in &f.facts {
            match AtomTemplate::parse(v.get_ref()) {
                Ok(t) => {
                    got.insert(k.get_ref().clone(), t);
                    spans.insert(k.get_ref().clone(), v.span());
                }
                Err(m) => e.at(v.span(), m),
            }
        }
        for k in FACT_KEYS {
            if !got.contains_key(k) {
                e.at(0..0, format!("`[facts]` has no `{k}`"));
            }
        }
        let mut take = |k: &str| got.remove(k);
        let facts = Facts {
            enabled: take("enabled")?,
            robot_at: take("robot_at")?,
            hand_empty: take("hand_empty")?,
            parts_gripper: take("parts_gripper")?,
            holding: take("holding")?,
            part_at: take("part_at")?,
            flipped: take("flipped")?,
            in_kit: take("in_kit")?,
            kit_free: take("kit_free")?,
            installed: take("installed")?,
            insert_free: take("insert_free")?,
            fits: take("fits")?,
            discarded: take("discarded")?,
            tray_at: take("tray_at")?,
            holding_tray: take("holding_tray")?,
            tray_on: take("tray_on")?,
            no_tray: take("no_tray")?,
            agv_at: take("agv_at")?,
            agv_goes: take("agv_goes")?,
        };
        for k in got.keys() {
            e.at(
                spans.get(k).cloned().unwrap_or(0..0),
                format!("`{k}` is not a fact btc reads or writes"),
            );
        }
        for (name, t, need) in facts.each() {
            let have: Vec<Var> = t.vars().collect();
            let sp = spans.get(name).cloned().unwrap_or(0..0);
            for v in need {
                if have.iter().filter(|h| *h == v).count() != 1 {
                    e.at(
                        sp.clone(),
                        format!("the `{name}` fact needs `{{{}}}` once", v.name()),
                    );
                }
            }
            for h in &have {
                if !need.contains(h) {
                    e.at(
                        sp.clone(),
                        format!("`{{{}}}` is not a hole of the `{name}` fact", h.name()),
                    );
                }
            }
        }
        Some(facts)
    }
}

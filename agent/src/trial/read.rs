//! The trial reader: YAML text to a [`Trial`], with a diagnostic (and its
//! line and column) for everything that does not fit the ARIAC 2023 trial
//! configuration format. It never stops at the first problem: each part of
//! the file is read on its own, and a part that does not fit is left out.

use super::model::*;
use super::yaml::{self, Node, Range, ScalarKind};
use btc_pddl::diagnostic::{codes, did_you_mean, Code, Diagnostic};
use btc_pddl::source::{FileId, Span};
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

struct Reader {
    file: FileId,
    diags: Vec<Diagnostic>,
    /// Fields read but not simulated: name -> (first place, count, why).
    unsimulated: BTreeMap<&'static str, (Range, usize, &'static str)>,
}

/// A mapping being read: which keys were asked for.
struct Fields<'a> {
    node: &'a Node,
    items: &'a [(Node, Node)],
    used: Vec<bool>,
    what: String,
}

impl<'a> Fields<'a> {
    fn get(&mut self, key: &str) -> Option<&'a Node> {
        let k = self
            .items
            .iter()
            .position(|(k, _)| k.as_text() == Some(key))?;
        self.used[k] = true;
        Some(&self.items[k].1)
    }

    fn has(&self, key: &str) -> bool {
        self.items.iter().any(|(k, _)| k.as_text() == Some(key))
    }
}

impl Reader {
    fn span(&self, r: Range) -> Span {
        Span::new(self.file, r.start, r.end)
    }

    fn error(&mut self, code: Code, r: Range, msg: impl Into<String>) -> &mut Diagnostic {
        self.diags
            .push(Diagnostic::error(code, self.span(r), msg.into()));
        self.diags.last_mut().expect("just pushed")
    }

    fn warn(&mut self, code: Code, r: Range, msg: impl Into<String>) -> &mut Diagnostic {
        self.diags
            .push(Diagnostic::warning(code, self.span(r), msg.into()));
        self.diags.last_mut().expect("just pushed")
    }

    /// `node` as a mapping, or a T003 error.
    fn fields<'a>(&mut self, node: &'a Node, what: &str) -> Option<Fields<'a>> {
        match node.as_map() {
            Some(items) => Some(Fields {
                node,
                items,
                used: vec![false; items.len()],
                what: what.to_owned(),
            }),
            None => {
                self.error(
                    codes::TRIAL_VALUE,
                    node.range,
                    format!(
                        "{what} must be a mapping (`key: value` lines), not {}",
                        node.kind()
                    ),
                );
                None
            }
        }
    }

    /// A field that must be there (T002 on the mapping otherwise).
    fn need<'a>(&mut self, f: &mut Fields<'a>, key: &str) -> Option<&'a Node> {
        let v = f.get(key);
        if v.is_none() {
            let at = Range {
                start: f.node.range.start,
                end: f.node.range.start,
            };
            let what = f.what.clone();
            self.error(
                codes::TRIAL_MISSING,
                at,
                format!("{what} has no `{key}`, which the ARIAC 2023 trial format requires"),
            );
        }
        v
    }

    /// Keys nobody asked for: not in the format (T004, a warning).
    fn done(&mut self, f: Fields<'_>, known: &[&str]) {
        for ((k, _), used) in f.items.iter().zip(&f.used) {
            if *used {
                continue;
            }
            let name = k.as_text().unwrap_or("?").to_owned();
            let hint = did_you_mean(&name, known.iter().copied())
                .unwrap_or_else(|| format!("{} has {}", f.what, quote_all(known)));
            self.warn(
                codes::TRIAL_UNKNOWN_FIELD,
                k.range,
                format!(
                    "`{name}` is not a field of {} in the ARIAC 2023 trial format; btc ignores it",
                    f.what
                ),
            )
            .hint = Some(hint);
        }
    }

    fn unsimulated(&mut self, name: &'static str, node: &Node, why: &'static str) {
        let e = self.unsimulated.entry(name).or_insert((node.range, 0, why));
        e.1 += 1;
    }

    fn report_unsimulated(&mut self) {
        let all = std::mem::take(&mut self.unsimulated);
        for (name, (r, n, why)) in all {
            let times = if n == 1 {
                "once".to_owned()
            } else {
                format!("{n} times")
            };
            self.warn(
                codes::TRIAL_NOT_SIMULATED,
                r,
                format!("`{name}` (given {times}) is read but not simulated: {why}"),
            );
        }
    }

    fn wrong(&mut self, node: &Node, what: &str, expected: &str) {
        self.error(
            codes::TRIAL_VALUE,
            node.range,
            format!("{what} must be {expected}, not {}", describe(node)),
        );
    }

    fn int(&mut self, node: &Node, what: &str, lo: i64, hi: i64) -> Option<i64> {
        match node.scalar() {
            Some(ScalarKind::Int(n)) if (lo..=hi).contains(&n) => Some(n),
            Some(ScalarKind::Float(x))
                if x.fract() == 0.0 && (lo as f64..=hi as f64).contains(&x) =>
            {
                Some(x as i64)
            }
            _ => {
                self.wrong(node, what, &format!("a whole number from {lo} to {hi}"));
                None
            }
        }
    }

    fn number(&mut self, node: &Node, what: &str) -> Option<f64> {
        match node.scalar() {
            Some(ScalarKind::Int(n)) => Some(n as f64),
            Some(ScalarKind::Float(x)) if x.is_finite() => Some(x),
            // ARIAC's reader calls float() on these, which takes quoted numbers.
            Some(ScalarKind::Text) => {
                match node.as_text().and_then(|t| t.trim().parse::<f64>().ok()) {
                    Some(x) if x.is_finite() => Some(x),
                    _ => {
                        self.wrong(node, what, "a number");
                        None
                    }
                }
            }
            _ => {
                self.wrong(node, what, "a number");
                None
            }
        }
    }

    fn seconds(&mut self, node: &Node, what: &str) -> Option<f64> {
        let x = self.number(node, what)?;
        if x < 0.0 {
            self.wrong(node, what, "a number of seconds, 0 or more");
            return None;
        }
        Some(x)
    }

    fn boolean(&mut self, node: &Node, what: &str) -> Option<bool> {
        match node.scalar() {
            Some(ScalarKind::Bool(b)) => Some(b),
            _ => {
                self.wrong(node, what, "`true` or `false`");
                None
            }
        }
    }

    fn text<'a>(&mut self, node: &'a Node, what: &str) -> Option<&'a str> {
        match node.scalar() {
            Some(ScalarKind::Null) | None => {
                self.wrong(node, what, "text");
                None
            }
            _ => node.as_text(),
        }
    }

    /// One of `names`; a did-you-mean hint otherwise.
    fn choice<'n>(&mut self, node: &Node, what: &str, names: &[&'n str]) -> Option<&'n str> {
        let t = self.text(node, what)?;
        if let Some(n) = names.iter().find(|n| **n == t) {
            return Some(n);
        }
        let hint = did_you_mean(t, names.iter().copied())
            .unwrap_or_else(|| format!("the choices are {}", quote_all(names)));
        self.error(
            codes::TRIAL_VALUE,
            node.range,
            format!("`{t}` is not {what}"),
        )
        .hint = Some(hint);
        None
    }

    fn part_type(&mut self, node: &Node) -> Option<PartType> {
        let names = PartType::ALL.map(PartType::name);
        let n = self.choice(node, "a part type", &names)?;
        PartType::ALL.into_iter().find(|t| t.name() == n)
    }

    fn color(&mut self, node: &Node) -> Option<Color> {
        let names = Color::ALL.map(Color::name);
        let n = self.choice(node, "a part colour", &names)?;
        Color::ALL.into_iter().find(|c| c.name() == n)
    }

    /// `type` and `color` of a part entry.
    fn kind(&mut self, f: &mut Fields<'_>) -> Option<PartKind> {
        let ty = self.need(f, "type");
        let color = self.need(f, "color");
        let ty = ty.and_then(|n| self.part_type(n));
        let color = color.and_then(|n| self.color(n));
        Some(PartKind {
            ty: ty?,
            color: color?,
        })
    }

    fn list<'a>(&mut self, node: &'a Node, what: &str) -> Option<&'a [Node]> {
        match node.as_seq() {
            Some(s) => Some(s),
            None => {
                self.wrong(node, what, "a list");
                None
            }
        }
    }

    /// A rotation: a number, or `pi`, `pi/N`, `-pi/N`, `N*pi`... as text.
    /// Rotations are not simulated, so a bad one is a warning.
    fn rotation(&mut self, node: &Node) {
        self.unsimulated(
            "rotation",
            node,
            "btc's world is symbolic; parts have no pose",
        );
        let ok = match node.scalar() {
            Some(ScalarKind::Int(_) | ScalarKind::Float(_)) => true,
            Some(ScalarKind::Text) => node.as_text().is_some_and(is_angle),
            _ => false,
        };
        if !ok {
            self.warn(
                codes::TRIAL_VALUE,
                node.range,
                format!("{} is not an angle", describe(node)),
            )
            .hint = Some("write a number of radians or `pi`, `pi/2`, `-pi/4`, `2*pi/3`; the rotation is not simulated, so the trial still runs".into());
        }
    }

    fn trial(&mut self, root: &Node) -> Option<Trial> {
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

    fn trays(&mut self, node: &Node) -> Vec<TrayOnTable> {
        let Some(mut f) = self.fields(node, "`kitting_trays`") else {
            return Vec::new();
        };
        let ids = self.need(&mut f, "tray_ids");
        let slots = self.need(&mut f, "slots");
        self.done(f, &["tray_ids", "slots"]);
        let ids: Vec<(u8, Range)> = ids
            .and_then(|n| self.list(n, "`tray_ids`"))
            .unwrap_or_default()
            .iter()
            .filter_map(|n| Some((self.int(n, "a kit tray id", 0, 9)? as u8, n.range)))
            .collect();
        let slot_nodes = slots
            .and_then(|n| self.list(n, "`slots`"))
            .unwrap_or_default();
        let slot_vals: Vec<(u8, Range)> = slot_nodes
            .iter()
            .filter_map(|n| Some((self.int(n, "a tray table slot", 1, 6)? as u8, n.range)))
            .collect();
        if ids.len() != slot_vals.len() {
            self.error(
                codes::TRIAL_VALUE,
                node.range,
                format!(
                    "`kitting_trays` lists {} tray ids and {} slots; each tray needs one slot",
                    ids.len(),
                    slot_vals.len()
                ),
            );
        }
        let mut out: Vec<TrayOnTable> = Vec::new();
        for ((id, r), (slot, sr)) in ids.into_iter().zip(slot_vals) {
            if out.iter().any(|t| t.slot == slot) {
                self.error(
                    codes::TRIAL_DUPLICATE,
                    sr,
                    format!("tray table slot {slot} is given twice"),
                );
                continue;
            }
            out.push(TrayOnTable {
                tray_id: id,
                slot,
                range: r,
            });
        }
        out
    }

    fn inserts(&mut self, node: &Node) {
        let Some(mut f) = self.fields(node, "`assembly_inserts`") else {
            return;
        };
        for st in ["as1", "as2", "as3", "as4"] {
            if let Some(n) = f.get(st) {
                self.unsimulated(
                    "assembly_inserts",
                    n,
                    "inserts have no pose in btc's world; every station's insert takes every part",
                );
                let ok = n.as_text().is_some_and(|t| is_angle(t.trim()));
                if !ok {
                    self.warn(
                        codes::TRIAL_VALUE,
                        n.range,
                        format!("{} is not an angle", describe(n)),
                    );
                }
            }
        }
        self.done(f, &["as1", "as2", "as3", "as4"]);
    }

    /// `binN` keys in order, each a list of lots.
    fn bins(&mut self, node: &Node) -> Vec<BinLot> {
        let Some(f) = self.fields(node, "`bins`") else {
            return Vec::new();
        };
        let mut out: Vec<BinLot> = Vec::new();
        let mut taken: BTreeMap<(u8, u8), Range> = BTreeMap::new();
        for (k, v) in f.items {
            let name = k.as_text().unwrap_or("");
            let Some(bin) = numbered(name, "bin", 1, 8) else {
                self.error(
                    codes::TRIAL_VALUE,
                    k.range,
                    format!("`{name}` is not a bin: the bins are `bin1` to `bin8`"),
                );
                continue;
            };
            if v.is_null() {
                continue;
            }
            let Some(lots) = self.list(v, &format!("`{name}`")) else {
                continue;
            };
            for lot in lots {
                let Some(mut lf) = self.fields(lot, &format!("a part lot of `{name}`")) else {
                    continue;
                };
                let kind = self.kind(&mut lf);
                let slots = self.need(&mut lf, "slots");
                if let Some(r) = lf.get("rotation") {
                    self.rotation(r);
                }
                let flipped = lf
                    .get("flipped")
                    .and_then(|n| self.boolean(n, "`flipped`"))
                    .unwrap_or(false);
                if lf.has("faulty") {
                    let n = lf.get("faulty").expect("has it");
                    self.warn(
                        codes::TRIAL_UNKNOWN_FIELD,
                        n.range,
                        "`faulty` in a bin is not part of the ARIAC 2023 trial format; btc ignores it",
                    )
                    .hint = Some(
                        "faulty parts are a challenge: `challenges: - faulty_part: {order_id: ..., quadrant1: true}`"
                            .into(),
                    );
                }
                self.done(lf, &["type", "color", "slots", "rotation", "flipped"]);
                let mut ss = Vec::new();
                if let Some(list) = slots.and_then(|n| self.list(n, "`slots`")) {
                    for s in list {
                        let Some(x) = self.int(s, "a bin slot", 1, 9) else {
                            continue;
                        };
                        let x = x as u8;
                        if let Some(first) = taken.get(&(bin, x)) {
                            let first = *first;
                            self.error(
                                codes::TRIAL_DUPLICATE,
                                s.range,
                                format!("slot {x} of `{name}` holds a part already"),
                            );
                            let sp = self.span(first);
                            if let Some(d) = self.diags.last_mut() {
                                d.labels.push(btc_pddl::diagnostic::Label {
                                    span: sp,
                                    message: "given here first".into(),
                                });
                            }
                            continue;
                        }
                        taken.insert((bin, x), s.range);
                        ss.push(x);
                    }
                }
                if let Some(kind) = kind {
                    out.push(BinLot {
                        bin,
                        kind,
                        slots: ss,
                        flipped,
                        range: lot.range,
                    });
                }
            }
        }
        out
    }

    fn agvs(&mut self, node: &Node) -> Vec<AgvLoad> {
        let Some(f) = self.fields(node, "`agvs`") else {
            return Vec::new();
        };
        let mut out: Vec<AgvLoad> = Vec::new();
        for (k, v) in f.items {
            let name = k.as_text().unwrap_or("");
            let Some(agv) = numbered(name, "agv", 1, 4) else {
                self.error(
                    codes::TRIAL_VALUE,
                    k.range,
                    format!("`{name}` is not an AGV: the AGVs are `agv1` to `agv4`"),
                );
                continue;
            };
            let Some(mut af) = self.fields(v, &format!("`{name}`")) else {
                continue;
            };
            let tray_id = self
                .need(&mut af, "tray_id")
                .and_then(|n| self.int(n, "a kit tray id", 0, 9))
                .unwrap_or(0) as u8;
            let mut parts: Vec<AgvPart> = Vec::new();
            if let Some(list) = af.get("parts").and_then(|n| self.list(n, "`parts`")) {
                for p in list {
                    let Some(mut pf) = self.fields(p, &format!("a part on `{name}`")) else {
                        continue;
                    };
                    let kind = self.kind(&mut pf);
                    let q = self
                        .need(&mut pf, "quadrant")
                        .and_then(|n| self.int(n, "a quadrant", 1, 4).map(|q| (q as u8, n.range)));
                    if let Some(r) = pf.get("rotation") {
                        self.rotation(r);
                    }
                    let flipped = pf
                        .get("flipped")
                        .and_then(|n| self.boolean(n, "`flipped`"))
                        .unwrap_or(false);
                    self.done(pf, &["type", "color", "quadrant", "rotation", "flipped"]);
                    let (Some(kind), Some((quadrant, qr))) = (kind, q) else {
                        continue;
                    };
                    if parts.iter().any(|x| x.quadrant == quadrant) {
                        self.error(
                            codes::TRIAL_DUPLICATE,
                            qr,
                            format!("quadrant {quadrant} of `{name}` holds a part already"),
                        );
                        continue;
                    }
                    parts.push(AgvPart {
                        kind,
                        quadrant,
                        flipped,
                        range: p.range,
                    });
                }
            }
            self.done(af, &["tray_id", "parts"]);
            out.push(AgvLoad {
                agv,
                tray_id,
                parts,
                range: v.range,
            });
        }
        out
    }

    fn conveyor(&mut self, node: &Node) -> Option<Conveyor> {
        let mut f = self.fields(node, "`conveyor_belt`")?;
        let active = f
            .get("active")
            .and_then(|n| self.boolean(n, "`active`"))
            .unwrap_or(false);
        let spawn_rate = match f.get("spawn_rate") {
            Some(n) => match self.number(n, "`spawn_rate`") {
                Some(x) if x > 0.0 => x,
                Some(_) => {
                    self.wrong(n, "`spawn_rate`", "a number of seconds above 0");
                    1.0
                }
                None => 1.0,
            },
            None if active => {
                let at = Range {
                    start: node.range.start,
                    end: node.range.start,
                };
                self.error(
                    codes::TRIAL_MISSING,
                    at,
                    "an active `conveyor_belt` needs `spawn_rate` (seconds between parts)",
                );
                1.0
            }
            None => 1.0,
        };
        let order = match f.get("order") {
            Some(n) => match self.choice(n, "a spawn order", &["sequential", "random"]) {
                Some("random") => SpawnOrder::Random,
                _ => SpawnOrder::Sequential,
            },
            None => SpawnOrder::Sequential,
        };
        let mut lots = Vec::new();
        if let Some(list) = f
            .get("parts_to_spawn")
            .and_then(|n| self.list(n, "`parts_to_spawn`"))
        {
            for p in list {
                let Some(mut pf) = self.fields(p, "a conveyor part lot") else {
                    continue;
                };
                let kind = self.kind(&mut pf);
                let number = self
                    .need(&mut pf, "number")
                    .and_then(|n| self.int(n, "`number`", 1, 1000))
                    .unwrap_or(0) as u32;
                if let Some(o) = pf.get("offset") {
                    self.unsimulated(
                        "offset",
                        o,
                        "the belt is one place in btc's world, parts have no position on it",
                    );
                    if let Some(x) = self.number(o, "`offset`") {
                        if !(-1.0..=1.0).contains(&x) {
                            self.wrong(o, "`offset`", "a number from -1 to 1");
                        }
                    }
                }
                if let Some(r) = pf.get("rotation") {
                    self.rotation(r);
                }
                let flipped = pf
                    .get("flipped")
                    .and_then(|n| self.boolean(n, "`flipped`"))
                    .unwrap_or(false);
                self.done(
                    pf,
                    &["type", "color", "number", "offset", "flipped", "rotation"],
                );
                if let Some(kind) = kind {
                    lots.push(ConveyorLot {
                        kind,
                        number,
                        flipped,
                        range: p.range,
                    });
                }
            }
        }
        self.done(f, &["active", "spawn_rate", "order", "parts_to_spawn"]);
        Some(Conveyor {
            active,
            spawn_rate,
            order,
            lots,
            range: node.range,
        })
    }

    /// A condition: in `f` directly (challenges) or under `announcement`.
    fn condition(&mut self, f: &mut Fields<'_>, what: &str) -> Option<Condition> {
        let given: Vec<&str> = CONDITION_FIELDS
            .iter()
            .copied()
            .filter(|k| f.has(k))
            .collect();
        if given.len() > 1 {
            let n = f.get(given[1]).expect("present");
            self.error(
                codes::TRIAL_VALUE,
                n.range,
                format!(
                    "{what} has more than one condition ({}); give one",
                    quote_all(&given)
                ),
            );
        }
        let Some(first) = given.first() else {
            let at = Range {
                start: f.node.range.start,
                end: f.node.range.start,
            };
            self.error(
                codes::TRIAL_MISSING,
                at,
                format!("{what} has no condition: give `time_condition`, `part_place_condition` or `submission_condition`"),
            );
            return None;
        };
        let n = f.get(first).expect("present");
        match *first {
            "time_condition" => self.seconds(n, "`time_condition`").map(Condition::Time),
            "part_place_condition" => {
                let mut pf = self.fields(n, "`part_place_condition`")?;
                let kind = self.kind(&mut pf);
                let agv = self
                    .need(&mut pf, "agv")
                    .and_then(|n| self.int(n, "an AGV number", 1, 4));
                self.done(pf, &["agv", "type", "color"]);
                Some(Condition::PartPlace {
                    agv: agv? as u8,
                    kind: kind?,
                })
            }
            _ => {
                let mut sf = self.fields(n, "`submission_condition`")?;
                let id = self
                    .need(&mut sf, "order_id")
                    .and_then(|n| self.text(n, "an order id"))
                    .map(str::to_owned);
                self.done(sf, &["order_id"]);
                id.map(Condition::Submission)
            }
        }
    }

    fn robot(&mut self, node: &Node) -> Option<Robot> {
        let n = self.choice(node, "a robot", &["floor_robot", "ceiling_robot"])?;
        Robot::ALL.into_iter().find(|r| r.name() == n)
    }

    fn challenges(&mut self, node: &Node) -> Vec<Challenge> {
        let Some(list) = self.list(node, "`challenges`") else {
            return Vec::new();
        };
        let mut out = Vec::new();
        let names = [
            "faulty_part",
            "dropped_part",
            "robot_malfunction",
            "sensor_blackout",
            "human",
        ];
        for item in list {
            let Some(items) = item.as_map() else {
                self.wrong(
                    item,
                    "a challenge",
                    "a mapping with one challenge, e.g. `- robot_malfunction: {...}`",
                );
                continue;
            };
            for (k, v) in items {
                let name = k.as_text().unwrap_or("");
                let Some(kind) = names.iter().find(|n| **n == name) else {
                    let hint = did_you_mean(name, names.iter().copied()).unwrap_or_else(|| {
                        format!(
                            "the challenges a trial file sets are {}; high-priority orders are orders with `priority: true` and insufficient parts are a trial without enough parts",
                            quote_all(&names)
                        )
                    });
                    self.error(
                        codes::TRIAL_VALUE,
                        k.range,
                        format!("`{name}` is not an ARIAC 2023 challenge"),
                    )
                    .hint = Some(hint);
                    continue;
                };
                let what = format!("the `{kind}` challenge");
                let Some(f) = self.fields(v, &what) else {
                    continue;
                };
                let c = match *kind {
                    "faulty_part" => self.faulty_part(f),
                    "dropped_part" => self.dropped_part(f),
                    "robot_malfunction" => self.robot_malfunction(f, &what),
                    "sensor_blackout" => self.sensor_blackout(f, &what),
                    _ => self.human(f, &what),
                };
                if let Some(kind) = c {
                    out.push(Challenge {
                        kind,
                        range: item.range,
                    });
                }
            }
        }
        out
    }

    fn faulty_part(&mut self, mut f: Fields<'_>) -> Option<ChallengeKind> {
        let id = self
            .need(&mut f, "order_id")
            .and_then(|n| self.text(n, "an order id"))
            .map(str::to_owned);
        let mut q = [false; 4];
        for (k, slot) in q.iter_mut().enumerate() {
            if let Some(n) = f.get(&format!("quadrant{}", k + 1)) {
                *slot = self.boolean(n, "a quadrant flag").unwrap_or(false);
            }
        }
        self.done(
            f,
            &[
                "order_id",
                "quadrant1",
                "quadrant2",
                "quadrant3",
                "quadrant4",
            ],
        );
        Some(ChallengeKind::FaultyPart {
            order_id: id?,
            quadrants: q,
        })
    }

    fn dropped_part(&mut self, mut f: Fields<'_>) -> Option<ChallengeKind> {
        let robot = self.need(&mut f, "robot").and_then(|n| self.robot(n));
        let kind = self.kind(&mut f);
        let after = self
            .need(&mut f, "drop_after")
            .and_then(|n| self.int(n, "`drop_after`", 0, 1000));
        let delay = self
            .need(&mut f, "delay")
            .and_then(|n| self.seconds(n, "`delay`"));
        self.done(f, &["robot", "type", "color", "drop_after", "delay"]);
        Some(ChallengeKind::DroppedPart {
            robot: robot?,
            kind: kind?,
            drop_after: after? as u32,
            delay: delay?,
        })
    }

    fn robot_malfunction(&mut self, mut f: Fields<'_>, what: &str) -> Option<ChallengeKind> {
        let duration = self.duration(&mut f);
        let robots = self.distinct(&mut f, "robots_to_disable", |r, n| r.robot(n));
        let condition = self.condition(&mut f, what);
        self.done_conditional(f, &["duration", "robots_to_disable"]);
        Some(ChallengeKind::RobotMalfunction {
            duration: duration?,
            robots,
            condition: condition?,
        })
    }

    fn sensor_blackout(&mut self, mut f: Fields<'_>, what: &str) -> Option<ChallengeKind> {
        let duration = self.duration(&mut f);
        let sensors = self.distinct(&mut f, "sensors_to_disable", |r, n| {
            r.choice(n, "a sensor type", &SENSOR_TYPES)
                .map(str::to_owned)
        });
        let condition = self.condition(&mut f, what);
        self.done_conditional(f, &["duration", "sensors_to_disable"]);
        Some(ChallengeKind::SensorBlackout {
            duration: duration?,
            sensors,
            condition: condition?,
        })
    }

    fn human(&mut self, mut f: Fields<'_>, what: &str) -> Option<ChallengeKind> {
        let behavior = self
            .need(&mut f, "behavior")
            .and_then(|n| {
                self.choice(
                    n,
                    "a human behavior",
                    &["indifferent", "antagonistic", "helpful"],
                )
            })
            .map(|b| match b {
                "antagonistic" => Behavior::Antagonistic,
                "helpful" => Behavior::Helpful,
                _ => Behavior::Indifferent,
            });
        let condition = self.condition(&mut f, what);
        self.done_conditional(f, &["behavior"]);
        Some(ChallengeKind::Human {
            behavior: behavior?,
            condition: condition?,
        })
    }

    fn duration(&mut self, f: &mut Fields<'_>) -> Option<f64> {
        self.need(f, "duration")
            .and_then(|n| self.seconds(n, "`duration`"))
    }

    /// The distinct values of the list under `key`, in order; a repeated
    /// value counts once (the competition's reader does the same).
    fn distinct<T: PartialEq>(
        &mut self,
        f: &mut Fields<'_>,
        key: &str,
        mut each: impl FnMut(&mut Self, &Node) -> Option<T>,
    ) -> Vec<T> {
        let mut out = Vec::new();
        let what = format!("`{key}`");
        if let Some(list) = self.need(f, key).and_then(|n| self.list(n, &what)) {
            for n in list {
                if let Some(v) = each(self, n) {
                    if !out.contains(&v) {
                        out.push(v);
                    }
                }
            }
        }
        out
    }

    /// `done` for a challenge that starts on a condition: `known` plus the
    /// three condition fields.
    fn done_conditional(&mut self, f: Fields<'_>, known: &[&str]) {
        let mut all = known.to_vec();
        all.extend(CONDITION_FIELDS);
        self.done(f, &all);
    }

    fn orders(&mut self, node: &Node) -> Vec<Order> {
        let Some(list) = self.list(node, "`orders`") else {
            return Vec::new();
        };
        if list.is_empty() {
            self.error(
                codes::TRIAL_MISSING,
                node.range,
                "`orders` is empty: a trial needs at least one order",
            );
        }
        let mut out: Vec<Order> = Vec::new();
        for o in list {
            let Some(order) = self.order(o) else {
                continue;
            };
            if let Some(first) = out.iter().find(|x| x.id == order.id) {
                let first = first.range;
                self.error(
                    codes::TRIAL_DUPLICATE,
                    o.range,
                    format!(
                        "order id `{}` is given twice; each order needs its own",
                        order.id
                    ),
                );
                let sp = self.span(first);
                if let Some(d) = self.diags.last_mut() {
                    d.labels.push(btc_pddl::diagnostic::Label {
                        span: sp,
                        message: "the first order with this id".into(),
                    });
                }
                continue;
            }
            out.push(order);
        }
        out
    }

    fn order(&mut self, node: &Node) -> Option<Order> {
        let mut f = self.fields(node, "an order")?;
        let id = self
            .need(&mut f, "id")
            .and_then(|n| self.text(n, "an order id"))
            .map(str::to_owned);
        let what = match &id {
            Some(id) => format!("order `{id}`"),
            None => "an order".to_owned(),
        };
        let ty_node = self.need(&mut f, "type");
        let ty = ty_node
            .and_then(|n| self.choice(n, "an order type", &["kitting", "assembly", "combined"]));
        let priority = match f.get("priority") {
            Some(n) => self.boolean(n, "`priority`").unwrap_or(false),
            None => {
                let at = Range {
                    start: node.range.start,
                    end: node.range.start,
                };
                self.error(
                    codes::TRIAL_MISSING,
                    at,
                    format!("{what} has no `priority` (`true` or `false`)"),
                );
                false
            }
        };
        let announcement = match self.need(&mut f, "announcement") {
            Some(n) => match self.fields(n, "`announcement`") {
                Some(mut af) => {
                    let c = self.condition(&mut af, &format!("the announcement of {what}"));
                    self.done(
                        af,
                        &[
                            "time_condition",
                            "part_place_condition",
                            "submission_condition",
                        ],
                    );
                    c
                }
                None => None,
            },
            None => None,
        };
        let tasks = ["kitting_task", "assembly_task", "combined_task"];
        let given: Vec<&str> = tasks.iter().copied().filter(|k| f.has(k)).collect();
        let task = match (ty, given.as_slice()) {
            (_, []) => {
                let at = Range {
                    start: node.range.start,
                    end: node.range.start,
                };
                self.error(
                    codes::TRIAL_MISSING,
                    at,
                    format!("{what} has no task: give `kitting_task`, `assembly_task` or `combined_task`"),
                );
                None
            }
            (_, [one]) => {
                let n = f.get(one).expect("present");
                if let Some(t) = ty {
                    if format!("{t}_task") != *one {
                        self.error(
                            codes::TRIAL_VALUE,
                            n.range,
                            format!("{what} is of type `{t}` but gives `{one}`"),
                        )
                        .hint = Some(format!("a `{t}` order gives `{t}_task`"));
                    }
                }
                match *one {
                    "kitting_task" => self.kitting(n),
                    "assembly_task" => self.assembly(n),
                    _ => self.combined(n),
                }
            }
            (_, [_, second, ..]) => {
                let n = f.get(second).expect("present");
                self.error(
                    codes::TRIAL_VALUE,
                    n.range,
                    format!("{what} gives more than one task; an order has exactly one"),
                );
                None
            }
        };
        self.done(
            f,
            &[
                "id",
                "type",
                "announcement",
                "priority",
                "kitting_task",
                "assembly_task",
                "combined_task",
            ],
        );
        Some(Order {
            id: id?,
            priority,
            announcement: announcement?,
            task: task?,
            range: node.range,
        })
    }

    fn station(&mut self, node: &Node) -> Option<u8> {
        let n = self.choice(node, "an assembly station", &["as1", "as2", "as3", "as4"])?;
        numbered(n, "as", 1, 4)
    }

    fn kitting(&mut self, node: &Node) -> Option<Task> {
        let mut f = self.fields(node, "`kitting_task`")?;
        let agv = self
            .need(&mut f, "agv_number")
            .and_then(|n| self.int(n, "an AGV number", 1, 4));
        let tray = self
            .need(&mut f, "tray_id")
            .and_then(|n| self.int(n, "a kit tray id", 0, 9));
        let dest = self.need(&mut f, "destination").and_then(|n| {
            let d = self.choice(
                n,
                "a kit destination",
                &["warehouse", "kitting", "as1", "as2", "as3", "as4"],
            )?;
            Some(match d {
                "warehouse" => Destination::Warehouse,
                "kitting" => Destination::Kitting,
                s => Destination::Station(numbered(s, "as", 1, 4)?),
            })
        });
        let mut products: Vec<KitProduct> = Vec::new();
        if let Some(list) = self
            .need(&mut f, "products")
            .and_then(|n| self.list(n, "`products`"))
        {
            if list.is_empty() {
                self.error(
                    codes::TRIAL_MISSING,
                    node.range,
                    "this kitting task has no products",
                );
            }
            for p in list {
                let Some(mut pf) = self.fields(p, "a kitting product") else {
                    continue;
                };
                let kind = self.kind(&mut pf);
                let q = self
                    .need(&mut pf, "quadrant")
                    .and_then(|n| self.int(n, "a quadrant", 1, 4).map(|q| (q as u8, n.range)));
                self.done(pf, &["type", "color", "quadrant"]);
                let (Some(kind), Some((quadrant, qr))) = (kind, q) else {
                    continue;
                };
                if products.iter().any(|x| x.quadrant == quadrant) {
                    self.error(
                        codes::TRIAL_DUPLICATE,
                        qr,
                        format!("quadrant {quadrant} is asked for twice in this kit"),
                    );
                    continue;
                }
                products.push(KitProduct {
                    kind,
                    quadrant,
                    range: p.range,
                });
            }
        }
        self.done(f, &["agv_number", "tray_id", "destination", "products"]);
        Some(Task::Kitting {
            agv: agv? as u8,
            tray_id: tray? as u8,
            destination: dest?,
            products,
        })
    }

    fn products(&mut self, f: &mut Fields<'_>, at: &Node) -> Vec<AssemblyProduct> {
        let mut out: Vec<AssemblyProduct> = Vec::new();
        let Some(list) = self
            .need(f, "products")
            .and_then(|n| self.list(n, "`products`"))
        else {
            return out;
        };
        if list.is_empty() {
            self.error(codes::TRIAL_MISSING, at.range, "this task has no products");
        }
        for p in list {
            let Some(mut pf) = self.fields(p, "an assembly product") else {
                continue;
            };
            let kind = self.kind(&mut pf);
            for key in ["assembled_pose", "assembly_direction"] {
                if let Some(n) = pf.get(key) {
                    self.unsimulated(
                        if key == "assembled_pose" {
                            "assembled_pose"
                        } else {
                            "assembly_direction"
                        },
                        n,
                        "an assembled part is in its slot or not; btc's world has no poses",
                    );
                }
            }
            self.done(
                pf,
                &["type", "color", "assembled_pose", "assembly_direction"],
            );
            let Some(kind) = kind else {
                continue;
            };
            // An insert has one slot per part type.
            if out.iter().any(|x| x.kind.ty == kind.ty) {
                self.error(
                    codes::TRIAL_DUPLICATE,
                    p.range,
                    format!(
                        "a second {}: an insert has one slot per part type",
                        kind.ty.name()
                    ),
                );
                continue;
            }
            out.push(AssemblyProduct {
                kind,
                range: p.range,
            });
        }
        out
    }

    fn assembly(&mut self, node: &Node) -> Option<Task> {
        let mut f = self.fields(node, "`assembly_task`")?;
        let mut agvs = Vec::new();
        if let Some(n) = self.need(&mut f, "agv_number") {
            // ARIAC's reader iterates it; a single number is a common slip.
            let items: Vec<&Node> = match n.as_seq() {
                Some(s) => s.iter().collect(),
                None => vec![n],
            };
            for a in items {
                if let Some(x) = self.int(a, "an AGV number", 1, 4) {
                    if !agvs.contains(&(x as u8)) {
                        agvs.push(x as u8);
                    }
                }
            }
        }
        let station = self.need(&mut f, "station").and_then(|n| self.station(n));
        let products = self.products(&mut f, node);
        self.done(f, &["agv_number", "station", "products"]);
        Some(Task::Assembly {
            agvs,
            station: station?,
            products,
        })
    }

    fn combined(&mut self, node: &Node) -> Option<Task> {
        let mut f = self.fields(node, "`combined_task`")?;
        let station = self.need(&mut f, "station").and_then(|n| self.station(n));
        let products = self.products(&mut f, node);
        self.done(f, &["station", "products"]);
        Some(Task::Combined {
            station: station?,
            products,
        })
    }
}

/// Checks across the file: references between orders and challenges, and
/// the ARIAC 2023 rules for when things may happen.
fn check_rules(t: &Trial, r: &mut Reader) {
    let ids: Vec<&str> = t.orders.iter().map(|o| o.id.as_str()).collect();
    let refer = |r: &mut Reader, id: &str, at: Range, what: &str| {
        if !ids.contains(&id) {
            let hint = did_you_mean(id, ids.iter().copied())
                .unwrap_or_else(|| format!("the trial's orders are {}", quote_all(&ids)));
            r.error(
                codes::TRIAL_UNKNOWN_ORDER,
                at,
                format!("{what} names order `{id}`, which this trial does not have"),
            )
            .hint = Some(hint);
        }
    };
    for o in &t.orders {
        if let Condition::Submission(id) = &o.announcement {
            refer(
                r,
                id,
                o.range,
                &format!("the announcement of order `{}`", o.id),
            );
            if *id == o.id {
                r.error(
                    codes::TRIAL_RULE,
                    o.range,
                    format!("order `{}` is announced when it is itself submitted", o.id),
                );
            }
            if o.priority {
                r.warn(
                    codes::TRIAL_RULE,
                    o.range,
                    format!(
                        "high-priority order `{}` is announced on a submission; ARIAC 2023 announces high-priority orders on time or part placement only",
                        o.id
                    ),
                );
            }
        }
    }
    let mut humans = 0;
    for c in &t.challenges {
        let cond = match &c.kind {
            ChallengeKind::FaultyPart { order_id, .. } => {
                refer(r, order_id, c.range, "a `faulty_part` challenge");
                if let Some(o) = t.orders.iter().find(|o| o.id == *order_id) {
                    if o.task.order_type() == OrderType::Assembly {
                        r.warn(
                            codes::TRIAL_RULE,
                            c.range,
                            format!(
                                "order `{order_id}` is an assembly order: its parts start on AGVs and are never placed in a kit, so this faulty-part challenge cannot happen"
                            ),
                        );
                    }
                }
                None
            }
            ChallengeKind::RobotMalfunction { condition, .. }
            | ChallengeKind::SensorBlackout { condition, .. } => Some(condition),
            ChallengeKind::Human { condition, .. } => {
                humans += 1;
                if humans == 2 {
                    r.error(
                        codes::TRIAL_RULE,
                        c.range,
                        "a second `human` challenge: ARIAC 2023 has one human in a trial",
                    );
                }
                Some(condition)
            }
            ChallengeKind::DroppedPart { .. } => None,
        };
        if let Some(Condition::Submission(id)) = cond {
            refer(r, id, c.range, &format!("a `{}` challenge", c.kind.name()));
        }
    }
}

/// Orders the trial's parts cannot fulfil: ARIAC's insufficient-parts
/// challenge, which has no field of its own. Reported, not refused.
fn check_supply(t: &Trial, r: &mut Reader) {
    let mut have: BTreeMap<PartKind, usize> = BTreeMap::new();
    for b in &t.bins {
        *have.entry(b.kind).or_default() += b.slots.len();
    }
    if let Some(c) = t.conveyor.as_ref().filter(|c| c.active) {
        for l in &c.lots {
            *have.entry(l.kind).or_default() += l.number as usize;
        }
    }
    for o in &t.orders {
        let Task::Assembly { agvs, products, .. } = &o.task else {
            continue;
        };
        for p in products {
            let on = t
                .agvs
                .iter()
                .filter(|a| agvs.contains(&a.agv))
                .flat_map(|a| &a.parts)
                .any(|x| x.kind == p.kind);
            if !on {
                r.warn(
                    codes::TRIAL_SUPPLY,
                    p.range,
                    format!(
                        "order `{}` assembles a {} that no AGV it names ({}) carries; the insert will miss it (insufficient parts)",
                        o.id,
                        p.kind,
                        agvs.iter().map(|a| format!("agv{a}")).collect::<Vec<_>>().join(", ")
                    ),
                );
            }
        }
    }
    let mut need: BTreeMap<PartKind, (usize, Vec<&str>, Range)> = BTreeMap::new();
    for o in &t.orders {
        if o.task.order_type() == OrderType::Assembly {
            continue;
        }
        for k in o.task.kinds() {
            let e = need.entry(k).or_insert((0, Vec::new(), o.range));
            e.0 += 1;
            if !e.1.contains(&o.id.as_str()) {
                e.1.push(&o.id);
            }
        }
    }
    for (k, (n, orders, at)) in need {
        let h = have.get(&k).copied().unwrap_or(0);
        if h < n {
            r.warn(
                codes::TRIAL_SUPPLY,
                at,
                format!(
                    "the trial's orders ({}) need {n} {k}{} and its bins and conveyor hold {h}: {} will be submitted incomplete (insufficient parts)",
                    quote_all(&orders),
                    if n == 1 { "" } else { "s" },
                    if orders.len() == 1 { "the order" } else { "orders" }
                ),
            );
        }
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

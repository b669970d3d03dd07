//! The cell at the start: trays on the tray tables, assembly inserts, the
//! bins' part lots, parts on the AGVs, and the conveyor belt.

use super::*;

impl Reader {
    pub(super) fn trays(&mut self, node: &Node) -> Vec<TrayOnTable> {
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

    pub(super) fn inserts(&mut self, node: &Node) {
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
    pub(super) fn bins(&mut self, node: &Node) -> Vec<BinLot> {
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
            let lots = self.parts(
                lots,
                &format!("a part lot of `{name}`"),
                &["slots", "rotation", "flipped"],
                |r, lf| {
                    let slots = r.need(lf, "slots");
                    let flipped = r.placed(lf);
                    if lf.has("faulty") {
                        let n = lf.get("faulty").expect("has it");
                        r.warn(
                            codes::TRIAL_UNKNOWN_FIELD,
                            n.range,
                            "`faulty` in a bin is not part of the ARIAC 2023 trial format; btc ignores it",
                        )
                        .hint = Some(
                            "faulty parts are a challenge: `challenges: - faulty_part: {order_id: ..., quadrant1: true}`"
                                .into(),
                        );
                    }
                    (slots, flipped)
                },
                |r, part, _| {
                    let (slots, flipped) = part.own;
                    let slots = r.bin_slots(slots, bin, name, &mut taken);
                    Some(BinLot {
                        bin,
                        kind: part.kind?,
                        slots,
                        flipped,
                        range: part.node.range,
                    })
                },
            );
            out.extend(lots);
        }
        out
    }

    /// A bin lot's `slots`: each a slot of bin `bin` (`name`) no lot
    /// before it holds (`taken`: the first place each slot was given).
    pub(super) fn bin_slots(
        &mut self,
        slots: Option<&Node>,
        bin: u8,
        name: &str,
        taken: &mut BTreeMap<(u8, u8), Range>,
    ) -> Vec<u8> {
        let mut ss = Vec::new();
        let Some(list) = slots.and_then(|n| self.list(n, "`slots`")) else {
            return ss;
        };
        for s in list {
            let Some(x) = self.int(s, "a bin slot", 1, 9) else {
                continue;
            };
            let x = x as u8;
            if let Some(first) = taken.get(&(bin, x)) {
                let first = *first;
                self.twice(
                    s.range,
                    format!("slot {x} of `{name}` holds a part already"),
                    first,
                    "given here first",
                );
                continue;
            }
            taken.insert((bin, x), s.range);
            ss.push(x);
        }
        ss
    }

    pub(super) fn agvs(&mut self, node: &Node) -> Vec<AgvLoad> {
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
                parts = self.parts(
                    list,
                    &format!("a part on `{name}`"),
                    &["quadrant", "rotation", "flipped"],
                    |r, pf| (r.quadrant(pf), r.placed(pf)),
                    |r, part, parts: &[AgvPart]| {
                        let (kind, (q, flipped)) = (part.kind?, part.own);
                        let quadrant =
                            r.free_quadrant(q, parts.iter().map(|x| x.quadrant), |q| {
                                format!("quadrant {q} of `{name}` holds a part already")
                            })?;
                        Some(AgvPart {
                            kind,
                            quadrant,
                            flipped,
                            range: part.node.range,
                        })
                    },
                );
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

    pub(super) fn conveyor(&mut self, node: &Node) -> Option<Conveyor> {
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
                self.missing(
                    node,
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
            lots = self.parts(
                list,
                "a conveyor part lot",
                &["number", "offset", "flipped", "rotation"],
                |r, pf| {
                    let number = r
                        .need(pf, "number")
                        .and_then(|n| r.int(n, "`number`", 1, 1000))
                        .unwrap_or(0) as u32;
                    if let Some(o) = pf.get("offset") {
                        r.unsimulated(
                            "offset",
                            o,
                            "the belt is one place in btc's world, parts have no position on it",
                        );
                        if let Some(x) = r.number(o, "`offset`") {
                            if !(-1.0..=1.0).contains(&x) {
                                r.wrong(o, "`offset`", "a number from -1 to 1");
                            }
                        }
                    }
                    (number, r.placed(pf))
                },
                |_, part, _| {
                    let (number, flipped) = part.own;
                    Some(ConveyorLot {
                        kind: part.kind?,
                        number,
                        flipped,
                        range: part.node.range,
                    })
                },
            );
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
}

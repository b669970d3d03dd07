//! The trial's PDDL problem: every object the trial can involve (robots,
//! places, AGVs, trays, quadrants, insert slots, each part, those the
//! conveyor will bring included) and the initial facts, built as values and
//! printed once. Agents plan each part task from the shared world's state
//! with this problem's objects; the rules database compiles their plans
//! against it.

use super::template::{GroundAtom, Var};
use super::Cell;
use crate::trial::{PartKind, PartType, Trial};
use btc_pddl::written_problem::{ProblemWriter, WrittenProblem};
use serde::Serialize;
use std::collections::BTreeMap;

/// Where a part starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Origin {
    Bin {
        bin: u8,
        slot: u8,
    },
    Agv {
        agv: u8,
        quadrant: u8,
    },
    /// The n-th part of the trial's conveyor lots (file order).
    Conveyor {
        lot: usize,
        n: u32,
    },
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PartInfo {
    /// The PDDL object.
    pub name: String,
    pub kind: PartKind,
    pub origin: Origin,
    pub flipped: bool,
}

pub struct TrialProblem {
    pub parts: Vec<PartInfo>,
    /// Objects by type, in print order.
    pub objects: Vec<(String, Vec<String>)>,
    pub init: Vec<GroundAtom>,
    /// The problem as a value; the rules database compiles against it.
    pub written: WrittenProblem,
}

impl TrialProblem {
    pub fn build(cell: &Cell, trial: &Trial, name: &str) -> TrialProblem {
        let f = &cell.spec.facts;
        let t = &cell.spec.types;
        let mut parts: Vec<PartInfo> = Vec::new();
        let mut counts: BTreeMap<PartKind, u32> = BTreeMap::new();
        let mut new_part =
            |kind: PartKind, origin: Origin, flipped: bool, parts: &mut Vec<PartInfo>| {
                let k = counts.entry(kind).or_insert(0);
                *k += 1;
                parts.push(PartInfo {
                    name: cell.spec.names.part.fill(
                        None,
                        Some(kind.ty.name()),
                        Some(kind.color.name()),
                        Some(*k),
                    ),
                    kind,
                    origin,
                    flipped,
                });
            };
        for lot in &trial.bins {
            for &slot in &lot.slots {
                new_part(
                    lot.kind,
                    Origin::Bin { bin: lot.bin, slot },
                    lot.flipped,
                    &mut parts,
                );
            }
        }
        for a in &trial.agvs {
            for p in &a.parts {
                new_part(
                    p.kind,
                    Origin::Agv {
                        agv: a.agv,
                        quadrant: p.quadrant,
                    },
                    p.flipped,
                    &mut parts,
                );
            }
        }
        if let Some(c) = trial.conveyor.as_ref().filter(|c| c.active) {
            for (li, lot) in c.lots.iter().enumerate() {
                for n in 0..lot.number {
                    new_part(
                        lot.kind,
                        Origin::Conveyor { lot: li, n },
                        lot.flipped,
                        &mut parts,
                    );
                }
            }
        }

        let robots: Vec<String> = cell.spec.robots.iter().map(|r| r.object.clone()).collect();
        let mut places: Vec<String> = (1..=8).map(|n| cell.bin(n)).collect();
        places.push(cell.conveyor());
        places.extend([cell.tray_table(1), cell.tray_table(4)]);
        places.extend((1..=4).map(|n| cell.kitting_station(n)));
        places.extend((1..=4).map(|n| cell.station(n)));
        places.push(cell.warehouse());
        places.push(cell.disposal());
        let agvs: Vec<String> = (1..=4).map(|n| cell.agv(n)).collect();
        let trays: Vec<String> = (0..=9).map(|n| cell.tray(n)).collect();
        let quadrants: Vec<String> = (1..=4).map(|n| cell.quadrant(n)).collect();
        let slots: Vec<String> = PartType::ALL.iter().map(|&p| cell.insert_slot(p)).collect();
        let mut by_type: Vec<(String, Vec<String>)> = Vec::new();
        let mut add = |ty: &str, names: Vec<String>| match by_type.iter_mut().find(|(t, _)| t == ty)
        {
            Some((_, v)) => {
                for n in names {
                    if !v.contains(&n) {
                        v.push(n);
                    }
                }
            }
            None => by_type.push((ty.to_owned(), names)),
        };
        add(&t.robot, robots);
        add(&t.place, places);
        add(&t.agv, agvs.clone());
        add(&t.tray, trays);
        add(&t.quadrant, quadrants.clone());
        add(&t.insert_slot, slots);
        for ty in PartType::ALL {
            let names: Vec<String> = parts
                .iter()
                .filter(|p| p.kind.ty == ty)
                .map(|p| p.name.clone())
                .collect();
            if !names.is_empty() {
                add(cell.part_type_name(ty), names);
            }
        }
        // Domain constants are not declared again.
        if let Some(d) = &cell.domain.domain {
            for (_, names) in &mut by_type {
                names.retain(|n| !d.constants.iter().any(|c| c.name.name == *n));
            }
        }
        by_type.retain(|(_, v)| !v.is_empty());

        let mut init: Vec<GroundAtom> = cell.spec.always.clone();
        for r in &cell.spec.robots {
            let v = [
                (Var::Robot, r.object.as_str()),
                (Var::Place, r.start.as_str()),
            ];
            init.push(f.robot_at.ground(&v));
            init.push(f.hand_empty.ground(&v));
            init.push(f.parts_gripper.ground(&v));
            init.push(f.enabled.ground(&v));
        }
        for tr in &trial.trays {
            let tray = cell.tray(tr.tray_id);
            let table = cell.tray_table(tr.slot);
            init.push(
                f.tray_at
                    .ground(&[(Var::Tray, &tray), (Var::Place, &table)]),
            );
        }
        for n in 1..=4u8 {
            let agv = cell.agv(n);
            let ks = cell.kitting_station(n);
            init.push(f.agv_at.ground(&[(Var::Agv, &agv), (Var::Place, &ks)]));
            let load = trial.agvs.iter().find(|a| a.agv == n);
            match load {
                Some(l) => {
                    let tray = cell.tray(l.tray_id);
                    init.push(f.tray_on.ground(&[(Var::Tray, &tray), (Var::Agv, &agv)]));
                }
                None => init.push(f.no_tray.ground(&[(Var::Agv, &agv)])),
            }
            for q in 1..=4u8 {
                let used = load.is_some_and(|l| l.parts.iter().any(|p| p.quadrant == q));
                if !used {
                    let qn = cell.quadrant(q);
                    init.push(f.kit_free.ground(&[(Var::Agv, &agv), (Var::Quadrant, &qn)]));
                }
            }
        }
        for p in &parts {
            let slot = cell.insert_slot(p.kind.ty);
            init.push(f.fits.ground(&[(Var::Part, &p.name), (Var::Slot, &slot)]));
            match p.origin {
                Origin::Bin { bin, .. } => {
                    let b = cell.bin(bin);
                    init.push(f.part_at.ground(&[(Var::Part, &p.name), (Var::Place, &b)]));
                }
                Origin::Agv { agv, quadrant } => {
                    let a = cell.agv(agv);
                    let q = cell.quadrant(quadrant);
                    init.push(f.in_kit.ground(&[
                        (Var::Part, &p.name),
                        (Var::Agv, &a),
                        (Var::Quadrant, &q),
                    ]));
                }
                // Conveyor parts arrive while the trial runs.
                Origin::Conveyor { .. } => {}
            }
            if p.flipped && !matches!(p.origin, Origin::Conveyor { .. }) {
                init.push(f.flipped.ground(&[(Var::Part, &p.name)]));
            }
        }
        let mut seen = std::collections::HashSet::new();
        init.retain(|a| seen.insert(a.clone()));

        let written = write(name, cell.domain_name(), &by_type, &init);
        TrialProblem {
            parts,
            objects: by_type,
            init,
            written,
        }
    }
}

/// The problem as a value, with the text it reads as (what a diagnostic
/// on it shows).
fn write(
    name: &str,
    domain: &str,
    objects: &[(String, Vec<String>)],
    init: &[GroundAtom],
) -> WrittenProblem {
    let mut w = ProblemWriter::new("The trial's world, written by `btc trial`.", name, domain);
    for (ty, names) in objects {
        w.objects(ty, names);
    }
    for a in init {
        w.fact(&a.pred, &a.args);
    }
    w.finish()
}

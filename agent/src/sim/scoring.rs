//! The ARIAC 2023 task scores, as the competition's documentation defines
//! them (ARIAC 2023 docs, "Scoring", the `docs/competition/scoring.rst`
//! page of the ariac2023 release; the task manager plugin computes the
//! same): pure functions over the Boolean conditions the world is scored
//! on. Point values:
//!
//! | task | item | points |
//! |---|---|---|
//! | kitting | correct tray id | 3 (a wrong tray: 0, no separate penalty in 2023) |
//! | kitting | quadrant: right type and colour, not flipped, not faulty | 3 |
//! | kitting | quadrant: right type, wrong colour, not flipped | 2 |
//! | kitting | quadrant: right type and colour, flipped | 2 |
//! | kitting | quadrant: right type, wrong colour, flipped | 1 |
//! | kitting | quadrant: wrong type, faulty or empty | 0 |
//! | kitting | bonus when every quadrant scores 3 | n (the kit's part count) |
//! | kitting | extra parts penalty | m − n when m > n parts are on the tray |
//! | kitting | destination multiplier | 1 at the right destination, else 0; the score is never below 0 |
//! | assembly | slot: assembled, right colour and pose | 3 |
//! | assembly | slot: assembled, right colour or pose | 2 |
//! | assembly | slot: assembled, neither | 1 |
//! | assembly | bonus when every slot scores 3 | 4n |
//! | combined | slot: 5 / 4 / 3 (same conditions as assembly) | |
//! | combined | bonus when every slot scores 5 | 4n |
//! | assembly, combined | station multiplier | 1 at the right station, else 0 |
//!
//! [`order`] reads a submitted order's conditions off the cell's world.

use super::world::CellWorld;
use crate::cell::{Cell, Var};
use crate::trial::{Destination, Order, OrderType, Task as OrderTask};
use serde::Serialize;

/// An order's score, item by item.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Breakdown {
    Kit(KitScore),
    Insert(InsertScore),
}

/// What is in one quadrant of a submitted kit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Quadrant {
    pub quadrant: u8,
    /// A part is there.
    pub present: bool,
    pub correct_type: bool,
    pub correct_color: bool,
    pub flipped: bool,
    pub faulty: bool,
}

pub fn quadrant_points(q: &Quadrant) -> i64 {
    if !q.present || !q.correct_type || q.faulty {
        return 0;
    }
    match (q.correct_color, q.flipped) {
        (true, false) => 3,
        (false, false) | (true, true) => 2,
        (false, true) => 1,
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KitScore {
    pub tray: i64,
    pub quadrants: Vec<(u8, i64)>,
    pub bonus: i64,
    pub extra_parts_penalty: i64,
    pub destination: i64,
    pub score: i64,
}

/// `quadrants`: one per product the order asks for (n of them); `parts_on_tray`
/// counts every part on the tray (m).
pub fn kitting(
    correct_tray: bool,
    quadrants: &[Quadrant],
    parts_on_tray: usize,
    correct_destination: bool,
) -> KitScore {
    let n = quadrants.len() as i64;
    let tray = if correct_tray { 3 } else { 0 };
    let pts: Vec<(u8, i64)> = quadrants
        .iter()
        .map(|q| (q.quadrant, quadrant_points(q)))
        .collect();
    let sum: i64 = pts.iter().map(|(_, p)| p).sum();
    let bonus = if n > 0 && sum == 3 * n { n } else { 0 };
    let m = parts_on_tray as i64;
    let extra = if m > n { m - n } else { 0 };
    let destination = i64::from(correct_destination);
    let score = (tray + sum + bonus - extra).max(0) * destination;
    KitScore {
        tray,
        quadrants: pts,
        bonus,
        extra_parts_penalty: extra,
        destination,
        score,
    }
}

/// What is in the insert's slot for one product of an order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Slot {
    /// A part of the product's type is assembled in its slot.
    pub assembled: bool,
    pub correct_color: bool,
    pub correct_pose: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Insert {
    Assembly,
    Combined,
}

pub fn slot_points(kind: Insert, s: &Slot) -> i64 {
    if !s.assembled {
        return 0;
    }
    let base = match kind {
        Insert::Assembly => 0,
        Insert::Combined => 2,
    };
    base + match (s.correct_color, s.correct_pose) {
        (true, true) => 3,
        (true, false) | (false, true) => 2,
        (false, false) => 1,
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InsertScore {
    pub slots: Vec<i64>,
    pub bonus: i64,
    pub station: i64,
    pub score: i64,
}

pub fn insert(kind: Insert, slots: &[Slot], correct_station: bool) -> InsertScore {
    let n = slots.len() as i64;
    let pts: Vec<i64> = slots.iter().map(|s| slot_points(kind, s)).collect();
    let sum: i64 = pts.iter().sum();
    let full = match kind {
        Insert::Assembly => 3,
        Insert::Combined => 5,
    };
    let bonus = if n > 0 && sum == full * n { 4 * n } else { 0 };
    let station = i64::from(correct_station);
    InsertScore {
        slots: pts,
        bonus,
        station,
        score: (sum + bonus) * station,
    }
}

/// The most an order can score: every item right.
pub fn best(kind: crate::trial::OrderType, n: usize) -> i64 {
    let n = n as i64;
    match kind {
        crate::trial::OrderType::Kitting => 3 + 3 * n + n,
        crate::trial::OrderType::Assembly => 3 * n + 4 * n,
        crate::trial::OrderType::Combined => 5 * n + 4 * n,
    }
}

/// The score of an order submitted now.
pub fn order(w: &CellWorld, cell: &Cell, order: &Order) -> (i64, Breakdown) {
    let s = &w.kb.state;
    match &order.task {
        OrderTask::Kitting {
            agv,
            tray_id,
            destination,
            products,
        } => {
            let aobj = w.obj.agv[*agv as usize - 1];
            let tray = w.facts.tray_of(s, aobj).map(|t| w.name(t).to_owned());
            let correct_tray = tray.as_deref() == Some(cell.tray(*tray_id).as_str());
            let kit = w.facts.kit(s, aobj);
            let quadrants: Vec<Quadrant> = products
                .iter()
                .map(|p| {
                    let q = w.obj.quadrant[p.quadrant as usize - 1];
                    let there = kit.iter().find(|(qq, _)| *qq == q).map(|(_, part)| *part);
                    let kind = there.and_then(|x| w.kind_of(x));
                    Quadrant {
                        quadrant: p.quadrant,
                        present: there.is_some(),
                        correct_type: kind.is_some_and(|k| k.ty == p.kind.ty),
                        correct_color: kind.is_some_and(|k| k.color == p.kind.color),
                        flipped: there.is_some_and(|x| {
                            s.facts.contains(&w.facts.flipped.key(&[(Var::Part, x)]))
                        }),
                        faulty: there
                            .and_then(|x| w.part_of.get(&x))
                            .is_some_and(|&k| w.parts[k].faulty),
                    }
                })
                .collect();
            let want = match destination {
                Destination::Warehouse => w.obj.warehouse,
                Destination::Kitting => w.obj.kitting_station[*agv as usize - 1],
                Destination::Station(n) => w.obj.station[*n as usize - 1],
            };
            let at_dest = w.facts.agv_place(s, aobj) == Some(want);
            let k = kitting(
                correct_tray && tray.is_some(),
                &quadrants,
                kit.len(),
                at_dest,
            );
            (k.score, Breakdown::Kit(k))
        }
        OrderTask::Assembly {
            station, products, ..
        }
        | OrderTask::Combined { station, products } => {
            let st = w.obj.station[*station as usize - 1];
            let insert = w.facts.insert(s, st);
            let slots: Vec<Slot> = products
                .iter()
                .map(|p| {
                    let there = insert
                        .iter()
                        .find(|x| w.kind_of(**x).is_some_and(|k| k.ty == p.kind.ty));
                    Slot {
                        assembled: there.is_some(),
                        correct_color: there
                            .and_then(|x| w.kind_of(*x))
                            .is_some_and(|k| k.color == p.kind.color),
                        correct_pose: there.is_some_and(|x| {
                            !s.facts.contains(&w.facts.flipped.key(&[(Var::Part, *x)]))
                        }),
                    }
                })
                .collect();
            let kind = if order.task.order_type() == OrderType::Assembly {
                Insert::Assembly
            } else {
                Insert::Combined
            };
            let r = self::insert(kind, &slots, true);
            (r.score, Breakdown::Insert(r))
        }
    }
}

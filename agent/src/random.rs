//! Seeded random trials, built as [`Trial`] values: the paper's experiment
//! trials (Table 3: one order of four random parts per task type, and one
//! variant per agility challenge) and the soak test's trials (random
//! orders, supplies and challenge mixes).

use crate::trial::yaml::Range;
use crate::trial::*;

fn kind(rng: &mut fastrand::Rng, ty: PartType) -> PartKind {
    PartKind {
        ty,
        color: Color::ALL[rng.usize(..Color::ALL.len())],
    }
}

fn any_kind(rng: &mut fastrand::Rng) -> PartKind {
    let ty = PartType::ALL[rng.usize(..PartType::ALL.len())];
    kind(rng, ty)
}

/// The task types of the paper's experiments.
pub const TASK_TYPES: [OrderType; 3] =
    [OrderType::Kitting, OrderType::Assembly, OrderType::Combined];

/// The scenarios of the paper's Table 3: the normal one and one per
/// agility challenge.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Scenario {
    Normal,
    FaultyParts,
    FlippedParts,
    FaultyGripper,
    RobotMalfunction,
    SensorBlackout,
    HighPriorityOrder,
    InsufficientParts,
    HumanSafety,
}

impl Scenario {
    pub const ALL: [Scenario; 9] = [
        Scenario::Normal,
        Scenario::FaultyParts,
        Scenario::FlippedParts,
        Scenario::FaultyGripper,
        Scenario::RobotMalfunction,
        Scenario::SensorBlackout,
        Scenario::HighPriorityOrder,
        Scenario::InsufficientParts,
        Scenario::HumanSafety,
    ];

    pub fn title(self) -> &'static str {
        match self {
            Scenario::Normal => "none (baseline)",
            Scenario::FaultyParts => "faulty parts",
            Scenario::FlippedParts => "flipped parts",
            Scenario::FaultyGripper => "faulty gripper",
            Scenario::RobotMalfunction => "robot malfunction",
            Scenario::SensorBlackout => "sensor blackout",
            Scenario::HighPriorityOrder => "high-priority order",
            Scenario::InsufficientParts => "insufficient parts",
            Scenario::HumanSafety => "human safety",
        }
    }

    /// Faulty and flipped parts do not occur in assembly: its parts start
    /// on AGVs, placed by the system (the paper's Figure 5 discussion).
    pub fn applies(self, ty: OrderType) -> bool {
        !(ty == OrderType::Assembly
            && matches!(self, Scenario::FaultyParts | Scenario::FlippedParts))
    }
}

const R: Range = Range { start: 0, end: 0 };

fn time(t: f64) -> Condition {
    Condition::Time(t)
}

/// Stock for `kinds` in the bins: two of each (a spare for faults), in
/// random bins and slots.
fn stock(
    rng: &mut fastrand::Rng,
    kinds: &[PartKind],
    flipped: &[PartKind],
    omit: Option<PartKind>,
) -> Vec<BinLot> {
    let mut lots: Vec<BinLot> = Vec::new();
    let mut free: Vec<(u8, u8)> = (1..=8u8)
        .flat_map(|b| (1..=9u8).map(move |s| (b, s)))
        .collect();
    rng.shuffle(&mut free);
    let mut seen: Vec<PartKind> = Vec::new();
    for &k in kinds {
        if seen.contains(&k) || Some(k) == omit {
            continue;
        }
        seen.push(k);
        let need = kinds.iter().filter(|x| **x == k).count() + 1;
        for _ in 0..need {
            let Some((bin, slot)) = free.pop() else { break };
            let fl = flipped.contains(&k);
            match lots
                .iter_mut()
                .find(|l| l.bin == bin && l.kind == k && l.flipped == fl)
            {
                Some(l) => l.slots.push(slot),
                None => lots.push(BinLot {
                    bin,
                    kind: k,
                    slots: vec![slot],
                    flipped: fl,
                    range: R,
                }),
            }
        }
    }
    lots
}

fn kit_order(id: &str, agv: u8, tray: u8, kinds: &[PartKind], priority: bool, at: f64) -> Order {
    Order {
        id: id.into(),
        priority,
        announcement: time(at),
        task: kitting(agv, tray, kinds),
        range: R,
    }
}

/// A kitting task to the warehouse with `kinds` in quadrants 1, 2, ...
fn kitting(agv: u8, tray: u8, kinds: &[PartKind]) -> Task {
    Task::Kitting {
        agv,
        tray_id: tray,
        destination: Destination::Warehouse,
        products: kinds
            .iter()
            .enumerate()
            .map(|(q, k)| KitProduct {
                kind: *k,
                quadrant: q as u8 + 1,
                range: R,
            })
            .collect(),
    }
}

fn products(kinds: &[PartKind]) -> Vec<AssemblyProduct> {
    kinds
        .iter()
        .map(|k| AssemblyProduct { kind: *k, range: R })
        .collect()
}

/// One trial of the paper's experiments (Table 3) for a task type and a
/// scenario.
pub fn experiment(ty: OrderType, sc: Scenario, seed: u64) -> Trial {
    let mut rng = fastrand::Rng::with_seed(
        seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (ty as u64) << 8 ^ sc as u64,
    );
    // Four random parts; an insert has one slot per type, so assembly and
    // combined orders take one of each type.
    let kinds: Vec<PartKind> = match ty {
        OrderType::Kitting => (0..4).map(|_| any_kind(&mut rng)).collect(),
        _ => {
            let mut v: Vec<PartKind> = PartType::ALL.iter().map(|&t| kind(&mut rng, t)).collect();
            rng.shuffle(&mut v);
            v
        }
    };
    let mut flipped = Vec::new();
    if sc == Scenario::FlippedParts {
        let mut ks = kinds.clone();
        ks.dedup();
        rng.shuffle(&mut ks);
        flipped.extend(ks.into_iter().take(2));
    }
    let omit = (sc == Scenario::InsufficientParts).then(|| kinds[rng.usize(..kinds.len())]);
    let mut t = Trial {
        time_limit: Some(500.0),
        trays: vec![
            TrayOnTable {
                tray_id: 1,
                slot: 1,
                range: R,
            },
            TrayOnTable {
                tray_id: 2,
                slot: 2,
                range: R,
            },
        ],
        bins: Vec::new(),
        agvs: Vec::new(),
        conveyor: None,
        orders: Vec::new(),
        challenges: Vec::new(),
    };
    let hp_at = 5.0 + rng.f64() * 15.0;
    let split = sc == Scenario::HighPriorityOrder;
    match ty {
        OrderType::Kitting => {
            t.bins = stock(&mut rng, &kinds, &flipped, omit);
            if split {
                t.orders
                    .push(kit_order("REGULAR1", 4, 1, &kinds[..2], false, 0.0));
                t.orders
                    .push(kit_order("PRIORITY1", 3, 2, &kinds[2..], true, hp_at));
            } else {
                t.orders
                    .push(kit_order("KITTING1", 4, 1, &kinds, false, 0.0));
            }
        }
        OrderType::Assembly => {
            let on = |agv: u8, ks: &[PartKind]| {
                let parts: Vec<AgvPart> = ks
                    .iter()
                    .enumerate()
                    .filter(|(_, k)| Some(**k) != omit)
                    .map(|(q, k)| AgvPart {
                        kind: *k,
                        quadrant: q as u8 + 1,
                        flipped: false,
                        range: R,
                    })
                    .collect();
                AgvLoad {
                    agv,
                    tray_id: 0,
                    parts,
                    range: R,
                }
            };
            t.agvs = vec![on(1, &kinds[..2]), on(2, &kinds[2..])];
            let order =
                |id: &str, agvs: Vec<u8>, station: u8, ks: &[PartKind], priority: bool, at: f64| {
                    Order {
                        id: id.into(),
                        priority,
                        announcement: time(at),
                        task: Task::Assembly {
                            agvs,
                            station,
                            products: products(ks),
                        },
                        range: R,
                    }
                };
            if split {
                t.orders
                    .push(order("REGULAR1", vec![1], 1, &kinds[..2], false, 0.0));
                t.orders
                    .push(order("PRIORITY1", vec![2], 2, &kinds[2..], true, hp_at));
            } else {
                t.orders
                    .push(order("ASSEMBLY1", vec![1, 2], 1, &kinds, false, 0.0));
            }
        }
        OrderType::Combined => {
            t.bins = stock(&mut rng, &kinds, &flipped, omit);
            let order = |id: &str, station: u8, ks: &[PartKind], priority: bool, at: f64| Order {
                id: id.into(),
                priority,
                announcement: time(at),
                task: Task::Combined {
                    station,
                    products: products(ks),
                },
                range: R,
            };
            if split {
                t.orders.push(order("REGULAR1", 2, &kinds[..2], false, 0.0));
                t.orders
                    .push(order("PRIORITY1", 4, &kinds[2..], true, hp_at));
            } else {
                t.orders.push(order("COMBINED1", 2, &kinds, false, 0.0));
            }
        }
    }
    let worker = match ty {
        OrderType::Kitting => Robot::FloorRobot,
        OrderType::Assembly => Robot::CeilingRobot,
        OrderType::Combined => Robot::ALL[rng.usize(..2)],
    };
    let first = t.orders[0].id.clone();
    let ch = match sc {
        Scenario::FaultyParts => {
            let mut quadrants = [false; 4];
            quadrants[rng.usize(..4)] = true;
            Some(ChallengeKind::FaultyPart {
                order_id: first,
                quadrants,
            })
        }
        Scenario::FaultyGripper => Some(ChallengeKind::DroppedPart {
            robot: worker,
            kind: kinds[rng.usize(..kinds.len())],
            drop_after: 0,
            delay: 1.0 + rng.f64() * 2.0,
        }),
        Scenario::RobotMalfunction => Some(ChallengeKind::RobotMalfunction {
            duration: 20.0,
            robots: vec![worker],
            condition: time(3.0 + rng.f64() * 20.0),
        }),
        Scenario::SensorBlackout => Some(ChallengeKind::SensorBlackout {
            duration: 20.0,
            sensors: vec!["logical_camera".into(), "camera".into()],
            condition: time(3.0 + rng.f64() * 20.0),
        }),
        Scenario::HumanSafety => Some(ChallengeKind::Human {
            behavior: Behavior::Antagonistic,
            condition: time(rng.f64() * 10.0),
        }),
        _ => None,
    };
    if let Some(kind) = ch {
        t.challenges.push(Challenge { kind, range: R });
    }
    t
}

/// A random trial for the soak test: one to four orders of random types
/// (some high-priority, some announced on placements or submissions), a
/// supply that may fall short, parts on the conveyor, and a random mix of
/// challenges with every kind of condition.
pub fn soak(seed: u64) -> Trial {
    let mut rng = fastrand::Rng::with_seed(seed);
    let n_orders = rng.usize(1..=4);
    let mut t = Trial {
        time_limit: Some(400.0),
        trays: vec![
            TrayOnTable {
                tray_id: 1,
                slot: 1,
                range: R,
            },
            TrayOnTable {
                tray_id: 2,
                slot: 2,
                range: R,
            },
            TrayOnTable {
                tray_id: 3,
                slot: 4,
                range: R,
            },
            TrayOnTable {
                tray_id: 4,
                slot: 5,
                range: R,
            },
        ],
        bins: Vec::new(),
        agvs: Vec::new(),
        conveyor: None,
        orders: Vec::new(),
        challenges: Vec::new(),
    };
    let mut needed: Vec<PartKind> = Vec::new();
    let mut kit_agvs: Vec<u8> = vec![1, 2, 3, 4];
    rng.shuffle(&mut kit_agvs);
    let mut stations: Vec<u8> = vec![1, 2, 3, 4];
    rng.shuffle(&mut stations);
    let mut assembly_agvs_used = false;
    for k in 0..n_orders {
        let id = format!("ORDER{}", k + 1);
        let priority = k > 0 && rng.u8(..4) == 0;
        let announcement = if k == 0 {
            time(0.0)
        } else {
            match rng.u8(..3) {
                0 => time(rng.f64() * 60.0),
                1 if !priority => Condition::Submission(format!("ORDER{}", rng.usize(1..=k))),
                _ => time(rng.f64() * 30.0),
            }
        };
        let ty = TASK_TYPES[rng.usize(..3)];
        let n = rng.usize(1..=4);
        let task = match ty {
            OrderType::Kitting => {
                let Some(agv) = kit_agvs.pop() else { continue };
                let kinds: Vec<PartKind> = (0..n).map(|_| any_kind(&mut rng)).collect();
                needed.extend(&kinds);
                let tray = t.trays[rng.usize(..t.trays.len())].tray_id;
                kitting(agv, tray, &kinds)
            }
            OrderType::Assembly if !assembly_agvs_used => {
                let Some(station) = stations.pop() else {
                    continue;
                };
                // The AGVs that serve the station carry the parts.
                let agv = if station <= 2 { 1 } else { 3 };
                if !kit_agvs.contains(&agv) {
                    continue;
                }
                kit_agvs.retain(|&a| a != agv);
                assembly_agvs_used = true;
                let mut types = PartType::ALL.to_vec();
                rng.shuffle(&mut types);
                let kinds: Vec<PartKind> = types
                    .into_iter()
                    .take(n)
                    .map(|ty| kind(&mut rng, ty))
                    .collect();
                t.agvs.push(AgvLoad {
                    agv,
                    tray_id: 0,
                    parts: kinds
                        .iter()
                        .enumerate()
                        .filter(|_| rng.u8(..8) != 0)
                        .map(|(q, k)| AgvPart {
                            kind: *k,
                            quadrant: q as u8 + 1,
                            flipped: false,
                            range: R,
                        })
                        .collect(),
                    range: R,
                });
                Task::Assembly {
                    agvs: vec![agv],
                    station,
                    products: products(&kinds),
                }
            }
            _ => {
                let Some(station) = stations.pop() else {
                    continue;
                };
                let mut types = PartType::ALL.to_vec();
                rng.shuffle(&mut types);
                let kinds: Vec<PartKind> = types
                    .into_iter()
                    .take(n)
                    .map(|ty| kind(&mut rng, ty))
                    .collect();
                needed.extend(&kinds);
                Task::Combined {
                    station,
                    products: products(&kinds),
                }
            }
        };
        t.orders.push(Order {
            id,
            priority,
            announcement,
            task,
            range: R,
        });
    }
    // Supply: mostly enough, sometimes short; some of it on the belt, some
    // of it flipped.
    let mut flipped = Vec::new();
    if rng.bool() {
        flipped.push(any_kind(&mut rng));
        if let Some(k) = needed.get(rng.usize(..needed.len().max(1))) {
            flipped.push(*k);
        }
    }
    let omit = (rng.u8(..5) == 0 && !needed.is_empty()).then(|| needed[rng.usize(..needed.len())]);
    t.bins = stock(&mut rng, &needed, &flipped, omit);
    if rng.bool() && !needed.is_empty() {
        let lots: Vec<ConveyorLot> = (0..rng.usize(1..=3))
            .map(|_| ConveyorLot {
                kind: needed[rng.usize(..needed.len())],
                number: rng.u32(1..=3),
                flipped: rng.u8(..4) == 0,
                range: R,
            })
            .collect();
        t.conveyor = Some(Conveyor {
            active: true,
            spawn_rate: 2.0 + rng.f64() * 6.0,
            order: if rng.bool() {
                SpawnOrder::Random
            } else {
                SpawnOrder::Sequential
            },
            lots,
            range: R,
        });
    }
    // Challenges.
    let ids: Vec<String> = t.orders.iter().map(|o| o.id.clone()).collect();
    let cond = |rng: &mut fastrand::Rng| match rng.u8(..4) {
        0 if !ids.is_empty() => Condition::Submission(ids[rng.usize(..ids.len())].clone()),
        1 => Condition::PartPlace {
            agv: rng.u8(1..=4),
            kind: any_kind(rng),
        },
        _ => time(rng.f64() * 80.0),
    };
    let mut human = false;
    for _ in 0..rng.usize(0..=5) {
        let kind = match rng.u8(..5) {
            0 if !ids.is_empty() => {
                let mut quadrants = [false; 4];
                for q in &mut quadrants {
                    *q = rng.bool();
                }
                ChallengeKind::FaultyPart {
                    order_id: ids[rng.usize(..ids.len())].clone(),
                    quadrants,
                }
            }
            1 => ChallengeKind::DroppedPart {
                robot: Robot::ALL[rng.usize(..2)],
                kind: if needed.is_empty() {
                    any_kind(&mut rng)
                } else {
                    needed[rng.usize(..needed.len())]
                },
                drop_after: rng.u32(0..=1),
                delay: rng.f64() * 4.0,
            },
            2 => ChallengeKind::RobotMalfunction {
                duration: 5.0 + rng.f64() * 25.0,
                robots: match rng.u8(..3) {
                    0 => vec![Robot::FloorRobot],
                    1 => vec![Robot::CeilingRobot],
                    _ => Robot::ALL.to_vec(),
                },
                condition: cond(&mut rng),
            },
            3 => ChallengeKind::SensorBlackout {
                duration: 5.0 + rng.f64() * 20.0,
                sensors: vec![SENSOR_TYPES[rng.usize(..SENSOR_TYPES.len())].to_owned()],
                condition: cond(&mut rng),
            },
            _ if !human => {
                human = true;
                ChallengeKind::Human {
                    behavior: [
                        Behavior::Antagonistic,
                        Behavior::Indifferent,
                        Behavior::Helpful,
                    ][rng.usize(..3)],
                    condition: cond(&mut rng),
                }
            }
            _ => continue,
        };
        t.challenges.push(Challenge { kind, range: R });
    }
    t
}

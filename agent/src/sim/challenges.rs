//! The agility challenges at run time: the trial's own (faulty parts,
//! dropped parts, robot malfunctions, sensor blackouts, the human) and the
//! ones a trial implies (high-priority orders, insufficient parts, flipped
//! parts). Each kind is a type with its own state and rules; a
//! [`Challenge`] adds what every kind has (when it was met, how it ended,
//! the orders it touched). What a challenge does to the world (a robot
//! disabled, a part dropped) the simulation applies; here is only when and
//! to whom, and the runtime faults it means for a robot's tree.

use super::tasks::PartId;
use crate::cell::spec::Time;
use crate::cell::{Cell, Origin, PartInfo};
use crate::faults::{Blackout, FaultKind, FaultSpec, Trigger};
use crate::trial::{Behavior, ChallengeKind, Condition, PartKind, Robot, Trial};

/// ARIAC's faulty parts: the first part placed in each flagged quadrant of
/// the order's kit is faulty.
#[derive(Clone, Debug, PartialEq)]
pub struct FaultyPart {
    pub order_id: String,
    pub quadrants: [bool; 4],
    /// The quadrants whose first part was already placed.
    consumed: [bool; 4],
}

impl FaultyPart {
    pub fn new(order_id: String, quadrants: [bool; 4]) -> FaultyPart {
        FaultyPart {
            order_id,
            quadrants,
            consumed: [false; 4],
        }
    }

    /// A part placed in quadrant `q` (1–4) of the order's kit: whether it
    /// is faulty (the first in a flagged quadrant).
    pub fn placed(&mut self, q: u8) -> bool {
        let k = q as usize - 1;
        if !self.quadrants[k] || self.consumed[k] {
            return false;
        }
        self.consumed[k] = true;
        true
    }
}

/// ARIAC's faulty gripper: the (`drop_after` + 1)-th pick of the kind by
/// the robot is dropped `delay` seconds later.
#[derive(Clone, Debug, PartialEq)]
pub struct DroppedPart {
    pub robot: Robot,
    pub kind: PartKind,
    pub drop_after: u32,
    pub delay: f64,
    /// Picks of the kind seen.
    picks: u32,
    /// The drop to come: its tick and the part.
    pub drop: Option<(u64, PartId)>,
}

impl DroppedPart {
    /// A pick by `robot` of `part` (of `kind`) at `tick`.
    pub fn picked(&mut self, robot: Robot, kind: PartKind, part: PartId, tick: u64, time: &Time) {
        if robot != self.robot || kind != self.kind || self.drop.is_some() {
            return;
        }
        self.picks += 1;
        if self.picks == self.drop_after + 1 {
            self.drop = Some((tick + time.ticks(self.delay).max(1), part));
        }
    }

    /// The part to drop now, if its time came.
    pub fn due(&self, tick: u64) -> Option<PartId> {
        self.drop.filter(|(at, _)| *at <= tick).map(|(_, p)| p)
    }
}

/// Robots disabled for a while.
#[derive(Clone, Debug, PartialEq)]
pub struct Malfunction {
    pub robots: Vec<Robot>,
    pub duration: f64,
    pub condition: Condition,
}

/// Sensors silent for a while: the monitors cannot be read.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorBlackout {
    pub sensors: Vec<String>,
    pub duration: f64,
    pub condition: Condition,
}

/// A human in the cell: the ceiling robot keeps its distance while the
/// human is close.
#[derive(Clone, Debug, PartialEq)]
pub struct Human {
    pub behavior: Behavior,
    pub condition: Condition,
    /// The window of its approach (start, end ticks).
    pub window: Option<(u64, u64)>,
}

impl Human {
    /// Whether and when the human comes close, from `tick` on (seeded):
    /// antagonistic within 10 s for 5–15 s, indifferent once within 60 s
    /// for 3–7 s, helpful never.
    pub fn approach(&mut self, tick: u64, rng: &mut fastrand::Rng, time: &Time) -> bool {
        let (start, len) = match self.behavior {
            Behavior::Antagonistic => (
                rng.u64(0..=time.ticks(10.0)),
                time.ticks(5.0 + rng.f64() * 10.0).max(1),
            ),
            Behavior::Indifferent => (
                rng.u64(0..=time.ticks(60.0)),
                time.ticks(3.0 + rng.f64() * 4.0).max(1),
            ),
            Behavior::Helpful => (0, 0),
        };
        if len == 0 {
            return false;
        }
        self.window = Some((tick + start, tick + start + len));
        true
    }

    pub fn close_at(&self, tick: u64) -> bool {
        self.window.is_some_and(|(s, e)| s <= tick && tick < e)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Kind {
    FaultyPart(FaultyPart),
    DroppedPart(DroppedPart),
    RobotMalfunction(Malfunction),
    SensorBlackout(SensorBlackout),
    Human(Human),
    HighPriorityOrder { order: usize },
    InsufficientParts { kind: PartKind },
    FlippedParts { kind: PartKind, place: String },
}

impl Kind {
    /// One of the trial file's challenges, with its state at the start.
    pub fn of_trial(c: &ChallengeKind) -> Kind {
        match c.clone() {
            ChallengeKind::FaultyPart {
                order_id,
                quadrants,
            } => Kind::FaultyPart(FaultyPart::new(order_id, quadrants)),
            ChallengeKind::DroppedPart {
                robot,
                kind,
                drop_after,
                delay,
            } => Kind::DroppedPart(DroppedPart {
                robot,
                kind,
                drop_after,
                delay,
                picks: 0,
                drop: None,
            }),
            ChallengeKind::RobotMalfunction {
                duration,
                robots,
                condition,
            } => Kind::RobotMalfunction(Malfunction {
                robots,
                duration,
                condition,
            }),
            ChallengeKind::SensorBlackout {
                duration,
                sensors,
                condition,
            } => Kind::SensorBlackout(SensorBlackout {
                sensors,
                duration,
                condition,
            }),
            ChallengeKind::Human {
                behavior,
                condition,
            } => Kind::Human(Human {
                behavior,
                condition,
                window: None,
            }),
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            Kind::FaultyPart(_) => "faulty_part",
            Kind::DroppedPart(_) => "faulty_gripper",
            Kind::RobotMalfunction(_) => "robot_malfunction",
            Kind::SensorBlackout(_) => "sensor_blackout",
            Kind::Human(_) => "human",
            Kind::HighPriorityOrder { .. } => "high_priority_order",
            Kind::InsufficientParts { .. } => "insufficient_parts",
            Kind::FlippedParts { .. } => "flipped_part",
        }
    }

    /// What starts it, for the kinds a condition starts.
    pub fn condition(&self) -> Option<&Condition> {
        match self {
            Kind::RobotMalfunction(Malfunction { condition, .. })
            | Kind::SensorBlackout(SensorBlackout { condition, .. })
            | Kind::Human(Human { condition, .. }) => Some(condition),
            _ => None,
        }
    }
}

#[derive(Clone, Debug)]
pub struct Challenge {
    pub label: String,
    pub kind: Kind,
    pub met_at: Option<u64>,
    /// The tick its effect ends (malfunctions, blackouts, the human's
    /// approach).
    pub until: Option<u64>,
    pub ended: bool,
    /// What it did, in order (for the report).
    pub effects: Vec<String>,
    /// Orders it touched.
    pub orders: Vec<usize>,
}

impl Challenge {
    pub fn new(label: String, kind: Kind) -> Challenge {
        Challenge {
            label,
            kind,
            met_at: None,
            until: None,
            ended: false,
            effects: Vec::new(),
            orders: Vec::new(),
        }
    }

    pub fn in_effect(&self, tick: u64) -> bool {
        self.met_at.is_some() && !self.ended && self.until.is_none_or(|u| tick < u)
    }

    /// Whether it is met and its effect's time is over.
    pub fn expires(&self, tick: u64) -> bool {
        self.met_at.is_some() && !self.ended && self.until.is_some_and(|u| tick >= u)
    }

    /// Whether it disables robot `r` (a malfunction).
    pub fn disables(&self, r: Robot) -> bool {
        matches!(&self.kind, Kind::RobotMalfunction(m) if m.robots.contains(&r))
    }

    /// Met at `tick`: when its effect ends. A helpful human ends at once.
    pub fn trigger(&mut self, tick: u64, rng: &mut fastrand::Rng, time: &Time) {
        self.met_at = Some(tick);
        match &mut self.kind {
            Kind::RobotMalfunction(Malfunction { duration, .. })
            | Kind::SensorBlackout(SensorBlackout { duration, .. }) => {
                self.until = Some(tick + time.ticks(*duration).max(1));
            }
            Kind::Human(h) => {
                if h.approach(tick, rng, time) {
                    self.until = h.window.map(|(_, e)| e);
                } else {
                    self.ended = true;
                    self.note(
                        "the helpful human stops short of the ceiling robot: nothing to avoid",
                    );
                }
            }
            _ => {}
        }
    }

    /// The runtime fault it means for robot `robot` (whose object is
    /// `object`) from tick `from`, while in effect.
    pub fn fault(&self, robot: Robot, object: &str, from: u64) -> Option<FaultSpec> {
        if !self.in_effect(from) {
            return None;
        }
        let left = self.until.map(|u| u.saturating_sub(from).max(1));
        let (kind, duration) = match &self.kind {
            Kind::RobotMalfunction(m) if m.robots.contains(&robot) => {
                (FaultKind::RobotMalfunction, left)
            }
            Kind::SensorBlackout(_) => (FaultKind::SensorBlackout, left),
            Kind::Human(h) if robot == Robot::CeilingRobot && h.close_at(from) => (
                FaultKind::HumanTooClose,
                h.window.map(|(_, e)| e.saturating_sub(from).max(1)),
            ),
            _ => return None,
        };
        Some(fault(kind, &self.label, object, from, duration))
    }

    pub fn note(&mut self, e: impl Into<String>) {
        let e = e.into();
        if !self.effects.contains(&e) {
            self.effects.push(e);
        }
    }

    pub fn touch(&mut self, order: usize) {
        if !self.orders.contains(&order) {
            self.orders.push(order);
        }
    }

    /// How it ended, for the report; `full`: whether the order it is
    /// reported under scored full marks.
    pub fn end(&self, full: Option<bool>) -> String {
        if self.met_at.is_none() {
            return match self.effects.first() {
                Some(e) => format!("not met: {e}"),
                None => "not met".into(),
            };
        }
        let what = self.effects.join("; ");
        let head = match full {
            Some(true) => "recovered",
            Some(false) => "cost points",
            None => "met",
        };
        if what.is_empty() {
            head.into()
        } else {
            format!("{head}: {what}")
        }
    }
}

/// The trial's challenges at the start: its own, one per high-priority
/// order, one per lot of flipped parts.
pub fn at_start(cell: &Cell, trial: &Trial, parts: &[PartInfo]) -> Vec<Challenge> {
    let mut out: Vec<Challenge> = Vec::new();
    for (k, c) in trial.challenges.iter().enumerate() {
        let kind = Kind::of_trial(&c.kind);
        out.push(Challenge::new(format!("{}#{}", kind.name(), k + 1), kind));
    }
    for (k, o) in trial.orders.iter().enumerate() {
        if o.priority {
            out.push(Challenge::new(
                format!("high_priority_order({})", o.id),
                Kind::HighPriorityOrder { order: k },
            ));
        }
    }
    let mut flipped_lots: Vec<(PartKind, String)> = Vec::new();
    for p in parts.iter().filter(|p| p.flipped) {
        let place = match p.origin {
            Origin::Bin { bin, .. } => cell.bin(bin),
            Origin::Agv { agv, .. } => cell.agv(agv),
            Origin::Conveyor { .. } => cell.conveyor(),
        };
        if !flipped_lots.contains(&(p.kind, place.clone())) {
            flipped_lots.push((p.kind, place));
        }
    }
    for (kind, place) in flipped_lots {
        out.push(Challenge::new(
            format!("flipped_part({kind} in {place})"),
            Kind::FlippedParts { kind, place },
        ));
    }
    out
}

/// A runtime fault a challenge injects into a robot's tree from tick `at`.
pub fn fault(
    kind: FaultKind,
    label: &str,
    robot: &str,
    at: u64,
    duration: Option<u64>,
) -> FaultSpec {
    FaultSpec {
        kind,
        name: Some(label.to_owned()),
        trigger: Trigger::Tick(at.max(1)),
        robot: Some(robot.to_owned()),
        part: None,
        duration,
        retract: Some(Vec::new()),
        add: Vec::new(),
        goal: None,
        blackout: Blackout::Running,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trial::{Color, PartType};

    fn time() -> Time {
        Time {
            seconds_per_tick: 0.5,
            ticks_per_action: 2,
            conveyor_seconds: 30.0,
        }
    }

    fn kind() -> PartKind {
        PartKind {
            ty: PartType::Battery,
            color: Color::Red,
        }
    }

    #[test]
    fn a_faulty_part_is_the_first_placed_in_each_flagged_quadrant() {
        let mut f = FaultyPart::new("o".into(), [true, false, true, false]);
        assert!(f.placed(1));
        assert!(!f.placed(1), "the replacement is good");
        assert!(!f.placed(2), "quadrant 2 is not flagged");
        assert!(f.placed(3));
    }

    #[test]
    fn the_gripper_drops_the_pick_after_drop_after_picks_delay_seconds_later() {
        let Kind::DroppedPart(mut d) = Kind::of_trial(&ChallengeKind::DroppedPart {
            robot: Robot::FloorRobot,
            kind: kind(),
            drop_after: 1,
            delay: 2.0,
        }) else {
            unreachable!()
        };
        d.picked(Robot::CeilingRobot, kind(), PartId(7), 1, &time());
        let other = PartKind {
            color: Color::Blue,
            ..kind()
        };
        d.picked(Robot::FloorRobot, other, PartId(7), 1, &time());
        assert_eq!(d.drop, None, "another robot's or kind's picks do not count");
        d.picked(Robot::FloorRobot, kind(), PartId(3), 2, &time());
        assert_eq!(d.drop, None, "the first pick is kept");
        d.picked(Robot::FloorRobot, kind(), PartId(4), 10, &time());
        assert_eq!(d.drop, Some((14, PartId(4))));
        assert_eq!(d.due(13), None);
        assert_eq!(d.due(14), Some(PartId(4)));
        d.picked(Robot::FloorRobot, kind(), PartId(5), 11, &time());
        assert_eq!(d.drop, Some((14, PartId(4))), "one drop at a time");
    }

    fn challenge(c: ChallengeKind) -> Challenge {
        let k = Kind::of_trial(&c);
        Challenge::new(format!("{}#1", k.name()), k)
    }

    #[test]
    fn a_malfunction_disables_its_robots_for_its_duration() {
        let mut c = challenge(ChallengeKind::RobotMalfunction {
            duration: 3.0,
            robots: vec![Robot::FloorRobot],
            condition: Condition::Time(1.0),
        });
        assert!(c.disables(Robot::FloorRobot) && !c.disables(Robot::CeilingRobot));
        assert!(!c.in_effect(5));
        c.trigger(5, &mut fastrand::Rng::with_seed(1), &time());
        assert_eq!(c.until, Some(11));
        assert!(c.in_effect(10) && !c.in_effect(11) && c.expires(11));
        let f = c.fault(Robot::FloorRobot, "floor_robot", 6).unwrap();
        assert_eq!(f.kind, FaultKind::RobotMalfunction);
        assert_eq!(f.duration, Some(5));
        assert_eq!(f.name.as_deref(), Some("robot_malfunction#1"));
        assert!(c.fault(Robot::CeilingRobot, "ceiling_robot", 6).is_none());
    }

    #[test]
    fn a_blackout_reaches_every_robot_while_it_lasts() {
        let mut c = challenge(ChallengeKind::SensorBlackout {
            duration: 1.0,
            sensors: vec!["break_beam".into()],
            condition: Condition::Time(0.0),
        });
        c.trigger(1, &mut fastrand::Rng::with_seed(1), &time());
        for r in Robot::ALL {
            assert_eq!(
                c.fault(r, r.name(), 1).map(|f| f.kind),
                Some(FaultKind::SensorBlackout)
            );
            assert!(c.fault(r, r.name(), 3).is_none());
        }
    }

    #[test]
    fn the_human_comes_close_to_the_ceiling_robot_only_and_the_helpful_one_never() {
        for (behavior, within) in [(Behavior::Antagonistic, 20), (Behavior::Indifferent, 120)] {
            for seed in 1..20 {
                let mut c = challenge(ChallengeKind::Human {
                    behavior,
                    condition: Condition::Time(0.0),
                });
                c.trigger(4, &mut fastrand::Rng::with_seed(seed), &time());
                let Kind::Human(h) = &c.kind else {
                    unreachable!()
                };
                let (s, e) = h.window.unwrap();
                assert!(s >= 4 && s <= 4 + within && e > s, "{behavior:?} {s} {e}");
                assert_eq!(c.until, Some(e));
                let f = c.fault(Robot::CeilingRobot, "ceiling_robot", s).unwrap();
                assert_eq!(f.kind, FaultKind::HumanTooClose);
                assert_eq!(f.duration, Some(e - s));
                assert!(c.fault(Robot::FloorRobot, "floor_robot", s).is_none());
            }
        }
        let mut c = challenge(ChallengeKind::Human {
            behavior: Behavior::Helpful,
            condition: Condition::Time(0.0),
        });
        c.trigger(4, &mut fastrand::Rng::with_seed(1), &time());
        assert!(c.ended && !c.in_effect(4));
        assert!(c
            .end(None)
            .starts_with("met: the helpful human stops short"));
    }

    #[test]
    fn the_report_says_how_a_challenge_ended() {
        let mut c = Challenge::new(
            "insufficient_parts(red battery)".into(),
            Kind::InsufficientParts { kind: kind() },
        );
        assert_eq!(c.end(None), "not met");
        c.note("task 1: no part");
        c.note("task 1: no part");
        assert_eq!(c.end(None), "not met: task 1: no part");
        c.met_at = Some(3);
        c.touch(0);
        c.touch(0);
        assert_eq!(c.orders, vec![0]);
        assert_eq!(c.end(Some(true)), "recovered: task 1: no part");
        assert_eq!(c.end(Some(false)), "cost points: task 1: no part");
        assert!(c.fault(Robot::FloorRobot, "floor_robot", 3).is_none());
    }
}

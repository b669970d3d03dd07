//! The agility challenges at run time: the trial's own (faulty parts,
//! dropped parts, robot malfunctions, sensor blackouts, the human) and the
//! ones a trial implies (high-priority orders, insufficient parts, flipped
//! parts), each with when it was met and how it ended.

use crate::trial::{Behavior, ChallengeKind, Condition, PartKind, Robot};

#[derive(Clone, Debug, PartialEq)]
pub enum Kind {
    /// One of the trial file's challenges.
    Trial(ChallengeKind),
    HighPriorityOrder {
        order: usize,
    },
    InsufficientParts {
        kind: PartKind,
    },
    FlippedParts {
        kind: PartKind,
        place: String,
    },
}

impl Kind {
    pub fn name(&self) -> &'static str {
        match self {
            Kind::Trial(ChallengeKind::DroppedPart { .. }) => "faulty_gripper",
            Kind::Trial(c) => c.name(),
            Kind::HighPriorityOrder { .. } => "high_priority_order",
            Kind::InsufficientParts { .. } => "insufficient_parts",
            Kind::FlippedParts { .. } => "flipped_part",
        }
    }

    pub fn condition(&self) -> Option<&Condition> {
        match self {
            Kind::Trial(
                ChallengeKind::RobotMalfunction { condition, .. }
                | ChallengeKind::SensorBlackout { condition, .. }
                | ChallengeKind::Human { condition, .. },
            ) => Some(condition),
            _ => None,
        }
    }
}

#[derive(Clone, Debug)]
pub struct ChallengeRt {
    pub label: String,
    pub kind: Kind,
    pub met_at: Option<u64>,
    /// The tick its effect ends (malfunctions, blackouts, the human's
    /// approach).
    pub until: Option<u64>,
    pub ended: bool,
    /// What it did, in order (for the report).
    pub effects: Vec<String>,
    /// Faulty parts: the quadrants whose first part was already placed.
    pub consumed: [bool; 4],
    /// Dropped parts: picks of the kind seen, and the drop to come.
    pub picks: u32,
    pub drop: Option<(u64, usize)>,
    /// The human: the window of its approach (start, end ticks).
    pub window: Option<(u64, u64)>,
    /// Orders it touched.
    pub orders: Vec<usize>,
}

impl ChallengeRt {
    pub fn new(label: String, kind: Kind) -> ChallengeRt {
        ChallengeRt {
            label,
            kind,
            met_at: None,
            until: None,
            ended: false,
            effects: Vec::new(),
            consumed: [false; 4],
            picks: 0,
            drop: None,
            window: None,
            orders: Vec::new(),
        }
    }

    pub fn in_effect(&self, tick: u64) -> bool {
        self.met_at.is_some() && !self.ended && self.until.is_none_or(|u| tick < u)
    }

    /// The robots a malfunction disables.
    pub fn disables(&self, r: Robot) -> bool {
        matches!(&self.kind, Kind::Trial(ChallengeKind::RobotMalfunction { robots, .. }) if robots.contains(&r))
    }

    pub fn human(&self) -> Option<Behavior> {
        match &self.kind {
            Kind::Trial(ChallengeKind::Human { behavior, .. }) => Some(*behavior),
            _ => None,
        }
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
}

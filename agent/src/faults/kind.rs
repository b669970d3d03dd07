//! The eight ARIAC 2023 agility challenges, by name.

use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FaultKind {
    RobotMalfunction,
    FaultyGripper,
    FaultyPart,
    FlippedPart,
    SensorBlackout,
    HighPriorityOrder,
    InsufficientParts,
    HumanTooClose,
}

impl FaultKind {
    pub const ALL: [FaultKind; 8] = [
        FaultKind::RobotMalfunction,
        FaultKind::FaultyGripper,
        FaultKind::FaultyPart,
        FaultKind::FlippedPart,
        FaultKind::SensorBlackout,
        FaultKind::HighPriorityOrder,
        FaultKind::InsufficientParts,
        FaultKind::HumanTooClose,
    ];

    pub fn name(self) -> &'static str {
        match self {
            FaultKind::RobotMalfunction => "robot_malfunction",
            FaultKind::FaultyGripper => "faulty_gripper",
            FaultKind::FaultyPart => "faulty_part",
            FaultKind::FlippedPart => "flipped_part",
            FaultKind::SensorBlackout => "sensor_blackout",
            FaultKind::HighPriorityOrder => "high_priority_order",
            FaultKind::InsufficientParts => "insufficient_parts",
            FaultKind::HumanTooClose => "human_too_close",
        }
    }

    pub fn from_name(s: &str) -> Option<FaultKind> {
        FaultKind::ALL.into_iter().find(|k| k.name() == s)
    }
}

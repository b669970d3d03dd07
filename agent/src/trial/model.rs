//! A trial as btc reads it: the ARIAC 2023 trial configuration, typed, each
//! item with the byte range it came from (for diagnostics at run time).

use super::yaml::Range;
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PartType {
    Battery,
    Pump,
    Regulator,
    Sensor,
}

impl PartType {
    pub const ALL: [PartType; 4] = [
        PartType::Battery,
        PartType::Pump,
        PartType::Regulator,
        PartType::Sensor,
    ];

    pub fn name(self) -> &'static str {
        match self {
            PartType::Battery => "battery",
            PartType::Pump => "pump",
            PartType::Regulator => "regulator",
            PartType::Sensor => "sensor",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Color {
    Red,
    Green,
    Blue,
    Orange,
    Purple,
}

impl Color {
    pub const ALL: [Color; 5] = [
        Color::Red,
        Color::Green,
        Color::Blue,
        Color::Orange,
        Color::Purple,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Color::Red => "red",
            Color::Green => "green",
            Color::Blue => "blue",
            Color::Orange => "orange",
            Color::Purple => "purple",
        }
    }
}

/// A kind of part: what orders ask for and bins hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct PartKind {
    #[serde(rename = "type")]
    pub ty: PartType,
    pub color: Color,
}

impl std::fmt::Display for PartKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} {}", self.color.name(), self.ty.name())
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Trial {
    /// Seconds; `None` for `-1` (no limit).
    pub time_limit: Option<f64>,
    pub trays: Vec<TrayOnTable>,
    pub bins: Vec<BinLot>,
    pub agvs: Vec<AgvLoad>,
    pub conveyor: Option<Conveyor>,
    pub orders: Vec<Order>,
    pub challenges: Vec<Challenge>,
}

/// A kit tray on a tray table slot (`kitting_trays`: slots 1–3 on table 1,
/// 4–6 on table 2).
#[derive(Clone, Debug, PartialEq)]
pub struct TrayOnTable {
    pub tray_id: u8,
    pub slot: u8,
    pub range: Range,
}

/// Parts of one kind in a bin (`parts.bins.binN` entry).
#[derive(Clone, Debug, PartialEq)]
pub struct BinLot {
    pub bin: u8,
    pub kind: PartKind,
    pub slots: Vec<u8>,
    pub flipped: bool,
    pub range: Range,
}

/// An AGV that starts with a tray and parts (`parts.agvs.agvN`).
#[derive(Clone, Debug, PartialEq)]
pub struct AgvLoad {
    pub agv: u8,
    pub tray_id: u8,
    pub parts: Vec<AgvPart>,
    pub range: Range,
}

#[derive(Clone, Debug, PartialEq)]
pub struct AgvPart {
    pub kind: PartKind,
    pub quadrant: u8,
    pub flipped: bool,
    pub range: Range,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SpawnOrder {
    Sequential,
    Random,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Conveyor {
    pub active: bool,
    /// Seconds between two parts.
    pub spawn_rate: f64,
    pub order: SpawnOrder,
    pub lots: Vec<ConveyorLot>,
    pub range: Range,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ConveyorLot {
    pub kind: PartKind,
    pub number: u32,
    pub flipped: bool,
    pub range: Range,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum OrderType {
    Kitting,
    Assembly,
    Combined,
}

impl OrderType {
    pub fn name(self) -> &'static str {
        match self {
            OrderType::Kitting => "kitting",
            OrderType::Assembly => "assembly",
            OrderType::Combined => "combined",
        }
    }
}

/// When an order is announced or a challenge starts.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Condition {
    /// Seconds into the trial.
    Time(f64),
    /// A part of this kind placed on this AGV.
    PartPlace { agv: u8, kind: PartKind },
    /// This order submitted.
    Submission(String),
}

/// Where a kit goes when it is submitted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Destination {
    Warehouse,
    Kitting,
    Station(u8),
}

impl std::fmt::Display for Destination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Destination::Warehouse => f.write_str("warehouse"),
            Destination::Kitting => f.write_str("kitting"),
            Destination::Station(n) => write!(f, "as{n}"),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct KitProduct {
    pub kind: PartKind,
    pub quadrant: u8,
    pub range: Range,
}

#[derive(Clone, Debug, PartialEq)]
pub struct AssemblyProduct {
    pub kind: PartKind,
    pub range: Range,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Task {
    Kitting {
        agv: u8,
        tray_id: u8,
        destination: Destination,
        products: Vec<KitProduct>,
    },
    Assembly {
        agvs: Vec<u8>,
        station: u8,
        products: Vec<AssemblyProduct>,
    },
    Combined {
        station: u8,
        products: Vec<AssemblyProduct>,
    },
}

impl Task {
    pub fn order_type(&self) -> OrderType {
        match self {
            Task::Kitting { .. } => OrderType::Kitting,
            Task::Assembly { .. } => OrderType::Assembly,
            Task::Combined { .. } => OrderType::Combined,
        }
    }

    /// The parts the task asks for, in the file's order.
    pub fn kinds(&self) -> Vec<PartKind> {
        match self {
            Task::Kitting { products, .. } => products.iter().map(|p| p.kind).collect(),
            Task::Assembly { products, .. } | Task::Combined { products, .. } => {
                products.iter().map(|p| p.kind).collect()
            }
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Order {
    pub id: String,
    pub priority: bool,
    pub announcement: Condition,
    pub task: Task,
    pub range: Range,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Robot {
    FloorRobot,
    CeilingRobot,
}

impl Robot {
    pub const ALL: [Robot; 2] = [Robot::FloorRobot, Robot::CeilingRobot];

    pub fn name(self) -> &'static str {
        match self {
            Robot::FloorRobot => "floor_robot",
            Robot::CeilingRobot => "ceiling_robot",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Behavior {
    Indifferent,
    Antagonistic,
    Helpful,
}

/// The sensor types a blackout can disable.
pub const SENSOR_TYPES: [&str; 6] = [
    "break_beam",
    "proximity",
    "laser_profiler",
    "lidar",
    "camera",
    "logical_camera",
];

#[derive(Clone, Debug, PartialEq)]
pub enum ChallengeKind {
    /// The first part placed in each listed quadrant of the order's kit is
    /// faulty.
    FaultyPart {
        order_id: String,
        quadrants: [bool; 4],
    },
    /// The robot's gripper drops a part of this kind `delay` seconds after
    /// picking it, on the (`drop_after` + 1)-th such pick.
    DroppedPart {
        robot: Robot,
        kind: PartKind,
        drop_after: u32,
        delay: f64,
    },
    RobotMalfunction {
        duration: f64,
        robots: Vec<Robot>,
        condition: Condition,
    },
    SensorBlackout {
        duration: f64,
        sensors: Vec<String>,
        condition: Condition,
    },
    Human {
        behavior: Behavior,
        condition: Condition,
    },
}

impl ChallengeKind {
    pub fn name(&self) -> &'static str {
        match self {
            ChallengeKind::FaultyPart { .. } => "faulty_part",
            ChallengeKind::DroppedPart { .. } => "dropped_part",
            ChallengeKind::RobotMalfunction { .. } => "robot_malfunction",
            ChallengeKind::SensorBlackout { .. } => "sensor_blackout",
            ChallengeKind::Human { .. } => "human",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Challenge {
    pub kind: ChallengeKind,
    pub range: Range,
}

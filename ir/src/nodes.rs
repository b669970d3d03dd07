//! The control and decorator nodes a tree is built of.

use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum ControlKind {
    Sequence,
    ReactiveSequence,
    Fallback,
    ReactiveFallback,
    Parallel { success: u32, failure: u32 },
}

impl ControlKind {
    pub fn keyword(self) -> &'static str {
        match self {
            ControlKind::Sequence => "sequence",
            ControlKind::ReactiveSequence => "reactive_sequence",
            ControlKind::Fallback => "fallback",
            ControlKind::ReactiveFallback => "reactive_fallback",
            ControlKind::Parallel { .. } => "parallel",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum DecoratorKind {
    Retry { times: u32 },
    Repeat { times: u32 },
    Timeout { ms: u64 },
    Inverter,
    ForceSuccess,
    ForceFailure,
}

impl DecoratorKind {
    pub fn keyword(self) -> &'static str {
        match self {
            DecoratorKind::Retry { .. } => "retry",
            DecoratorKind::Repeat { .. } => "repeat",
            DecoratorKind::Timeout { .. } => "timeout",
            DecoratorKind::Inverter => "inverter",
            DecoratorKind::ForceSuccess => "force_success",
            DecoratorKind::ForceFailure => "force_failure",
        }
    }
}

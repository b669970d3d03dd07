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

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum DecoratorKind {
    Retry { times: Count },
    Repeat { times: Count },
    Timeout { ms: Count },
    Inverter,
    ForceSuccess,
    ForceFailure,
}

/// A decorator's count or duration: a number, or (in a rule's tree, when
/// the number depends on the plan step) a port of the enclosing tree,
/// which each call fills in (`{name}` in BT.CPP). In JSON a number is a
/// number and a port is `{"param": "name"}`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Count {
    Fixed(u64),
    Param { param: String },
}

impl Count {
    /// The number, when it is one.
    pub fn fixed(&self) -> Option<u64> {
        match self {
            Count::Fixed(n) => Some(*n),
            Count::Param { .. } => None,
        }
    }
}

impl std::fmt::Display for Count {
    /// `3`, or `{name}` as BT.CPP writes a port.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Count::Fixed(n) => write!(f, "{n}"),
            Count::Param { param } => write!(f, "{{{param}}}"),
        }
    }
}

impl DecoratorKind {
    pub fn keyword(&self) -> &'static str {
        match self {
            DecoratorKind::Retry { .. } => "retry",
            DecoratorKind::Repeat { .. } => "repeat",
            DecoratorKind::Timeout { .. } => "timeout",
            DecoratorKind::Inverter => "inverter",
            DecoratorKind::ForceSuccess => "force_success",
            DecoratorKind::ForceFailure => "force_failure",
        }
    }

    /// The count or duration, for the decorators that have one.
    pub fn count(&self) -> Option<&Count> {
        match self {
            DecoratorKind::Retry { times } | DecoratorKind::Repeat { times } => Some(times),
            DecoratorKind::Timeout { ms } => Some(ms),
            _ => None,
        }
    }

    /// The same decorator with its count replaced.
    pub fn with_count(&self, count: Count) -> DecoratorKind {
        match self {
            DecoratorKind::Retry { .. } => DecoratorKind::Retry { times: count },
            DecoratorKind::Repeat { .. } => DecoratorKind::Repeat { times: count },
            DecoratorKind::Timeout { .. } => DecoratorKind::Timeout { ms: count },
            other => other.clone(),
        }
    }
}

//! The control and decorator nodes a tree is built of.

use crate::vocab::{ControlName, DecoratorName, NodeSpec};
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
    pub fn name(self) -> ControlName {
        match self {
            ControlKind::Sequence => ControlName::Sequence,
            ControlKind::ReactiveSequence => ControlName::ReactiveSequence,
            ControlKind::Fallback => ControlName::Fallback,
            ControlKind::ReactiveFallback => ControlName::ReactiveFallback,
            ControlKind::Parallel { .. } => ControlName::Parallel,
        }
    }

    /// The control `name` with its parameters' values in the order the
    /// vocabulary lists them (`parallel`: success, failure).
    pub fn new(name: ControlName, params: &[u32]) -> ControlKind {
        let p = |i: usize| params.get(i).copied().unwrap_or(0);
        match name {
            ControlName::Sequence => ControlKind::Sequence,
            ControlName::ReactiveSequence => ControlKind::ReactiveSequence,
            ControlName::Fallback => ControlKind::Fallback,
            ControlName::ReactiveFallback => ControlKind::ReactiveFallback,
            ControlName::Parallel => ControlKind::Parallel {
                success: p(0),
                failure: p(1),
            },
        }
    }

    /// The parameters' values, in the vocabulary's order.
    pub fn params(self) -> Vec<u32> {
        match self {
            ControlKind::Parallel { success, failure } => vec![success, failure],
            _ => Vec::new(),
        }
    }

    pub fn spec(self) -> &'static NodeSpec {
        self.name().spec()
    }

    pub fn keyword(self) -> &'static str {
        self.spec().keyword
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
    Delay { ms: Count },
    RunOnce,
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
    pub fn name(&self) -> DecoratorName {
        match self {
            DecoratorKind::Retry { .. } => DecoratorName::Retry,
            DecoratorKind::Repeat { .. } => DecoratorName::Repeat,
            DecoratorKind::Timeout { .. } => DecoratorName::Timeout,
            DecoratorKind::Inverter => DecoratorName::Inverter,
            DecoratorKind::ForceSuccess => DecoratorName::ForceSuccess,
            DecoratorKind::ForceFailure => DecoratorName::ForceFailure,
            DecoratorKind::Delay { .. } => DecoratorName::Delay,
            DecoratorKind::RunOnce => DecoratorName::RunOnce,
        }
    }

    /// The decorator `name` with its count (ignored by those without one).
    pub fn new(name: DecoratorName, count: Count) -> DecoratorKind {
        match name {
            DecoratorName::Retry => DecoratorKind::Retry { times: count },
            DecoratorName::Repeat => DecoratorKind::Repeat { times: count },
            DecoratorName::Timeout => DecoratorKind::Timeout { ms: count },
            DecoratorName::Inverter => DecoratorKind::Inverter,
            DecoratorName::ForceSuccess => DecoratorKind::ForceSuccess,
            DecoratorName::ForceFailure => DecoratorKind::ForceFailure,
            DecoratorName::Delay => DecoratorKind::Delay { ms: count },
            DecoratorName::RunOnce => DecoratorKind::RunOnce,
        }
    }

    pub fn spec(&self) -> &'static NodeSpec {
        self.name().spec()
    }

    pub fn keyword(&self) -> &'static str {
        self.spec().keyword
    }

    /// The count or duration, for the decorators that have one.
    pub fn count(&self) -> Option<&Count> {
        match self {
            DecoratorKind::Retry { times } | DecoratorKind::Repeat { times } => Some(times),
            DecoratorKind::Timeout { ms } | DecoratorKind::Delay { ms } => Some(ms),
            _ => None,
        }
    }

    /// The same decorator with its count replaced.
    pub fn with_count(&self, count: Count) -> DecoratorKind {
        DecoratorKind::new(self.name(), count)
    }
}

//! A port as the engine resolved it when the tree was built: a constant
//! or a blackboard slot.

use super::value::Value;

/// Where a port's value comes from.
#[derive(Clone, Debug)]
pub(crate) enum Src {
    Const(Value),
    Slot(u32),
}

#[derive(Clone, Debug)]
pub(crate) struct PortBind {
    pub name: Box<str>,
    pub src: Src,
}

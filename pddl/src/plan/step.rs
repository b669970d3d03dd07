//! A plan step, and the call it makes. Steps that write the same call share
//! one: a long plan repeats few ground actions (100,000 steps of the P3
//! plan make 16 calls), so its steps then cost no name allocation each,
//! and passes over calls (typing, the name fit) can do each call's work
//! once.

use crate::ast::{Name, SmolStr};
use crate::source::Span;
use serde::ser::{Serialize, SerializeStruct, Serializer};
use std::sync::Arc;

/// What a step calls, as written: its action and arguments, lower-cased,
/// with where each is relative to the step's start (the same for every
/// step that writes the call the same way).
#[derive(Clone, Debug, PartialEq)]
pub struct Call {
    pub action: SmolStr,
    pub args: Box<[SmolStr]>,
    /// `(start, end)` of the action, then of each argument, as offsets
    /// from the step's span start.
    places: Box<[(u32, u32)]>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct PlanStep {
    pub call: Arc<Call>,
    pub time: Option<f64>,
    pub duration: Option<f64>,
    /// 1-based line number in the plan file.
    pub line: u32,
    /// The step as written, from its action name (or `(`) to its end.
    pub span: Span,
}

impl Call {
    /// The call of a step spanning `span`, from its names (which lie within
    /// it).
    pub fn new(action: Name, args: Vec<Name>, span: Span) -> Call {
        let at = |n: &Name| (n.span.start - span.start, n.span.end - span.start);
        let places = std::iter::once(at(&action))
            .chain(args.iter().map(at))
            .collect();
        Call {
            action: action.name,
            args: args.into_iter().map(|a| a.name).collect(),
            places,
        }
    }
}

impl PlanStep {
    /// A step with a call of its own.
    pub fn new(
        action: Name,
        args: Vec<Name>,
        time: Option<f64>,
        duration: Option<f64>,
        line: u32,
        span: Span,
    ) -> PlanStep {
        PlanStep {
            call: Arc::new(Call::new(action, args, span)),
            time,
            duration,
            line,
            span,
        }
    }

    pub fn action_name(&self) -> &str {
        &self.call.action
    }

    /// The action's name where this step writes it.
    pub fn action(&self) -> Name {
        self.name(self.call.action.clone(), 0)
    }

    pub fn arg_count(&self) -> usize {
        self.call.args.len()
    }

    /// The arguments where this step writes them.
    pub fn args(&self) -> impl ExactSizeIterator<Item = Name> + '_ {
        (0..self.call.args.len()).map(|i| self.name(self.call.args[i].clone(), i + 1))
    }

    fn name(&self, name: SmolStr, place: usize) -> Name {
        let (start, end) = self.call.places[place];
        Name {
            name,
            span: Span {
                file: self.span.file,
                start: self.span.start + start,
                end: self.span.start + end,
            },
        }
    }
}

/// As before calls were shared: the action and arguments as names.
impl Serialize for PlanStep {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut st = s.serialize_struct("PlanStep", 6)?;
        st.serialize_field("action", &self.action())?;
        st.serialize_field("args", &self.args().collect::<Vec<_>>())?;
        st.serialize_field("time", &self.time)?;
        st.serialize_field("duration", &self.duration)?;
        st.serialize_field("line", &self.line)?;
        st.serialize_field("span", &self.span)?;
        st.end()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn name(text: &str, start: usize, end: usize) -> Name {
        Name {
            name: text.into(),
            span: Span::new(3, start, end),
        }
    }

    #[test]
    fn names_are_placed_where_each_step_writes_them() {
        let span = Span::new(3, 10, 25);
        let (action, args) = (
            name("move", 11, 15),
            vec![name("a", 16, 17), name("bb", 20, 22)],
        );
        let step = PlanStep::new(action.clone(), args.clone(), None, None, 2, span);
        assert_eq!(step.action(), action);
        assert_eq!(step.args().collect::<Vec<_>>(), args);
        // The same call written at another place.
        let moved = PlanStep {
            span: Span::new(3, 40, 55),
            ..step.clone()
        };
        assert_eq!(moved.action().span, Span::new(3, 41, 45));
        assert_eq!(moved.args().nth(1).unwrap().span, Span::new(3, 50, 52));
    }
}

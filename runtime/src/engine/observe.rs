//! The tick's observers: the engine tells what happens (status changes,
//! steps, faults, fault records, commands) to the observers its caller
//! registered, as BehaviorTree.CPP tells its `StatusChangeLogger`s, and
//! keeps none of it. A trace file, a Groot2 replay and a test's log of
//! step events are each an observer (`crate::observers`, `crate::btlog`).

use super::record::FaultRecord;
use super::step::StepRt;
use super::{Engine, Injector, NodeMeta, Status};
use std::any::Any;

/// What happened during a tick.
#[derive(Clone, Debug, PartialEq)]
pub enum TickEvent {
    Status {
        tick: u64,
        node: u32,
        from: Status,
        to: Status,
    },
    StepStarted {
        tick: u64,
        step: u32,
    },
    StepFinished {
        tick: u64,
        step: u32,
    },
    Fault {
        tick: u64,
        fault: usize,
        ended: bool,
    },
    /// A fault record was written: [`RunView::record`] has it.
    Record(usize),
    Command {
        tick: u64,
        seq: u64,
        node: u32,
    },
}

/// What an observer may read of the run when it is told of an event: the
/// names behind the event's indexes.
pub struct RunView<'a> {
    pub meta: &'a [NodeMeta],
    steps: &'a [StepRt],
    injector: Option<&'a dyn Injector>,
    records: &'a [FaultRecord],
}

impl RunView<'_> {
    /// The plan step's action, as the plan writes it (0-based).
    pub fn step_label(&self, step: u32) -> Option<&str> {
        self.steps.get(step as usize).map(|s| s.label.as_str())
    }

    /// An injected fault's label and the name of its kind.
    pub fn fault(&self, fault: usize) -> Option<(String, &'static str)> {
        self.injector?.describe(fault)
    }

    pub fn record(&self, k: usize) -> Option<&FaultRecord> {
        self.records.get(k)
    }
}

/// Something told of every event of the run, in order. It is `Any` so
/// that the caller can have it back, with what it gathered, by its type
/// ([`Engine::observer`], [`Engine::take_observer`]).
pub trait Observer: Any {
    fn observe(&mut self, event: &TickEvent, run: &RunView<'_>);
}

impl<'w> Engine<'w> {
    /// Registers an observer: from now on it is told of every event.
    pub fn observe(&mut self, observer: impl Observer) {
        self.observers.push(Box::new(observer));
    }

    /// The first registered observer of type `O`.
    pub fn observer<O: Observer>(&self) -> Option<&O> {
        self.observers
            .iter()
            .find_map(|o| (o.as_ref() as &dyn Any).downcast_ref::<O>())
    }

    pub fn observer_mut<O: Observer>(&mut self) -> Option<&mut O> {
        self.observers
            .iter_mut()
            .find_map(|o| (o.as_mut() as &mut dyn Any).downcast_mut::<O>())
    }

    /// Unregisters the first observer of type `O` and gives it back.
    pub fn take_observer<O: Observer>(&mut self) -> Option<O> {
        let k = self
            .observers
            .iter()
            .position(|o| (o.as_ref() as &dyn Any).is::<O>())?;
        let o: Box<dyn Any> = self.observers.remove(k);
        o.downcast::<O>().ok().map(|b| *b)
    }

    /// Whether anyone observes the run (events are built only then).
    #[inline]
    pub(crate) fn observed(&self) -> bool {
        !self.observers.is_empty()
    }

    /// Tells every observer of `event`.
    #[cold]
    pub(crate) fn notify(&mut self, event: TickEvent) {
        let run = RunView {
            meta: &self.meta,
            steps: &self.steps,
            injector: self.injector.as_deref(),
            records: &self.records,
        };
        for o in &mut self.observers {
            o.observe(&event, &run);
        }
    }

    /// A status change, told when the run is observed.
    #[cold]
    pub(super) fn observe_status(&mut self, node: u32, from: Status, to: Status) {
        self.notify(TickEvent::Status {
            tick: self.tick,
            node,
            from,
            to,
        });
    }
}

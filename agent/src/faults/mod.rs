//! The eight ARIAC 2023 agility challenges in symbolic form, injected into
//! btc's engine: a scenario file's faults ([`Scenario`]), and the injector
//! that makes them happen at the engine's hook points ([`Faults`]). The
//! engine knows no kind of fault; this is where the ARIAC ones live, beside
//! the trial that models them in the cell (`crate::sim::challenges`). A new
//! kind of fault is a [`FaultKind`], what a scenario says of it
//! (`scenario`) and what it does at the hooks (`injector`).

mod engine;
mod injector;
mod kind;
mod scenario;

pub use btc_runtime::FaultOutcome;
pub use engine::FaultsOnEngine;
pub use injector::{FaultRt, Faults};
pub use kind::FaultKind;
pub use scenario::{Blackout, FaultSpec, Scenario, Trigger};

//! The ARIAC faults in an engine: what the replanning loop, the trial and
//! `btc run` ask of the faults of a run, on the engine that holds them.

use super::{Faults, Scenario};
use btc_runtime::{Engine, LoadError};

/// An engine's ARIAC faults ([`Faults`], its injector).
pub trait FaultsOnEngine {
    /// Arms a scenario's faults beside those the engine has.
    fn add_faults(&mut self, s: &Scenario) -> Result<(), LoadError>;
    /// The engine's faults, taken out of it (none if it had none).
    fn take_faults(&mut self) -> Faults;
    /// Puts faults taken from an earlier engine into this one; the goals
    /// of faults still to come are read again in this engine's KB.
    fn restore_faults(&mut self, faults: Faults);
    /// Lets time pass, with no tree ticked, until no fault with a duration
    /// is in effect or tick `limit` is reached; faults due meanwhile start
    /// and end (a malfunction's repair gives its facts back). Returns the
    /// ticks waited.
    fn wait_for_faults(&mut self, limit: u64) -> u64;
    /// The parts that faults discarded or found missing, with the fault's
    /// label.
    fn discarded_parts(&self) -> Vec<(String, String)>;
}

impl FaultsOnEngine for Engine<'_> {
    fn add_faults(&mut self, s: &Scenario) -> Result<(), LoadError> {
        let mut faults = self.take_faults();
        let steps = self.plan_steps();
        let armed = faults.arm(s, self.kb.as_mut(), steps);
        self.inject(faults);
        armed
    }

    fn take_faults(&mut self) -> Faults {
        self.take_injector::<Faults>().unwrap_or_default()
    }

    fn restore_faults(&mut self, mut faults: Faults) {
        faults.rebind(self.kb.as_mut());
        self.inject(faults);
    }

    fn wait_for_faults(&mut self, limit: u64) -> u64 {
        let start = self.tick;
        while self.tick < limit
            && self
                .injector::<Faults>()
                .is_some_and(Faults::timed_in_effect)
        {
            self.pass_tick();
        }
        self.tick - start
    }

    fn discarded_parts(&self) -> Vec<(String, String)> {
        self.injector::<Faults>()
            .map(Faults::discarded_parts)
            .unwrap_or_default()
    }
}

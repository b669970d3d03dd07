//! An executor of `btc_api::Agent::run_with` that runs the attempts in
//! btc's engine and reports the faults a scenario injects as a behaviour
//! would: the reference the embedders' executors are compared with.

use btc_api::{AttemptInput, Executed, Executor, Faults, Record, RunOptions};

/// An executor outside the loop that runs each attempt in btc's engine, the
/// first with a scenario's faults, and reports the faults that happened as
/// a behaviour would: the loop then knows of them only from the report.
pub struct ReportingEngine {
    faults: Option<Faults>,
    /// The KB the last attempt left.
    pub kb: Vec<String>,
}

impl ReportingEngine {
    pub fn new(faults: Faults) -> ReportingEngine {
        ReportingEngine {
            faults: Some(faults),
            kb: Vec::new(),
        }
    }
}

impl Executor for ReportingEngine {
    fn execute(&mut self, a: &AttemptInput) -> Result<Executed, String> {
        let faults = self.faults.take();
        let options = RunOptions {
            max_ticks: a.max_ticks,
            ..RunOptions::default()
        };
        let r = a
            .tree
            .run(&options, Vec::new(), faults.as_ref())
            .map_err(|e| e.to_string())?;
        let reported = faults
            .iter()
            .flat_map(Faults::reported)
            .filter_map(|(label, mut f)| {
                let met = r.faults.iter().find(|o| o.fault == label)?;
                f.tick = met.met_at?;
                Some(f)
            })
            .collect();
        self.kb = r.kb.clone();
        Ok(Executed {
            status: r.status,
            state: r.kb,
            ticks: r.ticks,
            steps_done: r.steps_done,
            records: r
                .records
                .iter()
                .map(|x| Record {
                    node_id: x.node_id.clone(),
                    node_name: x.node_name.clone(),
                    reason: x.reason.clone(),
                    step: x.step,
                    tick: x.tick,
                    faults: x.faults.clone(),
                })
                .collect(),
            faults: reported,
        })
    }
}

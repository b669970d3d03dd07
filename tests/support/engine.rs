//! An executor of `btc_api::Agent::run_with` that runs the attempts in
//! btc's engine and reports the faults a scenario injects as a behaviour
//! would: the reference the embedders' executors are compared with. An
//! order that preempts the tree stops it at its tick, as an embedder's
//! executor (and `btc run --replan`) does.

use btc_api::{
    AttemptInput, Executed, Executor, Faults, Record, ReportedFault, RunOptions, RunReport,
};

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

/// The faults of `faults` that the run `r` met, as a behaviour reports
/// them, with the tick each happened at.
fn met(faults: Option<&Faults>, r: &RunReport) -> Vec<ReportedFault> {
    faults
        .iter()
        .flat_map(|f| f.reported())
        .filter_map(|(label, mut f)| {
            let met = r.faults.iter().find(|o| o.fault == label)?;
            f.tick = met.met_at?;
            Some(f)
        })
        .collect()
}

/// Whether a goal holds in a KB of facts: an atom, or a conjunction of
/// atoms (what the scenarios' orders want); anything else is refused.
fn holds(goal: &str, kb: &[String]) -> bool {
    let inner = goal.strip_prefix("(and ").and_then(|g| g.strip_suffix(')'));
    let Some(inner) = inner else {
        assert!(!goal[1..].contains('('), "cannot evaluate `{goal}`");
        return kb.iter().any(|f| f == goal);
    };
    let mut depth = 0;
    let mut from = 0;
    let mut all = true;
    for (i, c) in inner.char_indices() {
        match c {
            '(' => {
                if depth == 0 {
                    from = i;
                }
                depth += 1;
            }
            ')' => {
                depth -= 1;
                if depth == 0 {
                    all &= holds(&inner[from..=i], kb);
                }
            }
            _ => {}
        }
    }
    all
}

impl Executor for ReportingEngine {
    fn execute(&mut self, a: &AttemptInput) -> Result<Executed, String> {
        let faults = self.faults.take();
        let run = |max_ticks: u64| {
            let options = RunOptions {
                max_ticks,
                ..RunOptions::default()
            };
            a.tree
                .run(&options, Vec::new(), faults.as_ref())
                .map_err(|e| e.to_string())
        };
        let mut r = run(a.max_ticks)?;
        let mut reported = met(faults.as_ref(), &r);
        // An order whose goal does not hold when it comes preempts the
        // tree before that tick, as in `btc run --replan`, where
        // `Tree::run` ticks to the end: the run again, up to the tick
        // before, with the order reported at its tick.
        let preempting = reported.iter().find_map(|f| {
            let goal = f
                .goal
                .as_ref()
                .filter(|_| f.kind == "high_priority_order")?;
            let at = f.tick;
            Some((goal.clone(), at, f.clone()))
        });
        if let Some((goal, at, order)) = preempting {
            let before = run(at.saturating_sub(1))?;
            let mut kb: Vec<String> = before
                .kb
                .iter()
                .filter(|k| !order.retract.contains(k))
                .cloned()
                .collect();
            kb.extend(order.add.iter().filter(|f| !before.kb.contains(f)).cloned());
            if !holds(&goal, &kb) {
                reported = met(faults.as_ref(), &before);
                reported.push(order);
                r = before;
                r.ticks = at;
                r.status = btc_api::Status::Running;
                r.kb = kb;
            }
        }
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

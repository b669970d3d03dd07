//! What a trial came to: the scoreboard per order and per agent, the
//! challenges and how each ended, every part task with its attempts.

use super::model::Sim;
use super::scoring;
pub use super::scoring::Breakdown;
use super::tasks::{Task, TaskState};
use crate::trial::OrderType;
use serde::Serialize;

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FaultMet {
    pub challenge: String,
    /// Trial seconds.
    pub at: f64,
    pub ended: String,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OrderReport {
    pub id: String,
    #[serde(rename = "type")]
    pub ty: OrderType,
    pub priority: bool,
    /// `submitted`, `not submitted` (the trial ended first) or `not announced`.
    pub state: String,
    pub announced: Option<f64>,
    pub submitted: Option<f64>,
    /// Submitted minus announced, in trial seconds.
    pub time: Option<f64>,
    pub score: i64,
    /// The most the order could score.
    pub best: i64,
    pub breakdown: Option<Breakdown>,
    pub part_tasks: usize,
    pub done: usize,
    pub failed: usize,
    pub reassignments: u32,
    pub faults: Vec<FaultMet>,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AgentReport {
    pub robot: String,
    /// Trial seconds with a task.
    pub busy: f64,
    pub tasks_done: usize,
    pub tasks_failed: usize,
    pub plans: usize,
    pub planning_ms: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ChallengeReport {
    pub challenge: String,
    pub kind: String,
    pub met: Option<f64>,
    pub ended: String,
}

#[derive(Clone, Debug, Serialize)]
pub struct TrialReport {
    pub trial: String,
    pub seed: u64,
    /// Trial seconds the simulation ran.
    pub seconds: f64,
    pub ticks: u64,
    /// The completion score: every submitted order's task score.
    pub score: i64,
    pub best: i64,
    pub orders: Vec<OrderReport>,
    pub agents: Vec<AgentReport>,
    pub challenges: Vec<ChallengeReport>,
    pub tasks: Vec<Task>,
    /// Why the simulation stopped.
    pub stopped: String,
    /// Wall-clock time of the whole run.
    pub elapsed_ms: f64,
    /// The task-level events and every attempt's tree trace, as JSON Lines
    /// (when tracing).
    #[serde(skip)]
    pub trace: String,
}

impl TrialReport {
    /// Every part task ended (done, or failed with its cause).
    pub fn all_tasks_ended(&self) -> bool {
        self.tasks.iter().all(|t| !t.is_open())
    }
}

/// Mean and spread of a number over repeated trials.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Spread {
    pub mean: f64,
    /// Sample standard deviation (0 for one value).
    pub sd: f64,
    pub min: f64,
    pub max: f64,
    pub n: usize,
}

impl Spread {
    pub fn of(values: &[f64]) -> Spread {
        let n = values.len();
        if n == 0 {
            return Spread {
                mean: 0.0,
                sd: 0.0,
                min: 0.0,
                max: 0.0,
                n: 0,
            };
        }
        let mean = values.iter().sum::<f64>() / n as f64;
        let var = if n > 1 {
            values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64
        } else {
            0.0
        };
        Spread {
            mean,
            sd: var.sqrt(),
            min: values.iter().copied().fold(f64::INFINITY, f64::min),
            max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            n,
        }
    }
}

/// Repeated trials: each order's score and time, and the trial's.
#[derive(Clone, Debug, Serialize)]
pub struct TrialsSummary {
    pub trial: String,
    pub seeds: Vec<u64>,
    pub score: Spread,
    pub seconds: Spread,
    pub orders: Vec<OrderSpread>,
}

#[derive(Clone, Debug, Serialize)]
pub struct OrderSpread {
    pub id: String,
    pub score: Spread,
    /// Over the runs that submitted the order.
    pub time: Spread,
    pub submitted: usize,
}

impl TrialsSummary {
    pub fn of(runs: &[TrialReport]) -> TrialsSummary {
        let f =
            |g: &dyn Fn(&TrialReport) -> f64| Spread::of(&runs.iter().map(g).collect::<Vec<_>>());
        let ids: Vec<String> = runs
            .first()
            .map(|r| r.orders.iter().map(|o| o.id.clone()).collect())
            .unwrap_or_default();
        let orders = ids
            .iter()
            .map(|id| {
                let os: Vec<&OrderReport> = runs
                    .iter()
                    .filter_map(|r| r.orders.iter().find(|o| o.id == *id))
                    .collect();
                OrderSpread {
                    id: id.clone(),
                    score: Spread::of(&os.iter().map(|o| o.score as f64).collect::<Vec<_>>()),
                    time: Spread::of(&os.iter().filter_map(|o| o.time).collect::<Vec<_>>()),
                    submitted: os.iter().filter(|o| o.submitted.is_some()).count(),
                }
            })
            .collect();
        TrialsSummary {
            trial: runs.first().map(|r| r.trial.clone()).unwrap_or_default(),
            seeds: runs.iter().map(|r| r.seed).collect(),
            score: f(&|r| r.score as f64),
            seconds: f(&|r| r.seconds),
            orders,
        }
    }
}

impl Sim<'_, '_> {
    /// What the trial came to.
    pub(super) fn report(&mut self, name: &str) -> TrialReport {
        let mut orders = Vec::new();
        for (k, o) in self.trial.orders.iter().enumerate() {
            let rt = &self.tm.orders[k];
            let tasks: Vec<&Task> = rt
                .tasks
                .iter()
                .map(|&t| &self.tm.tasks[t])
                .filter(|t| !matches!(t.state, TaskState::Split { .. }))
                .collect();
            let faults: Vec<FaultMet> = self
                .challenges
                .iter()
                .filter(|c| c.orders.contains(&k) && c.met_at.is_some())
                .map(|c| FaultMet {
                    challenge: c.label.clone(),
                    at: self.secs(c.met_at.unwrap_or(1) - 1),
                    ended: c.end(Some(
                        self.tm.orders[k].score
                            == scoring::best(o.task.order_type(), o.task.kinds().len()),
                    )),
                })
                .collect();
            orders.push(OrderReport {
                id: o.id.clone(),
                ty: o.task.order_type(),
                priority: o.priority,
                state: match (rt.announced, rt.submitted) {
                    (None, _) => "not announced".into(),
                    (Some(_), None) => "not submitted".into(),
                    (Some(_), Some(_)) => "submitted".into(),
                },
                announced: rt.announced.map(|t| self.secs(t - 1)),
                submitted: rt.submitted.map(|t| self.secs(t)),
                time: match (rt.announced, rt.submitted) {
                    (Some(a), Some(s)) => Some(self.secs(s + 1 - a)),
                    _ => None,
                },
                score: if rt.submitted.is_some() { rt.score } else { 0 },
                best: scoring::best(o.task.order_type(), o.task.kinds().len()),
                breakdown: rt.breakdown.clone(),
                part_tasks: tasks.len(),
                done: tasks.iter().filter(|t| t.is_done()).count(),
                failed: tasks
                    .iter()
                    .filter(|t| matches!(t.state, TaskState::Failed { .. }))
                    .count(),
                reassignments: tasks.iter().map(|t| t.reassignments).sum(),
                faults,
            });
        }
        let agents = self
            .agents
            .iter()
            .map(|a| AgentReport {
                robot: self.cell.robot(a.robot).object.clone(),
                busy: self.secs(a.busy),
                tasks_done: a.done,
                tasks_failed: self
                    .tm
                    .tasks
                    .iter()
                    .filter(|t| {
                        matches!(t.state, TaskState::Failed { .. })
                            && t.attempts
                                .last()
                                .is_some_and(|x| x.agent == self.cell.robot(a.robot).object)
                    })
                    .count(),
                plans: a.plans,
                planning_ms: a.planning_ms,
            })
            .collect();
        let challenges = self
            .challenges
            .iter()
            .map(|c| ChallengeReport {
                challenge: c.label.clone(),
                kind: c.kind.name().to_owned(),
                met: c.met_at.map(|t| self.secs(t - 1)),
                ended: c.end(None),
            })
            .collect();
        let trace = self.trace.finish();
        let score = orders.iter().map(|o| o.score).sum();
        let best = orders.iter().map(|o| o.best).sum();
        TrialReport {
            trial: name.to_owned(),
            seed: self.opts.seed,
            seconds: self.secs(self.tick),
            ticks: self.tick,
            score,
            best,
            orders,
            agents,
            challenges,
            tasks: self.tm.tasks.clone(),
            stopped: self.stopped.clone(),
            elapsed_ms: 0.0,
            trace,
        }
    }
}

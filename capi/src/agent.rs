//! The closed loop with the host as executor: btc-api's `Agent` runs its
//! loop and hands each attempt to a C callback, as JSON, and reads back
//! what the host's tree did (the shapes are in `btc.h`).

use crate::boundary::{bad_argument, c_string, guard, optional_text};
use crate::btc_project;
use crate::handle::{self, Handle};
use btc_api::{
    Agent, AgentOptions, AttemptInput, Executed, Executor, Record, ReportedFault, Status,
};
use serde::Deserialize;
use std::ffi::{c_char, c_int, c_void, CStr};
use std::path::Path;

/// An agent: a project and the problem it runs.
#[repr(C)]
pub struct btc_agent(pub(crate) Handle<Agent>);

/// Where the executor writes its answer.
pub struct btc_reply {
    text: Option<String>,
}

/// The executor: runs one attempt (`attempt_json`) and answers through
/// `reply`; 0 when it ran the attempt, nonzero when it could not.
pub type btc_execute_fn = Option<
    unsafe extern "C" fn(
        user: *mut c_void,
        attempt_json: *const c_char,
        reply: *mut btc_reply,
    ) -> c_int,
>;

/// The executor's answer, copied.
#[no_mangle]
pub unsafe extern "C" fn btc_reply_set(reply: *mut btc_reply, text: *const c_char) {
    if reply.is_null() || text.is_null() {
        return;
    }
    let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        (*reply).text = Some(CStr::from_ptr(text).to_string_lossy().into_owned());
    }));
}

#[no_mangle]
pub unsafe extern "C" fn btc_agent_new(
    project: *mut btc_project,
    problem: *const c_char,
    error: *mut *mut c_char,
) -> *mut btc_agent {
    guard(error, std::ptr::null_mut(), || {
        let project = handle::take(project, "project", |p: btc_project| p.0)?;
        let problem = optional_text(problem, "problem")?;
        let agent = Agent::new(project, problem.map(Path::new));
        Ok(Box::into_raw(Box::new(btc_agent(Handle::new(agent)))))
    })
}

#[no_mangle]
pub unsafe extern "C" fn btc_agent_free(agent: *mut btc_agent) {
    handle::free(agent, |a| &mut a.0);
}

/// `{"max_replans": 5, "max_ticks": 100000}`, both optional.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct OptionsWire {
    max_replans: Option<usize>,
    max_ticks: Option<u64>,
}

#[no_mangle]
pub unsafe extern "C" fn btc_agent_run(
    agent: *mut btc_agent,
    options_json: *const c_char,
    execute: btc_execute_fn,
    user: *mut c_void,
    error: *mut *mut c_char,
) -> *mut c_char {
    guard(error, std::ptr::null_mut(), || {
        let agent = handle::get_mut(agent, "agent", |a| &mut a.0)?;
        let Some(execute) = execute else {
            return Err(bad_argument("`execute` is a null function pointer"));
        };
        let mut options = AgentOptions::default();
        if let Some(o) = optional_text(options_json, "options_json")? {
            let o: OptionsWire = serde_json::from_str(o).map_err(|e| {
                bad_argument(format!("`options_json` is not the agent's options: {e}"))
            })?;
            if let Some(r) = o.max_replans {
                options.max_replans = r;
            }
            if let Some(t) = o.max_ticks {
                options.run.max_ticks = t;
            }
        }
        let mut host = Host { execute, user };
        let report = agent.run_with(&options, &mut host)?;
        serde_json::to_string(&report)
            .map(c_string)
            .map_err(|e| bad_argument(format!("cannot write the report: {e}")))
    })
}

/// The host's executor behind the callback.
struct Host {
    execute: unsafe extern "C" fn(*mut c_void, *const c_char, *mut btc_reply) -> c_int,
    user: *mut c_void,
}

impl Executor for Host {
    fn execute(&mut self, attempt: &AttemptInput) -> Result<Executed, String> {
        let input = serde_json::json!({
            "attempt": attempt.attempt,
            "tree_xml": attempt.tree.to_btcpp_xml(),
            "nodes": attempt.tree.nodes(),
            "steps": attempt.tree.steps(),
            "state": attempt.state,
            "goal": attempt.goal,
            "tick": attempt.tick,
            "max_ticks": attempt.max_ticks,
        });
        let input = std::ffi::CString::new(input.to_string())
            .map_err(|_| "the attempt's JSON holds a NUL".to_owned())?;
        let mut reply = btc_reply { text: None };
        // SAFETY: the host gave this callback and its `user` pointer for
        // this run; the texts outlive the call.
        let code = unsafe { (self.execute)(self.user, input.as_ptr(), &mut reply) };
        let text = reply.text.unwrap_or_default();
        if code != 0 {
            return Err(if text.is_empty() {
                format!("the executor failed (it returned {code}) without saying why")
            } else {
                text
            });
        }
        let wire: ExecutedWire = serde_json::from_str(&text).map_err(|e| {
            format!(
                "the executor's answer is not an attempt's outcome ({e}): {}",
                cut(&text)
            )
        })?;
        Ok(wire.into())
    }
}

fn cut(text: &str) -> &str {
    match text.char_indices().nth(200) {
        Some((at, _)) => &text[..at],
        None => text,
    }
}

#[derive(Deserialize)]
#[serde(rename_all = "lowercase")]
enum StatusWire {
    Success,
    Failure,
    Running,
}

#[derive(Deserialize)]
struct RecordWire {
    node_id: String,
    #[serde(default)]
    node_name: String,
    #[serde(default)]
    reason: String,
    #[serde(default)]
    step: Option<usize>,
    #[serde(default)]
    tick: u64,
    #[serde(default)]
    faults: Vec<String>,
}

#[derive(Deserialize)]
struct FaultWire {
    kind: String,
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    part: Option<String>,
    #[serde(default)]
    robot: Option<String>,
    #[serde(default)]
    duration: Option<u64>,
    #[serde(default)]
    goal: Option<String>,
    #[serde(default)]
    retract: Vec<String>,
    #[serde(default)]
    add: Vec<String>,
    #[serde(default)]
    tick: u64,
}

#[derive(Deserialize)]
struct ExecutedWire {
    status: StatusWire,
    state: Vec<String>,
    #[serde(default)]
    ticks: u64,
    #[serde(default)]
    steps_done: usize,
    #[serde(default)]
    records: Vec<RecordWire>,
    #[serde(default)]
    faults: Vec<FaultWire>,
}

impl From<ExecutedWire> for Executed {
    fn from(w: ExecutedWire) -> Executed {
        Executed {
            status: match w.status {
                StatusWire::Success => Status::Success,
                StatusWire::Failure => Status::Failure,
                StatusWire::Running => Status::Running,
            },
            state: w.state,
            ticks: w.ticks,
            steps_done: w.steps_done,
            records: w
                .records
                .into_iter()
                .map(|r| Record {
                    node_id: r.node_id,
                    node_name: r.node_name,
                    reason: r.reason,
                    step: r.step,
                    tick: r.tick,
                    faults: r.faults,
                })
                .collect(),
            faults: w
                .faults
                .into_iter()
                .map(|f| ReportedFault {
                    kind: f.kind,
                    name: f.name,
                    robot: f.robot,
                    part: f.part,
                    duration: f.duration,
                    retract: f.retract,
                    add: f.add,
                    goal: f.goal,
                    tick: f.tick,
                })
                .collect(),
        }
    }
}

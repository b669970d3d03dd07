//! The closed loop with py_trees as its executor: `btc.Agent` (in
//! `btc/_agent.py`) ticks each attempt's tree with the user's behaviours;
//! here the loop of btc-api calls it for each attempt and reads its report.

use crate::{raise, Tree};
use btc_api as api;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::PathBuf;

/// The Python callable that runs an attempt, as the loop's executor. A
/// Python exception it raises stops the loop and is raised again as it was.
struct PyExecutor<'py> {
    execute: Bound<'py, PyAny>,
    raised: Option<PyErr>,
}

fn status(text: &str) -> PyResult<api::Status> {
    match text {
        "SUCCESS" => Ok(api::Status::Success),
        "FAILURE" => Ok(api::Status::Failure),
        "RUNNING" => Ok(api::Status::Running),
        other => Err(pyo3::exceptions::PyValueError::new_err(format!(
            "an attempt ends SUCCESS, FAILURE or RUNNING, not `{other}`"
        ))),
    }
}

/// `d[key]`, or `None` when it is missing or None.
fn opt<'py, T: FromPyObjectOwned<'py>>(d: &Bound<'py, PyAny>, key: &str) -> PyResult<Option<T>> {
    match d.get_item(key) {
        Ok(v) if !v.is_none() => v.extract().map(Some).map_err(Into::into),
        Ok(_) => Ok(None),
        Err(e) if e.is_instance_of::<pyo3::exceptions::PyKeyError>(d.py()) => Ok(None),
        Err(e) => Err(e),
    }
}

fn record(d: &Bound<'_, PyAny>) -> PyResult<api::Record> {
    Ok(api::Record {
        node_id: opt(d, "node_id")?.unwrap_or_default(),
        node_name: opt(d, "node_name")?.unwrap_or_default(),
        reason: opt(d, "reason")?.unwrap_or_default(),
        step: opt(d, "step")?,
        tick: opt(d, "tick")?.unwrap_or_default(),
        faults: opt(d, "faults")?.unwrap_or_default(),
    })
}

fn fault(d: &Bound<'_, PyAny>) -> PyResult<api::ReportedFault> {
    Ok(api::ReportedFault {
        kind: opt(d, "kind")?.unwrap_or_default(),
        name: opt(d, "name")?,
        robot: opt(d, "robot")?,
        part: opt(d, "part")?,
        duration: opt(d, "duration")?,
        retract: opt(d, "retract")?.unwrap_or_default(),
        add: opt(d, "add")?.unwrap_or_default(),
        goal: opt(d, "goal")?,
        tick: opt(d, "tick")?.unwrap_or_default(),
    })
}

impl PyExecutor<'_> {
    fn call(&self, a: &api::AttemptInput) -> PyResult<api::Executed> {
        let py = self.execute.py();
        let d = PyDict::new(py);
        d.set_item("attempt", a.attempt)?;
        d.set_item("tree", Py::new(py, Tree::new(a.tree.clone()))?)?;
        d.set_item("state", PyList::new(py, &a.state)?)?;
        d.set_item("goal", &a.goal)?;
        d.set_item("tick", a.tick)?;
        d.set_item("max_ticks", a.max_ticks)?;
        let out = self.execute.call1((d,))?;
        let list = |key: &str| -> PyResult<Vec<Bound<'_, PyAny>>> {
            Ok(opt::<Vec<Bound<'_, PyAny>>>(&out, key)?.unwrap_or_default())
        };
        Ok(api::Executed {
            status: status(&out.get_item("status")?.extract::<String>()?)?,
            state: out.get_item("state")?.extract()?,
            ticks: out.get_item("ticks")?.extract()?,
            steps_done: opt(&out, "steps_done")?.unwrap_or_default(),
            records: list("records")?
                .iter()
                .map(record)
                .collect::<PyResult<_>>()?,
            faults: list("faults")?.iter().map(fault).collect::<PyResult<_>>()?,
        })
    }
}

impl api::Executor for PyExecutor<'_> {
    fn execute(&mut self, a: &api::AttemptInput) -> Result<api::Executed, String> {
        self.call(a).map_err(|e| {
            let text = e.to_string();
            self.raised = Some(e);
            text
        })
    }
}

/// The closed loop for `problem` with `execute(attempt) -> dict` running
/// each attempt: the report as JSON text.
pub(crate) fn run(
    project: &mut api::Project,
    py: Python<'_>,
    execute: Bound<'_, PyAny>,
    problem: Option<PathBuf>,
    max_replans: usize,
    max_ticks: u64,
) -> PyResult<String> {
    let options = api::AgentOptions {
        run: api::RunOptions {
            max_ticks,
            ..api::RunOptions::default()
        },
        max_replans,
    };
    let mut executor = PyExecutor {
        execute,
        raised: None,
    };
    let report = project.run_agent(problem.as_deref(), &options, &mut executor);
    if let Some(e) = executor.raised.take() {
        return Err(e);
    }
    let report = report.map_err(|e| raise(py, e))?;
    serde_json::to_string(&report)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))
}

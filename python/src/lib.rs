//! The Python face of btc-api: the classes of the `btc` package
//! (`btc/__init__.py` re-exports them). Texts and paths come in, plain
//! Python values go out; bad input raises `btc.BtcError` carrying the
//! diagnostics, never a crash of the host process.

mod agent;
mod module_data;

use btc_api as api;
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use std::path::PathBuf;

create_exception!(
    _btc,
    BtcError,
    PyException,
    "Bad input: `.diagnostics` says what and where."
);

/// What went wrong, where, and what to do.
#[pyclass(module = "btc", frozen, get_all)]
#[derive(Clone)]
struct Diagnostic {
    code: String,
    /// `"error"` or `"warning"`.
    severity: String,
    message: String,
    path: String,
    line: u32,
    column: u32,
    end_line: u32,
    end_column: u32,
    hint: Option<String>,
    /// Machine-applicable repairs: `(title, path, line, column, end_line,
    /// end_column, replacement)`.
    fixes: Vec<(String, String, u32, u32, u32, u32, String)>,
}

#[pymethods]
impl Diagnostic {
    fn __str__(&self) -> String {
        let mut s = format!(
            "{}:{}:{}: {}[{}]: {}",
            self.path, self.line, self.column, self.severity, self.code, self.message
        );
        if let Some(h) = &self.hint {
            s.push_str(&format!(" (hint: {h})"));
        }
        s
    }

    fn __repr__(&self) -> String {
        format!(
            "<Diagnostic {} {}:{}:{}>",
            self.code, self.path, self.line, self.column
        )
    }
}

impl From<&api::Diagnostic> for Diagnostic {
    fn from(d: &api::Diagnostic) -> Diagnostic {
        Diagnostic {
            code: d.code.clone(),
            severity: match d.severity {
                api::Severity::Error => "error",
                api::Severity::Warning => "warning",
            }
            .to_owned(),
            message: d.message.clone(),
            path: d.path.clone(),
            line: d.start.line,
            column: d.start.column,
            end_line: d.end.line,
            end_column: d.end.column,
            hint: d.hint.clone(),
            fixes: d
                .fixes
                .iter()
                .map(|f| {
                    (
                        f.title.clone(),
                        f.path.clone(),
                        f.start.line,
                        f.start.column,
                        f.end.line,
                        f.end.column,
                        f.replacement.clone(),
                    )
                })
                .collect(),
        }
    }
}

/// `btc.BtcError(message, diagnostics)`, raised.
pub(crate) fn raise(py: Python<'_>, e: api::Error) -> PyErr {
    let diags: Vec<Diagnostic> = e.diagnostics.iter().map(Diagnostic::from).collect();
    let err = BtcError::new_err(e.to_string());
    match diags.into_pyobject(py) {
        Ok(list) => {
            let _ = err.value(py).setattr("diagnostics", list);
            err
        }
        Err(x) => x,
    }
}

/// One step of a plan.
#[pyclass(module = "btc", frozen, get_all)]
#[derive(Clone)]
struct Step {
    action: String,
    args: Vec<String>,
    time: Option<f64>,
    duration: Option<f64>,
}

#[pymethods]
impl Step {
    fn __str__(&self) -> String {
        self.value().to_string()
    }

    fn __repr__(&self) -> String {
        format!("<Step {}>", self.value())
    }
}

impl Step {
    fn value(&self) -> api::Step {
        api::Step {
            action: self.action.clone(),
            args: self.args.clone(),
            time: self.time,
            duration: self.duration,
        }
    }
}

/// A plan: its steps and cost; `str()` is its sas_plan text.
#[pyclass(module = "btc", frozen)]
struct Plan {
    plan: api::Plan,
}

#[pymethods]
impl Plan {
    /// Reads a plan in any format btc reads (sas_plan, timed, bare lines,
    /// FF's output).
    #[staticmethod]
    fn parse(py: Python<'_>, text: &str) -> PyResult<Plan> {
        api::Plan::parse(text)
            .map(|plan| Plan { plan })
            .map_err(|e| raise(py, e))
    }

    #[getter]
    fn steps(&self) -> Vec<Step> {
        self.plan
            .steps
            .iter()
            .map(|s| Step {
                action: s.action.clone(),
                args: s.args.clone(),
                time: s.time,
                duration: s.duration,
            })
            .collect()
    }

    #[getter]
    fn cost(&self) -> Option<f64> {
        self.plan.cost
    }

    fn __len__(&self) -> usize {
        self.plan.steps.len()
    }

    fn __str__(&self) -> String {
        self.plan.to_string()
    }

    fn __repr__(&self) -> String {
        format!("<Plan of {} steps>", self.plan.steps.len())
    }

    fn __eq__(&self, other: &Plan) -> bool {
        self.plan == other.plan
    }
}

/// A compiled tree, in each of btc's output forms.
#[pyclass(module = "btc", frozen)]
pub(crate) struct Tree {
    tree: api::Tree,
    /// The py_trees module read as data (`btc._pytrees.TreeData`), once.
    data: std::sync::OnceLock<Py<PyAny>>,
}

impl Tree {
    pub(crate) fn new(tree: api::Tree) -> Tree {
        Tree {
            tree,
            data: std::sync::OnceLock::new(),
        }
    }

    fn data<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        if let Some(d) = self.data.get() {
            return Ok(d.bind(py).clone());
        }
        let text = self.pytrees_module(py)?;
        let values = module_data::read(py, &text)?;
        let d = py
            .import("btc._pytrees")?
            .getattr("TreeData")?
            .call((), Some(&values))?;
        let _ = self.data.set(d.clone().unbind());
        Ok(d)
    }
}

#[pymethods]
impl Tree {
    fn to_btcpp_xml(&self) -> String {
        self.tree.to_btcpp_xml()
    }

    fn to_json(&self) -> String {
        self.tree.to_json()
    }

    fn to_mermaid(&self) -> String {
        self.tree.to_mermaid()
    }

    fn to_dot(&self) -> String {
        self.tree.to_dot()
    }

    /// The py_trees module's text (`btc compile --emit pytrees --runtime
    /// import`); `to_py_trees` reads its data without running it.
    fn pytrees_module(&self, py: Python<'_>) -> PyResult<String> {
        self.tree.pytrees_module().map_err(|e| raise(py, e))
    }

    /// The tree as py_trees behaviours, built in this process: leaf
    /// classes from `nodes` (a module, or a mapping of node id -> class)
    /// where it names them, btc's own otherwise (simulated actions, and
    /// conditions that evaluate their formulas on the knowledge base).
    /// Run it with the knowledge base of `knowledge_base()` on the
    /// blackboard (`btc.btc_runtime.run(root, kb, max_ticks)`).
    #[pyo3(signature = (nodes=None))]
    fn to_py_trees<'py>(
        &self,
        py: Python<'py>,
        nodes: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let data = self.data(py)?;
        py.import("btc._pytrees")?
            .call_method1("build", (data, nodes))
    }

    /// A fresh knowledge base for the tree: the problem's initial state and
    /// the plan's steps, none started.
    #[pyo3(signature = (ticks_per_action=1, ms_per_tick=10))]
    fn knowledge_base<'py>(
        &self,
        py: Python<'py>,
        ticks_per_action: u32,
        ms_per_tick: u64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let data = self.data(py)?;
        let pt = py.import("btc._pytrees")?;
        let world = pt.call_method1("world", (&data,))?;
        let plan = pt.call_method1("plan", (&data,))?;
        py.import("btc.btc_runtime")?
            .getattr("KnowledgeBase")?
            .call1((world, plan, ticks_per_action, ms_per_tick))
    }

    /// The plan's steps as `(action arg ...)`.
    #[getter]
    fn steps(&self) -> Vec<String> {
        self.tree.steps()
    }
}

/// A rules file and what it names, loaded once and kept: checking,
/// planning and compiling again re-do only what changed.
#[pyclass(module = "btc", unsendable)]
struct Project {
    project: api::Project,
}

#[pymethods]
impl Project {
    #[new]
    fn open(py: Python<'_>, path: PathBuf) -> PyResult<Project> {
        api::Project::open(&path)
            .map(|project| Project { project })
            .map_err(|e| raise(py, e))
    }

    /// A project from texts (nothing is read from disk).
    #[staticmethod]
    #[pyo3(signature = (*, rules, domain, problem=None))]
    fn from_texts(
        py: Python<'_>,
        rules: &str,
        domain: &str,
        problem: Option<&str>,
    ) -> PyResult<Project> {
        api::Project::from_texts(rules, domain, problem)
            .map(|project| Project { project })
            .map_err(|e| raise(py, e))
    }

    /// Every diagnostic of the rules, their imports, domain and problem.
    fn check(&self) -> Vec<Diagnostic> {
        self.project.check().iter().map(Diagnostic::from).collect()
    }

    /// A plan for `problem` (a path; default: the project's problem).
    #[pyo3(signature = (problem=None))]
    fn plan(&mut self, py: Python<'_>, problem: Option<PathBuf>) -> PyResult<Plan> {
        self.project
            .plan(problem.as_deref())
            .map(|plan| Plan { plan })
            .map_err(|e| raise(py, e))
    }

    /// The closed loop for `problem`, each attempt run by `execute(attempt)
    /// -> dict` (`btc.Agent` is the way to call it): the report as JSON.
    #[pyo3(signature = (execute, problem=None, max_replans=5, max_ticks=100_000))]
    fn _run_agent(
        &mut self,
        py: Python<'_>,
        execute: Bound<'_, PyAny>,
        problem: Option<PathBuf>,
        max_replans: usize,
        max_ticks: u64,
    ) -> PyResult<String> {
        agent::run(
            &mut self.project,
            py,
            execute,
            problem,
            max_replans,
            max_ticks,
        )
    }

    /// Compiles `plan` with the rules for `problem`.
    #[pyo3(signature = (plan, problem=None))]
    fn compile(&mut self, py: Python<'_>, plan: &Plan, problem: Option<PathBuf>) -> PyResult<Tree> {
        self.project
            .compile(&plan.plan, problem.as_deref())
            .map(Tree::new)
            .map_err(|e| raise(py, e))
    }
}

/// A plan for `problem` in `domain` (paths), without rules.
#[pyfunction]
fn plan(py: Python<'_>, domain: PathBuf, problem: PathBuf) -> PyResult<Plan> {
    api::plan(&domain, &problem)
        .map(|plan| Plan { plan })
        .map_err(|e| raise(py, e))
}

/// The `btc` command (`args`: the command line, program name first): its
/// exit status. What it prints goes to this process's stdout and stderr.
/// The data of a py_trees module btc wrote, as `btc._pytrees.TreeData`'s
/// keyword arguments (what `Tree.to_py_trees` builds from).
#[pyfunction]
fn _module_data<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    module_data::read(py, text)
}

#[pyfunction]
fn _main(py: Python<'_>, args: Vec<std::ffi::OsString>) -> u8 {
    // Long commands (a trial, the language server) must not hold the GIL.
    py.detach(|| btc::exit_status(btc::run(args)))
}

#[pymodule]
fn _btc(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", api::VERSION)?;
    m.add("BtcError", m.py().get_type::<BtcError>())?;
    m.add_class::<Diagnostic>()?;
    m.add_class::<Step>()?;
    m.add_class::<Plan>()?;
    m.add_class::<Tree>()?;
    m.add_class::<Project>()?;
    m.add_function(wrap_pyfunction!(plan, m)?)?;
    m.add_function(wrap_pyfunction!(_main, m)?)?;
    m.add_function(wrap_pyfunction!(_module_data, m)?)?;
    Ok(())
}

//! btc's library facade ([`btc_api`]) through a C ABI, declared by
//! `include/btc.h`: opaque handles for projects, plans and trees, texts
//! in and out (UTF-8, NUL-terminated), errors as JSON diagnostics. Every
//! entry point checks its pointers and catches panics, so bad input never
//! crashes the host; every value btc allocates has its free function.
//!
//! The logic stays in `btc-api`: each function here reads its arguments,
//! calls one method and converts the result.
#![allow(non_camel_case_types)]
// Each entry point documents its contract in the header; the pointers are
// checked (null, kind) before use.
#![allow(clippy::missing_safety_doc)]

mod agent;
mod boundary;
mod handle;

use boundary::{bad_argument, c_string, guard, optional_text, text};
use btc_api::{Error, Plan, Project, Target, Tree};
use handle::Handle;
use std::ffi::{c_char, CStr};
use std::path::Path;

pub use agent::{
    btc_agent, btc_agent_free, btc_agent_new, btc_agent_run, btc_execute_fn, btc_reply,
    btc_reply_set,
};

/// A project: a rules file and what it names, loaded once.
#[repr(C)]
pub struct btc_project(pub(crate) Handle<Project>);
/// A plan value.
#[repr(C)]
pub struct btc_plan(pub(crate) Handle<Plan>);
/// A compiled tree.
#[repr(C)]
pub struct btc_tree(pub(crate) Handle<Tree>);

/// `btc_tree_emit`'s targets: the outputs of `btc compile --emit`.
pub const BTC_TARGET_BTCPP_XML: i32 = 0;
pub const BTC_TARGET_PY_TREES: i32 = 1;
pub const BTC_TARGET_JSON: i32 = 2;
pub const BTC_TARGET_DOT: i32 = 3;
pub const BTC_TARGET_MERMAID: i32 = 4;
pub const BTC_TARGET_COMMANDS: i32 = 5;

fn target(code: i32) -> Result<Target, Error> {
    Ok(match code {
        BTC_TARGET_BTCPP_XML => Target::BtcppXml,
        BTC_TARGET_PY_TREES => Target::PyTrees,
        BTC_TARGET_JSON => Target::Json,
        BTC_TARGET_DOT => Target::Dot,
        BTC_TARGET_MERMAID => Target::Mermaid,
        BTC_TARGET_COMMANDS => Target::Commands,
        other => return Err(bad_argument(format!("{other} is not a BTC_TARGET_ value"))),
    })
}

fn json(value: &impl serde::Serialize) -> Result<String, Error> {
    serde_json::to_string(value).map_err(|e| bad_argument(format!("cannot write JSON: {e}")))
}

/// btc's version, a static text (not to be freed).
#[no_mangle]
pub extern "C" fn btc_version() -> *const c_char {
    static VERSION: &CStr =
        match CStr::from_bytes_with_nul(concat!(env!("CARGO_PKG_VERSION"), "\0").as_bytes()) {
            Ok(v) => v,
            Err(_) => c"",
        };
    VERSION.as_ptr()
}

/// Frees a text btc returned (results and errors). Null is ignored.
#[no_mangle]
pub unsafe extern "C" fn btc_string_free(text: *mut c_char) {
    if !text.is_null() {
        let _ = std::panic::catch_unwind(|| drop(std::ffi::CString::from_raw(text)));
    }
}

// ------------------------------------------------------------- projects

#[no_mangle]
pub unsafe extern "C" fn btc_project_open(
    path: *const c_char,
    error: *mut *mut c_char,
) -> *mut btc_project {
    guard(error, std::ptr::null_mut(), || {
        let path = text(path, "path")?;
        let p = Project::open(path)?;
        Ok(Box::into_raw(Box::new(btc_project(Handle::new(p)))))
    })
}

#[no_mangle]
pub unsafe extern "C" fn btc_project_from_texts(
    rules: *const c_char,
    domain: *const c_char,
    problem: *const c_char,
    error: *mut *mut c_char,
) -> *mut btc_project {
    guard(error, std::ptr::null_mut(), || {
        let rules = text(rules, "rules")?;
        let domain = text(domain, "domain")?;
        let problem = optional_text(problem, "problem")?;
        let p = Project::from_texts(rules, domain, problem)?;
        Ok(Box::into_raw(Box::new(btc_project(Handle::new(p)))))
    })
}

#[no_mangle]
pub unsafe extern "C" fn btc_project_free(project: *mut btc_project) {
    handle::free(project, |p| &mut p.0);
}

/// Every diagnostic of the project, as a JSON array.
#[no_mangle]
pub unsafe extern "C" fn btc_project_check(
    project: *const btc_project,
    error: *mut *mut c_char,
) -> *mut c_char {
    guard(error, std::ptr::null_mut(), || {
        let p = handle::get(project, "project", |p| &p.0)?;
        Ok(c_string(json(&p.check())?))
    })
}

#[no_mangle]
pub unsafe extern "C" fn btc_project_plan(
    project: *mut btc_project,
    problem: *const c_char,
    error: *mut *mut c_char,
) -> *mut btc_plan {
    guard(error, std::ptr::null_mut(), || {
        let p = handle::get_mut(project, "project", |p| &mut p.0)?;
        let problem = optional_text(problem, "problem")?;
        let plan = p.plan(problem.map(Path::new))?;
        Ok(Box::into_raw(Box::new(btc_plan(Handle::new(plan)))))
    })
}

#[no_mangle]
pub unsafe extern "C" fn btc_project_compile(
    project: *mut btc_project,
    plan: *const btc_plan,
    problem: *const c_char,
    error: *mut *mut c_char,
) -> *mut btc_tree {
    guard(error, std::ptr::null_mut(), || {
        let p = handle::get_mut(project, "project", |p| &mut p.0)?;
        let plan = handle::get(plan, "plan", |p| &p.0)?;
        let problem = optional_text(problem, "problem")?;
        let tree = p.compile(plan, problem.map(Path::new))?;
        Ok(Box::into_raw(Box::new(btc_tree(Handle::new(tree)))))
    })
}

/// The `.kb` text of the problem's world (btc::Kb reads it).
#[no_mangle]
pub unsafe extern "C" fn btc_project_knowledge_base(
    project: *mut btc_project,
    problem: *const c_char,
    error: *mut *mut c_char,
) -> *mut c_char {
    guard(error, std::ptr::null_mut(), || {
        let p = handle::get_mut(project, "project", |p| &mut p.0)?;
        let problem = optional_text(problem, "problem")?;
        Ok(c_string(p.knowledge_base(problem.map(Path::new))?))
    })
}

// ---------------------------------------------------------------- plans

/// A plan for a domain and problem (paths), without rules.
#[no_mangle]
pub unsafe extern "C" fn btc_plan_files(
    domain: *const c_char,
    problem: *const c_char,
    error: *mut *mut c_char,
) -> *mut btc_plan {
    guard(error, std::ptr::null_mut(), || {
        let domain = text(domain, "domain")?;
        let problem = text(problem, "problem")?;
        let plan = btc_api::plan(domain, problem)?;
        Ok(Box::into_raw(Box::new(btc_plan(Handle::new(plan)))))
    })
}

#[no_mangle]
pub unsafe extern "C" fn btc_plan_parse(
    plan_text: *const c_char,
    error: *mut *mut c_char,
) -> *mut btc_plan {
    guard(error, std::ptr::null_mut(), || {
        let t = text(plan_text, "text")?;
        let plan = Plan::parse(t)?;
        Ok(Box::into_raw(Box::new(btc_plan(Handle::new(plan)))))
    })
}

/// The plan in `sas_plan` form.
#[no_mangle]
pub unsafe extern "C" fn btc_plan_to_text(
    plan: *const btc_plan,
    error: *mut *mut c_char,
) -> *mut c_char {
    guard(error, std::ptr::null_mut(), || {
        let plan = handle::get(plan, "plan", |p| &p.0)?;
        Ok(c_string(plan.to_string()))
    })
}

/// The plan as JSON: `{"steps": [{"action", "args", "time", "duration"}], "cost"}`.
#[no_mangle]
pub unsafe extern "C" fn btc_plan_to_json(
    plan: *const btc_plan,
    error: *mut *mut c_char,
) -> *mut c_char {
    guard(error, std::ptr::null_mut(), || {
        let plan = handle::get(plan, "plan", |p| &p.0)?;
        Ok(c_string(json(plan)?))
    })
}

#[no_mangle]
pub unsafe extern "C" fn btc_plan_free(plan: *mut btc_plan) {
    handle::free(plan, |p| &mut p.0);
}

// ---------------------------------------------------------------- trees

#[no_mangle]
pub unsafe extern "C" fn btc_tree_emit(
    tree: *const btc_tree,
    target_code: i32,
    error: *mut *mut c_char,
) -> *mut c_char {
    guard(error, std::ptr::null_mut(), || {
        let tree = handle::get(tree, "tree", |t| &t.0)?;
        Ok(c_string(tree.emit(target(target_code)?)?))
    })
}

/// The leaf node ids the tree uses, as a JSON array of
/// `{"id", "kind", "ports": [{"name", "direction", "type"}], "formula"}`.
#[no_mangle]
pub unsafe extern "C" fn btc_tree_nodes(
    tree: *const btc_tree,
    error: *mut *mut c_char,
) -> *mut c_char {
    guard(error, std::ptr::null_mut(), || {
        let tree = handle::get(tree, "tree", |t| &t.0)?;
        Ok(c_string(json(&tree.nodes())?))
    })
}

/// The plan's steps as a JSON array of `(action arg ...)` texts.
#[no_mangle]
pub unsafe extern "C" fn btc_tree_steps(
    tree: *const btc_tree,
    error: *mut *mut c_char,
) -> *mut c_char {
    guard(error, std::ptr::null_mut(), || {
        let tree = handle::get(tree, "tree", |t| &t.0)?;
        Ok(c_string(json(&tree.steps())?))
    })
}

#[no_mangle]
pub unsafe extern "C" fn btc_tree_free(tree: *mut btc_tree) {
    handle::free(tree, |t| &mut t.0);
}

//! The C ABI called as a C host calls it: results equal btc-api's own,
//! errors come back as JSON diagnostics, and bad pointers (null, not
//! UTF-8, a handle of another kind) are refused with A001, never a crash.

use btc_capi::*;
use std::ffi::{c_char, CStr, CString};
use std::path::PathBuf;
use std::ptr::null_mut;

fn example(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../examples")
        .join(path)
}

fn c(s: &str) -> CString {
    CString::new(s).unwrap()
}

/// Takes a text btc returned (and frees it).
unsafe fn take(p: *mut c_char) -> String {
    assert!(!p.is_null());
    let s = CStr::from_ptr(p).to_str().unwrap().to_owned();
    btc_string_free(p);
    s
}

/// The codes of an error text.
unsafe fn codes(error: *mut c_char) -> Vec<String> {
    let v: serde_json::Value = serde_json::from_str(&take(error)).unwrap();
    v["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["code"].as_str().unwrap().to_owned())
        .collect()
}

#[test]
fn the_ariac_example_plans_and_compiles_as_btc_api_does() {
    let rules = example("ariac/rules.btrules");
    unsafe {
        let mut err = null_mut();
        let path = c(rules.to_str().unwrap());
        let project = btc_project_open(path.as_ptr(), &mut err);
        assert!(!project.is_null() && err.is_null());
        let check: serde_json::Value =
            serde_json::from_str(&take(btc_project_check(project, &mut err))).unwrap();
        assert!(check
            .as_array()
            .unwrap()
            .iter()
            .all(|d| d["severity"] != "error"));
        let plan = btc_project_plan(project, std::ptr::null(), &mut err);
        assert!(!plan.is_null(), "{}", take(err));
        let tree = btc_project_compile(project, plan, std::ptr::null(), &mut err);
        assert!(!tree.is_null(), "{}", take(err));
        let xml = take(btc_tree_emit(tree, BTC_TARGET_BTCPP_XML, &mut err));

        let mut p = btc_api::Project::open(&rules).unwrap();
        let plan_rs = p.plan(None).unwrap();
        assert_eq!(take(btc_plan_to_text(plan, &mut err)), plan_rs.to_string());
        let tree_rs = p.compile(&plan_rs, None).unwrap();
        assert_eq!(xml, tree_rs.to_btcpp_xml());
        assert_eq!(
            take(btc_tree_nodes(tree, &mut err)),
            serde_json::to_string(&tree_rs.nodes()).unwrap()
        );
        assert_eq!(
            take(btc_project_knowledge_base(
                project,
                std::ptr::null(),
                &mut err
            )),
            p.knowledge_base(None).unwrap()
        );
        let mermaid = take(btc_tree_emit(tree, BTC_TARGET_MERMAID, &mut err));
        assert_eq!(mermaid, tree_rs.to_mermaid());
        btc_tree_free(tree);
        btc_plan_free(plan);
        btc_project_free(project);
    }
}

#[test]
fn texts_with_errors_come_back_as_diagnostics() {
    unsafe {
        let mut err = null_mut();
        let rules = c("domain \"domain.pddl\"\naction A(\n");
        let domain = c("(define (domain d) (:predicates (p))");
        let project =
            btc_project_from_texts(rules.as_ptr(), domain.as_ptr(), std::ptr::null(), &mut err);
        // Loading texts succeeds; their errors are the check's.
        assert!(!project.is_null(), "{}", take(err));
        let check: serde_json::Value =
            serde_json::from_str(&take(btc_project_check(project, &mut err))).unwrap();
        let codes_found: Vec<&str> = check
            .as_array()
            .unwrap()
            .iter()
            .map(|d| d["code"].as_str().unwrap())
            .collect();
        assert!(
            codes_found.iter().any(|c| c.starts_with('R')),
            "{codes_found:?}"
        );
        assert!(
            codes_found.iter().any(|c| c.starts_with('P')),
            "{codes_found:?}"
        );
        // Planning it is refused with those errors.
        let plan = btc_project_plan(project, std::ptr::null(), &mut err);
        assert!(plan.is_null());
        assert!(!codes(err).is_empty());
        btc_project_free(project);

        let bad_plan = c("(move a b\nnot a step)");
        assert!(btc_plan_parse(bad_plan.as_ptr(), &mut err).is_null());
        assert!(codes(err).iter().all(|c| c.starts_with('L')));

        let missing = c("/no/such/rules.btrules");
        assert!(btc_project_open(missing.as_ptr(), &mut err).is_null());
        assert_eq!(codes(err), ["F001"]);
    }
}

#[test]
fn bad_pointers_are_refused_not_followed() {
    unsafe {
        let mut err = null_mut();
        assert!(btc_project_open(std::ptr::null(), &mut err).is_null());
        assert_eq!(codes(err), ["A001"]);
        // Not UTF-8.
        let latin1 = CString::new(vec![b'r', 0xe9, b'.', b'b']).unwrap();
        assert!(btc_project_open(latin1.as_ptr(), &mut err).is_null());
        assert_eq!(codes(err), ["A001"]);
        assert!(btc_plan_parse(std::ptr::null(), &mut err).is_null());
        assert_eq!(codes(err), ["A001"]);
        assert!(btc_project_check(std::ptr::null(), &mut err).is_null());
        assert_eq!(codes(err), ["A001"]);
        assert!(btc_tree_emit(std::ptr::null(), 0, &mut err).is_null());
        assert_eq!(codes(err), ["A001"]);

        // A plan handle where a project is expected.
        let text = c("(move a b)\n");
        let plan = btc_plan_parse(text.as_ptr(), &mut err);
        assert!(!plan.is_null());
        let as_project = plan as *mut btc_project;
        assert!(btc_project_plan(as_project, std::ptr::null(), &mut err).is_null());
        assert_eq!(codes(err), ["A001"]);
        btc_project_free(as_project); // ignored: not a project
        assert_eq!(take(btc_plan_to_text(plan, &mut err)), "(move a b)\n");
        // An unknown target.
        let rules = example("ariac/rules.btrules");
        let path = c(rules.to_str().unwrap());
        let project = btc_project_open(path.as_ptr(), &mut err);
        let tree = btc_project_compile(project, plan, std::ptr::null(), &mut err);
        assert!(tree.is_null(), "a plan for another problem");
        assert!(!codes(err).is_empty());
        let good = btc_project_plan(project, std::ptr::null(), &mut err);
        let tree = btc_project_compile(project, good, std::ptr::null(), &mut err);
        assert!(btc_tree_emit(tree, 42, &mut err).is_null());
        assert_eq!(codes(err), ["A001"]);
        // Without an error pointer, a failure is only its null result.
        assert!(btc_tree_emit(tree, 42, null_mut()).is_null());
        btc_tree_free(tree);
        btc_plan_free(good);
        btc_plan_free(plan);
        btc_project_free(project);
        btc_string_free(null_mut());
        assert_eq!(
            CStr::from_ptr(btc_version()).to_str().unwrap(),
            btc_api::VERSION
        );
    }
}

/// An executor that answers with the text in `user` and the code it holds.
unsafe extern "C" fn answer(
    user: *mut std::ffi::c_void,
    attempt: *const c_char,
    reply: *mut btc_reply,
) -> std::ffi::c_int {
    let (code, text) = &*(user as *const (i32, CString));
    let attempt: serde_json::Value =
        serde_json::from_str(CStr::from_ptr(attempt).to_str().unwrap()).unwrap();
    assert!(attempt["tree_xml"].as_str().unwrap().contains("KbStep"));
    assert!(!attempt["state"].as_array().unwrap().is_empty());
    btc_reply_set(reply, text.as_ptr());
    *code
}

unsafe fn agent() -> *mut btc_agent {
    let rules = example("ariac/rules.btrules");
    let path = c(rules.to_str().unwrap());
    let mut err = null_mut();
    let project = btc_project_open(path.as_ptr(), &mut err);
    let agent = btc_agent_new(project, std::ptr::null(), &mut err);
    assert!(!agent.is_null() && err.is_null());
    agent
}

#[test]
fn the_agent_runs_the_hosts_executor_and_refuses_what_it_cannot_read() {
    unsafe {
        let mut err = null_mut();
        // The executor did the whole plan: the goal is reached.
        let done = (
            0,
            c(
                r#"{"status": "success", "state": ["(on battery_red agv1)", "(is_enabled floor_robot)"],
                  "ticks": 4, "steps_done": 4}"#,
            ),
        );
        let a = agent();
        let report = btc_agent_run(
            a,
            c(r#"{"max_replans": 2}"#).as_ptr(),
            Some(answer),
            &done as *const _ as *mut _,
            &mut err,
        );
        assert!(!report.is_null(), "{}", take(err));
        let report: serde_json::Value = serde_json::from_str(&take(report)).unwrap();
        assert_eq!(report["goal_reached"], true, "{report}");
        assert_eq!(report["attempts"].as_array().unwrap().len(), 1);
        // An executor that fails, or answers what is not an outcome: an
        // error with diagnostics, the host goes on.
        for (code, text, says) in [
            (
                1,
                "the action server went away",
                "the action server went away",
            ),
            (0, "{\"status\": \"flying\"}", "not an attempt's outcome"),
            (0, "not json", "not an attempt's outcome"),
            (
                0,
                r#"{"status": "failure", "state": ["(on battery_red the_moon)"]}"#,
                "the_moon",
            ),
        ] {
            let user = (code, c(text));
            let r = btc_agent_run(
                a,
                std::ptr::null(),
                Some(answer),
                &user as *const _ as *mut _,
                &mut err,
            );
            assert!(r.is_null());
            let e = take(err);
            assert!(e.contains(says), "{text}: {e}");
        }
        // No executor, bad options, a handle of another kind.
        assert!(btc_agent_run(a, std::ptr::null(), None, null_mut(), &mut err).is_null());
        assert_eq!(codes(err), ["A001"]);
        let bad = c("{\"max_replan\": 1}");
        assert!(btc_agent_run(a, bad.as_ptr(), Some(answer), null_mut(), &mut err).is_null());
        assert_eq!(codes(err), ["A001"]);
        let text = c("(move a b)\n");
        let plan = btc_plan_parse(text.as_ptr(), &mut err);
        assert!(btc_agent_new(plan.cast(), std::ptr::null(), &mut err).is_null());
        assert_eq!(codes(err), ["A001"]);
        btc_plan_free(plan);
        btc_agent_free(a);
    }
}

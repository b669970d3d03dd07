//! btc's C ABI as a C host drives it, with malformed texts: the bytes are
//! cut at `\n%%\n` into rules, domain, problem and plan, passed as C
//! strings as they are (not UTF-8, or cut at a NUL, as a C caller would);
//! a project is made from the texts, checked, planned, and the given plan
//! parsed, written back and compiled, every target emitted; handles of
//! the wrong kind and null pointers go to the same calls. Nothing may
//! panic through the boundary (every entry point catches), crash, hang or
//! leak: every result and error is freed.
#![no_main]

use btc_capi::*;
use libfuzzer_sys::fuzz_target;
use std::ffi::{c_char, CString};
use std::ptr::{null, null_mut};

/// A C string of `bytes` up to the first NUL, as C would see them.
fn c_text(bytes: &[u8]) -> CString {
    let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
    CString::new(&bytes[..end]).unwrap_or_default()
}

/// Frees a result and its call's error: exactly one of them is set.
unsafe fn done(text: *mut c_char, error: *mut c_char) {
    assert!(text.is_null() != error.is_null());
    btc_string_free(text);
    btc_string_free(error);
}

fuzz_target!(|data: &[u8]| {
    let mut pieces: Vec<&[u8]> = Vec::new();
    let mut rest = data;
    while let Some(at) = rest.windows(4).position(|w| w == b"\n%%\n") {
        pieces.push(&rest[..at]);
        rest = &rest[at + 4..];
    }
    pieces.push(rest);
    let get = |i: usize| c_text(pieces.get(i).copied().unwrap_or(b""));
    let (rules, domain, problem, plan) = (get(0), get(1), get(2), get(3));
    unsafe {
        let mut err = null_mut();
        let problem_ptr = if pieces.len() > 2 {
            problem.as_ptr()
        } else {
            null()
        };
        let project =
            btc_project_from_texts(rules.as_ptr(), domain.as_ptr(), problem_ptr, &mut err);
        btc_string_free(err);
        let parsed = btc_plan_parse(plan.as_ptr(), &mut err);
        btc_string_free(err);
        if !parsed.is_null() {
            let back = btc_plan_to_text(parsed, &mut err);
            done(back, err);
            let j = btc_plan_to_json(parsed, &mut err);
            done(j, err);
        }
        if !project.is_null() {
            let check = btc_project_check(project, &mut err);
            done(check, err);
            let kb = btc_project_knowledge_base(project, null(), &mut err);
            done(kb, err);
            let planned = btc_project_plan(project, null(), &mut err);
            btc_string_free(err);
            for p in [parsed, planned] {
                let tree = btc_project_compile(project, p, null(), &mut err);
                btc_string_free(err);
                if tree.is_null() {
                    continue;
                }
                for target in 0..=6 {
                    let out = btc_tree_emit(tree, target, &mut err);
                    done(out, err);
                }
                done(btc_tree_nodes(tree, &mut err), err);
                done(btc_tree_steps(tree, &mut err), err);
                // A tree where a project or plan is expected.
                let wrong = btc_project_plan(tree.cast(), null(), &mut err);
                assert!(wrong.is_null());
                btc_string_free(err);
                btc_plan_free(tree.cast());
                btc_tree_free(tree);
            }
            btc_plan_free(planned);
            // Files the texts name do not exist on this side: a path
            // argument made of the input.
            let other = btc_project_plan(project, rules.as_ptr(), &mut err);
            btc_plan_free(other);
            btc_string_free(err);
        }
        btc_plan_free(parsed);
        btc_project_free(project);
        // Null everywhere.
        let none = btc_project_from_texts(null(), domain.as_ptr(), null(), &mut err);
        assert!(none.is_null());
        btc_string_free(err);
    }
});

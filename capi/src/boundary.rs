//! What every entry point does at the C boundary: read the caller's
//! pointers (null and non-UTF-8 texts become A001), run the work with
//! panics caught (A002), and hand results and errors back as texts btc
//! allocated, which the caller frees with `btc_string_free`.

use btc_api::{Diagnostic, Error, Position, Severity};
use btc_pddl::diagnostic::codes;
use std::ffi::{c_char, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Where diagnostics about the C API's own arguments are placed.
const API_PATH: &str = "<c-api>";

/// A diagnostic about something that is not in a file.
pub(crate) fn unplaced(code: &str, message: impl Into<String>) -> Diagnostic {
    let at = Position { line: 0, column: 0 };
    Diagnostic {
        code: code.to_owned(),
        severity: Severity::Error,
        message: message.into(),
        path: API_PATH.to_owned(),
        start: at,
        end: at,
        hint: None,
        labels: Vec::new(),
        fixes: Vec::new(),
    }
}

/// A001: a bad argument.
pub(crate) fn bad_argument(message: impl Into<String>) -> Error {
    Error {
        diagnostics: vec![unplaced(codes::A_ARGUMENT.id, message)],
    }
}

/// The text a `const char *` argument points at; `name` says which
/// argument in the error.
///
/// # Safety
/// `ptr` is null or points at a NUL-terminated string.
pub(crate) unsafe fn text<'a>(ptr: *const c_char, name: &str) -> Result<&'a str, Error> {
    if ptr.is_null() {
        return Err(bad_argument(format!("`{name}` is a null pointer")));
    }
    CStr::from_ptr(ptr)
        .to_str()
        .map_err(|e| bad_argument(format!("`{name}` is not UTF-8 text: {e}")))
}

/// An optional text argument: null is `None`.
///
/// # Safety
/// As [`text`].
pub(crate) unsafe fn optional_text<'a>(
    ptr: *const c_char,
    name: &str,
) -> Result<Option<&'a str>, Error> {
    if ptr.is_null() {
        Ok(None)
    } else {
        text(ptr, name).map(Some)
    }
}

/// A text handed to the caller: a NUL inside it (a PDDL text can hold
/// one) is cut there rather than failing, since C strings cannot hold it.
pub(crate) fn c_string(s: String) -> *mut c_char {
    let s = match CString::new(s) {
        Ok(c) => c,
        Err(e) => {
            let at = e.nul_position();
            let mut bytes = e.into_vec();
            bytes.truncate(at);
            CString::new(bytes).unwrap_or_default()
        }
    };
    s.into_raw()
}

/// The JSON text of an error: `{"diagnostics": [...]}`.
pub(crate) fn error_json(e: &Error) -> String {
    serde_json::json!({ "diagnostics": e.diagnostics }).to_string()
}

/// Runs `work` with panics caught. On failure, writes the error's JSON to
/// `*error` (when `error` is not null) and returns `failed`; on success
/// clears `*error`.
///
/// # Safety
/// `error` is null or points at a writable `char *`.
pub(crate) unsafe fn guard<T>(
    error: *mut *mut c_char,
    failed: T,
    work: impl FnOnce() -> Result<T, Error>,
) -> T {
    if !error.is_null() {
        *error = std::ptr::null_mut();
    }
    let outcome = catch_unwind(AssertUnwindSafe(work)).unwrap_or_else(|panic| {
        let what = panic
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "no message".to_owned());
        Err(Error {
            diagnostics: vec![unplaced(
                codes::A_INTERNAL.id,
                format!("btc failed inside its C API and recovered: {what}"),
            )
            .with_hint(
                "this is a bug in btc; the handles this call used may be left unusable: free them",
            )],
        })
    });
    match outcome {
        Ok(v) => v,
        Err(e) => {
            if !error.is_null() {
                *error = c_string(error_json(&e));
            }
            failed
        }
    }
}

trait WithHint {
    fn with_hint(self, hint: &str) -> Self;
}

impl WithHint for Diagnostic {
    fn with_hint(mut self, hint: &str) -> Self {
        self.hint = Some(hint.to_owned());
        self
    }
}

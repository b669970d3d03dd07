//! Python names and literals: every name and string from rules, plans and
//! PDDL files is written as an escaped Python string literal ([`py_str`]);
//! class names are sanitized and made unique ([`py_ident`], [`Names`]).

use std::collections::BTreeSet;
use std::fmt::Write;

/// Python's hard keywords: never identifiers.
pub(crate) const PY_KEYWORDS: &[&str] = &[
    "False", "None", "True", "and", "as", "assert", "async", "await", "break", "class", "continue",
    "def", "del", "elif", "else", "except", "finally", "for", "from", "global", "if", "import",
    "in", "is", "lambda", "nonlocal", "not", "or", "pass", "raise", "return", "try", "while",
    "with", "yield",
];

/// Builtins and module-level names of the generated module that a generated
/// class must not shadow.
pub(crate) const RESERVED: &[&str] = &[
    // builtins
    "ArithmeticError",
    "AssertionError",
    "AttributeError",
    "BaseException",
    "Ellipsis",
    "Exception",
    "ImportError",
    "IndexError",
    "KeyError",
    "LookupError",
    "NameError",
    "NotImplemented",
    "NotImplementedError",
    "OverflowError",
    "RuntimeError",
    "StopIteration",
    "SystemExit",
    "TypeError",
    "ValueError",
    "ZeroDivisionError",
    "abs",
    "all",
    "any",
    "bool",
    "callable",
    "dict",
    "enumerate",
    "float",
    "frozenset",
    "getattr",
    "hasattr",
    "int",
    "isinstance",
    "iter",
    "len",
    "list",
    "map",
    "max",
    "min",
    "next",
    "object",
    "print",
    "range",
    "repr",
    "reversed",
    "round",
    "set",
    "setattr",
    "sorted",
    "str",
    "sum",
    "super",
    "tuple",
    "type",
    "zip",
    // modules
    "py_trees",
    "sys",
    "importlib",
    // the runtime's names (`btc_runtime.py`; a test keeps this list whole)
    "Action",
    "AlwaysFailure",
    "AlwaysSuccess",
    "Condition",
    "Delay",
    "KB_KEY",
    "KbApply",
    "KbBehaviour",
    "KbHolds",
    "KnowledgeBase",
    "MAX_CALL_DEPTH",
    "Parallel",
    "Plan",
    "PlanStep",
    "READ",
    "ReactiveFallback",
    "ReactiveSequence",
    "Repeat",
    "Result",
    "Sleep",
    "Retry",
    "Status",
    "Step",
    "Timeout",
    "Unresolved",
    "WRITE",
    "WaitForStep",
    "World",
    "build_tree",
    "format_float",
    "main",
    "put_kb",
    "run",
    "value_text",
    // modules the runtime imports
    "argparse",
    "json",
    "time",
    "Decimal",
    // the generated module's own names
    "CLASSES",
    "MAX_TICKS",
    "NODE_CLASS_NAMES",
    "NODE_MODULE",
    "PLAN",
    "ROOT",
    "SHAPES",
    "STEPS",
    "STEP_NODES",
    "TREES",
    "WORLD",
    "create_behavior_tree",
    "run_main",
];

/// `s` as a Python string literal: double-quoted, ASCII only, no raw line
/// breaks, so it is safe anywhere a literal goes (and inside a comment).
pub fn py_str(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    push_py_str(&mut out, s);
    out
}

/// [`py_str`] appended to `out`: the module writes one literal per name of
/// every step, so this path allocates nothing.
pub fn push_py_str(out: &mut String, s: &str) {
    out.push('"');
    // Names are almost always plain printable ASCII: copied whole.
    if s.bytes()
        .all(|b| (b' '..=b'~').contains(&b) && b != b'\\' && b != b'"')
    {
        out.push_str(s);
        out.push('"');
        return;
    }
    for c in s.chars() {
        match c {
            '\\' => out.push_str("\\\\"),
            '"' => out.push_str("\\\""),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            ' '..='~' => out.push(c),
            c if (c as u32) < 0x100 => {
                let _ = write!(out, "\\x{:02x}", c as u32);
            }
            c if (c as u32) < 0x10000 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => {
                let _ = write!(out, "\\U{:08x}", c as u32);
            }
        }
    }
    out.push('"');
}

/// `s` made a Python identifier `[A-Za-z_][A-Za-z0-9_]*` for a class name:
/// other characters become `_`; a name that would start with `_` or a digit
/// gets the prefix `Node` (no dunders, no clash with the module's private
/// names); a keyword gets a trailing `_`.
pub fn py_ident(s: &str) -> String {
    let mut out: String = s
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if !out.starts_with(|c: char| c.is_ascii_alphabetic()) {
        out.insert_str(0, "Node");
    }
    if PY_KEYWORDS.contains(&out.as_str()) {
        out.push('_');
    }
    out
}

/// Whether `s` may be written as a keyword argument as is (ASCII, so
/// Python's NFKC normalization of identifiers cannot change it).
pub(crate) fn is_plain_kwarg(s: &str) -> bool {
    s.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
        && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !PY_KEYWORDS.contains(&s)
}

/// Identifiers handed out so far; [`Names::fresh`] makes a new one unique.
#[derive(Default)]
pub struct Names {
    taken: BTreeSet<String>,
}

impl Names {
    pub fn reserving(names: &[&str]) -> Names {
        Names {
            taken: names.iter().map(|s| s.to_string()).collect(),
        }
    }

    /// [`py_ident`] of `s`, with `_2`, `_3`, ... appended while taken.
    pub fn fresh(&mut self, s: &str) -> String {
        let base = py_ident(s);
        let mut name = base.clone();
        let mut k = 2;
        while self.taken.contains(&name) {
            name = format!("{base}_{k}");
            k += 1;
        }
        self.taken.insert(name.clone());
        name
    }
}

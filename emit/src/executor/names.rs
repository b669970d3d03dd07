//! C++ names and text: identifiers that are not keywords or members
//! BehaviorTree.CPP's bases take, class names, string literals, comments.

use super::*;

const CPP_KEYWORDS: &[&str] = &[
    "alignas",
    "alignof",
    "and",
    "and_eq",
    "asm",
    "auto",
    "bitand",
    "bitor",
    "bool",
    "break",
    "case",
    "catch",
    "char",
    "char8_t",
    "char16_t",
    "char32_t",
    "class",
    "compl",
    "concept",
    "const",
    "consteval",
    "constexpr",
    "constinit",
    "const_cast",
    "continue",
    "co_await",
    "co_return",
    "co_yield",
    "decltype",
    "default",
    "delete",
    "do",
    "double",
    "dynamic_cast",
    "else",
    "enum",
    "explicit",
    "export",
    "extern",
    "false",
    "float",
    "for",
    "friend",
    "goto",
    "if",
    "inline",
    "int",
    "long",
    "mutable",
    "namespace",
    "new",
    "noexcept",
    "not",
    "not_eq",
    "nullptr",
    "operator",
    "or",
    "or_eq",
    "private",
    "protected",
    "public",
    "register",
    "reinterpret_cast",
    "requires",
    "return",
    "short",
    "signed",
    "sizeof",
    "static",
    "static_assert",
    "static_cast",
    "struct",
    "switch",
    "template",
    "this",
    "thread_local",
    "throw",
    "true",
    "try",
    "typedef",
    "typeid",
    "typename",
    "union",
    "unsigned",
    "using",
    "virtual",
    "void",
    "volatile",
    "wchar_t",
    "while",
    "xor",
    "xor_eq",
];

/// Members of the generated classes' bases (BT.CPP's `TreeNode` and its
/// subclasses, `btc::Action`, `btc::Condition`) and names the generated code
/// uses: a port accessor never takes one of these names.
pub(super) const TAKEN_MEMBERS: &[&str] = &[
    "UID",
    "checkPostConditions",
    "checkPreConditions",
    "config",
    "emitWakeUpSignal",
    "executeTick",
    "formula",
    "fullPath",
    "getInput",
    "getLockedPortContent",
    "getRawPortValue",
    "getRemappedKey",
    "groundFormula",
    "halt",
    "haltNode",
    "input",
    "isBlackboardPointer",
    "isHalted",
    "kb",
    "modifyPortsRemapping",
    "name",
    "onHalted",
    "onRunning",
    "onStart",
    "providedPorts",
    "registrationName",
    "requiresWakeUp",
    "resetStatus",
    "setOutput",
    "setPostTickFunction",
    "setPreTickFunction",
    "setRegistrationID",
    "setStatus",
    "setTickMonitorCallback",
    "setWakeUpInstance",
    "status",
    "std",
    "step",
    "stripBlackboardPointer",
    "subscribeToStatusChange",
    "tick",
    "type",
    "waitValidStatus",
];

pub(super) fn is_keyword(s: &str) -> bool {
    CPP_KEYWORDS.contains(&s)
}

/// `s` with every character a C++ identifier cannot hold replaced by `_`
/// (and a `_` in front of a leading digit).
pub(super) fn identifier(s: &str) -> String {
    let mut out: String = s
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if out.is_empty() || out.starts_with(|c: char| c.is_ascii_digit()) {
        out.insert(0, '_');
    }
    out
}

/// The C++ class the user writes for a node.
pub fn class_name(id: &str) -> String {
    identifier(id)
}

/// The generated base of that class.
pub fn base_name(id: &str) -> String {
    format!("{}Base", class_name(id))
}

/// A C++ string literal.
pub(super) fn literal(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\x{:02x}\"\"", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Text for a `//` comment: one line, nothing that ends the comment early.
pub(super) fn comment(s: &str) -> String {
    s.replace(['\n', '\r'], " ")
}

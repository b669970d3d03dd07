//! A C++ executor for BehaviorTree.CPP, generated from the nodes a rules
//! file declares (`btc executor`). It is a CMake project:
//!
//! - `btc_nodes.hpp`: one base class per declared action and condition,
//!   with `providedPorts()` typed as the rules declare them (PDDL objects
//!   and `string`: `std::string`; `int`: `int`; `float`: `double`; `bool`)
//!   and one accessor per port. Action bases simulate the action as
//!   `btc run` does; condition bases evaluate their formula on the KB.
//! - `nodes.hpp`: the user's classes, one per node, deriving from the bases.
//!   btc writes it once and never overwrites it: when the rules declare new
//!   nodes, their classes are appended ([`update_user_nodes`]).
//! - `btc_nodes.cpp`: `registerNodes(factory, kb)`, registering the user's
//!   classes and btc's KB nodes.
//! - `main.cpp`: loads a compiled tree and its world (`.kb`), ticks it to the
//!   end and prints each step as it starts and finishes, the final status,
//!   the goal check and the KB.
//! - `CMakeLists.txt`, and `btc_support/`: btc's support library
//!   (`integrations/btcpp/`), so the project builds with nothing but
//!   BehaviorTree.CPP installed.
//!
//! Everything but `nodes.hpp` is btc's, rewritten on every run.

use btc_ir::{LeafKind, NodeModel, PortDirection};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::source::Span;
use std::collections::BTreeSet;
use std::fmt::Write as _;

/// What is generated: the C++ namespace and executable name, the rules
/// file named in comments, and the nodes to declare.
pub struct Spec<'a> {
    pub name: &'a str,
    pub rules: &'a str,
    pub nodes: &'a [NodeModel],
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Owner {
    /// btc's: rewritten by every run.
    Btc,
    /// The user's: written when missing, then only appended to.
    User,
}

#[derive(Clone, Debug, PartialEq)]
pub struct File {
    /// Relative to the executor's folder, with `/`.
    pub path: String,
    pub text: String,
    pub owner: Owner,
}

/// The file the user's node classes live in.
pub const USER_NODES: &str = "nodes.hpp";

/// Node IDs BehaviorTree.CPP 4.10 registers itself (its factory's
/// `builtinNodes()`, as `runtime/src/btcpp_builtins.xml` has them from
/// BT.CPP): a rules file may not declare them again.
pub const BTCPP_BUILTINS: &[&str] = &[
    "AlwaysFailure",
    "AlwaysSuccess",
    "AsyncFallback",
    "AsyncSequence",
    "Delay",
    "Fallback",
    "ForceFailure",
    "ForceSuccess",
    "IfThenElse",
    "Inverter",
    "KeepRunningUntilFailure",
    "LoopBool",
    "LoopDouble",
    "LoopInt",
    "LoopString",
    "Parallel",
    "ParallelAll",
    "Precondition",
    "ReactiveFallback",
    "ReactiveSequence",
    "Repeat",
    "RetryUntilSuccessful",
    "RunOnce",
    "Script",
    "ScriptCondition",
    "Sequence",
    "SequenceWithMemory",
    "SetBlackboard",
    "SkipUnlessUpdated",
    "Sleep",
    "SubTree",
    "Switch2",
    "Switch3",
    "Switch4",
    "Switch5",
    "Switch6",
    "Timeout",
    "TryCatch",
    "UnsetBlackboard",
    "WaitValueUpdate",
    "WasEntryUpdated",
    "WhileDoElse",
];

/// The nodes btc's support library registers (`btc::registerKbNodes`).
pub const SUPPORT_NODES: &[&str] = &["KbHolds", "KbApply", "KbStep", "WaitForStep"];

/// btc's support library, written into `btc_support/`. Read through
/// `emit/btcpp`, a link to `integrations/btcpp`, so that the packaged
/// crate carries the files (`cargo package` follows the link).
const SUPPORT: &[(&str, &str)] = &[
    ("CMakeLists.txt", include_str!("../btcpp/CMakeLists.txt")),
    (
        "cmake/btc_btcppConfig.cmake.in",
        include_str!("../btcpp/cmake/btc_btcppConfig.cmake.in"),
    ),
    (
        "include/btc/kb.hpp",
        include_str!("../btcpp/include/btc/kb.hpp"),
    ),
    (
        "include/btc/nodes.hpp",
        include_str!("../btcpp/include/btc/nodes.hpp"),
    ),
    ("src/sexp.hpp", include_str!("../btcpp/src/sexp.hpp")),
    ("src/sexp.cpp", include_str!("../btcpp/src/sexp.cpp")),
    ("src/world.hpp", include_str!("../btcpp/src/world.hpp")),
    ("src/world.cpp", include_str!("../btcpp/src/world.cpp")),
    ("src/kb.cpp", include_str!("../btcpp/src/kb.cpp")),
    ("src/nodes.cpp", include_str!("../btcpp/src/nodes.cpp")),
    (
        "include/btc/executor.hpp",
        include_str!("../btcpp/include/btc/executor.hpp"),
    ),
    (
        "src/executor.cpp",
        include_str!("../btcpp/src/executor.cpp"),
    ),
];

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
const TAKEN_MEMBERS: &[&str] = &[
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

fn is_keyword(s: &str) -> bool {
    CPP_KEYWORDS.contains(&s)
}

/// `s` with every character a C++ identifier cannot hold replaced by `_`
/// (and a `_` in front of a leading digit).
fn identifier(s: &str) -> String {
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
fn literal(s: &str) -> String {
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
fn comment(s: &str) -> String {
    s.replace(['\n', '\r'], " ")
}

fn port_type_enum(ty: &str) -> &'static str {
    match ty {
        "int" => "btc::PortType::Int",
        "float" => "btc::PortType::Double",
        "bool" => "btc::PortType::Bool",
        _ => "btc::PortType::String",
    }
}

fn port_description(ty: &str) -> String {
    match ty {
        "int" | "float" | "bool" | "string" => String::new(),
        pddl => format!("a PDDL object of type {pddl}"),
    }
}

/// A node's declaration as the rules write it, for comments.
fn declaration(m: &NodeModel) -> String {
    let kind = match m.kind {
        LeafKind::Action => "action",
        LeafKind::Condition => "condition",
    };
    let ports: Vec<String> = m
        .ports
        .iter()
        .map(|p| {
            let out = if p.direction == PortDirection::Output {
                "out "
            } else {
                ""
            };
            format!("{out}{}: {}", p.name, p.ty)
        })
        .collect();
    let mut s = format!("{kind} {}({})", m.id, ports.join(", "));
    if let Some(f) = &m.formula {
        let _ = write!(s, " = {f}");
    }
    comment(&s)
}

/// Accessor names for a node's ports: the port's name when it is a usable
/// C++ member name, else with `_port` after it; setters for output ports
/// are `set_NAME`. Unique within the class.
fn accessors(m: &NodeModel) -> Vec<String> {
    let mut taken: BTreeSet<String> = TAKEN_MEMBERS.iter().map(|s| (*s).to_owned()).collect();
    let mut out = Vec::new();
    for p in &m.ports {
        let mut a = identifier(&p.name);
        if is_keyword(&a) || taken.contains(&a) || a.starts_with("set_") {
            a.push_str("_port");
        }
        while taken.contains(&a) || taken.contains(&format!("set_{a}")) {
            a.push('_');
        }
        taken.insert(a.clone());
        taken.insert(format!("set_{a}"));
        out.push(a);
    }
    out
}

/// Problems that keep nodes from becoming C++ classes or from being
/// registered: `C001` (a name that is a C++ keyword, or two names that give
/// one class), `C002` (a node BT.CPP or btc's support library registers
/// already). `nodes` are the nodes to generate, each with its declaration.
pub fn check(nodes: &[(&NodeModel, Span)]) -> Vec<Diagnostic> {
    let mut diags = Vec::new();
    let mut classes: Vec<(String, &str, Span)> = Vec::new();
    for (m, span) in nodes {
        if BTCPP_BUILTINS.contains(&m.id.as_str()) || SUPPORT_NODES.contains(&m.id.as_str()) {
            let who = if SUPPORT_NODES.contains(&m.id.as_str()) {
                "btc's support library (`std::kb`)"
            } else {
                "BehaviorTree.CPP"
            };
            diags.push(
                Diagnostic::error(
                    codes::C_REGISTERED,
                    *span,
                    format!("`{}` is a node {who} registers already: the executor cannot register it again", m.id),
                )
                .with_hint(format!("rename the node, or `import std::{}` to use the built-in one", if who.starts_with("btc") { "kb" } else { "btcpp" })),
            );
            continue;
        }
        let class = class_name(&m.id);
        if is_keyword(&class) {
            diags.push(
                Diagnostic::error(
                    codes::C_CLASS_NAME,
                    *span,
                    format!(
                        "`{}` is a C++ keyword: the executor cannot name a class after it",
                        m.id
                    ),
                )
                .with_hint("rename the node"),
            );
            continue;
        }
        let clash = [class.clone(), base_name(&m.id)]
            .into_iter()
            .find_map(|name| {
                classes
                    .iter()
                    .find(|(c, _, _)| *c == name)
                    .map(|(_, other, _)| (name, *other))
            });
        if let Some((name, other)) = clash {
            diags.push(
                Diagnostic::error(
                    codes::C_CLASS_NAME,
                    *span,
                    format!(
                        "`{}` and `{other}` would both make the C++ class `{name}`",
                        m.id
                    ),
                )
                .with_hint("rename one of the nodes"),
            );
            continue;
        }
        classes.push((class.clone(), &m.id, *span));
        classes.push((base_name(&m.id), &m.id, *span));
    }
    diags
}

fn header(out: &mut String, spec: &Spec, what: &str) {
    let _ = writeln!(
        out,
        "// {what}\n// Generated by `btc executor` from {}; btc rewrites this file.",
        comment(spec.rules)
    );
}

fn base_class(out: &mut String, m: &NodeModel) {
    let base = base_name(&m.id);
    let names = accessors(m);
    let parent = match m.kind {
        LeafKind::Action => "btc::Action",
        LeafKind::Condition => "btc::Condition",
    };
    let _ = writeln!(out, "/// `{}`", declaration(m));
    let _ = writeln!(out, "class {base} : public {parent}\n{{\npublic:");
    if m.kind == LeafKind::Condition {
        let _ = writeln!(
            out,
            "  /// The condition's formula over its ports (empty: it always holds).\n  \
             static constexpr const char* formula = {};\n",
            literal(
                &m.formula
                    .as_ref()
                    .map(ToString::to_string)
                    .unwrap_or_default()
            )
        );
    }
    let _ = write!(
        out,
        "  {base}(const std::string& name, const BT::NodeConfig& config, btc::Kb& kb)\n    : {parent}(name, config, kb"
    );
    if m.kind == LeafKind::Condition {
        out.push_str(", formula, {");
        for (i, p) in m.ports.iter().enumerate() {
            if i > 0 {
                out.push_str(", ");
            }
            let _ = write!(out, "{{ {}, {} }}", literal(&p.name), port_type_enum(&p.ty));
        }
        out.push('}');
    }
    out.push_str(")\n  {}\n\n  static BT::PortsList providedPorts()\n  {\n    return {");
    for (i, p) in m.ports.iter().enumerate() {
        let dir = match p.direction {
            PortDirection::Input => "InputPort",
            PortDirection::Output => "OutputPort",
        };
        let _ = write!(
            out,
            "{}\n      BT::{dir}<{}>({}, {})",
            if i > 0 { "," } else { "" },
            p.cpp_type(),
            literal(&p.name),
            literal(&port_description(&p.ty))
        );
    }
    out.push_str(" };\n  }\n");
    if !m.ports.is_empty() {
        out.push_str("\nprotected:\n");
    }
    for (p, a) in m.ports.iter().zip(&names) {
        let ty = p.cpp_type();
        let what = match port_description(&p.ty) {
            d if d.is_empty() => String::new(),
            d => format!(": {d}"),
        };
        match p.direction {
            PortDirection::Input => {
                let _ = writeln!(
                    out,
                    "  /// Port `{}`{what}.\n  {ty} {a}() const {{ return btc::input<{ty}>(*this, {}); }}",
                    comment(&p.name),
                    literal(&p.name)
                );
            }
            PortDirection::Output => {
                let _ = writeln!(
                    out,
                    "  /// Output port `{}`{what}.\n  void set_{a}(const {ty}& value) {{ btc::output<{ty}>(*this, {}, value); }}",
                    comment(&p.name),
                    literal(&p.name)
                );
            }
        }
    }
    out.push_str("};\n\n");
}

fn nodes_header(spec: &Spec) -> String {
    let mut out = String::new();
    header(
        &mut out,
        spec,
        "One base class per node the rules declare; your classes (nodes.hpp) derive from them.",
    );
    let _ = writeln!(
        out,
        "#pragma once\n\n#include <btc/nodes.hpp>\n\n#include <string>\n\nnamespace {}\n{{\n",
        spec.name
    );
    for m in spec.nodes {
        base_class(&mut out, m);
    }
    let _ = writeln!(
        out,
        "/// Registers btc's KB nodes and the classes of nodes.hpp, all sharing `kb`.\n\
         void registerNodes(BT::BehaviorTreeFactory& factory, btc::Kb& kb);\n\n}}  // namespace {}",
        spec.name
    );
    out
}

fn register_source(spec: &Spec) -> String {
    let mut out = String::new();
    header(&mut out, spec, "Registers every node of the rules.");
    let _ = writeln!(
        out,
        "#include <functional>\n\n#include \"nodes.hpp\"\n\nnamespace {}\n{{\n\n\
         void registerNodes(BT::BehaviorTreeFactory& factory, btc::Kb& kb)\n{{\n  btc::registerKbNodes(factory, kb);",
        spec.name
    );
    for m in spec.nodes {
        let _ = writeln!(
            out,
            "  factory.registerNodeType<{}>({}, std::ref(kb));",
            class_name(&m.id),
            literal(&m.id)
        );
    }
    let _ = writeln!(out, "}}\n\n}}  // namespace {}", spec.name);
    out
}

fn user_class(out: &mut String, m: &NodeModel) {
    let class = class_name(&m.id);
    let base = base_name(&m.id);
    let _ = writeln!(out, "/// `{}`", declaration(m));
    let _ = writeln!(
        out,
        "class {class} : public {base}\n{{\npublic:\n  using {base}::{base};"
    );
    let accessors: Vec<String> = accessors(m)
        .into_iter()
        .zip(&m.ports)
        .filter(|(_, p)| p.direction == PortDirection::Input)
        .map(|(a, _)| format!("{a}()"))
        .collect();
    let ports = if accessors.is_empty() {
        String::new()
    } else {
        format!(" Ports: {}.", accessors.join(", "))
    };
    match m.kind {
        LeafKind::Action => {
            let _ = writeln!(
                out,
                "\n  // Simulated until you override these (see btc_nodes.hpp).{ports}\n  \
                 // BT::NodeStatus onStart() override;\n  \
                 // BT::NodeStatus onRunning() override;\n  \
                 // void onHalted() override;"
            );
        }
        LeafKind::Condition => {
            let how = if m.formula.is_some() {
                "evaluates its formula on the KB"
            } else {
                "always holds"
            };
            let _ = writeln!(
                out,
                "\n  // It {how} until you override tick().{ports}\n  // BT::NodeStatus tick() override;"
            );
        }
    }
    out.push_str("};\n\n");
}

/// The user's `nodes.hpp` as first written: a class per node.
pub fn user_nodes(spec: &Spec) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "// Your nodes: one class per node of {}, deriving from the bases\n\
         // `btc executor` generates in btc_nodes.hpp. btc writes this file once\n\
         // and never overwrites it; when the rules declare new nodes, their classes\n\
         // are appended at the end. The bases' default bodies simulate the node as\n\
         // `btc run` does; override them to drive your robot.\n\
         #pragma once\n\n#include \"btc_nodes.hpp\"\n\nnamespace {}\n{{\n",
        comment(spec.rules),
        spec.name
    );
    for m in spec.nodes {
        user_class(&mut out, m);
    }
    let _ = writeln!(out, "}}  // namespace {}", spec.name);
    out
}

/// What regenerating does to the user's `nodes.hpp`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct UserUpdate {
    /// The new text, when classes were appended.
    pub text: Option<String>,
    /// Nodes whose classes were appended.
    pub added: Vec<String>,
    /// Classes deriving from a base btc no longer generates, with the byte
    /// range of the derivation in the file.
    pub stale: Vec<(String, std::ops::Range<usize>)>,
}

/// `text` with comments blanked out (same length, so offsets stay).
fn without_comments(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = b.to_vec();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                out[i] = b' ';
                i += 1;
            }
        } else if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
            while i < b.len() && !(b[i] == b'*' && b.get(i + 1) == Some(&b'/')) {
                if b[i] != b'\n' {
                    out[i] = b' ';
                }
                i += 1;
            }
            for _ in 0..2 {
                if i < b.len() {
                    out[i] = b' ';
                    i += 1;
                }
            }
        } else if b[i] == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' && b[i] != b'\n' {
                if b[i] == b'\\' {
                    out[i] = b' ';
                    i += 1;
                }
                if i < b.len() {
                    out[i] = b' ';
                    i += 1;
                }
            }
            i += 1;
        } else {
            i += 1;
        }
    }
    String::from_utf8(out).unwrap_or_default()
}

/// Identifier tokens of C++ code, with their offsets.
fn words(code: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, c) in code.char_indices() {
        let w = c.is_ascii_alphanumeric() || c == '_';
        match (w, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push((s, &code[s..i]));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push((s, &code[s..]));
    }
    out
}

/// Brings the user's `nodes.hpp` up to date with the rules: a class for
/// every node that has none is appended (nothing the user wrote changes),
/// and classes that derive from a base the rules no longer give are listed.
pub fn update_user_nodes(existing: &str, spec: &Spec) -> UserUpdate {
    let code = without_comments(existing);
    let toks = words(&code);
    let mut classes: BTreeSet<&str> = BTreeSet::new();
    let mut bases: Vec<(usize, &str, &str)> = Vec::new(); // (offset, class, base)
    for w in toks.windows(2) {
        if matches!(w[0].1, "class" | "struct") {
            classes.insert(w[1].1);
        }
    }
    for (i, w) in toks.iter().enumerate() {
        if matches!(w.1, "class" | "struct") {
            if let Some((_, class)) = toks.get(i + 1) {
                // `class X : public YBase` (access specifier optional).
                let mut j = i + 2;
                if matches!(toks.get(j).map(|t| t.1), Some("final")) {
                    j += 1;
                }
                if matches!(
                    toks.get(j).map(|t| t.1),
                    Some("public" | "protected" | "private")
                ) {
                    j += 1;
                }
                if let Some((off, base)) = toks.get(j) {
                    let between = &code[w.0 + w.1.len()..*off];
                    if base.ends_with("Base") && between.contains(':') && !between.contains('{') {
                        bases.push((*off, class, base));
                    }
                }
            }
        }
    }
    let wanted: BTreeSet<String> = spec.nodes.iter().map(|m| base_name(&m.id)).collect();
    let mut update = UserUpdate::default();
    for (off, class, base) in bases {
        if !wanted.contains(base) {
            update.stale.push((class.to_owned(), off..off + base.len()));
        }
    }
    let missing: Vec<&NodeModel> = spec
        .nodes
        .iter()
        .filter(|m| !classes.contains(class_name(&m.id).as_str()))
        .collect();
    if missing.is_empty() {
        return update;
    }
    let mut text = existing.to_owned();
    if !text.ends_with('\n') {
        text.push('\n');
    }
    let _ = writeln!(
        text,
        "\n// Appended by `btc executor` for nodes the rules declare since.\nnamespace {}\n{{\n",
        spec.name
    );
    for m in &missing {
        user_class(&mut text, m);
        update.added.push(m.id.clone());
    }
    let _ = writeln!(text, "}}  // namespace {}", spec.name);
    update.text = Some(text);
    update
}

fn main_source(spec: &Spec) -> String {
    let mut out = String::new();
    header(
        &mut out,
        spec,
        "Runs a compiled tree in BehaviorTree.CPP with the nodes of nodes.hpp.",
    );
    out.push_str(MAIN_CPP.replace("@NAMESPACE@", spec.name).as_str());
    out
}

fn cmake_lists(spec: &Spec) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# The executor for {}: `btc executor` rewrites this file.\n\
         # Build: cmake -S . -B build -DCMAKE_PREFIX_PATH=<BehaviorTree.CPP prefix> && cmake --build build",
        comment(spec.rules)
    );
    let _ = writeln!(
        out,
        "cmake_minimum_required(VERSION 3.16)\nproject({name}_executor LANGUAGES CXX)\n\n\
         # btc's support library (written by btc into btc_support/), unless a\n\
         # parent project provides it already.\n\
         if(NOT TARGET btc::btcpp)\n  add_subdirectory(btc_support btc_support)\nendif()\n\n\
         add_executable({name}_executor main.cpp btc_nodes.cpp)\n\
         target_compile_features({name}_executor PRIVATE cxx_std_17)\n\
         target_link_libraries({name}_executor PRIVATE btc::btcpp)",
        name = spec.name
    );
    out
}

/// Every file of the executor, the user's `nodes.hpp` as first written.
pub fn files(spec: &Spec) -> Vec<File> {
    let btc = |path: &str, text: String| File {
        path: path.to_owned(),
        text,
        owner: Owner::Btc,
    };
    let mut out = vec![
        btc("CMakeLists.txt", cmake_lists(spec)),
        btc("main.cpp", main_source(spec)),
        btc("btc_nodes.hpp", nodes_header(spec)),
        btc("btc_nodes.cpp", register_source(spec)),
        File {
            path: USER_NODES.to_owned(),
            text: user_nodes(spec),
            owner: Owner::User,
        },
    ];
    for (path, text) in SUPPORT {
        out.push(btc(&format!("btc_support/{path}"), (*text).to_owned()));
    }
    out
}

/// A C++ namespace (and executable name) from a rules file's folder name.
pub fn namespace_for(stem: &str) -> String {
    let mut n = identifier(&stem.to_lowercase());
    if is_keyword(&n) || n == "btc" || n == "std" || n == "BT" {
        n.push_str("_nodes");
    }
    n
}

const MAIN_CPP: &str = r#"#include <btc/executor.hpp>

#include "btc_nodes.hpp"

// `EXECUTOR TREE.xml WORLD.kb [--ticks-per-action N] [--max-ticks N] [--btlog FILE]`,
// or `EXECUTOR --palette`: see btc::runExecutor (btc_support/include/btc/executor.hpp).
int main(int argc, char** argv)
{
  return btc::runExecutor(argc, argv, &@NAMESPACE@::registerNodes);
}
"#;

#[cfg(test)]
mod tests {
    use super::*;
    use btc_ir::PortModel;

    fn node(id: &str, kind: LeafKind, ports: &[(&str, &str)]) -> NodeModel {
        NodeModel {
            id: id.into(),
            kind,
            ports: ports
                .iter()
                .map(|(n, t)| PortModel {
                    name: (*n).into(),
                    direction: PortDirection::Input,
                    ty: (*t).into(),
                })
                .collect(),
            formula: None,
        }
    }

    #[test]
    fn accessors_avoid_keywords_and_base_members() {
        let m = node(
            "N",
            LeafKind::Action,
            &[
                ("robot", "robot"),
                ("class", "int"),
                ("name", "string"),
                ("name_port", "int"),
            ],
        );
        assert_eq!(
            accessors(&m),
            ["robot", "class_port", "name_port", "name_port_port"]
        );
    }

    #[test]
    fn the_builtin_list_is_btcpp_4_10s() {
        let models = include_str!("../../runtime/src/btcpp_builtins.xml");
        let ids: Vec<&str> = models
            .split("ID=\"")
            .skip(1)
            .map(|r| &r[..r.find('"').unwrap()])
            .collect();
        assert_eq!(ids, BTCPP_BUILTINS);
    }

    /// The node vocabulary's BT.CPP side is BT.CPP 4.10's: each entry's tag
    /// is a built-in (so the executor refuses to register it again), a
    /// `<Control>` when it takes a block and a `<Decorator>` when it takes
    /// one child, and each parameter is one of its input ports, of a C++
    /// type that holds the table's range.
    #[test]
    fn the_vocabulary_agrees_with_btcpp_4_10s_models() {
        use btc_ir::vocab::{Arity, ParamType, NODES};
        let models = include_str!("../../runtime/src/btcpp_builtins.xml");
        for spec in NODES {
            assert!(BTCPP_BUILTINS.contains(&spec.tag), "{}", spec.tag);
            let at = models
                .find(&format!(" ID=\"{}\"", spec.tag))
                .unwrap_or_else(|| panic!("no model for {}", spec.tag));
            let element = models[..at].rsplit('<').next().unwrap();
            let want = match spec.arity {
                Arity::One => "Decorator",
                Arity::AtLeast(_) => "Control",
            };
            assert_eq!(element, want, "{}", spec.tag);
            let rest = &models[at..];
            let body = match rest.find('>') {
                Some(i) if rest[..i].ends_with('/') => "",
                _ => &rest[..rest.find(&format!("</{element}>")).unwrap()],
            };
            for p in spec.params {
                let decl = format!("<input_port name=\"{}\" type=\"", p.port);
                let ty = body
                    .split(&decl)
                    .nth(1)
                    .and_then(|r| r.split('"').next())
                    .unwrap_or_else(|| panic!("{} has no input port {}", spec.tag, p.port));
                let (min, max) = match ty {
                    "int" => (i64::from(i32::MIN), i64::from(i32::MAX)),
                    "unsigned int" => (0, i64::from(u32::MAX)),
                    other => panic!("{}.{}: C++ type {other}", spec.tag, p.port),
                };
                assert!(
                    min <= p.min && p.max <= max,
                    "{}.{}: {}..={} does not fit `{ty}`",
                    spec.tag,
                    p.port,
                    p.min,
                    p.max
                );
                let unsigned = matches!(p.ty, ParamType::Millis);
                assert_eq!(ty == "unsigned int", unsigned, "{}.{}", spec.tag, p.port);
            }
        }
    }

    #[test]
    fn literals_escape_what_cpp_reads_specially() {
        assert_eq!(literal("a\"b\\c\n?"), "\"a\\\"b\\\\c\\n?\"");
    }

    #[test]
    fn user_file_keeps_its_classes_and_gains_missing_ones() {
        let a = node("MoveTo", LeafKind::Action, &[("robot", "robot")]);
        let b = node("Grasp", LeafKind::Action, &[]);
        let first = Spec {
            name: "ns",
            rules: "r.btrules",
            nodes: std::slice::from_ref(&a),
        };
        let mut text = user_nodes(&first);
        text = text.replace(
            "using MoveToBase::MoveToBase;",
            "using MoveToBase::MoveToBase;\n  BT::NodeStatus onStart() override { return BT::NodeStatus::SUCCESS; }",
        );
        let both = [a.clone(), b];
        let second = Spec {
            name: "ns",
            rules: "r.btrules",
            nodes: &both,
        };
        let up = update_user_nodes(&text, &second);
        assert_eq!(up.added, ["Grasp"]);
        let new = up.text.unwrap();
        assert!(new.starts_with(&text), "the user's text is kept as it was");
        assert!(new.contains("class Grasp : public GraspBase"));
        assert!(update_user_nodes(&new, &second).text.is_none());
        // MoveTo dropped from the rules: its class is stale.
        let only_b = [both[1].clone()];
        let third = Spec {
            name: "ns",
            rules: "r.btrules",
            nodes: &only_b,
        };
        let up = update_user_nodes(&new, &third);
        assert_eq!(up.stale.len(), 1);
        assert_eq!(up.stale[0].0, "MoveTo");
        assert_eq!(&new[up.stale[0].1.clone()], "MoveToBase");
    }

    #[test]
    fn commented_out_classes_do_not_count() {
        let a = node("MoveTo", LeafKind::Action, &[]);
        let spec = Spec {
            name: "ns",
            rules: "r",
            nodes: std::slice::from_ref(&a),
        };
        let up = update_user_nodes("// class MoveTo : public MoveToBase {};\n", &spec);
        assert_eq!(up.added, ["MoveTo"]);
        assert!(up.stale.is_empty());
    }

    #[test]
    fn reserved_and_clashing_names_are_reported() {
        let a = node("Sleep", LeafKind::Action, &[]);
        let b = node("delete", LeafKind::Action, &[]);
        let c = node("Move-To", LeafKind::Action, &[]);
        let d = node("Move_To", LeafKind::Action, &[]);
        let s = Span::new(0, 0, 1);
        let diags = check(&[(&a, s), (&b, s), (&c, s), (&d, s)]);
        let ids: Vec<&str> = diags.iter().map(|d| d.code).collect();
        assert_eq!(ids, ["C002", "C001", "C001"], "{diags:#?}");
    }
}

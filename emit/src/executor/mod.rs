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

mod names;
mod user;

pub use names::{base_name, class_name};
use names::{comment, identifier, is_keyword, literal, TAKEN_MEMBERS};
pub use user::{update_user_nodes, user_nodes, UserUpdate};

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
    ("CMakeLists.txt", include_str!("../../btcpp/CMakeLists.txt")),
    (
        "cmake/btc_btcppConfig.cmake.in",
        include_str!("../../btcpp/cmake/btc_btcppConfig.cmake.in"),
    ),
    (
        "include/btc/kb.hpp",
        include_str!("../../btcpp/include/btc/kb.hpp"),
    ),
    (
        "include/btc/nodes.hpp",
        include_str!("../../btcpp/include/btc/nodes.hpp"),
    ),
    ("src/sexp.hpp", include_str!("../../btcpp/src/sexp.hpp")),
    ("src/sexp.cpp", include_str!("../../btcpp/src/sexp.cpp")),
    ("src/world.hpp", include_str!("../../btcpp/src/world.hpp")),
    ("src/world.cpp", include_str!("../../btcpp/src/world.cpp")),
    ("src/kb.cpp", include_str!("../../btcpp/src/kb.cpp")),
    ("src/nodes.cpp", include_str!("../../btcpp/src/nodes.cpp")),
    (
        "include/btc/executor.hpp",
        include_str!("../../btcpp/include/btc/executor.hpp"),
    ),
    (
        "src/executor.cpp",
        include_str!("../../btcpp/src/executor.cpp"),
    ),
];

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
mod tests;

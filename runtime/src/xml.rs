//! BehaviorTree.CPP v4 XML to a [`TreeDoc`]: `<root>`, `<BehaviorTree ID>`
//! elements, `<TreeNodesModel>` (leaf kinds, port types, and the formulas
//! btc writes as `description="holds when ..."`), and btc's `KbStep`.
//! The reader is iterative: depth is checked, never the stack. The PDDL
//! text btc writes into attributes (`KbStep` effects, `KbHolds` formulas,
//! `KbApply` effects, model formulas) is decoded here, once.

use crate::engine::MAX_DEPTH;
use crate::error::LoadError;
use crate::spec::{
    default_name, Amount, Kind, NodeScripts, SNode, StepConditions, TreeDoc, Verdict,
};
use btc_ir::vocab::{NodeName, NodeSpec};
use btc_ir::{LeafKind, NodeModel, PortDirection, PortModel, PortValue};
use btc_pddl::diagnostic::{codes, did_you_mean};
use btc_pddl::logic::decode;
use quick_xml::events::attributes::Attributes;
use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;
use std::borrow::Cow;

fn syntax(msg: impl Into<String>, at: usize) -> LoadError {
    LoadError::new(codes::X_TREE_SYNTAX, msg).at(at)
}

/// An element as read: its name and attributes are slices of the file's
/// text (a value is owned only when it had entities to unescape), so
/// reading an element allocates one vector, and only what the tree keeps
/// is copied out of it.
struct Elem<'a> {
    name: &'a str,
    attrs: Vec<Attr<'a>>,
    /// Where the element's `<` is.
    at: usize,
}

struct Attr<'a> {
    key: &'a str,
    value: Cow<'a, str>,
    /// Where the attribute's name is: diagnostics about it point there.
    at: usize,
}

/// The element `e` (whose `<` is at `at`) read from `text`, the string the
/// reader reads. quick-xml's events borrow from that string but name it
/// with their own shorter lifetime, so the element's bytes are found again
/// in `text` (by address) and its attributes read from there.
fn elem<'a>(text: &'a str, e: &BytesStart, at: usize) -> Result<Elem<'a>, LoadError> {
    let content =
        slice_in(text, e).ok_or_else(|| syntax("an element that is not in the file", at))?;
    let name = &content[..e.name().as_ref().len()];
    let mut attrs = Vec::new();
    for a in Attributes::new(content, name.len()) {
        let a = a.map_err(|err| syntax(format!("a bad attribute in <{name}>: {err}"), at))?;
        let key = slice_in(content, a.key.into_inner())
            .ok_or_else(|| syntax(format!("a bad attribute name in <{name}>"), at))?;
        let key_at = at + 1 + (key.as_ptr() as usize - content.as_ptr() as usize);
        let value = a
            .unescape_value()
            .map_err(|err| syntax(format!("a bad attribute value in <{name}>: {err}"), at))?;
        attrs.push(Attr {
            key,
            value,
            at: key_at,
        });
    }
    Ok(Elem { name, attrs, at })
}

/// `part`, a slice of `text`'s bytes, as a slice of `text`.
fn slice_in<'a>(text: &'a str, part: &[u8]) -> Option<&'a str> {
    let start = (part.as_ptr() as usize).checked_sub(text.as_ptr() as usize)?;
    text.get(start..start.checked_add(part.len())?)
}

impl Elem<'_> {
    /// Where attribute `k`'s name is (the element's `<` without it).
    fn attr_at(&self, k: &str) -> usize {
        self.attrs
            .iter()
            .find(|a| a.key == k)
            .map_or(self.at, |a| a.at)
    }

    /// Where the element's tag name is.
    fn name_at(&self) -> usize {
        self.at + 1
    }

    fn get(&self, k: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|a| a.key == k)
            .map(|a| a.value.as_ref())
    }

    fn int(&self, k: &str, default: Option<i64>) -> Result<i64, LoadError> {
        match (self.get(k), default) {
            (Some(v), _) => v.trim().parse().map_err(|_| {
                LoadError::new(
                    codes::X_BAD_PORT,
                    format!("<{}>: `{k}=\"{v}\"` is not a whole number", self.name),
                )
                .at(self.at)
            }),
            (None, Some(d)) => Ok(d),
            (None, None) => Err(LoadError::new(
                codes::X_BAD_PORT,
                format!("<{}> needs the attribute `{k}`", self.name),
            )
            .at(self.at)),
        }
    }

    /// `k="{key}"`: the blackboard entry the attribute reads.
    fn entry(&self, k: &str) -> Option<String> {
        let v = self.get(k)?.trim();
        let key = v.strip_prefix('{')?.strip_suffix('}')?;
        (!key.is_empty()).then(|| key.to_owned())
    }

    /// A count (`num_attempts`): written out, or `{key}`.
    fn times(&self, k: &str) -> Result<Amount<i32>, LoadError> {
        Ok(match self.entry(k) {
            Some(key) => Amount::Entry(key),
            None => Amount::Fixed(self.count(k, None)?),
        })
    }

    /// A duration in milliseconds (`msec`): written out, or `{key}`.
    fn millis(&self, k: &str) -> Result<Amount<u64>, LoadError> {
        if let Some(key) = self.entry(k) {
            return Ok(Amount::Entry(key));
        }
        let ms = self.int(k, None)?;
        u64::try_from(ms).map(Amount::Fixed).map_err(|_| {
            LoadError::new(
                codes::X_BAD_PORT,
                format!("<{}>: `{k}` must not be negative", self.name),
            )
            .at(self.at)
        })
    }

    fn count(&self, k: &str, default: Option<i64>) -> Result<i32, LoadError> {
        let n = self.int(k, default)?;
        i32::try_from(n).ok().filter(|n| *n >= -1).ok_or_else(|| {
            LoadError::new(
                codes::X_BAD_PORT,
                format!("<{}>: `{k}` must be -1 or more, not {n}", self.name),
            )
            .at(self.at)
        })
    }
}

/// `{key}` is a blackboard entry (`{=}`: the port's own name); anything
/// else is a literal.
fn port_value(v: String) -> PortValue {
    let t = v.trim();
    if t.len() >= 2 && t.starts_with('{') && t.ends_with('}') {
        PortValue::Param(t[1..t.len() - 1].trim().to_owned())
    } else {
        PortValue::Text(v)
    }
}

/// The attributes that are ports: all but `name`, `skip` and the pre- and
/// post-conditions.
fn ports(e: &Elem, skip: &[&str]) -> Vec<(String, PortValue)> {
    e.attrs
        .iter()
        .filter(|a| {
            a.key != "name" && !skip.contains(&a.key) && !NodeScripts::ATTRIBUTES.contains(&a.key)
        })
        .map(|a| (a.key.to_owned(), port_value(a.value.to_string())))
        .collect()
}

/// The pre- and post-condition attributes (`_skipIf`...); any other
/// attribute starting with `_` but `_autoremap` is refused (X041).
fn node_scripts(e: &Elem) -> Result<NodeScripts, LoadError> {
    let mut scripts = NodeScripts::default();
    for a in &e.attrs {
        let k = a.key;
        match NodeScripts::ATTRIBUTES.iter().position(|s| *s == k) {
            Some(i) => *scripts.slot(i) = Some(a.value.to_string()),
            None if k.starts_with('_') && k != "_autoremap" => {
                let known = NodeScripts::ATTRIBUTES
                    .iter()
                    .copied()
                    .chain(["_autoremap"]);
                let mut err = LoadError::new(
                    codes::X_UNSUPPORTED,
                    format!("<{}>: the attribute `{k}` is not one btc runs", e.name),
                )
                .at(a.at);
                err = err.hint(match did_you_mean(k, known) {
                    Some(h) => h,
                    None => "btc runs the pre- and post-conditions `_failureIf`, `_successIf`, `_skipIf`, `_while`, `_onSuccess`, `_onFailure`, `_post` and `_onHalted`, and SubTree's `_autoremap`".into(),
                });
                return Err(err);
            }
            None => {}
        }
    }
    Ok(scripts)
}

/// A status named in an attribute (`Precondition`'s `else`).
fn verdict(e: &Elem, key: &str, default: Verdict) -> Result<Verdict, LoadError> {
    Ok(match e.get(key).map(str::trim) {
        None => default,
        Some("SUCCESS") => Verdict::Success,
        Some("FAILURE") => Verdict::Failure,
        Some("SKIPPED") => Verdict::Skipped,
        Some("RUNNING") => Verdict::Running,
        Some(v) => {
            return Err(LoadError::new(
                codes::X_BAD_PORT,
                format!(
                    "<{}>: `{key}=\"{v}\"` is not SUCCESS, FAILURE, SKIPPED or RUNNING",
                    e.name
                ),
            )
            .at(e.at))
        }
    })
}

/// A `KbStep`'s condition attributes, when it has any.
fn step_conditions(e: &Elem) -> Result<Option<Box<StepConditions>>, LoadError> {
    let get = |k: &str| pddl(e, k, decode::formula, "a condition");
    let c = StepConditions {
        start: get("start_condition")?,
        over_all: get("over_all_condition")?,
        end: get("end_condition")?,
    };
    Ok((c != StepConditions::default()).then(|| Box::new(c)))
}

/// BehaviorTree.CPP 4.10's built-in nodes that btc's engine does not run
/// (`runtime/src/btcpp_builtins.xml` lists them all): refused by name
/// rather than taken for a node of the embedder's.
const NOT_RUN: [&str; 12] = [
    "AsyncFallback",
    "AsyncSequence",
    "LoopBool",
    "LoopDouble",
    "LoopInt",
    "LoopString",
    "ParallelAll",
    "SkipUnlessUpdated",
    "TryCatch",
    "UnsetBlackboard",
    "WaitValueUpdate",
    "WasEntryUpdated",
];

/// A node of the vocabulary ([`btc_ir::vocab::NODES`]), its attributes
/// named by the table's ports. No wildcard: a node added to the table does
/// not compile until the reader knows it.
fn vocab_kind(spec: &NodeSpec, e: &Elem) -> Result<Kind, LoadError> {
    use btc_ir::{ControlName as C, DecoratorName as D};
    let port = |i: usize| spec.params[i].port;
    Ok(match spec.name {
        NodeName::Control(C::Sequence) => Kind::Sequence,
        NodeName::Control(C::ReactiveSequence) => Kind::ReactiveSequence,
        NodeName::Control(C::Fallback) => Kind::Fallback,
        NodeName::Control(C::ReactiveFallback) => Kind::ReactiveFallback,
        // BT.CPP's defaults: every child must succeed, one failure fails it.
        NodeName::Control(C::Parallel) => Kind::Parallel {
            success: e.count(port(0), Some(-1))?,
            failure: e.count(port(1), Some(1))?,
        },
        NodeName::Decorator(D::Inverter) => Kind::Inverter,
        NodeName::Decorator(D::ForceSuccess) => Kind::ForceSuccess,
        NodeName::Decorator(D::ForceFailure) => Kind::ForceFailure,
        NodeName::Decorator(D::Retry) => Kind::Retry(e.times(port(0))?),
        NodeName::Decorator(D::Repeat) => Kind::Repeat(e.times(port(0))?),
        NodeName::Decorator(D::Timeout) => Kind::Timeout(e.millis(port(0))?),
        NodeName::Decorator(D::Delay) => Kind::Delay(e.millis(port(0))?),
        NodeName::Decorator(D::RunOnce) => Kind::RunOnce {
            then_skip: match e.get("then_skip").map(str::trim) {
                None | Some("true") | Some("1") => true,
                Some("false") | Some("0") => false,
                Some(v) => {
                    return Err(LoadError::new(
                        codes::X_BAD_PORT,
                        format!("<{}>: `then_skip=\"{v}\"` is not true or false", e.name),
                    )
                    .at(e.at))
                }
            },
        },
    })
}

fn node_of(e: Elem) -> Result<SNode, LoadError> {
    if NOT_RUN.contains(&e.name) {
        return Err(LoadError::new(
            codes::X_UNSUPPORTED,
            format!(
                "<{}> is a BehaviorTree.CPP 4.10 node btc does not run",
                e.name
            ),
        )
        .at(e.name_at())
        .hint("docs/runtime.md lists the nodes btc runs"));
    }
    let name = e.get("name").map(str::to_owned);
    let scripts = node_scripts(&e)?;
    let kind = if let Some(spec) = NodeSpec::by_tag(e.name) {
        vocab_kind(spec, &e)?
    } else {
        match e.name {
            "SequenceWithMemory" | "SequenceStar" => Kind::SequenceWithMemory,
            "KeepRunningUntilFailure" => Kind::KeepRunningUntilFailure,
            "IfThenElse" => Kind::IfThenElse,
            "WhileDoElse" => Kind::WhileDoElse,
            "Switch2" | "Switch3" | "Switch4" | "Switch5" | "Switch6" => {
                let n: usize = e.name["Switch".len()..].parse().unwrap_or(2);
                let variable = e.get("variable").map(|v| port_value(v.to_owned()));
                let variable = variable.ok_or_else(|| {
                    LoadError::new(
                        codes::X_BAD_PORT,
                        format!("<{}> needs the attribute `variable`", e.name),
                    )
                    .at(e.at)
                })?;
                let cases = (1..=n)
                    .map(|k| {
                        e.get(&format!("case_{k}"))
                            .map(|v| port_value(v.to_owned()))
                            .unwrap_or(PortValue::Text(String::new()))
                    })
                    .collect();
                Kind::Switch {
                    variable: Box::new(variable),
                    cases,
                }
            }
            "Precondition" => Kind::Precondition {
                code: e
                    .get("if")
                    .ok_or_else(|| {
                        LoadError::new(codes::X_BAD_PORT, "<Precondition> needs the attribute `if`")
                            .at(e.at)
                    })?
                    .to_owned(),
                otherwise: verdict(&e, "else", Verdict::Failure)?,
            },
            "SubTree" => {
                let id = e.get("ID").ok_or_else(|| {
                    LoadError::new(codes::X_BAD_PORT, "<SubTree> needs the attribute `ID`").at(e.at)
                })?;
                let id = id.to_owned();
                let autoremap = e.get("_autoremap").is_some_and(|v| v.trim() == "true");
                Kind::SubTree {
                    id,
                    ports: ports(&e, &["ID", "_autoremap"]),
                    autoremap,
                }
            }
            "KbStep" => {
                let step = e.int("step", None)?;
                let step = usize::try_from(step)
                    .ok()
                    .filter(|s| *s >= 1)
                    .ok_or_else(|| {
                        LoadError::new(
                            codes::X_BAD_PORT,
                            format!("<KbStep>: `step` counts from 1, not {step}"),
                        )
                        .at(e.at)
                    })?;
                Kind::Step {
                    step: step - 1,
                    start_effect: pddl(&e, "start_effect", decode::effect, "an effect")?
                        .map(Box::new),
                    end_effect: pddl(&e, "end_effect", decode::effect, "an effect")?.map(Box::new),
                    conditions: step_conditions(&e)?,
                }
            }
            // Groot 1 spelling: <Action ID="MoveTo" .../>.
            "Action" | "Condition" => {
                let id = e.get("ID").ok_or_else(|| {
                    LoadError::new(
                        codes::X_BAD_PORT,
                        format!("<{}> needs the attribute `ID`", e.name),
                    )
                    .at(e.at)
                })?;
                let id = id.to_owned();
                let kind = Some(if e.name == "Action" {
                    LeafKind::Action
                } else {
                    LeafKind::Condition
                });
                Kind::Leaf {
                    id,
                    kind,
                    ports: ports(&e, &["ID"]),
                }
            }
            _ => {
                let mut ps = ports(&e, &[]);
                kb_ports(&e, &mut ps)?;
                Kind::Leaf {
                    id: e.name.to_owned(),
                    kind: None,
                    ports: ps,
                }
            }
        }
    };
    check_scripts(&e, &kind, &scripts)?;
    Ok(SNode {
        kind,
        name,
        children: Vec::new(),
        scripts,
        at: Some(e.at),
    })
}

/// The node's scripts parse (X040 at the attribute that holds the one that
/// does not), checked here where the file's positions are known; the engine
/// compiles them when it builds the tree.
fn check_scripts(e: &Elem, kind: &Kind, scripts: &NodeScripts) -> Result<(), LoadError> {
    let code = match kind {
        Kind::Precondition { code, .. } => Some(("if", code.as_str())),
        Kind::Leaf { id, ports, .. } if id == "Script" || id == "ScriptCondition" => {
            ports.iter().find_map(|(k, v)| match v {
                PortValue::Text(t) if k == "code" => Some(("code", t.as_str())),
                _ => None,
            })
        }
        _ => None,
    };
    for (attr, text) in scripts.given().chain(code) {
        if let Err(err) = crate::script::parse(text) {
            return Err(
                crate::script::syntax_error(default_name(kind), attr, text, &err)
                    .at(e.attr_at(attr)),
            );
        }
    }
    Ok(())
}

/// A PDDL attribute decoded (empty or absent: `None`); X005 when it is no
/// PDDL `what`.
fn pddl<T>(
    e: &Elem,
    key: &str,
    decode: fn(&str) -> Result<T, String>,
    what: &str,
) -> Result<Option<T>, LoadError> {
    match e.get(key).map(str::trim).filter(|t| !t.is_empty()) {
        None => Ok(None),
        Some(t) => decode(t)
            .map(Some)
            .map_err(|m| bad_pddl(e, key, t, what, &m)),
    }
}

fn bad_pddl(e: &Elem, key: &str, text: &str, what: &str, why: &str) -> LoadError {
    LoadError::new(
        codes::X_KB,
        format!("<{}>: `{key}=\"{text}\"` is not {what}: {why}", e.name),
    )
    .at(e.at)
}

/// `KbHolds`' formula and `KbApply`'s effect, written out, as PDDL values.
fn kb_ports(e: &Elem, ports: &mut [(String, PortValue)]) -> Result<(), LoadError> {
    for (k, v) in ports {
        let PortValue::Text(t) = v else { continue };
        *v = match (e.name, k.as_str()) {
            ("KbHolds", "formula") => PortValue::Formula(std::sync::Arc::new(
                decode::formula(t).map_err(|m| bad_pddl(e, k, t, "a PDDL condition", &m))?,
            )),
            ("KbApply", "effect") => PortValue::Effect(std::sync::Arc::new(
                decode::effect(t).map_err(|m| bad_pddl(e, k, t, "a PDDL effect", &m))?,
            )),
            _ => continue,
        };
    }
    Ok(())
}

fn model_of(e: &Elem, kind: LeafKind) -> Result<NodeModel, LoadError> {
    let id = e.get("ID").ok_or_else(|| {
        LoadError::new(
            codes::X_BAD_PORT,
            format!("<{}> in <TreeNodesModel> needs the attribute `ID`", e.name),
        )
        .at(e.at)
    })?;
    let formula = match e
        .get("description")
        .and_then(|d| d.strip_prefix("holds when "))
    {
        Some(t) if kind == LeafKind::Condition => Some(
            decode::formula(t)
                .map_err(|m| bad_pddl(e, "description", t, "a PDDL condition", &m))?,
        ),
        _ => None,
    };
    Ok(NodeModel {
        id: id.to_owned(),
        kind,
        ports: Vec::new(),
        formula,
    })
}

fn port_model(e: &Elem) -> Option<PortModel> {
    let direction = match e.name {
        "input_port" | "inout_port" => PortDirection::Input,
        "output_port" => PortDirection::Output,
        _ => return None,
    };
    let ty = match e.get("type").unwrap_or("std::string") {
        "int" | "long" | "unsigned" | "unsigned int" | "int64_t" | "uint64_t" => "int",
        "double" | "float" => "float",
        "bool" => "bool",
        _ => "string",
    };
    Some(PortModel {
        name: e.get("name")?.to_owned(),
        direction,
        ty: ty.to_owned(),
    })
}

enum Place {
    Outside,
    Root,
    Tree(String),
    Models,
    Model(Option<usize>),
    Skip(usize),
}

/// An `<include path="...">` of a file, as written.
#[derive(Clone, Debug, PartialEq)]
pub struct Include {
    pub path: String,
    /// Byte offset of the `<include>` element.
    pub at: usize,
}

/// One file as read, before its includes are resolved and its main tree
/// is chosen.
#[derive(Debug)]
pub struct Parsed {
    /// Its trees and models (`main` still empty).
    pub doc: TreeDoc,
    /// Its `main_tree_to_execute`.
    pub main: Option<String>,
    pub includes: Vec<Include>,
}

/// Parses a BT.CPP v4 XML document that includes no other file (a tree
/// read from text has no folder to find them in; [`crate::include::load`]
/// reads a file and what it includes).
pub fn parse(text: &str) -> Result<TreeDoc, LoadError> {
    let p = parse_file(text)?;
    if let Some(inc) = p.includes.first() {
        return Err(LoadError::new(
            codes::X_INCLUDE_READ,
            format!(
                "<include path=\"{}\">: this tree is read as text, with no folder to find the file in",
                inc.path
            ),
        )
        .at(inc.at)
        .hint("run the tree from its file (`btc run --tree FILE`)"));
    }
    finish(p.doc, p.main)
}

/// The document's main tree: `main_tree_to_execute`, or its only tree.
pub fn finish(mut doc: TreeDoc, main: Option<String>) -> Result<TreeDoc, LoadError> {
    doc.main = match main {
        Some(m) => m,
        None if doc.trees.len() == 1 => doc.trees[0].0.clone(),
        None => {
            return Err(syntax("<root> does not say which tree to run", 0)
                .hint("add `main_tree_to_execute=\"ID\"` to <root>"))
        }
    };
    if doc.tree(&doc.main).is_none() {
        return Err(LoadError::new(
            codes::X_SUBTREE,
            format!("the main tree `{}` is not defined in this file", doc.main),
        ));
    }
    Ok(doc)
}

/// Parses one BT.CPP v4 XML file: its trees, models and includes.
pub fn parse_file(text: &str) -> Result<Parsed, LoadError> {
    let mut includes = Vec::new();
    let mut r = Reader::from_str(text);
    r.config_mut().trim_text(true);
    let mut doc = TreeDoc::default();
    let mut main: Option<String> = None;
    let mut place = Place::Outside;
    let mut stack: Vec<SNode> = Vec::new();
    let mut tree_root: Option<SNode> = None;
    let mut saw_root = false;
    // IDs seen so far (a set: a list made 100,000 trees quadratic).
    let mut tree_ids = std::collections::HashSet::new();
    loop {
        let at = r.buffer_position() as usize;
        let ev = r.read_event().map_err(|e| {
            syntax(
                format!("this is not well-formed XML: {e}"),
                r.error_position() as usize,
            )
        })?;
        // Where the element's `<` is: the reader stands after its `>`.
        let end = r.buffer_position() as usize;
        let (start, empty) = match &ev {
            Event::Start(e) => (Some(elem(text, e, end.saturating_sub(e.len() + 2))?), false),
            Event::Empty(e) => (Some(elem(text, e, end.saturating_sub(e.len() + 3))?), true),
            _ => (None, false),
        };
        let at = start.as_ref().map_or(at, |e| e.at);
        if let Some(e) = start {
            match &mut place {
                Place::Outside => {
                    if e.name != "root" {
                        return Err(syntax(
                            format!("a BT.CPP file starts with <root>, not <{}>", e.name),
                            at,
                        ));
                    }
                    saw_root = true;
                    if let Some(f) = e.get("BTCPP_format") {
                        if f.trim() != "4" {
                            return Err(syntax(
                                format!("BTCPP_format=\"{f}\": the runtime reads BT.CPP v4 files"),
                                at,
                            )
                            .hint("convert it with BT.CPP's v3-to-v4 script, or Groot2"));
                        }
                    }
                    main = e.get("main_tree_to_execute").map(str::to_owned);
                    if !empty {
                        place = Place::Root;
                    }
                }
                Place::Root => match e.name {
                    "BehaviorTree" => {
                        let id = e.get("ID").unwrap_or("MainTree").to_owned();
                        if !tree_ids.insert(id.clone()) {
                            return Err(syntax(format!("the tree `{id}` is defined twice"), at));
                        }
                        if empty {
                            return Err(syntax(format!("the tree `{id}` has no root node"), at));
                        }
                        place = Place::Tree(id);
                    }
                    "TreeNodesModel" => {
                        if !empty {
                            place = Place::Models;
                        }
                    }
                    "include" => {
                        if e.get("ros_pkg").is_some() {
                            return Err(LoadError::new(
                                codes::X_UNSUPPORTED,
                                "<include ros_pkg>: btc does not look up ROS packages",
                            )
                            .at(e.attr_at("ros_pkg"))
                            .hint("give `path` relative to this file, without `ros_pkg`"));
                        }
                        let path = e.get("path").map(str::trim).filter(|p| !p.is_empty());
                        let Some(path) = path else {
                            return Err(LoadError::new(
                                codes::X_INCLUDE_READ,
                                "<include> needs the attribute `path`",
                            )
                            .at(at));
                        };
                        includes.push(Include {
                            path: path.to_owned(),
                            at,
                        });
                        if !empty {
                            place = Place::Skip(1);
                        }
                    }
                    _ => {
                        if !empty {
                            place = Place::Skip(1);
                        }
                    }
                },
                Place::Tree(id) => {
                    if stack.len() >= MAX_DEPTH {
                        return Err(LoadError::new(
                            codes::X_TOO_DEEP,
                            format!("the tree is nested deeper than {MAX_DEPTH} levels"),
                        )
                        .at(at));
                    }
                    if stack.is_empty() && tree_root.is_some() {
                        return Err(syntax(
                            format!("the tree `{id}` has more than one root node"),
                            at,
                        ));
                    }
                    let n = node_of(e)?;
                    if empty {
                        match stack.last_mut() {
                            Some(p) => p.children.push(n),
                            None => tree_root = Some(n),
                        }
                    } else {
                        stack.push(n);
                    }
                }
                Place::Models => {
                    let kind = match e.name {
                        "Action" => Some(LeafKind::Action),
                        "Condition" => Some(LeafKind::Condition),
                        _ => None,
                    };
                    let idx = match kind {
                        Some(k) => {
                            doc.models.push(model_of(&e, k)?);
                            Some(doc.models.len() - 1)
                        }
                        None => None,
                    };
                    if !empty {
                        place = Place::Model(idx);
                    }
                }
                Place::Model(idx) => {
                    if let (Some(i), Some(p)) = (idx, port_model(&e)) {
                        doc.models[*i].ports.push(p);
                    }
                    if !empty {
                        place = Place::Skip(1);
                    }
                }
                Place::Skip(d) => {
                    if !empty {
                        *d += 1;
                    }
                }
            }
            continue;
        }
        match ev {
            Event::End(_) => {
                place = match place {
                    Place::Root => Place::Outside,
                    Place::Models => Place::Root,
                    Place::Model(_) => Place::Models,
                    Place::Skip(1) => Place::Root,
                    Place::Skip(d) => Place::Skip(d - 1),
                    Place::Tree(id) => match stack.pop() {
                        Some(n) => {
                            match stack.last_mut() {
                                Some(p) => p.children.push(n),
                                None => tree_root = Some(n),
                            }
                            Place::Tree(id)
                        }
                        None => {
                            let root = tree_root.take().ok_or_else(|| {
                                syntax(format!("the tree `{id}` has no root node"), at)
                            })?;
                            doc.trees.push((id, root));
                            Place::Root
                        }
                    },
                    Place::Outside => Place::Outside,
                };
            }
            Event::Text(t) if matches!(place, Place::Tree(_)) && !t.is_empty() => {
                return Err(syntax("text inside a tree: only elements are allowed", at));
            }
            Event::Eof => break,
            _ => {}
        }
    }
    if !saw_root {
        return Err(syntax("this file has no <root> element", 0));
    }
    Ok(Parsed {
        doc,
        main,
        includes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn braces_name_blackboard_entries() {
        assert_eq!(
            port_value("{target}".into()),
            PortValue::Param("target".into())
        );
        assert_eq!(port_value("{=}".into()), PortValue::Param("=".into()));
        assert_eq!(port_value("bin1".into()), PortValue::Text("bin1".into()));
        assert_eq!(port_value("{".into()), PortValue::Text("{".into()));
    }

    #[test]
    fn errors_point_at_the_element() {
        let text = "<root BTCPP_format=\"4\">\n  <BehaviorTree ID=\"M\">\n    <Repeat num_cycles=\"x\">\n      <AlwaysSuccess/>\n    </Repeat>\n  </BehaviorTree>\n</root>\n";
        let e = parse(text).unwrap_err();
        assert_eq!(e.code.id, "X003");
        assert_eq!(&text[e.offset.unwrap()..][..7], "<Repeat");
    }

    #[test]
    fn v3_files_and_includes_are_refused() {
        let e = parse("<root BTCPP_format=\"3\"></root>").unwrap_err();
        assert_eq!(e.code.id, "X001");
        let e = parse("<root><include path=\"x.xml\"/></root>").unwrap_err();
        assert_eq!(e.code.id, "X042");
        let text = "<root><include path=\"x.xml\" ros_pkg=\"p\"/></root>";
        let e = parse(text).unwrap_err();
        assert_eq!(e.code.id, "X041");
        assert_eq!(&text[e.offset.unwrap()..][..9], "ros_pkg=\"");
    }

    #[test]
    fn script_errors_point_at_their_attribute() {
        // Attribute values with entities and multi-byte text before: the
        // position is the attribute's name, in bytes of the file.
        let text = "<root BTCPP_format=\"4\"><BehaviorTree ID=\"M\">\n<Sequence name=\"é&gt;\" _skipIf=\"a &gt; = 1\">\n<Script code=\"x := 1\"/><AlwaysSuccess _onSucces=\"x := 2\"/></Sequence></BehaviorTree></root>";
        let e = parse(text).unwrap_err();
        assert_eq!(e.code.id, "X040");
        assert_eq!(&text[e.offset.unwrap()..][..8], "_skipIf=");
        assert!(
            e.message.starts_with("`_skipIf` of `Sequence`: "),
            "{}",
            e.message
        );
        let text = text.replace("a &gt; = 1", "a &gt; 1");
        let e = parse(&text).unwrap_err();
        assert_eq!(e.code.id, "X041");
        assert_eq!(&text[e.offset.unwrap()..][..10], "_onSucces=");
        let text = text
            .replace("_onSucces", "_onSuccess")
            .replace("x := 1", "x :=");
        let e = parse(&text).unwrap_err();
        assert_eq!(e.code.id, "X040");
        assert_eq!(&text[e.offset.unwrap()..][..5], "code=");
        let text = "<root BTCPP_format=\"4\"><BehaviorTree ID=\"M\"><Precondition else=\"FAILURE\" if=\"((\"><AlwaysSuccess/></Precondition></BehaviorTree></root>";
        let e = parse(text).unwrap_err();
        assert_eq!(e.code.id, "X040");
        assert_eq!(&text[e.offset.unwrap()..][..3], "if=");
    }

    #[test]
    fn bt_cpp_nodes_btc_does_not_run_are_refused_by_name() {
        for id in NOT_RUN {
            let text = format!(
                "<root BTCPP_format=\"4\"><BehaviorTree ID=\"M\"><{id}/></BehaviorTree></root>"
            );
            let e = parse(&text).unwrap_err();
            assert_eq!(e.code.id, "X041", "{id}");
            assert_eq!(&text[e.offset.unwrap()..][..id.len()], id, "the tag name");
            assert_eq!(
                e.message,
                format!("<{id}> is a BehaviorTree.CPP 4.10 node btc does not run")
            );
        }
    }

    #[test]
    fn models_give_leaf_kinds_ports_and_formulas() {
        let text = "<root main_tree_to_execute=\"M\"><BehaviorTree ID=\"M\"><Ok robot=\"r\"/></BehaviorTree><TreeNodesModel><Condition ID=\"Ok\" description=\"holds when (ok ?robot)\"><input_port name=\"robot\" type=\"int\"/></Condition></TreeNodesModel></root>";
        let d = parse(text).unwrap();
        let m = d.model("Ok").unwrap();
        assert_eq!(m.kind, LeafKind::Condition);
        assert_eq!(
            m.formula.as_ref().map(|f| f.to_string()).as_deref(),
            Some("(ok ?robot)")
        );
        assert_eq!(m.ports[0].ty, "int");
    }
}

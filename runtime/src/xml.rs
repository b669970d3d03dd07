//! BehaviorTree.CPP v4 XML to a [`TreeDoc`]: `<root>`, `<BehaviorTree ID>`
//! elements, `<TreeNodesModel>` (leaf kinds, port types, and the formulas
//! btc writes as `description="holds when ..."`), and btc's `KbStep`.
//! The reader is iterative: depth is checked, never the stack. The PDDL
//! text btc writes into attributes (`KbStep` effects, `KbHolds` formulas,
//! `KbApply` effects, model formulas) is decoded here, once.

use crate::engine::MAX_DEPTH;
use crate::error::LoadError;
use crate::spec::{Amount, Kind, SNode, StepConditions, TreeDoc};
use btc_ir::{LeafKind, NodeModel, PortDirection, PortModel, PortValue};
use btc_pddl::diagnostic::codes;
use btc_pddl::logic::decode;
use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;

fn syntax(msg: impl Into<String>, at: usize) -> LoadError {
    LoadError::new(codes::X_TREE_SYNTAX, msg).at(at)
}

struct Elem {
    name: String,
    attrs: Vec<(String, String)>,
    at: usize,
}

fn elem(e: &BytesStart, r: &Reader<&[u8]>, at: usize) -> Result<Elem, LoadError> {
    let name = String::from_utf8_lossy(e.name().as_ref()).into_owned();
    let mut attrs = Vec::new();
    for a in e.attributes() {
        let a = a.map_err(|err| syntax(format!("a bad attribute in <{name}>: {err}"), at))?;
        let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
        let value = a
            .decode_and_unescape_value(r.decoder())
            .map_err(|err| syntax(format!("a bad attribute value in <{name}>: {err}"), at))?
            .into_owned();
        attrs.push((key, value));
    }
    Ok(Elem { name, attrs, at })
}

impl Elem {
    fn get(&self, k: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(a, _)| a == k)
            .map(|(_, v)| v.as_str())
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

/// The attributes that are ports (all but `name` and `skip`), moved out.
fn ports(e: &mut Elem, skip: &[&str]) -> Vec<(String, PortValue)> {
    std::mem::take(&mut e.attrs)
        .into_iter()
        .filter(|(k, _)| k != "name" && !skip.contains(&k.as_str()))
        .map(|(k, v)| (k, port_value(v)))
        .collect()
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

fn node_of(mut e: Elem) -> Result<SNode, LoadError> {
    let name = e.get("name").map(str::to_owned);
    let kind = match e.name.as_str() {
        "Sequence" => Kind::Sequence,
        "ReactiveSequence" => Kind::ReactiveSequence,
        "SequenceWithMemory" | "SequenceStar" => Kind::SequenceWithMemory,
        "Fallback" => Kind::Fallback,
        "ReactiveFallback" => Kind::ReactiveFallback,
        "Parallel" => Kind::Parallel {
            success: e.count("success_count", Some(-1))?,
            failure: e.count("failure_count", Some(1))?,
        },
        "Inverter" => Kind::Inverter,
        "ForceSuccess" => Kind::ForceSuccess,
        "ForceFailure" => Kind::ForceFailure,
        "KeepRunningUntilFailure" => Kind::KeepRunningUntilFailure,
        "RetryUntilSuccessful" => Kind::Retry(match e.entry("num_attempts") {
            Some(k) => Amount::Entry(k),
            None => Amount::Fixed(e.count("num_attempts", None)?),
        }),
        "Repeat" => Kind::Repeat(match e.entry("num_cycles") {
            Some(k) => Amount::Entry(k),
            None => Amount::Fixed(e.count("num_cycles", None)?),
        }),
        "Timeout" => Kind::Timeout(match e.entry("msec") {
            Some(k) => Amount::Entry(k),
            None => {
                let ms = e.int("msec", None)?;
                Amount::Fixed(u64::try_from(ms).map_err(|_| {
                    LoadError::new(codes::X_BAD_PORT, "<Timeout>: `msec` must not be negative")
                        .at(e.at)
                })?)
            }
        }),
        "SubTree" => {
            let id = e.get("ID").ok_or_else(|| {
                LoadError::new(codes::X_BAD_PORT, "<SubTree> needs the attribute `ID`").at(e.at)
            })?;
            let id = id.to_owned();
            let autoremap = e.get("_autoremap").is_some_and(|v| v.trim() == "true");
            Kind::SubTree {
                id,
                ports: ports(&mut e, &["ID", "_autoremap"]),
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
                start_effect: pddl(&e, "start_effect", decode::effect, "an effect")?,
                end_effect: pddl(&e, "end_effect", decode::effect, "an effect")?,
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
                ports: ports(&mut e, &["ID"]),
            }
        }
        _ => {
            let mut ps = ports(&mut e, &[]);
            kb_ports(&e, &mut ps)?;
            Kind::Leaf {
                id: std::mem::take(&mut e.name),
                kind: None,
                ports: ps,
            }
        }
    };
    Ok(SNode {
        kind,
        name,
        children: Vec::new(),
        at: Some(e.at),
    })
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
        *v = match (e.name.as_str(), k.as_str()) {
            ("KbHolds", "formula") => PortValue::Formula(
                decode::formula(t).map_err(|m| bad_pddl(e, k, t, "a PDDL condition", &m))?,
            ),
            ("KbApply", "effect") => PortValue::Effect(
                decode::effect(t).map_err(|m| bad_pddl(e, k, t, "a PDDL effect", &m))?,
            ),
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
    let direction = match e.name.as_str() {
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

/// Parses a BT.CPP v4 XML document.
pub fn parse(text: &str) -> Result<TreeDoc, LoadError> {
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
            Event::Start(e) => (Some(elem(e, &r, end.saturating_sub(e.len() + 2))?), false),
            Event::Empty(e) => (Some(elem(e, &r, end.saturating_sub(e.len() + 3))?), true),
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
                Place::Root => match e.name.as_str() {
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
                        return Err(syntax(
                            "<include> is not supported: put every tree in one file",
                            at,
                        ))
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
                    let kind = match e.name.as_str() {
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
        assert!(e.message.contains("include"));
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

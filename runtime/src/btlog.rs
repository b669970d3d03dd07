//! Groot2 replays: a run in BehaviorTree.CPP's `FileLogger2` format
//! (`.btlog`, `src/loggers/bt_file_logger_v2.cpp` of BT.CPP 4.10).
//!
//! The file is `BTCPP4-FileLogger2`, the protocol byte 1, the tree as XML
//! (what BT.CPP's `WriteTreeToXML(tree, true, true)` writes: one
//! `<BehaviorTree>` per tree instance with its `_fullpath`, every node with
//! its `_uid` and its ports, then the models of every node, BT.CPP's own
//! included) with its length in front, the first timestamp (microseconds
//! since the epoch), and one 9-byte record per status change: 6 bytes of
//! microseconds since the first timestamp, the node's uid (2 bytes) and
//! its status (1 byte: IDLE 0, RUNNING 1, SUCCESS 2, FAILURE 3, SKIPPED 4), all little
//! endian. Node uids are BT.CPP's: preorder from 1, subtrees expanded where
//! they are called, as btc's engine numbers its nodes (uid = index + 1).
//!
//! Times are simulated: a change at tick `t` is at `t * ms_per_tick`. As
//! BT.CPP's `Tree::tickRoot` does, the root goes back to IDLE after the
//! tick that finished the tree; that change is written too.

use crate::engine::{Engine, Observer, RunView, Status, TickEvent};
use crate::error::LoadError;
use crate::spec::{default_name, Kind, SNode, TreeDoc, Verdict};
use btc_ir::{LeafKind, PortDirection, PortValue};
use btc_pddl::diagnostic::codes;
use quick_xml::escape::escape;
use std::fmt::Write as _;

/// BT.CPP 4.10's own node models, as its `writeTreeNodesModelXML` writes
/// them for a bare factory (runtime/tests/btcpp_conformance.rs checks it).
const BUILTIN_MODELS: &str = include_str!("btcpp_builtins.xml");

/// The most nodes a `.btlog` can name (uids are 16 bits).
pub const MAX_NODES: usize = u16::MAX as usize;

/// An XML element, kept in order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Element {
    pub name: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Element>,
    pub text: Option<String>,
}

impl Element {
    fn new(name: &str) -> Element {
        Element {
            name: name.to_owned(),
            ..Element::default()
        }
    }

    fn attr(mut self, k: &str, v: impl Into<String>) -> Element {
        self.attrs.push((k.to_owned(), v.into()));
        self
    }

    fn write(&self, out: &mut String, depth: usize) {
        for _ in 0..depth {
            out.push_str("    ");
        }
        let _ = write!(out, "<{}", self.name);
        for (k, v) in &self.attrs {
            let _ = write!(out, " {k}=\"{}\"", escape(v.as_str()));
        }
        match (&self.text, self.children.is_empty()) {
            (None, true) => out.push_str("/>\n"),
            (Some(t), true) => {
                let _ = writeln!(out, ">{}</{}>", escape(t.as_str()), self.name);
            }
            _ => {
                out.push_str(">\n");
                for c in &self.children {
                    c.write(out, depth + 1);
                }
                for _ in 0..depth {
                    out.push_str("    ");
                }
                let _ = writeln!(out, "</{}>", self.name);
            }
        }
    }
}

/// A node model: element name (`Action`, `Decorator`...), ID, ports.
#[derive(Clone, Debug, PartialEq)]
struct Model {
    element: Element,
}

impl Model {
    fn id(&self) -> &str {
        self.element
            .attrs
            .iter()
            .find(|(k, _)| k == "ID")
            .map_or("", |(_, v)| v.as_str())
    }

    /// Ports with a default value: BT.CPP lists them on every node.
    fn defaults(&self) -> impl Iterator<Item = (&str, &str)> {
        self.element.children.iter().filter_map(|p| {
            let get = |k: &str| {
                p.attrs
                    .iter()
                    .find(|(a, _)| a == k)
                    .map(|(_, v)| v.as_str())
            };
            Some((get("name")?, get("default")?))
        })
    }
}

/// Reads models from `<TreeNodesModel>` XML (BT.CPP's own).
fn read_models(text: &str) -> Vec<Model> {
    use quick_xml::events::Event;
    let mut r = quick_xml::Reader::from_str(text);
    r.config_mut().trim_text(true);
    let mut stack: Vec<Element> = Vec::new();
    let mut out = Vec::new();
    let decoder = r.decoder();
    let elem = |e: &quick_xml::events::BytesStart| {
        let mut el = Element::new(&String::from_utf8_lossy(e.name().as_ref()));
        for a in e.attributes().flatten() {
            let v = a
                .decode_and_unescape_value(decoder)
                .map(|v| v.into_owned())
                .unwrap_or_default();
            el.attrs
                .push((String::from_utf8_lossy(a.key.as_ref()).into_owned(), v));
        }
        el
    };
    let mut close = |stack: &mut Vec<Element>, el: Element| match stack.len() {
        // Elements right under <TreeNodesModel> are models.
        2 => out.push(Model { element: el }),
        0 => {}
        _ => stack.last_mut().expect("a parent").children.push(el),
    };
    loop {
        match r.read_event() {
            Ok(Event::Start(e)) => stack.push(elem(&e)),
            Ok(Event::Empty(e)) => {
                let el = elem(&e);
                close(&mut stack, el);
            }
            Ok(Event::Text(t)) => {
                if let Some(top) = stack.last_mut() {
                    top.text = t
                        .decode()
                        .ok()
                        .and_then(|d| quick_xml::escape::unescape(&d).ok().map(|u| u.into_owned()));
                }
            }
            Ok(Event::End(_)) => {
                if let Some(el) = stack.pop() {
                    close(&mut stack, el);
                }
            }
            Ok(Event::Eof) | Err(_) => break,
            _ => {}
        }
    }
    out
}

/// The models of btc's support library's nodes (`btc::registerKbNodes`).
fn support_model(id: &str) -> Option<Model> {
    let port = |name: &str, ty: &str, default: Option<&str>, text: &str| {
        let mut p = Element::new("input_port")
            .attr("name", name)
            .attr("type", ty);
        if let Some(d) = default {
            p = p.attr("default", d);
        }
        p.text = Some(text.to_owned());
        p
    };
    let s = "std::string";
    let (kind, ports) = match id {
        "KbStep" => (
            "Decorator",
            vec![
                port(
                    "end_condition",
                    s,
                    Some(""),
                    "checked when the child succeeds",
                ),
                port("end_effect", s, Some(""), "applied when the child succeeds"),
                port(
                    "over_all_condition",
                    s,
                    Some(""),
                    "checked when an action of the step starts",
                ),
                port(
                    "start_condition",
                    s,
                    Some(""),
                    "checked when the step starts",
                ),
                port("start_effect", s, Some(""), "applied when the step starts"),
                port("step", "int", None, "the plan step, from 1"),
            ],
        ),
        "KbHolds" => (
            "Condition",
            vec![port("formula", s, None, "a ground PDDL condition")],
        ),
        "KbApply" => (
            "Action",
            vec![port("effect", s, None, "a ground PDDL effect")],
        ),
        "WaitForStep" => (
            "Action",
            vec![port(
                "step",
                "int",
                None,
                "the plan step to wait for, from 1",
            )],
        ),
        _ => return None,
    };
    let mut e = Element::new(kind).attr("ID", id);
    e.children = ports;
    Some(Model { element: e })
}

fn doc_model(m: &btc_ir::NodeModel) -> Model {
    let kind = match m.kind {
        LeafKind::Action => "Action",
        LeafKind::Condition => "Condition",
    };
    let mut e = Element::new(kind).attr("ID", m.id.clone());
    for p in &m.ports {
        let dir = match p.direction {
            PortDirection::Input => "input_port",
            PortDirection::Output => "output_port",
        };
        let mut port = Element::new(dir)
            .attr("name", p.name.clone())
            .attr("type", p.cpp_type());
        // As the executor's generated bases describe a PDDL-typed port.
        if !matches!(p.ty.as_str(), "int" | "float" | "bool" | "string") {
            port.text = Some(format!("a PDDL object of type {}", p.ty));
        }
        e.children.push(port);
    }
    Model { element: e }
}

/// A status as BT.CPP writes it (`Precondition`'s `else`).
fn verdict_text(v: Verdict) -> &'static str {
    match v {
        Verdict::Success => "SUCCESS",
        Verdict::Failure => "FAILURE",
        Verdict::Skipped => "SKIPPED",
        Verdict::Running => "RUNNING",
    }
}

fn port_text(v: &PortValue) -> String {
    match v {
        PortValue::Param(p) => format!("{{{p}}}"),
        other => other.to_text(),
    }
}

struct Writer<'a, 'w> {
    doc: &'a TreeDoc,
    engine: &'a Engine<'w>,
    models: &'a [Model],
    next: usize,
    /// `<BehaviorTree>` elements, in the order BT.CPP makes the instances.
    trees: Vec<Element>,
}

impl Writer<'_, '_> {
    fn model(&self, id: &str) -> Option<&Model> {
        self.models.iter().find(|m| m.id() == id)
    }

    /// The node's ports as BT.CPP's `config().input_ports` holds them.
    fn ports(&self, n: &SNode) -> Vec<(String, String)> {
        let mut ports: Vec<(String, String)> = match &n.kind {
            Kind::Parallel { .. }
            | Kind::Retry(_)
            | Kind::Repeat(_)
            | Kind::Timeout(_)
            | Kind::Delay(_) => n
                .kind
                .vocab_ports()
                .into_iter()
                .map(|(k, v)| (k.to_owned(), v))
                .collect(),
            Kind::Switch { variable, cases } => std::iter::once(("variable".into(), &**variable))
                .chain(
                    cases
                        .iter()
                        .enumerate()
                        .map(|(k, c)| (format!("case_{}", k + 1), c)),
                )
                .map(|(k, v)| (k, port_text(v)))
                .collect(),
            Kind::RunOnce { then_skip } => vec![("then_skip".into(), then_skip.to_string())],
            Kind::Precondition { code, otherwise } => vec![
                ("if".into(), code.clone()),
                ("else".into(), verdict_text(*otherwise).into()),
            ],
            Kind::SubTree { ports, .. } | Kind::Leaf { ports, .. } => ports
                .iter()
                .filter(|(k, _)| k != "_autoremap")
                .map(|(k, v)| (k.clone(), port_text(v)))
                .collect(),
            Kind::Step {
                step,
                start_effect,
                end_effect,
                conditions,
            } => {
                let info = self.doc.steps.get(*step);
                fn text<T: std::fmt::Display>(given: Option<&T>, planned: Option<&T>) -> String {
                    given.or(planned).map(T::to_string).unwrap_or_default()
                }
                let c = conditions.as_deref().cloned().unwrap_or_default();
                vec![
                    ("step".into(), (step + 1).to_string()),
                    (
                        "start_effect".into(),
                        text(
                            start_effect.as_deref(),
                            info.and_then(|s| s.logic.eff_start.as_deref()),
                        ),
                    ),
                    (
                        "end_effect".into(),
                        text(
                            end_effect.as_deref(),
                            info.and_then(|s| s.logic.eff_end.as_deref()),
                        ),
                    ),
                    (
                        "start_condition".into(),
                        text(
                            c.start.as_ref(),
                            info.and_then(|s| s.logic.pre_start.as_deref()),
                        ),
                    ),
                    (
                        "over_all_condition".into(),
                        text(
                            c.over_all.as_ref(),
                            info.and_then(|s| s.logic.pre_over_all.as_deref()),
                        ),
                    ),
                    (
                        "end_condition".into(),
                        text(
                            c.end.as_ref(),
                            info.and_then(|s| s.logic.pre_end.as_deref()),
                        ),
                    ),
                ]
            }
            _ => Vec::new(),
        };
        // BT.CPP's `config().pre_conditions` and `post_conditions`.
        ports.extend(
            n.scripts
                .given()
                .map(|(a, code)| (a.to_owned(), code.to_owned())),
        );
        if !matches!(n.kind, Kind::SubTree { .. }) {
            if let Some(m) = self.model(default_name(&n.kind)) {
                for (k, d) in m.defaults() {
                    if !ports.iter().any(|(p, _)| p == k) {
                        ports.push((k.to_owned(), d.to_owned()));
                    }
                }
            }
        }
        ports
    }

    /// The element of `n` (and, for a SubTree, its instance's tree).
    fn node(&mut self, n: &SNode, path: &str) -> Result<Element, LoadError> {
        let i = self.next;
        self.next += 1;
        let id = default_name(&n.kind);
        let meta = self.engine.meta.get(i).ok_or_else(mismatch)?;
        if meta.id != id && !(meta.id == "SubTree" && matches!(n.kind, Kind::SubTree { .. })) {
            return Err(mismatch());
        }
        let uid = (i + 1).to_string();
        if let Kind::SubTree { id: tid, .. } = &n.kind {
            let full = if path.is_empty() {
                format!("{tid}::{uid}")
            } else {
                format!("{path}/{tid}::{uid}")
            };
            let mut e = Element::new("SubTree")
                .attr("ID", tid.clone())
                .attr("_fullpath", full.clone())
                .attr("_uid", uid);
            e.attrs.extend(self.ports(n));
            let def = self.doc.tree(tid).ok_or_else(mismatch)?;
            // BT.CPP lists the instance's tree where it makes it: before
            // the trees of instances further on.
            let slot = self.trees.len();
            self.trees.push(
                Element::new("BehaviorTree")
                    .attr("ID", tid.clone())
                    .attr("_fullpath", full.clone()),
            );
            let root = self.node(def, &full)?;
            self.trees[slot].children.push(root);
            return Ok(e);
        }
        let mut e = Element::new(id)
            .attr("name", meta.name.clone())
            .attr("_uid", uid);
        e.attrs.extend(self.ports(n));
        for c in &n.children {
            let child = self.node(c, path)?;
            e.children.push(child);
        }
        Ok(e)
    }
}

fn mismatch() -> LoadError {
    LoadError::new(
        codes::X_BTLOG,
        "the tree document and the engine's nodes disagree: the .btlog cannot name the nodes",
    )
}

/// The tree of `engine` (built from `doc`) as BT.CPP's `WriteTreeToXML`
/// writes it: the XML a `.btlog` carries.
pub fn tree_xml(doc: &TreeDoc, engine: &Engine) -> Result<String, LoadError> {
    if engine.node_count() > MAX_NODES {
        return Err(LoadError::new(
            codes::X_BTLOG,
            format!(
                "the tree has {} nodes; a .btlog names at most {MAX_NODES} (its node ids are 16 bits)",
                engine.node_count()
            ),
        )
        .hint("Groot2 cannot replay a tree this large: run it without --btlog"));
    }
    let mut models = read_models(BUILTIN_MODELS);
    for m in &doc.models {
        if !models.iter().any(|x| x.id() == m.id) {
            models.push(doc_model(m));
        }
    }
    for id in ["KbStep", "KbHolds", "KbApply", "WaitForStep"] {
        let used = engine.meta.iter().any(|n| n.id == id);
        if used && !models.iter().any(|x| x.id() == id) {
            models.extend(support_model(id));
        }
    }
    models.sort_by(|a, b| a.id().cmp(b.id()));
    let main = doc.tree(&doc.main).ok_or_else(mismatch)?;
    let mut w = Writer {
        doc,
        engine,
        models: &models,
        next: 0,
        trees: vec![Element::new("BehaviorTree")
            .attr("ID", doc.main.clone())
            .attr("_fullpath", "")],
    };
    let root = w.node(main, "")?;
    w.trees[0].children.push(root);
    if w.next != engine.node_count() {
        return Err(mismatch());
    }
    let mut top = Element::new("root").attr("BTCPP_format", "4");
    top.children = std::mem::take(&mut w.trees);
    let mut nodes_model = Element::new("TreeNodesModel");
    nodes_model.children = models.into_iter().map(|m| m.element).collect();
    top.children.push(nodes_model);
    let mut out = String::new();
    top.write(&mut out, 0);
    Ok(out)
}

fn code(s: Status) -> u8 {
    match s {
        Status::Idle => 0,
        Status::Running => 1,
        Status::Success => 2,
        Status::Failure => 3,
        Status::Skipped => 4,
    }
}

/// The Groot2 replay of a run, as BT.CPP's `FileLogger2` makes it: an
/// observer that keeps each status change as the 9 bytes of its record
/// (time, node uid, status), and [`BtlogRecorder::finish`] writes the file.
#[derive(Debug)]
pub struct BtlogRecorder {
    ms_per_tick: u64,
    records: Vec<u8>,
}

impl BtlogRecorder {
    /// A recorder for an engine that runs `ms_per_tick` simulated
    /// milliseconds a tick (the replay's clock).
    pub fn new(ms_per_tick: u64) -> Self {
        BtlogRecorder {
            ms_per_tick,
            records: Vec::new(),
        }
    }

    fn record(&mut self, tick: u64, node: u32, to: Status) {
        let usec = tick.saturating_mul(self.ms_per_tick).saturating_mul(1000);
        self.records.extend_from_slice(&usec.to_le_bytes()[..6]);
        self.records
            .extend_from_slice(&((node + 1) as u16).to_le_bytes());
        self.records.push(code(to));
    }

    /// The `.btlog` of the finished run: `status` is what the run came to;
    /// `start_usec` the wall-clock start (microseconds since the epoch).
    pub fn finish(
        mut self,
        doc: &TreeDoc,
        engine: &Engine,
        status: Status,
        start_usec: i64,
    ) -> Result<Vec<u8>, LoadError> {
        let xml = tree_xml(doc, engine)?;
        let len = i32::try_from(xml.len()).map_err(|_| {
            LoadError::new(
                codes::X_BTLOG,
                "the tree's XML is over 2 GiB: a .btlog cannot hold it",
            )
        })?;
        if status.is_done() && engine.node_count() > 0 {
            // Tree::tickRoot's reset of the root after the last tick.
            self.record(engine.tick, 0, Status::Idle);
        }
        let mut out = Vec::with_capacity(64 + xml.len() + self.records.len());
        out.extend_from_slice(b"BTCPP4-FileLogger2");
        out.push(1);
        out.extend_from_slice(&len.to_le_bytes());
        out.extend_from_slice(xml.as_bytes());
        out.extend_from_slice(&start_usec.to_le_bytes());
        out.extend_from_slice(&self.records);
        Ok(out)
    }
}

impl Observer for BtlogRecorder {
    fn observe(&mut self, event: &TickEvent, _: &RunView<'_>) {
        if let TickEvent::Status { tick, node, to, .. } = *event {
            self.record(tick, node, to);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::Options;

    fn leaf(id: &str) -> SNode {
        SNode::leaf(id)
    }

    fn doc(root: SNode) -> TreeDoc {
        TreeDoc {
            main: "M".into(),
            trees: vec![("M".into(), root)],
            ..TreeDoc::default()
        }
    }

    #[test]
    fn a_tree_too_large_for_16_bit_uids_is_refused_with_x030() {
        let root = SNode {
            kind: Kind::Sequence,
            name: None,
            children: (0..MAX_NODES).map(|_| leaf("AlwaysSuccess")).collect(),
            scripts: Default::default(),
            at: None,
        };
        let d = doc(root);
        let e = Engine::build(&d, None, Options::default()).unwrap();
        let err = tree_xml(&d, &e).unwrap_err();
        assert_eq!(err.code.id, "X030");
        assert!(err.message.contains("65535"), "{}", err.message);
    }

    #[test]
    fn records_are_nine_bytes_after_the_header_the_xml_and_the_start() {
        let d = doc(leaf("AlwaysSuccess"));
        let mut e = Engine::build(&d, None, Options::default()).unwrap();
        e.observe(BtlogRecorder::new(10));
        let s = e.run(10, |_| {});
        let rec = e.take_observer::<BtlogRecorder>().unwrap();
        let b = rec.finish(&d, &e, s, 1234).unwrap();
        assert_eq!(&b[..19], b"BTCPP4-FileLogger2\x01");
        let n = i32::from_le_bytes(b[19..23].try_into().unwrap()) as usize;
        let xml = std::str::from_utf8(&b[23..23 + n]).unwrap();
        assert!(
            xml.contains(r#"<AlwaysSuccess name="AlwaysSuccess" _uid="1"/>"#),
            "{xml}"
        );
        assert_eq!(
            i64::from_le_bytes(b[23 + n..31 + n].try_into().unwrap()),
            1234
        );
        let records = &b[31 + n..];
        // IDLE -> SUCCESS at tick 1 (10 ms), then tickRoot's reset to IDLE.
        assert_eq!(records.len(), 18);
        assert_eq!(&records[..9], &[0x10, 0x27, 0, 0, 0, 0, 1, 0, 2]);
        assert_eq!(records[17], 0);
    }
}

//! BehaviorTree.CPP v4 XML. The main tree calls one `<BehaviorTree>` per
//! rule through `<SubTree>` with port remapping (or, with `inline`, is one
//! flat tree); every leaf and subtree is declared in `<TreeNodesModel>` so
//! Groot2 opens the file. A plan step is a `KbStep` decorator carrying the
//! step's effects; the KB conditions btc adds are `KbHolds` leaves.
//!
//! `SubTree` elements get no `name` attribute: Groot2's monitor crashes on it.

use crate::sink::{Handover, Sink};
use crate::sizing::{steps_with_nodes, StepSizer, SAMPLE_STEPS};
use btc_ir::*;
use std::fmt::Write as _;
use std::io;
use std::sync::Arc;

/// Whether a character must be escaped (or replaced) in an attribute value.
const fn needs_escape(c: char) -> bool {
    matches!(
        c,
        '&' | '<' | '>' | '"' | '\'' | '\u{0}'..='\u{1F}' | '\u{FFFE}' | '\u{FFFF}'
    )
}

/// Appends `s` escaped for an XML attribute value. Newlines and tabs become
/// character references (a parser would fold them into spaces otherwise);
/// characters XML 1.0 forbids become U+FFFD.
pub fn escape_attr_into(out: &mut String, s: &str) {
    // Runs of plain text are copied whole; bytes are classed by a table
    // (a long plan's attributes are nearly all plain ASCII), and only a
    // flagged byte is looked at as a character.
    let b = s.as_bytes();
    let (mut plain_from, mut i) = (0, 0);
    while i < b.len() {
        if !FLAGGED[b[i] as usize] {
            i += 1;
            continue;
        }
        // A flagged byte starts a character: ASCII, or U+EFxx's lead byte.
        let c = s[i..].chars().next().expect("a character starts here");
        let len = c.len_utf8();
        if needs_escape(c) {
            out.push_str(&s[plain_from..i]);
            plain_from = i + len;
            match c {
                '&' => out.push_str("&amp;"),
                '<' => out.push_str("&lt;"),
                '>' => out.push_str("&gt;"),
                '"' => out.push_str("&quot;"),
                '\'' => out.push_str("&apos;"),
                '\n' => out.push_str("&#10;"),
                '\r' => out.push_str("&#13;"),
                '\t' => out.push_str("&#9;"),
                _ => out.push('\u{FFFD}'),
            }
        }
        i += len;
    }
    out.push_str(&s[plain_from..]);
}

/// The bytes that may start a character [`needs_escape`] takes: the ASCII
/// ones, and 0xEF, the lead byte of U+FFFE and U+FFFF.
static FLAGGED: [bool; 256] = {
    let mut t = [false; 256];
    let mut i = 0;
    while i < 128 {
        t[i] = needs_escape(i as u8 as char);
        i += 1;
    }
    t[0xEF] = true;
    t
};

/// [`escape_attr_into`] as a value; borrows when nothing needs escaping.
pub fn escape_attr(s: &str) -> std::borrow::Cow<'_, str> {
    if !s.chars().any(needs_escape) {
        return std::borrow::Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len() + 8);
    escape_attr_into(&mut out, s);
    std::borrow::Cow::Owned(out)
}

/// An XML element name from an id: ids are BT.CPP node names, which user
/// rules spell freely; anything not allowed in a name becomes `_`.
pub fn element_name(id: &str) -> std::borrow::Cow<'_, str> {
    let valid = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.';
    if id.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_') && id.chars().all(valid) {
        return std::borrow::Cow::Borrowed(id);
    }
    let mut out: String = id
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if !out.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_') {
        out.insert(0, '_');
    }
    std::borrow::Cow::Owned(out)
}

/// An indenting XML writer straight into a `String`: elements are opened,
/// given attributes one at a time and closed, with no per-element
/// allocation (a 100,000-step plan writes a million elements).
struct Xml<'w> {
    out: String,
    depth: usize,
    /// Where values are printed before they are escaped.
    scratch: String,
    /// Shared conditions and effects as escaped text, by the address of
    /// their value: the steps that repeat a ground action share them, and
    /// each is printed once. (The IR is borrowed for the whole emit, so an
    /// address names one value.)
    shared: rustc_hash::FxHashMap<usize, Box<str>>,
    /// Steps' nodes as XML, by the address of the shared node and the
    /// depth they were written at.
    step_nodes: rustc_hash::FxHashMap<(usize, usize), Box<str>>,
    /// Steps' `(action arg ...)` as escaped text, by the address of their
    /// shared logic.
    step_calls: rustc_hash::FxHashMap<usize, Box<str>>,
    /// Steps' text after their number, by the addresses of their shared
    /// logic and child and the depth.
    step_tails: rustc_hash::FxHashMap<(usize, usize, usize), Box<str>>,
    /// Sizes the buffer by the plan's first steps (when it is returned
    /// whole).
    sizer: StepSizer,
    /// Where the buffer goes at step boundaries.
    sink: Sink<'w>,
}

impl<'w> Xml<'w> {
    fn new(capacity: usize, sink: Sink<'w>) -> Xml<'w> {
        let mut out = String::with_capacity(capacity);
        out.push_str(r#"<?xml version="1.0" encoding="UTF-8"?>"#);
        Xml {
            out,
            depth: 0,
            scratch: String::new(),
            shared: Default::default(),
            step_nodes: Default::default(),
            step_calls: Default::default(),
            step_tails: Default::default(),
            sizer: StepSizer::new(0),
            sink,
        }
    }

    fn newline(&mut self) {
        self.out.push('\n');
        for _ in 0..self.depth {
            self.out.push_str("  ");
        }
    }

    /// `<name` on a new line; attributes follow, then [`Xml::close`].
    fn open(&mut self, name: &str) -> &mut Self {
        self.newline();
        self.out.push('<');
        self.out.push_str(name);
        self
    }

    fn attr(&mut self, key: &str, value: &str) -> &mut Self {
        self.out.push(' ');
        self.out.push_str(key);
        self.out.push_str("=\"");
        escape_attr_into(&mut self.out, value);
        self.out.push('"');
        self
    }

    /// An attribute whose value is `value` printed (and escaped); empty
    /// for none.
    fn attr_display(&mut self, key: &str, value: Option<&impl std::fmt::Display>) -> &mut Self {
        self.scratch.clear();
        if let Some(v) = value {
            let _ = write!(self.scratch, "{v}");
        }
        self.out.push(' ');
        self.out.push_str(key);
        self.out.push_str("=\"");
        escape_attr_into(&mut self.out, &self.scratch);
        self.out.push('"');
        self
    }

    /// [`Xml::attr_display`] of a shared value, printed once per value.
    fn attr_shared<T: std::fmt::Display>(
        &mut self,
        key: &str,
        value: Option<&Arc<T>>,
    ) -> &mut Self {
        let Some(v) = value else {
            return self.attr(key, "");
        };
        let text = self
            .shared
            .entry(Arc::as_ptr(v) as *const u8 as usize)
            .or_insert_with(|| {
                let mut s = String::new();
                escape_attr_into(&mut s, &v.to_string());
                s.into()
            });
        self.out.push(' ');
        self.out.push_str(key);
        self.out.push_str("=\"");
        self.out.push_str(text);
        self.out.push('"');
        self
    }

    /// An attribute whose value is written by `f` (unescaped: only for
    /// numbers and already-safe text).
    fn attr_with(&mut self, key: &str, f: impl FnOnce(&mut String)) -> &mut Self {
        self.out.push(' ');
        self.out.push_str(key);
        self.out.push_str("=\"");
        f(&mut self.out);
        self.out.push('"');
        self
    }

    /// A node's `name`: BT.CPP has no interpolation in names, so a part
    /// that a call fills in is written `?param`, the subtree port that
    /// carries its value (inlined trees have every part filled).
    fn name(&mut self, name: &Option<Label>) -> &mut Self {
        if let Some(n) = name {
            self.attr_display("name", Some(n));
        }
        self
    }

    /// BT.CPP's pre- and post-condition attributes (`_skipIf="..."`).
    fn scripts(&mut self, scripts: &NodeScripts) -> &mut Self {
        for (attr, text) in scripts.given() {
            self.attr(attr, text);
        }
        self
    }

    fn port(&mut self, p: &Port) -> &mut Self {
        match &p.value {
            PortValue::Text(s) => self.attr(&p.name, s),
            PortValue::Param(s) => {
                self.out.push(' ');
                self.out.push_str(&p.name);
                self.out.push_str("=\"{");
                escape_attr_into(&mut self.out, s);
                self.out.push_str("}\"");
                self
            }
            PortValue::Formula(f) => self.attr_shared(&p.name, Some(f)),
            PortValue::Effect(e) => self.attr_shared(&p.name, Some(e)),
            other => self.attr(&p.name, &other.to_text()),
        }
    }

    /// Ends the start tag: `/>` when `empty`, else `>` and a level deeper.
    fn close(&mut self, empty: bool) {
        if empty {
            self.out.push_str("/>");
        } else {
            self.out.push('>');
            self.depth += 1;
        }
    }

    fn end(&mut self, name: &str) {
        self.depth -= 1;
        self.newline();
        self.out.push_str("</");
        self.out.push_str(name);
        self.out.push('>');
    }
}

fn number(x: &mut Xml, key: &str, n: impl std::fmt::Display) {
    x.attr_with(key, |out| {
        let _ = write!(out, "{n}");
    });
}

/// [`number`] for an integer, without the formatting machinery (one per
/// step of a long plan).
fn integer(x: &mut Xml, key: &str, n: impl itoa::Integer) {
    x.attr_with(key, |out| push_int(out, n));
}

fn node(x: &mut Xml, n: &Node, ir: &TreeIr) {
    match n {
        Node::Control {
            control,
            name,
            children,
            scripts,
        } => {
            let spec = control.spec();
            let tag = spec.tag;
            x.open(tag).name(name).scripts(scripts);
            for (p, v) in spec.params.iter().zip(control.params()) {
                number(x, p.port, v);
            }
            x.close(children.is_empty());
            if children.is_empty() {
                return;
            }
            for c in children {
                node(x, c, ir);
            }
            x.end(tag);
        }
        Node::Decorator {
            decorator,
            name,
            child,
            scripts,
        } => {
            let spec = decorator.spec();
            let tag = spec.tag;
            x.open(tag).name(name).scripts(scripts);
            if let (Some(p), Some(count)) = (spec.params.first(), decorator.count()) {
                number(x, p.port, count);
            }
            x.close(false);
            node(x, child, ir);
            x.end(tag);
        }
        Node::Leaf {
            id,
            name,
            ports,
            scripts,
            ..
        } => {
            x.open(&element_name(id)).name(name).scripts(scripts);
            for p in ports {
                x.port(p);
            }
            x.close(true);
        }
        Node::SubTree { id, ports, scripts } => {
            x.open("SubTree").attr("ID", id).scripts(scripts);
            for p in ports {
                x.port(p);
            }
            x.close(true);
        }
        Node::Step { step, child } => {
            x.sizer.start(&x.out);
            let info = ir.steps.get(*step);
            x.open("KbStep");
            x.out.push_str(" name=\"step ");
            push_int(&mut x.out, step + 1);
            if let Some(s) = info {
                let key = Arc::as_ptr(&s.logic) as usize;
                let call = x.step_calls.entry(key).or_insert_with(|| {
                    let mut out = String::from(": (");
                    escape_attr_into(&mut out, &s.logic.action);
                    for a in s.logic.args.iter() {
                        out.push(' ');
                        escape_attr_into(&mut out, a);
                    }
                    out.push(')');
                    out.into()
                });
                x.out.push_str(call);
            }
            x.out.push('"');
            integer(x, "step", step + 1);
            // What follows the step's number is its logic's and its
            // child's: written once for the steps that share both.
            match info.filter(|s| Arc::strong_count(&s.logic) > 1) {
                Some(s) => {
                    let key = (
                        Arc::as_ptr(&s.logic) as usize,
                        Arc::as_ptr(child) as usize,
                        x.depth,
                    );
                    if let Some(text) = x.step_tails.get(&key) {
                        x.out.push_str(text);
                    } else {
                        let start = x.out.len();
                        x.sink.hold();
                        step_tail(x, info, child, ir);
                        x.sink.release();
                        let text = x.out[start..].into();
                        x.step_tails.insert(key, text);
                    }
                }
                None => step_tail(x, info, child, ir),
            }
            // Room after the steps for the rule trees and the models.
            x.sizer.written(&mut x.out, 65_536);
            x.sink.step_done(&mut x.out);
        }
    }
}

/// A `KbStep`'s effects and conditions, its child and its end tag.
fn step_tail(x: &mut Xml, info: Option<&StepInfo>, child: &Arc<Node>, ir: &TreeIr) {
    x.attr_shared(
        "start_effect",
        info.and_then(|s| s.logic.eff_start.as_ref()),
    )
    .attr_shared("end_effect", info.and_then(|s| s.logic.eff_end.as_ref()));
    // The step's conditions, so an executor that does not read the
    // domain checks what `btc run` checks (written only when there
    // are some: most steps have just a precondition).
    if let Some(s) = info {
        for (key, cond) in [
            ("start_condition", &s.logic.pre_start),
            ("over_all_condition", &s.logic.pre_over_all),
            ("end_condition", &s.logic.pre_end),
        ] {
            if cond.is_some() {
                x.attr_shared(key, cond.as_ref());
            }
        }
    }
    x.close(false);
    shared_node(x, child, ir);
    x.end("KbStep");
}

/// [`node`] of a node that steps share: written once per depth, then
/// copied.
fn shared_node(x: &mut Xml, n: &Arc<Node>, ir: &TreeIr) {
    let key = (Arc::as_ptr(n) as usize, x.depth);
    if let Some(text) = x.step_nodes.get(&key) {
        x.out.push_str(text);
        return;
    }
    let start = x.out.len();
    x.sink.hold();
    node(x, n, ir);
    x.sink.release();
    let text = x.out[start..].into();
    x.step_nodes.insert(key, text);
}

/// The XML document for a compiled plan.
pub fn emit(ir: &TreeIr, inline: bool) -> String {
    emit_into(ir, inline, Sink::none()).expect("a buffer is written without errors")
}

/// [`emit`] streamed to `w` as it is produced.
pub fn emit_to(ir: &TreeIr, inline: bool, w: &mut dyn io::Write) -> io::Result<()> {
    emit_into(ir, inline, Sink::to(w)).map(drop)
}

/// [`emit_to`], its buffers handed over whole as they fill.
pub fn emit_handing_over(ir: &TreeIr, inline: bool, hand: &mut Handover<'_>) -> io::Result<()> {
    emit_into(ir, inline, Sink::hand(hand)).map(drop)
}

fn emit_into(ir: &TreeIr, inline: bool, sink: Sink<'_>) -> io::Result<String> {
    // Room for the first steps; the rest is sized as they are written.
    let estimate = 4096 + ir.steps.len().min(SAMPLE_STEPS) * 512 + ir.trees.len() * 2048;
    let sizer = sink.sizer(steps_with_nodes(ir));
    let mut x = Xml::new(sink.capacity(estimate), sink);
    x.sizer = sizer;
    x.open("root")
        .attr("BTCPP_format", "4")
        .attr("main_tree_to_execute", &ir.main_tree)
        .close(false);
    x.open("BehaviorTree")
        .attr("ID", &ir.main_tree)
        .close(false);
    if inline {
        node(&mut x, &ir.inlined(), ir);
    } else {
        node(&mut x, &ir.root, ir);
    }
    x.end("BehaviorTree");
    if !inline {
        for t in &ir.trees {
            x.open("BehaviorTree").attr("ID", &t.id).close(false);
            node(&mut x, &t.root, ir);
            x.end("BehaviorTree");
        }
    }
    x.open("TreeNodesModel").close(false);
    for m in &ir.nodes {
        let tag = match m.kind {
            LeafKind::Action => "Action",
            LeafKind::Condition => "Condition",
        };
        x.open(tag).attr("ID", &element_name(&m.id));
        if let Some(f) = &m.formula {
            x.attr("description", &format!("holds when {f}"));
        }
        x.close(m.ports.is_empty());
        if m.ports.is_empty() {
            continue;
        }
        for p in &m.ports {
            let kind = match p.direction {
                PortDirection::Input => "input_port",
                PortDirection::Output => "output_port",
            };
            x.open(kind)
                .attr("name", &p.name)
                .attr("type", p.cpp_type());
            if !matches!(p.ty.as_str(), "int" | "float" | "bool" | "string") {
                x.attr("description", &format!("a PDDL object of type {}", p.ty));
            }
            x.close(true);
        }
        x.end(tag);
    }
    // The step decorator btc emits around every plan step.
    if ir.steps.iter().any(|s| !s.skipped) {
        x.open("Decorator")
            .attr("ID", "KbStep")
            .attr(
                "description",
                "a plan step: applies its PDDL effects to the KB when it starts and when its child succeeds; its conditions are checked when it starts (before at-start effects), while it runs and when its child succeeds",
            )
            .close(false);
        for (name, ty) in [
            ("step", "int"),
            ("start_effect", "std::string"),
            ("end_effect", "std::string"),
            ("start_condition", "std::string"),
            ("over_all_condition", "std::string"),
            ("end_condition", "std::string"),
        ] {
            x.open("input_port")
                .attr("name", name)
                .attr("type", ty)
                .close(true);
        }
        x.end("Decorator");
    }
    if !inline {
        for t in &ir.trees {
            x.open("SubTree")
                .attr("ID", &t.id)
                .close(t.params.is_empty());
            if t.params.is_empty() {
                continue;
            }
            for p in &t.params {
                x.open("input_port").attr("name", p).close(true);
            }
            x.end("SubTree");
        }
    }
    x.end("TreeNodesModel");
    x.end("root");
    x.out.push('\n');
    x.sink.finish(x.out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_everything_that_could_break_out() {
        assert_eq!(
            escape_attr("a\"b'c<d>&e\nf"),
            "a&quot;b&apos;c&lt;d&gt;&amp;e&#10;f"
        );
        assert_eq!(escape_attr("</BehaviorTree>"), "&lt;/BehaviorTree&gt;");
        assert_eq!(escape_attr("x\u{1}y"), "x\u{FFFD}y");
        assert_eq!(escape_attr("日本ü"), "日本ü");
    }

    /// The table-driven scan escapes as a look at every character does,
    /// on strings mixing specials, controls, U+FFFE/U+FFFF and the other
    /// characters whose first byte is 0xEF.
    #[test]
    fn the_byte_scan_agrees_with_a_character_scan() {
        let pieces = [
            "a", "&", "<", ">", "\"", "'", "\n", "\r", "\t", "\u{1}", "\u{1F}", " ", "\u{7F}", "ü",
            "日", "\u{FFFE}", "\u{FFFF}", "\u{FFFD}", "\u{F000}", "\u{FEFF}", "🦀",
        ];
        let reference = |s: &str| -> String {
            s.chars()
                .map(|c| match c {
                    '&' => "&amp;".to_owned(),
                    '<' => "&lt;".to_owned(),
                    '>' => "&gt;".to_owned(),
                    '"' => "&quot;".to_owned(),
                    '\'' => "&apos;".to_owned(),
                    '\n' => "&#10;".to_owned(),
                    '\r' => "&#13;".to_owned(),
                    '\t' => "&#9;".to_owned(),
                    c if needs_escape(c) => "\u{FFFD}".to_owned(),
                    c => c.to_string(),
                })
                .collect()
        };
        // Every string of up to three pieces.
        let n = pieces.len();
        for k in 0..n * n * n + n * n + n {
            let (mut s, mut k) = (String::new(), k);
            loop {
                s.push_str(pieces[k % n]);
                if k < n {
                    break;
                }
                k = k / n - 1;
            }
            let mut out = String::new();
            escape_attr_into(&mut out, &s);
            assert_eq!(out, reference(&s), "{s:?}");
        }
    }

    #[test]
    fn element_names_are_valid() {
        assert_eq!(element_name("MoveTo"), "MoveTo");
        assert_eq!(element_name("1st node"), "_1st_node");
        assert_eq!(element_name("a<b"), "a_b");
    }
}

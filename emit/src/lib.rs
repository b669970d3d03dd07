//! Output formats for the tree IR. Every emitter is a pure function from
//! [`TreeIr`] to text; names and strings from rules and plans are escaped
//! for the target language so they never break out of their place.

pub mod btcpp;
pub mod commands;
pub mod dot;
pub mod executor;
pub mod kb;
pub mod pytrees;
mod sink;
pub use sink::Handover;
mod sizing;

use btc_ir::TreeIr;
use std::io::Write as _;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// BehaviorTree.CPP v4 XML (Groot2 opens it).
    Btcpp,
    /// A py_trees 2.x Python module.
    Pytrees,
    /// The IR as JSON.
    Json,
    /// Graphviz DOT.
    Dot,
    /// Mermaid flowchart.
    Mermaid,
    /// Canonical robot commands, JSON Lines.
    Commands,
}

impl Format {
    pub const ALL: &'static [(Format, &'static str)] = &[
        (Format::Btcpp, "btcpp"),
        (Format::Pytrees, "pytrees"),
        (Format::Json, "json"),
        (Format::Dot, "dot"),
        (Format::Mermaid, "mermaid"),
        (Format::Commands, "commands"),
    ];

    pub fn name(self) -> &'static str {
        Format::ALL
            .iter()
            .find(|(f, _)| *f == self)
            .map(|(_, n)| *n)
            .expect("listed")
    }

    /// The usual file extension of the format.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Btcpp => "xml",
            Format::Pytrees => "py",
            Format::Json => "json",
            Format::Dot => "dot",
            Format::Mermaid => "mmd",
            Format::Commands => "jsonl",
        }
    }
}

/// The IR as pretty JSON, written into a buffer of its exact size: its
/// length is counted first, by a pass that writes nothing. Grown by
/// doubling instead, a long plan's buffer ends up to twice the text's size
/// (256 MB for 136 MB of JSON), and its pages are touched by the copies.
fn json(ir: &TreeIr) -> String {
    let mut count = ByteCount(0);
    serde_json::to_writer_pretty(&mut count, ir).expect("the IR serializes");
    let mut out = Vec::with_capacity(count.0 + 1);
    serde_json::to_writer_pretty(&mut out, ir).expect("the IR serializes");
    out.push(b'\n');
    String::from_utf8(out).expect("serde_json writes UTF-8")
}

/// A writer that keeps only how many bytes were written to it: an
/// output's size without its text.
#[derive(Debug, Default)]
pub struct ByteCount(pub usize);

impl std::io::Write for ByteCount {
    fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
        self.0 += b.len();
        Ok(b.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

#[derive(Clone, Debug, Default)]
pub struct Options {
    /// One flat tree instead of a `<SubTree>` per rule (BT.CPP).
    pub inline: bool,
    /// py_trees: import leaf behaviours from this module instead of
    /// generating simulated ones.
    pub node_module: Option<String>,
    /// py_trees: paste the runtime in, or import `btc_runtime`.
    pub runtime: pytrees::Runtime,
    /// py_trees: name the domain and problem files (as the IR records
    /// them) in the module's header. Off by default, so a module's text
    /// does not depend on where its inputs were.
    pub source_paths: bool,
}

impl Options {
    fn pytrees(&self) -> pytrees::PyOptions<'_> {
        pytrees::PyOptions {
            runtime: self.runtime,
            node_module: self.node_module.as_deref(),
            source_paths: self.source_paths,
        }
    }
}

pub fn emit(ir: &TreeIr, format: Format, options: &Options) -> String {
    match format {
        Format::Btcpp => btcpp::emit(ir, options.inline),
        Format::Pytrees => pytrees::emit(ir, &options.pytrees()),
        Format::Json => json(ir),
        Format::Dot => dot::emit_dot(ir),
        Format::Mermaid => dot::emit_mermaid(ir),
        Format::Commands => commands::emit(ir),
    }
}

/// [`emit`] written to `w`: the text a long plan makes most of (the
/// steps of BT.CPP XML and py_trees, all of JSON) is streamed as it is
/// produced, never whole in memory; the bytes are [`emit`]'s.
pub fn emit_to(
    ir: &TreeIr,
    format: Format,
    options: &Options,
    w: &mut dyn std::io::Write,
) -> std::io::Result<()> {
    match format {
        Format::Btcpp => btcpp::emit_to(ir, options.inline, w),
        Format::Pytrees => pytrees::emit_to(ir, &options.pytrees(), w),
        Format::Json => {
            let mut w = std::io::BufWriter::with_capacity(sink::CHUNK, w);
            serde_json::to_writer_pretty(&mut w, ir)?;
            w.write_all(b"\n")?;
            w.flush()
        }
        Format::Dot | Format::Mermaid | Format::Commands => {
            w.write_all(emit(ir, format, options).as_bytes())
        }
    }
}

/// [`emit_to`], the buffers of BT.CPP XML and py_trees handed over whole
/// as they fill (to be written on whichever core is free); the other
/// formats' text is handed over in the pieces they write it in.
pub fn emit_handing_over(
    ir: &TreeIr,
    format: Format,
    options: &Options,
    hand: &mut Handover<'_>,
) -> std::io::Result<()> {
    match format {
        Format::Btcpp => btcpp::emit_handing_over(ir, options.inline, hand),
        Format::Pytrees => pytrees::emit_handing_over(ir, &options.pytrees(), hand),
        _ => emit_to(ir, format, options, &mut HandingOver(hand)),
    }
}

/// The parts an output can be made in on two threads at once, in the
/// order their texts follow each other: py_trees in two (its plan, then
/// its tree), the other formats in one.
pub fn parts(format: Format) -> &'static [Part] {
    match format {
        Format::Pytrees => &[Part::First, Part::Second],
        _ => &[Part::First],
    }
}

/// One of the [`parts`] of an output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    First,
    Second,
}

/// [`emit_handing_over`] of one of `format`'s [`parts`]: the parts' texts,
/// one after the other, are the whole output's.
pub fn emit_part_handing_over(
    ir: &TreeIr,
    format: Format,
    options: &Options,
    part: Part,
    hand: &mut Handover<'_>,
) -> std::io::Result<()> {
    match (format, part) {
        (Format::Pytrees, _) => pytrees::emit_part_handing_over(ir, &options.pytrees(), part, hand),
        (_, Part::First) => emit_handing_over(ir, format, options, hand),
        (_, Part::Second) => Ok(()),
    }
}

/// A writer that hands over a copy of what it is given.
struct HandingOver<'h, 'a>(&'h mut Handover<'a>);

impl std::io::Write for HandingOver<'_, '_> {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        (self.0)(bytes.to_vec());
        Ok(bytes.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

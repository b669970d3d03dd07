//! The node vocabulary: every control node and decorator of the rules
//! language, once. The rules parser, the language server, the emitters,
//! the XML reader, the engine builder, the VS Code grammar and the docs
//! table all read [`NODES`]; what a node *does* when ticked stays written
//! by hand in each executor (the engine's `Op`s, `btc_runtime.py`).
//!
//! Adding a decorator: a variant of [`DecoratorName`] and of
//! [`crate::DecoratorKind`], its entry here, and its tick semantics.

use serde::{Deserialize, Serialize};

/// The control nodes, by keyword.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ControlName {
    Sequence,
    ReactiveSequence,
    Fallback,
    ReactiveFallback,
    Parallel,
}

/// The decorators, by keyword.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DecoratorName {
    Retry,
    Repeat,
    Timeout,
    Inverter,
    ForceSuccess,
    ForceFailure,
    Delay,
    RunOnce,
}

/// Which node an entry describes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NodeName {
    Control(ControlName),
    Decorator(DecoratorName),
}

/// How many children a node takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Arity {
    /// A decorator: the one template after it.
    One,
    /// A control node: a block of at least this many.
    AtLeast(usize),
}

/// What a parameter's whole number means.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamType {
    /// How many times (BT.CPP reads an `int`).
    Count,
    /// A duration in milliseconds (BT.CPP reads an `unsigned`).
    Millis,
    /// How many children must succeed or fail (`Parallel`).
    Threshold,
}

impl ParamType {
    pub fn name(self) -> &'static str {
        match self {
            ParamType::Count => "count",
            ParamType::Millis => "duration (ms)",
            ParamType::Threshold => "threshold",
        }
    }
}

/// A node's parameter: its name in the rules, the BT.CPP port it fills,
/// and the whole numbers it takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Param {
    /// As written in the rules: `retry(times: 3)`.
    pub name: &'static str,
    /// The BT.CPP attribute: `num_attempts="3"`.
    pub port: &'static str,
    pub ty: ParamType,
    /// What the number counts, for messages.
    pub what: &'static str,
    pub min: i64,
    pub max: i64,
}

impl Param {
    /// In markdown: `` `times` (`num_attempts`): count, 1 to 2147483647 ``.
    pub fn describe(&self) -> String {
        format!(
            "`{}` (`{}`): {}, {} to {}",
            self.name,
            self.port,
            self.ty.name(),
            self.min,
            self.max
        )
    }
}

/// How the py_trees emitter writes a node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PyTrees {
    /// The code of the node's tuple in a generated module, and the
    /// behaviour `btc_runtime.py` builds for it.
    Built {
        code: &'static str,
        class: &'static str,
    },
    /// py_trees cannot run it as btc's engine does: the py_trees target
    /// refuses the rules (E001) with this reason.
    NotExpressible { why: &'static str },
}

/// One node kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NodeSpec {
    pub name: NodeName,
    /// The rules keyword: `retry`.
    pub keyword: &'static str,
    /// The BT.CPP 4 element: `RetryUntilSuccessful`.
    pub tag: &'static str,
    pub arity: Arity,
    /// In the order a call writes them by position.
    pub params: &'static [Param],
    /// The DOT/Mermaid label; `{param}` is replaced by its value.
    pub label: &'static str,
    pub pytrees: PyTrees,
    /// One line for hover and the docs.
    pub summary: &'static str,
}

const COUNT_MAX: i64 = i32::MAX as i64;
const MILLIS_MAX: i64 = u32::MAX as i64;

/// Every node kind, in the order the docs list them.
pub static NODES: &[NodeSpec] = &[
    NodeSpec {
        name: NodeName::Control(ControlName::Sequence),
        keyword: "sequence",
        tag: "Sequence",
        arity: Arity::AtLeast(0),
        params: &[],
        label: "→",
        pytrees: PyTrees::Built {
            code: "Q",
            class: "py_trees.composites.Sequence(memory=True)",
        },
        summary: "runs its children in order until one fails",
    },
    NodeSpec {
        name: NodeName::Control(ControlName::ReactiveSequence),
        keyword: "reactive_sequence",
        tag: "ReactiveSequence",
        arity: Arity::AtLeast(0),
        params: &[],
        label: "→ (reactive)",
        pytrees: PyTrees::Built {
            code: "q",
            class: "btc_runtime.ReactiveSequence",
        },
        summary: "a sequence that ticks its earlier children again on every tick",
    },
    NodeSpec {
        name: NodeName::Control(ControlName::Fallback),
        keyword: "fallback",
        tag: "Fallback",
        arity: Arity::AtLeast(0),
        params: &[],
        label: "?",
        pytrees: PyTrees::Built {
            code: "F",
            class: "py_trees.composites.Selector(memory=True)",
        },
        summary: "runs its children in order until one succeeds",
    },
    NodeSpec {
        name: NodeName::Control(ControlName::ReactiveFallback),
        keyword: "reactive_fallback",
        tag: "ReactiveFallback",
        arity: Arity::AtLeast(0),
        params: &[],
        label: "? (reactive)",
        pytrees: PyTrees::Built {
            code: "f",
            class: "btc_runtime.ReactiveFallback",
        },
        summary: "a fallback that ticks its earlier children again on every tick",
    },
    NodeSpec {
        name: NodeName::Control(ControlName::Parallel),
        keyword: "parallel",
        tag: "Parallel",
        arity: Arity::AtLeast(0),
        params: &[
            Param {
                name: "success",
                port: "success_count",
                ty: ParamType::Threshold,
                what: "children that must succeed",
                min: 0,
                max: COUNT_MAX,
            },
            Param {
                name: "failure",
                port: "failure_count",
                ty: ParamType::Threshold,
                what: "children that may fail",
                min: 0,
                max: COUNT_MAX,
            },
        ],
        label: "⇒ (success {success}, failure {failure})",
        pytrees: PyTrees::Built {
            code: "P",
            class: "btc_runtime.Parallel",
        },
        summary: "ticks all its children; succeeds or fails at the thresholds",
    },
    NodeSpec {
        name: NodeName::Decorator(DecoratorName::Retry),
        keyword: "retry",
        tag: "RetryUntilSuccessful",
        arity: Arity::One,
        params: &[Param {
            name: "times",
            port: "num_attempts",
            ty: ParamType::Count,
            what: "attempts",
            min: 1,
            max: COUNT_MAX,
        }],
        label: "retry {times}",
        pytrees: PyTrees::Built {
            code: "retry",
            class: "btc_runtime.Retry",
        },
        summary: "runs its child again after a failure, up to `times` attempts",
    },
    NodeSpec {
        name: NodeName::Decorator(DecoratorName::Repeat),
        keyword: "repeat",
        tag: "Repeat",
        arity: Arity::One,
        params: &[Param {
            name: "times",
            port: "num_cycles",
            ty: ParamType::Count,
            what: "repetitions",
            min: 1,
            max: COUNT_MAX,
        }],
        label: "repeat {times}",
        pytrees: PyTrees::Built {
            code: "repeat",
            class: "btc_runtime.Repeat",
        },
        summary: "runs its child `times` times while it succeeds",
    },
    NodeSpec {
        name: NodeName::Decorator(DecoratorName::Timeout),
        keyword: "timeout",
        tag: "Timeout",
        arity: Arity::One,
        params: &[Param {
            name: "msec",
            port: "msec",
            ty: ParamType::Millis,
            what: "milliseconds",
            min: 1,
            max: MILLIS_MAX,
        }],
        label: "timeout {msec} ms",
        pytrees: PyTrees::Built {
            code: "timeout",
            class: "btc_runtime.Timeout",
        },
        summary: "halts its child and fails when it runs longer than `msec`",
    },
    NodeSpec {
        name: NodeName::Decorator(DecoratorName::Inverter),
        keyword: "inverter",
        tag: "Inverter",
        arity: Arity::One,
        params: &[],
        label: "invert",
        pytrees: PyTrees::Built {
            code: "inverter",
            class: "py_trees.decorators.Inverter",
        },
        summary: "swaps its child's success and failure",
    },
    NodeSpec {
        name: NodeName::Decorator(DecoratorName::ForceSuccess),
        keyword: "force_success",
        tag: "ForceSuccess",
        arity: Arity::One,
        params: &[],
        label: "force success",
        pytrees: PyTrees::Built {
            code: "force_success",
            class: "py_trees.decorators.FailureIsSuccess",
        },
        summary: "succeeds when its child finishes",
    },
    NodeSpec {
        name: NodeName::Decorator(DecoratorName::ForceFailure),
        keyword: "force_failure",
        tag: "ForceFailure",
        arity: Arity::One,
        params: &[],
        label: "force failure",
        pytrees: PyTrees::Built {
            code: "force_failure",
            class: "py_trees.decorators.SuccessIsFailure",
        },
        summary: "fails when its child finishes",
    },
    NodeSpec {
        name: NodeName::Decorator(DecoratorName::Delay),
        keyword: "delay",
        tag: "Delay",
        arity: Arity::One,
        params: &[Param {
            name: "msec",
            port: "delay_msec",
            ty: ParamType::Millis,
            what: "milliseconds",
            min: 1,
            max: MILLIS_MAX,
        }],
        label: "delay {msec} ms",
        pytrees: PyTrees::Built {
            code: "delay",
            class: "btc_runtime.Delay",
        },
        summary: "ticks its child once `msec` have passed since it started",
    },
    NodeSpec {
        name: NodeName::Decorator(DecoratorName::RunOnce),
        keyword: "run_once",
        tag: "RunOnce",
        arity: Arity::One,
        params: &[],
        label: "run once",
        pytrees: PyTrees::NotExpressible {
            why: "is SKIPPED after its child has run (BT.CPP `then_skip`), a status py_trees does not have",
        },
        summary: "runs its child to completion once; afterwards it is skipped",
    },
];

impl NodeSpec {
    /// The entry for a rules keyword.
    pub fn by_keyword(word: &str) -> Option<&'static NodeSpec> {
        NODES.iter().find(|s| s.keyword == word)
    }

    /// The entry for a BT.CPP element.
    pub fn by_tag(tag: &str) -> Option<&'static NodeSpec> {
        NODES.iter().find(|s| s.tag == tag)
    }

    pub fn param(&self, name: &str) -> Option<&'static Param> {
        self.params.iter().find(|p| p.name == name)
    }

    /// The label with each `{param}` replaced by `value(param)`.
    pub fn label_with(&self, value: impl Fn(&Param) -> String) -> String {
        self.params.iter().fold(self.label.to_owned(), |l, p| {
            l.replace(&format!("{{{}}}", p.name), &value(p))
        })
    }

    /// How a call is written, in markdown: `` `retry(N) T` ``.
    pub fn shape(&self) -> String {
        match (self.arity, self.params.is_empty()) {
            (Arity::One, true) => format!("`{} T`", self.keyword),
            (Arity::One, false) => format!("`{}(N) T`", self.keyword),
            (Arity::AtLeast(_), true) => format!("`{} [\"name\"] {{ ... }}`", self.keyword),
            (Arity::AtLeast(_), false) => {
                let p: Vec<String> = self
                    .params
                    .iter()
                    .map(|p| format!("{}: N", p.name))
                    .collect();
                format!("`{}({}) {{ ... }}`", self.keyword, p.join(", "))
            }
        }
    }

    /// The keyword closest to `word` (for "did you mean"), when one is
    /// close enough to be a likely typo.
    pub fn closest(word: &str) -> Option<&'static NodeSpec> {
        NODES
            .iter()
            .map(|s| (edit_distance(word, s.keyword), s))
            .filter(|(d, s)| *d <= 1 + s.keyword.len() / 4)
            .min_by_key(|(d, _)| *d)
            .map(|(_, s)| s)
    }
}

fn entry(name: NodeName) -> &'static NodeSpec {
    NODES
        .iter()
        .find(|s| s.name == name)
        .expect("every node name has its entry in NODES (vocab tests check it)")
}

impl NodeName {
    pub fn spec(self) -> &'static NodeSpec {
        entry(self)
    }
}

impl ControlName {
    pub fn spec(self) -> &'static NodeSpec {
        entry(NodeName::Control(self))
    }

    pub fn keyword(self) -> &'static str {
        self.spec().keyword
    }

    pub fn from_keyword(word: &str) -> Option<ControlName> {
        match NodeSpec::by_keyword(word)?.name {
            NodeName::Control(c) => Some(c),
            NodeName::Decorator(_) => None,
        }
    }
}

impl DecoratorName {
    pub fn spec(self) -> &'static NodeSpec {
        entry(NodeName::Decorator(self))
    }

    pub fn keyword(self) -> &'static str {
        self.spec().keyword
    }

    pub fn from_keyword(word: &str) -> Option<DecoratorName> {
        match NodeSpec::by_keyword(word)?.name {
            NodeName::Decorator(d) => Some(d),
            NodeName::Control(_) => None,
        }
    }

    /// The one parameter, for the decorators that have one.
    pub fn param(self) -> Option<Param> {
        self.spec().params.first().copied()
    }

    /// Every decorator, in table order.
    pub fn all() -> impl Iterator<Item = DecoratorName> {
        NODES.iter().filter_map(|s| match s.name {
            NodeName::Decorator(d) => Some(d),
            NodeName::Control(_) => None,
        })
    }
}

/// The node table of `docs/language.md`, between its markers (a test in
/// `tests/docs.rs` compares the two).
pub fn markdown_table() -> String {
    let mut out = String::from(
        "| keyword | shape | BT.CPP | parameters (BT.CPP port) | py_trees | what it does |\n|---|---|---|---|---|---|\n",
    );
    for s in NODES {
        let params: Vec<String> = s.params.iter().map(Param::describe).collect();
        let pytrees = match s.pytrees {
            PyTrees::Built { class, .. } => format!("`{class}`"),
            PyTrees::NotExpressible { .. } => "not expressible (E001)".to_owned(),
        };
        out.push_str(&format!(
            "| `{}` | {} | `{}` | {} | {} | {} |\n",
            s.keyword,
            s.shape(),
            s.tag,
            if params.is_empty() {
                "-".to_owned()
            } else {
                params.join("; ")
            },
            pytrees,
            s.summary
        ));
    }
    out
}

/// The VS Code grammar's pattern for template keywords: the vocabulary's,
/// longest first so that no keyword shadows a longer one, then `steps`
/// and its modes `backchained` and `scheduled`.
pub fn grammar_keyword_pattern() -> String {
    let mut words: Vec<&str> = NODES.iter().map(|s| s.keyword).collect();
    words.sort_by(|a, b| b.len().cmp(&a.len()).then(a.cmp(b)));
    words.extend(["steps", "backchained", "scheduled"]);
    format!(
        "(?<![A-Za-z0-9_?-])(?:{})(?![A-Za-z0-9_-])",
        words.join("|")
    )
}

/// Levenshtein distance over bytes (keywords are ASCII).
fn edit_distance(a: &str, b: &str) -> usize {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.iter().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_has_one_entry_and_keywords_and_tags_are_unique() {
        let names = [
            ControlName::Sequence,
            ControlName::ReactiveSequence,
            ControlName::Fallback,
            ControlName::ReactiveFallback,
            ControlName::Parallel,
        ]
        .map(NodeName::Control);
        for n in names
            .into_iter()
            .chain(DecoratorName::all().map(NodeName::Decorator))
        {
            assert_eq!(NODES.iter().filter(|s| s.name == n).count(), 1, "{n:?}");
        }
        for s in NODES {
            assert_eq!(NodeSpec::by_keyword(s.keyword), Some(s));
            assert_eq!(NodeSpec::by_tag(s.tag), Some(s));
            for p in s.params {
                assert!(
                    s.label.contains(&format!("{{{}}}", p.name)),
                    "{}",
                    s.keyword
                );
            }
        }
    }

    #[test]
    fn closest_keyword_catches_typos_only() {
        assert_eq!(NodeSpec::closest("retyr").map(|s| s.keyword), Some("retry"));
        assert_eq!(
            NodeSpec::closest("force_sucess").map(|s| s.keyword),
            Some("force_success")
        );
        assert_eq!(
            NodeSpec::closest("sequense").map(|s| s.keyword),
            Some("sequence")
        );
        assert_eq!(NodeSpec::closest("pick_part"), None);
    }
}

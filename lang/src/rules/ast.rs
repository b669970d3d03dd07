//! The `.btrules` syntax tree. Every item's spans are relative to the item's
//! own start (see [`ItemNode::offset`]), so editing one item leaves the
//! others' trees equal — the incremental checker relies on that.

pub use super::name::Key;
pub use btc_ir::ControlKind;
use btc_pddl::ast::{Effect, Formula};
use btc_pddl::source::Span;
use serde::{Deserialize, Serialize};

/// A name as written (case kept: node names are CamelCase) and its folded
/// [`Key`]. Names the language compares case-sensitively (nodes, trees,
/// tables, ports, captures) compare by `text`; names of PDDL things (types,
/// objects, action-name parts) and table keys compare by `key`.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Ident {
    pub text: String,
    pub key: Key,
    pub span: Span,
}

impl Ident {
    pub fn new(text: String, span: Span) -> Ident {
        Ident {
            key: Key::new(&text),
            text,
            span,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum StrPart {
    Text {
        text: String,
    },
    /// `{?var}`
    Var {
        name: Ident,
    },
    /// `{capture}`
    Capture {
        name: Ident,
    },
    /// A value spliced in where a `tree`'s string interpolates a port that
    /// its call gives a value with no text of its own yet (a table
    /// lookup). Never parsed: lowering puts it in when it expands the call,
    /// so it is evaluated per step like any other part.
    Value {
        value: Box<Value>,
    },
}

/// A string literal, split at its `{...}` interpolations.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StrLit {
    pub parts: Vec<StrPart>,
    pub span: Span,
    /// Where the literal's text has a character written as an escape
    /// (`\"`, `\\`, `\n`, `\t`, `\{`, `\}`: two bytes in the file for one
    /// in the text): their offsets in the text, in order. What maps an
    /// offset in a plain literal's text back into the file
    /// ([`StrLit::source_offset`]); empty for strings btc makes itself.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub escapes: Vec<u32>,
}

impl StrLit {
    /// Where byte `at` of a plain literal's text (see [`StrLit::plain`])
    /// is in the file: after the opening quote, one more byte for each
    /// escape before it. `at` may be the text's length (the closing quote).
    pub fn source_offset(&self, at: usize) -> usize {
        let escaped = self.escapes.partition_point(|&e| (e as usize) < at);
        self.span.start as usize + 1 + at + escaped
    }

    /// The text when the literal has no interpolation.
    pub fn plain(&self) -> Option<String> {
        let mut s = String::new();
        for p in &self.parts {
            match p {
                StrPart::Text { text } => s.push_str(text),
                _ => return None,
            }
        }
        Some(s)
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum ImportTarget {
    /// `import "move.xml" as Move`: `alias` names a BT.CPP file's main tree.
    Path {
        path: StrLit,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alias: Option<Ident>,
    },
    Std {
        module: Ident,
    },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum NodeKind {
    Action,
    Condition,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PortDecl {
    pub out: bool,
    pub name: Ident,
    /// A PDDL type, or `string`, `int`, `float`, `bool`.
    pub ty: Ident,
    pub span: Span,
}

/// Ports as `(name, type, out)`, as tests compare them.
#[cfg(test)]
pub fn port_triples(ports: &[PortDecl]) -> Vec<(&str, &str, bool)> {
    ports
        .iter()
        .map(|p| (p.name.text.as_str(), p.ty.text.as_str(), p.out))
        .collect()
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NodeDecl {
    pub kind: NodeKind,
    pub name: Ident,
    pub ports: Vec<PortDecl>,
    /// `condition C(...) = (formula)`: evaluated on the KB by the runtime.
    pub formula: Option<Formula>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TreeDecl {
    pub name: Ident,
    pub ports: Vec<PortDecl>,
    pub body: Vec<Template>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Literal {
    Int { value: i64, span: Span },
    Float { value: f64, span: Span },
    Str { value: StrLit },
    Bool { value: bool, span: Span },
    Name { name: Ident },
}

impl Literal {
    pub fn span(&self) -> Span {
        match self {
            Literal::Int { span, .. }
            | Literal::Float { span, .. }
            | Literal::Bool { span, .. } => *span,
            Literal::Str { value } => value.span,
            Literal::Name { name } => name.span,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TableEntry {
    pub key: Ident,
    pub value: Literal,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TableDecl {
    pub name: Ident,
    pub entries: Vec<TableEntry>,
    pub span: Span,
}

/// One piece of a rule's action-name pattern: `PICK_{op}` is
/// `[Lit("PICK_"), Capture("op")]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum NamePart {
    /// Literal characters, as written and folded (they match case-insensitively).
    Lit {
        text: String,
        key: Key,
        span: Span,
    },
    Capture {
        name: Ident,
    },
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Param {
    /// Variable name without `?`, lower-cased (PDDL is case-insensitive).
    pub var: Ident,
    /// `[?x]`: the step may omit it.
    pub optional: bool,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pattern {
    pub name: Vec<NamePart>,
    pub params: Vec<Param>,
    pub span: Span,
}

impl Pattern {
    /// The literal action name (folded) when the pattern has no capture.
    pub fn literal_name(&self) -> Option<&Key> {
        match self.name.as_slice() {
            [NamePart::Lit { key, .. }] => Some(key),
            _ => None,
        }
    }

    /// The pattern as written, folded: what "did you mean" compares with
    /// the domain's action names.
    pub fn name_key(&self) -> Key {
        Key::new(&self.name_text())
    }

    pub fn name_span(&self) -> Span {
        let first = self.name.first().map(part_span).unwrap_or(self.span);
        let last = self.name.last().map(part_span).unwrap_or(self.span);
        first.to(last)
    }

    /// The pattern as written, e.g. `PICK_{op}`.
    pub fn name_text(&self) -> String {
        self.name
            .iter()
            .map(|p| match p {
                NamePart::Lit { text, .. } => text.clone(),
                NamePart::Capture { name } => format!("{{{}}}", name.text),
            })
            .collect()
    }
}

fn part_span(p: &NamePart) -> Span {
    match p {
        NamePart::Lit { span, .. } => *span,
        NamePart::Capture { name } => name.span,
    }
}

/// One side of an `==` / `!=` guard.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Operand {
    /// `?x`: the object the step binds to it.
    Var { name: Ident },
    /// `"floor_robot"`: an object or constant, by name (`name.span` is the
    /// string's, quotes included).
    Object { name: Ident },
}

impl Operand {
    pub fn span(&self) -> Span {
        match self {
            Operand::Var { name } | Operand::Object { name } => name.span,
        }
    }

    pub fn var(&self) -> Option<&Ident> {
        match self {
            Operand::Var { name } => Some(name),
            Operand::Object { .. } => None,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Guard {
    Ne {
        left: Operand,
        right: Operand,
        span: Span,
    },
    Eq {
        left: Operand,
        right: Operand,
        span: Span,
    },
    /// `?x - type`
    IsType { var: Ident, ty: Ident, span: Span },
    /// `capture in table`
    InTable {
        key: Ident,
        table: Ident,
        span: Span,
    },
}

impl Guard {
    pub fn span(&self) -> Span {
        match self {
            Guard::Ne { span, .. }
            | Guard::Eq { span, .. }
            | Guard::IsType { span, .. }
            | Guard::InTable { span, .. } => *span,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
#[allow(clippy::large_enum_variant)] // one per rule
pub enum RuleBody {
    Skip {
        span: Span,
    },
    Template {
        body: Vec<Template>,
        effect: Option<Effect>,
    },
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Rule {
    pub pattern: Pattern,
    pub guards: Vec<Guard>,
    pub body: RuleBody,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StepsMode {
    InOrder,
    Parallel,
    Backchained,
    /// The plan's own schedule: each step starts once the steps that end
    /// before it starts (in the timed plan) have ended.
    Scheduled,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Value {
    Var {
        name: Ident,
    },
    Str {
        value: StrLit,
    },
    Int {
        value: i64,
        span: Span,
    },
    Float {
        value: f64,
        span: Span,
    },
    Bool {
        value: bool,
        span: Span,
    },
    /// `table[key]`: the key is a capture, a variable or a string.
    Lookup {
        table: Ident,
        key: Box<Value>,
        span: Span,
    },
    /// A bare name: a capture, or a table key.
    Name {
        name: Ident,
    },
}

impl Value {
    pub fn span(&self) -> Span {
        match self {
            Value::Var { name } | Value::Name { name } => name.span,
            Value::Str { value } => value.span,
            Value::Int { span, .. }
            | Value::Float { span, .. }
            | Value::Bool { span, .. }
            | Value::Lookup { span, .. } => *span,
        }
    }
}

/// The decorators of the language and their parameters: the node
/// vocabulary's.
pub use btc_ir::vocab::{DecoratorName, Param as DecoratorParam};

/// A decorator's argument, by position (`retry(3)`) or by its parameter's
/// name (`timeout(msec: ?t)`). It takes the values a port takes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DecoratorArg {
    pub param: Option<Ident>,
    pub value: Value,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Arg {
    pub port: Ident,
    pub value: Value,
}

/// A BT.CPP pre- or post-condition script on a node, `skip_if: "done"`
/// in the brackets after a call; `key` is one of `NodeScripts::KEYS`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScriptAttr {
    pub key: Ident,
    pub code: StrLit,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Template {
    Control {
        control: ControlKind,
        name: Option<StrLit>,
        children: Vec<Template>,
        span: Span,
    },
    Decorator {
        decorator: DecoratorName,
        /// `(3)`, `(msec: ?t)`: checked against the decorator's parameter.
        args: Vec<DecoratorArg>,
        name: Option<StrLit>,
        child: Box<Template>,
        span: Span,
    },
    Call {
        name: Ident,
        args: Vec<Arg>,
        /// `[skip_if: "...", on_success: "..."]` after the arguments.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        scripts: Vec<ScriptAttr>,
        /// The node's `name`: only a leaf of an imported BT.CPP tree has
        /// one (`<Move name="move" .../>`); the rules have no syntax for it.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        label: Option<StrLit>,
        span: Span,
    },
    /// `script "code"` (BT.CPP's `Script`) or `script_condition "code"`
    /// (`ScriptCondition`).
    Script {
        condition: bool,
        code: StrLit,
        span: Span,
    },
    Steps {
        mode: StepsMode,
        span: Span,
    },
    /// Text that did not parse; reported already.
    Error {
        span: Span,
    },
}

impl Template {
    pub fn span(&self) -> Span {
        match self {
            Template::Control { span, .. }
            | Template::Decorator { span, .. }
            | Template::Call { span, .. }
            | Template::Script { span, .. }
            | Template::Steps { span, .. }
            | Template::Error { span } => *span,
        }
    }

    /// The templates right inside this one: a control's block, the
    /// template a decorator decorates.
    pub fn children(&self) -> &[Template] {
        match self {
            Template::Control { children, .. } => children,
            Template::Decorator { child, .. } => std::slice::from_ref(&**child),
            Template::Call { .. }
            | Template::Script { .. }
            | Template::Steps { .. }
            | Template::Error { .. } => &[],
        }
    }

    /// Calls `f` on this template and every template inside it, each
    /// before the ones inside it. The one walk over templates: the passes
    /// that only look at each template use it (the parser bounds the
    /// nesting, `parse::MAX_ITEM_DEPTH`).
    pub fn walk<'t>(&'t self, f: &mut dyn FnMut(&'t Template)) {
        f(self);
        for c in self.children() {
            c.walk(f);
        }
    }

    /// [`Template::walk`] over each template of a body, in order.
    pub fn walk_all<'t>(body: &'t [Template], f: &mut dyn FnMut(&'t Template)) {
        for t in body {
            t.walk(f);
        }
    }
}

/// One per top-level item: boxing the large variants would buy nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Item {
    Domain {
        path: StrLit,
        span: Span,
    },
    Problem {
        path: StrLit,
        span: Span,
    },
    Import {
        target: ImportTarget,
        span: Span,
    },
    Node(NodeDecl),
    Tree(TreeDecl),
    Table(TableDecl),
    Rule(Rule),
    Plan {
        body: Vec<Template>,
        span: Span,
    },
    /// An item that did not parse; its diagnostics are reported.
    Error {
        span: Span,
    },
}

impl Item {
    pub fn span(&self) -> Span {
        match self {
            Item::Domain { span, .. }
            | Item::Problem { span, .. }
            | Item::Import { span, .. }
            | Item::Plan { span, .. }
            | Item::Error { span } => *span,
            Item::Node(n) => n.span,
            Item::Tree(t) => t.span,
            Item::Table(t) => t.span,
            Item::Rule(r) => r.span,
        }
    }
}

/// A top-level item with its place in the file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ItemNode {
    /// Byte offset of the item's first token; the item's spans are relative to it.
    pub offset: u32,
    /// Shared with the database's memo of the item's parse, so that
    /// assembling a file of tens of thousands of items copies none.
    pub item: std::sync::Arc<Item>,
}

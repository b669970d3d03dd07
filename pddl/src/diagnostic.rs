//! Diagnostics as plain data. The terminal (ariadne), JSON and LSP renderings
//! are all made from this one value.

use crate::source::Span;
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    Error,
    Warning,
}

/// A stable diagnostic code with a one-line title for the reference table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Code {
    pub id: &'static str,
    pub title: &'static str,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Label {
    pub span: Span,
    pub message: String,
}

/// A machine-applicable repair: replace `span` with `replacement`. The
/// language server offers these as quick fixes.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Fix {
    pub title: String,
    pub span: Span,
    pub replacement: String,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Diagnostic {
    pub code: &'static str,
    pub severity: Severity,
    pub message: String,
    pub span: Span,
    /// Secondary places, e.g. the earlier definition of a duplicate.
    pub labels: Vec<Label>,
    pub hint: Option<String>,
    /// Boxed: most diagnostics have none, and `Result<_, Diagnostic>` stays small.
    #[serde(skip_serializing_if = "<[Fix]>::is_empty")]
    pub fixes: Box<[Fix]>,
}

impl Diagnostic {
    pub fn error(code: Code, span: Span, message: impl Into<String>) -> Diagnostic {
        Diagnostic {
            code: code.id,
            severity: Severity::Error,
            message: message.into(),
            span,
            labels: Vec::new(),
            hint: None,
            fixes: Box::default(),
        }
    }

    pub fn warning(code: Code, span: Span, message: impl Into<String>) -> Diagnostic {
        Diagnostic {
            severity: Severity::Warning,
            ..Diagnostic::error(code, span, message)
        }
    }

    pub fn with_hint(mut self, hint: impl Into<String>) -> Diagnostic {
        self.hint = Some(hint.into());
        self
    }

    pub fn with_fix(
        mut self,
        title: impl Into<String>,
        span: Span,
        replacement: impl Into<String>,
    ) -> Diagnostic {
        let mut fixes = std::mem::take(&mut self.fixes).into_vec();
        fixes.push(Fix {
            title: title.into(),
            span,
            replacement: replacement.into(),
        });
        self.fixes = fixes.into_boxed_slice();
        self
    }

    /// "did you mean `X`?" with the replacement of the diagnostic's own span
    /// by `X` as a fix; `otherwise` is the hint when there is no candidate.
    pub fn suggest(
        self,
        candidate: Option<String>,
        otherwise: impl FnOnce() -> String,
    ) -> Diagnostic {
        match candidate {
            Some(c) => {
                let span = self.span;
                self.with_hint(format!("did you mean `{c}`?")).with_fix(
                    format!("change to `{c}`"),
                    span,
                    c,
                )
            }
            None => self.with_hint(otherwise()),
        }
    }

    pub fn with_label(mut self, span: Span, message: impl Into<String>) -> Diagnostic {
        self.labels.push(Label {
            span,
            message: message.into(),
        });
        self
    }

    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }
}

/// Keeps the first [`MAX_DIAGNOSTICS_PER_FILE`](crate::limits::MAX_DIAGNOSTICS_PER_FILE)
/// diagnostics of one kind that a pass makes, and counts the rest into one
/// closing diagnostic: a file of a million bad characters costs a hundred
/// diagnostics, not a million.
pub struct Cap {
    seen: usize,
    code: Code,
    what: &'static str,
}

impl Cap {
    /// `what` names the kind in the summary ("lexical error").
    pub fn new(code: Code, what: &'static str) -> Cap {
        Cap {
            seen: 0,
            code,
            what,
        }
    }

    pub fn push(&mut self, out: &mut Vec<Diagnostic>, d: Diagnostic) {
        self.seen += 1;
        if self.seen <= crate::limits::MAX_DIAGNOSTICS_PER_FILE {
            out.push(d);
        }
    }

    /// Whether a diagnostic pushed now would be kept (so that its message
    /// need not be built otherwise).
    pub fn full(&self) -> bool {
        self.seen >= crate::limits::MAX_DIAGNOSTICS_PER_FILE
    }

    /// Counts one more without building it (see [`Cap::full`]).
    pub fn skip(&mut self) {
        self.seen += 1;
    }

    pub fn finish(self, out: &mut Vec<Diagnostic>, at: Span) {
        let max = crate::limits::MAX_DIAGNOSTICS_PER_FILE;
        if let Some(more) = self.seen.checked_sub(max).filter(|n| *n > 0) {
            out.push(Diagnostic::error(
                self.code,
                at,
                format!(
                    "and {more} more {}{} in this file, not shown",
                    self.what,
                    if more == 1 { "" } else { "s" }
                ),
            ));
        }
    }
}

/// A user's word as a message shows it: cut to 60 characters, so that a
/// 10 MB name makes a short message.
pub fn shown(word: &str) -> std::borrow::Cow<'_, str> {
    const MAX: usize = 60;
    match word.char_indices().nth(MAX) {
        Some((cut, _)) => format!("{}…", &word[..cut]).into(),
        None => word.into(),
    }
}

pub fn has_errors(diags: &[Diagnostic]) -> bool {
    diags.iter().any(Diagnostic::is_error)
}

/// "did you mean" support: the closest candidate within a small edit distance.
/// Names longer than [`MAX_SUGGESTION_NAME`](crate::limits::MAX_SUGGESTION_NAME)
/// get no suggestion, and candidates whose length is too far from the
/// name's are skipped unmeasured: the distance is quadratic in the lengths.
pub fn closest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let max = crate::limits::MAX_SUGGESTION_NAME;
    let len = name.chars().count();
    if len > max {
        return None;
    }
    let limit = len.div_ceil(3).max(1);
    candidates
        .into_iter()
        // A difference in length is a lower bound of the distance (and a
        // char has at most 4 bytes, so long candidates go unmeasured).
        .filter(|c| c.len() <= 4 * max && c.chars().count().abs_diff(len) <= limit)
        .map(|c| (edit_distance(name, c), c))
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, c)| (*d, *c))
        .map(|(_, c)| c)
}

pub fn did_you_mean<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<String> {
    closest(name, candidates).map(|c| format!("did you mean `{c}`?"))
}

fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().flat_map(char::to_lowercase).collect();
    let b: Vec<char> = b.chars().flat_map(char::to_lowercase).collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    for i in 1..=a.len() {
        cur[0] = i;
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            cur[j] = (prev[j] + 1).min(cur[j - 1] + 1).min(prev[j - 1] + cost);
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len()]
}

/// Every diagnostic code btc emits. The language reference's table is
/// generated from, and tested against, this list.
pub mod codes {
    use super::Code;

    macro_rules! codes {
        ($($name:ident = $id:literal, $title:literal;)*) => {
            $(pub const $name: Code = Code { id: $id, title: $title };)*
            pub const ALL: &[Code] = &[$($name),*];
        };
    }

    codes! {
        // Reading files
        FILE_UNREADABLE = "F001", "a file cannot be read";
        FILE_ENCODING = "F002", "a file is not UTF-8 text";
        FILE_TOO_LARGE = "F003", "a file is larger than btc reads";
        FILE_NOT_REGULAR = "F004", "a path that is a folder or a device, not a file";
        MORE_DIAGNOSTICS = "F005", "more diagnostics in one file than btc shows";
        DOCUMENT_TOO_LARGE = "F006", "a document larger than the language server analyses";
        // PDDL syntax
        INVALID_TOKEN = "P001", "a character or word that PDDL does not allow";
        UNCLOSED_PAREN = "P002", "a `(` is never closed";
        UNEXPECTED_CLOSE = "P003", "a `)` closes nothing";
        TOO_DEEP = "P004", "parentheses nested deeper than btc supports";
        EXPECTED = "P005", "the structure of a PDDL file is not what the grammar asks for";
        UNSUPPORTED = "P006", "a PDDL feature btc does not support";
        UNKNOWN_REQUIREMENT = "P007", "a requirement flag that PDDL does not define";
        NOT_A_DEFINE = "P008", "a file is not a PDDL domain or problem";
        UNKNOWN_SECTION = "P009", "a section keyword that does not belong here";
        // PDDL semantics
        UNKNOWN_TYPE = "P101", "a type that the domain does not declare";
        UNKNOWN_PREDICATE = "P102", "a predicate that the domain does not declare";
        UNKNOWN_OBJECT = "P103", "a constant or object that is not declared";
        UNBOUND_VARIABLE = "P104", "a variable that no parameter or quantifier binds";
        WRONG_ARITY = "P105", "a predicate, function or action used with the wrong number of arguments";
        TYPE_MISMATCH = "P106", "an argument whose type does not fit the parameter";
        DUPLICATE = "P107", "something defined twice";
        UNDECLARED_REQUIREMENT = "P108", "a feature used without its `:requirements` flag";
        UNKNOWN_FUNCTION = "P109", "a numeric function that the domain does not declare";
        DOMAIN_MISMATCH = "P110", "a problem names another domain";
        TYPE_CYCLE = "P111", "a type that is its own ancestor";
        DERIVED_EFFECT = "P112", "an action effect that changes a derived predicate";
        NOT_STRATIFIED = "P113", "derived predicates that depend on their own negation";
        NOT_GROUND = "P114", "a variable where only objects may stand";
        // Plans
        PLAN_SYNTAX = "L001", "a plan line in no format btc knows";
        PLAN_UNKNOWN_ACTION = "L002", "a plan step whose action the domain does not define";
        PLAN_ARITY = "L003", "a plan step with the wrong number of arguments";
        PLAN_UNKNOWN_OBJECT = "L004", "a plan step argument that is no object or constant";
        PLAN_TYPE = "L005", "a plan step argument whose type does not fit the action";
        PLAN_EMPTY = "L006", "a plan with no steps";
        PLAN_MISFIT = "L010", "a plan whose object names are not those of its problem";
        PLAN_CONCURRENT_IN_ORDER = "L011", "a timed plan with concurrent steps that plain `steps` runs one after another";
        // Validation
        PRECONDITION_FAILS = "V001", "a plan step whose precondition does not hold";
        GOAL_NOT_REACHED = "V002", "a plan that does not reach the goal";
        COST_MISMATCH = "V003", "a plan whose stated cost differs from its computed cost";
        EFFECT_CONFLICT = "V004", "a numeric effect that cannot be computed";
        DURATION_NOT_ALLOWED = "V005", "a timed step whose duration its action's `:duration` does not allow";
        INTERFERENCE = "V006", "two events at the same time that interfere (a mutex)";
        OVER_ALL_BROKEN = "V007", "an `over all` condition broken while its action runs";
        UNTIMED_PLAN = "V008", "a plan without times for a domain with durative actions";
        // Planning
        PLAN_UNSUPPORTED = "S001", "a PDDL feature the planner does not support";
        PLAN_COST = "S002", "an action cost the planner cannot compute";
        PLAN_UNSOLVABLE = "S003", "a goal that no plan reaches";
        PLAN_TIMEOUT = "S004", "a search stopped by its time limit";
        // .btrules
        R_SYNTAX = "R001", "text that is not `.btrules` syntax";
        R_UNKNOWN_ACTION = "R002", "a rule for an action the domain does not have";
        R_PARAM_COUNT = "R003", "a rule pattern whose parameter count does not fit the PDDL action";
        R_PORT_TYPE = "R004", "a value whose type cannot flow into the port it is bound to";
        R_EFFECT_DIFFERS = "R005", "a rule effect that disagrees with the PDDL action's effect";
        R_UNBOUND = "R006", "a variable or capture that the rule does not bind";
        R_UNKNOWN_NODE = "R007", "a call to a node or tree that is not declared";
        R_UNKNOWN_PORT = "R008", "a port the node does not declare";
        R_UNKNOWN_TABLE = "R009", "a lookup in a table that is not declared";
        R_MISSING_PORT = "R010", "a call that leaves a declared port out";
        R_UNKNOWN_KEY = "R011", "a table lookup with a key the table does not have";
        R_UNCOVERED = "R012", "a domain action that no rule covers";
        R_SHADOWED = "R013", "a rule that an earlier rule always matches first";
        R_UNUSED = "R014", "a declaration nothing uses";
        R_NO_RULE = "R015", "a plan step that no rule matches";
        R_STEP_TYPE = "R016", "a plan step whose argument types do not fit the rule";
        R_NO_DOMAIN = "R017", "a PDDL domain or problem that is missing or unusable";
        R_IMPORT = "R018", "an import that cannot be found";
        R_DUPLICATE = "R019", "a name declared twice";
        R_UNKNOWN_OBJECT = "R020", "a string naming an object the domain or problem does not have";
        R_UNKNOWN_TYPE = "R021", "a port type that is neither a PDDL type nor a basic type";
        R_PLAN_BLOCK = "R022", "a `plan` block that is missing, repeated or has no `steps`";
        R_BAD_ARGUMENT = "R023", "a control or decorator argument that makes no sense";
        R_LOOKUP_OBJECT = "R024", "a table lookup by a variable, with no key for an object of the problem the variable can stand for";
        R_NO_RULES = "R025", "a rules file with a domain and no rules yet";
        R_EFFECT_UNBOUND = "R033", "a rule effect that reads an optional parameter a step leaves out";
        R_BACKCHAIN = "R034", "a plan `steps backchained` cannot regress its goal through";
        R_SCHEDULE_DURATION = "R035", "a timed plan's durative step without a stated duration, which `steps scheduled` needs";
        // .btrules: rules that no step can match, and skips that lose effects
        R_CONTRADICTION = "R040", "a rule whose guards contradict each other, so no step matches it";
        R_GUARD_TYPE = "R041", "a type guard that the variable's type can never fit";
        R_DISJOINT = "R042", "a repeated variable (or `==` guard) whose parameters' types share no object";
        R_GUARD_OBJECT = "R043", "a guard comparing a variable with an object that can never stand there";
        R_SKIP_CHANGES = "R044", "a `=> skip` rule for steps whose effects change the world";
        R_TOO_DEEP = "R060", "a template nested deeper than btc supports";
        // Node palettes imported from BT.CPP XML (`import "nodes.xml"`)
        R_PALETTE = "R070", "an imported BT.CPP XML file that is not well-formed, or has neither a <TreeNodesModel> nor a <BehaviorTree>";
        R_PALETTE_TYPE = "R071", "a palette port whose C++ type btc cannot check";
        // BT.CPP trees imported from XML (`import "move.xml" as Move`)
        R_XML_CONSTRUCT = "R072", "a construct in an imported BT.CPP tree that btc cannot carry into every output";
        R_XML_SUBTREE = "R073", "a <SubTree> of an imported BT.CPP file that names no tree of the file, or calls itself";
        R_XML_TREE_NAME = "R074", "an imported BT.CPP file whose tree an `as` name or `main_tree_to_execute` cannot pick";
        R_XML_NODE = "R075", "a node of an imported BT.CPP tree that neither a palette nor the rules declare";
        // .btrules: BT.CPP scripts on nodes (`[skip_if: "..."]`, `script "..."`)
        R_SCRIPT_KEY = "R120", "a script attribute on a node that is not one of BT.CPP's pre- or post-conditions";
        R_SCRIPT_TWICE = "R121", "a node that gives the same pre- or post-condition twice";
        R_SCRIPT_TEXT = "R122", "a script string that interpolates, which BT.CPP scripts cannot";
        R_SCRIPT_SYNTAX = "R123", "a script that does not parse, which BT.CPP refuses when it loads the tree";
        // Emitting (btc compile --emit): what a target cannot express
        E_PYTREES_NODE = "E001", "a node a py_trees module cannot run as btc's engine does";
        // Running trees (btc run)
        X_TREE_SYNTAX = "X001", "a behavior tree file that is not BT.CPP v4 XML or btc's JSON IR";
        X_UNKNOWN_NODE = "X002", "a tree node that is neither built in nor declared";
        X_BAD_PORT = "X003", "a node attribute or port value the runtime cannot use";
        X_SUBTREE = "X004", "a SubTree that is not defined, or that calls itself";
        X_KB = "X005", "a KB formula or effect in a tree that does not fit the problem";
        X_SCENARIO = "X006", "a fault scenario file that is not valid";
        X_TOO_DEEP = "X007", "a tree nested deeper than the runtime runs";
        X_REPLAN_UNSOLVABLE = "X008", "a goal that replanning cannot reach after a fault";
        X_REPLAN_LIMIT = "X009", "a closed loop that stopped at its replan or tick limit";
        X_WORLD = "X010", "a JSON IR whose world is missing or does not fit together";
        X_TRIGGER = "X011", "a fault trigger that names no action of the tree, so the fault never happens";
        X_BTLOG = "X030", "a run that a Groot2 `.btlog` file cannot hold";
        X_SCRIPT = "X040", "a BT.CPP script that does not parse";
        X_UNSUPPORTED = "X041", "a BT.CPP XML construct btc does not run";
        X_INCLUDE_READ = "X042", "an `<include>` whose file cannot be read";
        X_INCLUDE_CYCLE = "X043", "an `<include>` that includes itself, or nests too deep";
        // The C++ executor for BehaviorTree.CPP (`btc executor`)
        C_CLASS_NAME = "C001", "a node whose name cannot become a C++ class of the executor";
        C_REGISTERED = "C002", "a node that BehaviorTree.CPP or btc's support library registers already";
        C_STALE_CLASS = "C003", "a class in the executor's nodes.hpp for a node the rules no longer declare";
        // Embedding: btc's C API (btc-capi, the C++ library over it)
        A_ARGUMENT = "A001", "a null pointer, a text that is not UTF-8 or a handle of another kind given to btc's C API";
        A_INTERNAL = "A002", "a failure inside btc that its C API caught instead of crashing the host (a bug in btc)";
        // ARIAC trials (btc trial)
        TRIAL_SYNTAX = "T001", "a trial file that is not YAML btc reads";
        TRIAL_MISSING = "T002", "a trial field the ARIAC 2023 format requires is missing";
        TRIAL_VALUE = "T003", "a trial value of the wrong kind or out of range";
        TRIAL_UNKNOWN_FIELD = "T004", "a trial field the ARIAC 2023 format does not have";
        TRIAL_NOT_SIMULATED = "T005", "a trial field btc reads but its symbolic world does not simulate";
        TRIAL_DUPLICATE = "T006", "something given twice in a trial (an order id, a slot, a quadrant)";
        TRIAL_UNKNOWN_ORDER = "T007", "a condition or challenge naming an order the trial does not have";
        TRIAL_RULE = "T008", "a trial that breaks an ARIAC 2023 rule";
        TRIAL_SUPPLY = "T009", "an order the trial's parts cannot fulfil (insufficient parts)";
        CELL_INVALID = "T010", "a cell file that is not valid";
        CELL_MAPPING = "T011", "a cell mapping that does not fit the cell's PDDL domain";
    }
}

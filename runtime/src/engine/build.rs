//! Building: a loaded tree compiled into the engine's arena. Nodes are
//! laid out in preorder with their children as index ranges, subtrees are
//! expanded with their blackboard scopes, ports become constants or slots,
//! and the KB's formulas and effects are compiled once.

use super::control::threshold;
use super::guard::{CompiledScript, Guard};
use super::state::NodeState;
use super::step::StepRt;
use super::{ActionInfo, CondInfo, Engine, NodeDef, NodeMeta, Op, Options, PortBind, Src, Status};
use super::{Arg, NO_GUARD};
use super::{Value, MAX_CALLS, MAX_DEPTH};
use crate::error::LoadError;
use crate::kb::{ConditionId, EffectId, FormulaId, Kb};
use crate::spec::{
    default_name, Amount, Kind, NodeScripts, SNode, StepConditions, TreeDoc, Verdict,
};
use btc_ir::{LeafKind, NodeModel, PortValue};
use btc_pddl::diagnostic::{codes, did_you_mean};
use btc_pddl::logic::{self, Binding, Effect, Formula, Name, Terms};
use rustc_hash::FxHashMap;

/// A blackboard scope: key to slot.
type Scope = FxHashMap<String, u32>;

struct Builder<'d, 'e, 'w> {
    doc: &'d TreeDoc,
    /// The document's trees and node models by ID: looking them up in the
    /// lists per node made loading quadratic.
    trees: FxHashMap<&'d str, &'d SNode>,
    models: FxHashMap<&'d str, &'d NodeModel>,
    e: &'e mut Engine<'w>,
    instances: FxHashMap<String, u32>,
    /// The tree instance being built (`Main`, `Check#1`): names new entries.
    tree: String,
    /// Children of the nodes being built, before they move to `kids`.
    pending: Vec<u32>,
}

impl<'w> Engine<'w> {
    /// Compiles a loaded document into an engine. `kb` is the simulated
    /// world; without it, trees that read or write the KB are refused.
    pub fn build(
        doc: &TreeDoc,
        kb: Option<Kb<'w>>,
        opts: Options,
    ) -> Result<Engine<'w>, LoadError> {
        let mut e = Engine {
            nodes: Vec::new(),
            kids: Vec::new(),
            meta: Vec::new(),
            ports: Vec::new(),
            actions: Vec::new(),
            conds: Vec::new(),
            scripts: Vec::new(),
            guards: Vec::new(),
            slot_names: Vec::new(),
            bb: Vec::new(),
            bb_gen: 1,
            status: Vec::new(),
            state: Vec::new(),
            kb,
            steps: Vec::new(),
            opts,
            tick: 0,
            now_ms: 0,
            observers: Vec::new(),
            last_failure: None,
            records: Vec::new(),
            injector: None,
            inject_live: false,
            controller: None,
            handlers: Vec::new(),
            halt_handlers: Vec::new(),
            record_slots: [0; 4],
            step_running: None,
        };
        e.load_steps(doc)?;
        let main = doc.tree(&doc.main).ok_or_else(|| {
            LoadError::new(
                codes::X_SUBTREE,
                format!("the main tree `{}` is not defined", doc.main),
            )
        })?;
        let mut scope = Scope::default();
        for (k, key) in ["fault_node", "fault_step", "fault_reason", "fault_kb"]
            .iter()
            .enumerate()
        {
            let s = e.new_slot(format!("{}/{key}", doc.main), Value::Empty);
            scope.insert((*key).to_owned(), s);
            e.record_slots[k] = s;
        }
        let mut b = Builder {
            doc,
            // The first definition of an ID counts, as `TreeDoc::tree` has it.
            trees: doc
                .trees
                .iter()
                .rev()
                .map(|(id, n)| (id.as_str(), n))
                .collect(),
            models: doc
                .models
                .iter()
                .rev()
                .map(|m| (m.id.as_str(), m))
                .collect(),
            e: &mut e,
            instances: FxHashMap::default(),
            tree: doc.main.clone(),
            pending: Vec::new(),
        };
        b.node(main, &mut scope, None, None, 0, 0)?;
        let n = e.nodes.len();
        e.status = vec![Status::Idle; n];
        e.state = vec![NodeState::Fresh; n];
        Ok(e)
    }

    fn load_steps(&mut self, doc: &TreeDoc) -> Result<(), LoadError> {
        for s in &doc.steps {
            let mut rt = StepRt {
                label: s.label(),
                skipped: s.skipped,
                duration: s.duration,
                ..StepRt::default()
            };
            if !s.skipped {
                rt.pre_start = self.kb_formula(s.logic.pre_start.as_deref(), &rt.label)?;
                rt.pre_over_all = self.kb_formula(s.logic.pre_over_all.as_deref(), &rt.label)?;
                rt.pre_end = self.kb_formula(s.logic.pre_end.as_deref(), &rt.label)?;
                rt.eff_start = self.kb_effect(s.logic.eff_start.as_deref(), &rt.label)?;
                rt.eff_end = self.kb_effect(s.logic.eff_end.as_deref(), &rt.label)?;
            }
            self.steps.push(rt);
        }
        Ok(())
    }

    fn need_kb(&mut self, what: &str) -> Result<&mut Kb<'w>, LoadError> {
        self.kb.as_mut().ok_or_else(|| no_kb(what))
    }

    fn kb_formula(
        &mut self,
        f: Option<&Formula>,
        what: &str,
    ) -> Result<Option<FormulaId>, LoadError> {
        let Some(f) = f else {
            return Ok(None);
        };
        let kb = self.need_kb(what)?;
        kb.formula(f).map(Some).map_err(|m| {
            LoadError::new(
                codes::X_KB,
                format!("{what}: `{f}` is not a condition of this problem: {m}"),
            )
        })
    }

    fn kb_effect(&mut self, e: Option<&Effect>, what: &str) -> Result<Option<EffectId>, LoadError> {
        let Some(e) = e else {
            return Ok(None);
        };
        let kb = self.need_kb(what)?;
        kb.effect(e).map(Some).map_err(|m| {
            LoadError::new(
                codes::X_KB,
                format!("{what}: `{e}` is not an effect of this problem: {m}"),
            )
        })
    }

    fn new_slot(&mut self, name: String, v: Value) -> u32 {
        self.slot_names.push(name);
        self.bb.push(v);
        (self.bb.len() - 1) as u32
    }
}

/// X005 for a KB node whose port holds something other than PDDL.
fn not_pddl(n: &SNode, id: &str, key: &str, v: &PortValue, what: &str) -> LoadError {
    LoadError::new(
        codes::X_KB,
        format!(
            "`{id}`: port `{key}` holds `{}`, which is not a PDDL {what} value",
            v.to_text()
        ),
    )
    .at_opt(n.at)
    .hint("trees written by `btc compile` carry PDDL values here; check the file was not edited by hand")
}

fn no_kb(what: &str) -> LoadError {
    LoadError::new(
        codes::X_KB,
        format!("{what} reads or writes the KB, and no PDDL problem was given"),
    )
    .hint("pass `--problem PROBLEM` (and `--domain DOMAIN` unless it is beside the problem)")
}
const BUILTIN_LEAVES: &[&str] = &[
    "AlwaysSuccess",
    "AlwaysFailure",
    "Sleep",
    "SetBlackboard",
    "KbHolds",
    "KbApply",
    "WaitForStep",
    "Script",
    "ScriptCondition",
];

impl<'d, 'e, 'w> Builder<'d, 'e, 'w> {
    fn err(&self, code: btc_pddl::diagnostic::Code, n: &SNode, msg: String) -> LoadError {
        LoadError::new(code, msg).at_opt(n.at)
    }

    #[allow(clippy::too_many_arguments)]
    fn node(
        &mut self,
        n: &SNode,
        scope: &mut Scope,
        step: Option<u32>,
        parent: Option<u32>,
        depth: usize,
        calls: usize,
    ) -> Result<u32, LoadError> {
        if depth > MAX_DEPTH {
            return Err(self.err(
                codes::X_TOO_DEEP,
                n,
                format!("the tree is nested deeper than {MAX_DEPTH} levels"),
            ));
        }
        let me = self.e.nodes.len() as u32;
        let mut name = n
            .name
            .clone()
            .unwrap_or_else(|| default_name(&n.kind).to_owned());
        let mut id = default_name(&n.kind).to_owned();
        let mut my_step = step;
        self.e.nodes.push(NodeDef {
            op: Op::AlwaysSuccess,
            first: 0,
            len: 0,
            guard: NO_GUARD,
        });
        self.e.meta.push(NodeMeta {
            id: String::new(),
            name: String::new(),
            step,
            parent,
        });
        let arity = |want: &[usize], b: &Self| -> Result<(), LoadError> {
            if !want.contains(&n.children.len()) {
                let takes = match want {
                    [1] => "exactly one child".to_owned(),
                    [a, b] => format!("{a} or {b} children"),
                    _ => format!("{} children", want[0]),
                };
                return Err(b.err(
                    codes::X_BAD_PORT,
                    n,
                    format!(
                        "`{}` takes {takes}, and has {}",
                        default_name(&n.kind),
                        n.children.len()
                    ),
                ));
            }
            Ok(())
        };
        let op = match &n.kind {
            Kind::Sequence => Op::Sequence,
            Kind::ReactiveSequence => Op::ReactiveSequence,
            Kind::SequenceWithMemory => Op::SequenceWithMemory,
            Kind::Fallback => Op::Fallback,
            Kind::ReactiveFallback => Op::ReactiveFallback,
            Kind::Parallel { success, failure } => {
                let c = n.children.len() as i64;
                for ((what, _), t) in n.kind.vocab_ports().into_iter().zip([*success, *failure]) {
                    if threshold(t, c) > c {
                        return Err(self
                            .err(
                                codes::X_BAD_PORT,
                                n,
                                format!(
                                    "{} has {c} children, fewer than its {what} {t}",
                                    default_name(&n.kind)
                                ),
                            )
                            .hint(
                                "BT.CPP refuses such a Parallel: it could never finish that way",
                            ));
                    }
                }
                Op::Parallel {
                    success: *success,
                    failure: *failure,
                }
            }
            Kind::Inverter => Op::Inverter,
            Kind::ForceSuccess => Op::ForceSuccess,
            Kind::ForceFailure => Op::ForceFailure,
            Kind::KeepRunningUntilFailure => Op::KeepRunningUntilFailure,
            Kind::Retry(k) => Op::Retry(self.arg(k, scope)),
            Kind::Repeat(k) => Op::Repeat(self.arg(k, scope)),
            Kind::Timeout(ms) => Op::Timeout(self.arg(ms, scope)),
            Kind::IfThenElse => {
                arity(&[2, 3], self)?;
                Op::IfThenElse
            }
            Kind::WhileDoElse => {
                arity(&[2, 3], self)?;
                Op::WhileDoElse
            }
            Kind::Switch { variable, cases } => {
                arity(&[cases.len() + 1], self)?;
                let mut ports = vec![("variable".to_owned(), (**variable).clone())];
                for (k, c) in cases.iter().enumerate() {
                    ports.push((format!("case_{}", k + 1), c.clone()));
                }
                let (first, _) = self.bind_ports(n, &ports, &|_| None, scope)?;
                Op::Switch {
                    variable: first,
                    first_case: first + 1,
                    cases: cases.len() as u32,
                }
            }
            Kind::Delay(ms) => Op::Delay(self.arg(ms, scope)),
            Kind::RunOnce { then_skip } => Op::RunOnce {
                then_skip: *then_skip,
            },
            Kind::Precondition { code, otherwise } => Op::Precondition {
                script: self.script(n, "if", code, scope)?,
                otherwise: match otherwise {
                    Verdict::Success => Status::Success,
                    Verdict::Failure => Status::Failure,
                    Verdict::Skipped => Status::Skipped,
                    Verdict::Running => Status::Running,
                },
            },
            Kind::SubTree { .. } => {
                id = "SubTree".into();
                Op::SubTree
            }
            Kind::Step {
                step: k,
                start_effect,
                end_effect,
                conditions,
            } => {
                let k32 = u32::try_from(*k).unwrap_or(u32::MAX);
                while self.e.steps.len() <= *k && self.e.steps.len() < 100_000 {
                    let idx = self.e.steps.len();
                    // A step the tree file names but no plan describes:
                    // skipped until a KbStep refers to it.
                    self.e.steps.push(StepRt {
                        label: format!("step {}", idx + 1),
                        skipped: true,
                        ..StepRt::default()
                    });
                }
                if *k >= self.e.steps.len() {
                    return Err(self.err(
                        codes::X_BAD_PORT,
                        n,
                        format!("step {} is out of range", k + 1),
                    ));
                }
                if *k >= self.doc.steps.len() && self.e.steps[*k].skipped {
                    self.e.steps[*k].skipped = false;
                    if let Some(nm) = &n.name {
                        self.derive_step(*k, nm, conditions.is_none())
                            .map_err(|e| e.at_opt(n.at))?;
                    }
                    if let Some(c) = conditions {
                        self.given_conditions(*k, c).map_err(|e| e.at_opt(n.at))?;
                    }
                }
                let label = format!("`{}`", self.e.steps[*k].label);
                if let Some(f) = self
                    .e
                    .kb_effect(start_effect.as_deref(), &label)
                    .map_err(|e| e.at_opt(n.at))?
                {
                    self.e.steps[*k].eff_start = Some(f);
                }
                if let Some(f) = self
                    .e
                    .kb_effect(end_effect.as_deref(), &label)
                    .map_err(|e| e.at_opt(n.at))?
                {
                    self.e.steps[*k].eff_end = Some(f);
                }
                if n.name.is_none() {
                    name = self.e.steps[*k].label.clone();
                }
                my_step = Some(k32);
                self.e.meta[me as usize].step = my_step;
                Op::Step(k32)
            }
            Kind::Leaf {
                id: lid,
                kind,
                ports,
            } => self.leaf(n, lid, *kind, ports, scope)?,
        };
        if matches!(
            op,
            Op::Inverter
                | Op::ForceSuccess
                | Op::ForceFailure
                | Op::KeepRunningUntilFailure
                | Op::Retry(_)
                | Op::Repeat(_)
                | Op::Timeout(_)
                | Op::Step(_)
                | Op::Delay(_)
                | Op::RunOnce { .. }
                | Op::Precondition { .. }
        ) {
            arity(&[1], self)?;
        }
        let guard = if n.scripts.is_empty() {
            NO_GUARD
        } else {
            self.guard(n, scope)?
        };
        {
            let m = &mut self.e.meta[me as usize];
            m.name = name;
            m.id = id;
        }
        let mark = self.pending.len();
        if let Kind::SubTree {
            id: tid,
            ports,
            autoremap,
        } = &n.kind
        {
            if !n.children.is_empty() {
                return Err(self.err(
                    codes::X_BAD_PORT,
                    n,
                    "a SubTree has no children of its own".into(),
                ));
            }
            let Some(def) = self.trees.get(tid.as_str()).copied() else {
                let hint = did_you_mean(tid, self.doc.trees.iter().map(|(t, _)| t.as_str()));
                let mut e = self.err(
                    codes::X_SUBTREE,
                    n,
                    format!("SubTree `{tid}` is not defined"),
                );
                if let Some(h) = hint {
                    e = e.hint(h);
                }
                return Err(e);
            };
            if calls >= MAX_CALLS {
                return Err(self.err(
                    codes::X_SUBTREE,
                    n,
                    format!("SubTree `{tid}` calls itself (or nests more than {MAX_CALLS} calls)"),
                ));
            }
            let count = self.instances.entry(tid.clone()).or_insert(0);
            *count += 1;
            let inst = format!("{tid}#{count}");
            let mut child: Scope = if *autoremap {
                scope.clone()
            } else {
                Scope::default()
            };
            for (k, v) in ports {
                let slot = match v {
                    PortValue::Param(p) => {
                        let p = if p == "=" { k } else { p };
                        self.slot_in(scope, p)
                    }
                    other => self
                        .e
                        .new_slot(format!("{inst}/{k}"), Value::from_port(other)),
                };
                child.insert(k.clone(), slot);
            }
            let outer = std::mem::replace(&mut self.tree, inst);
            let c = self.node(def, &mut child, my_step, Some(me), depth + 1, calls + 1);
            self.tree = outer;
            if *autoremap {
                // BT.CPP creates an autoremapped subtree's new entries in
                // the parent's blackboard (all but `_private` ones and the
                // call's own ports): later nodes of the parent see them.
                for (k, slot) in child {
                    if !k.starts_with('_') && !ports.iter().any(|(p, _)| *p == k) {
                        scope.entry(k).or_insert(slot);
                    }
                }
            }
            self.pending.push(c?);
        } else {
            for c in &n.children {
                let k = self.node(c, scope, my_step, Some(me), depth + 1, calls)?;
                self.pending.push(k);
            }
        }
        let first = self.e.kids.len() as u32;
        let len = (self.pending.len() - mark) as u32;
        self.e.kids.extend(self.pending.drain(mark..));
        self.e.nodes[me as usize] = NodeDef {
            op,
            first,
            len,
            guard,
        };
        Ok(me)
    }

    /// A step's conditions as its `KbStep` gives them.
    fn given_conditions(&mut self, k: usize, c: &StepConditions) -> Result<(), LoadError> {
        let what = format!("`{}`", self.e.steps[k].label);
        let start = self.e.kb_formula(c.start.as_ref(), &what)?;
        let over_all = self.e.kb_formula(c.over_all.as_ref(), &what)?;
        let end = self.e.kb_formula(c.end.as_ref(), &what)?;
        let st = &mut self.e.steps[k];
        st.pre_start = start;
        st.pre_over_all = over_all;
        st.pre_end = end;
        Ok(())
    }

    /// A step known only from a tree file (`KbStep name="step 3: (grasp r
    /// p bin1)"`): its label, and unless the file gives them (`conditions`
    /// false), its conditions: the domain action's, grounded.
    fn derive_step(&mut self, k: usize, name: &str, conditions: bool) -> Result<(), LoadError> {
        let Some(open) = name.find('(') else {
            return Ok(());
        };
        let inner = name[open + 1..].trim_end().trim_end_matches(')');
        let mut words = inner.split_whitespace();
        let Some(act) = words.next().map(str::to_lowercase) else {
            return Ok(());
        };
        let args: Vec<Name> = words.map(|w| logic::name(&w.to_lowercase())).collect();
        let Some(a) = self.doc.actions.iter().find(|a| *a.name == *act) else {
            return Ok(());
        };
        if a.params.len() != args.len() {
            return Ok(());
        }
        let params = a.param_names();
        let binding = Binding {
            params: &params,
            objects: &args,
        };
        let ground = |parts: &[Formula]| {
            Formula::conjunction(parts.iter().map(|f| f.ground(&binding)).collect())
        };
        let (pre_start, over_all, pre_end) = (
            ground(&a.pre_start),
            ground(&a.pre_over_all),
            ground(&a.pre_end),
        );
        let label = format!(
            "step {}: ({})",
            k + 1,
            std::iter::once(act.as_str())
                .chain(args.iter().map(|a| &**a))
                .collect::<Vec<_>>()
                .join(" ")
        );
        if !conditions {
            self.e.steps[k].label = label;
            return Ok(());
        }
        let what = format!("`{label}`");
        let pre_start = self.e.kb_formula(pre_start.as_ref(), &what)?;
        let over_all = self.e.kb_formula(over_all.as_ref(), &what)?;
        let pre_end = self.e.kb_formula(pre_end.as_ref(), &what)?;
        let st = &mut self.e.steps[k];
        st.label = label;
        st.pre_start = pre_start;
        st.pre_over_all = over_all;
        st.pre_end = pre_end;
        Ok(())
    }

    /// A script of node `n` (its attribute or port `what`), parsed, its
    /// variables bound to blackboard slots of the scope.
    fn script(
        &mut self,
        n: &SNode,
        what: &str,
        text: &str,
        scope: &mut Scope,
    ) -> Result<u32, LoadError> {
        let script = crate::script::parse(text).map_err(|e| {
            crate::script::syntax_error(default_name(&n.kind), what, text, &e).at_opt(n.at)
        })?;
        let slots = script.vars.iter().map(|v| self.slot_in(scope, v)).collect();
        self.e.scripts.push(CompiledScript {
            script,
            slots,
            text: text.into(),
        });
        Ok((self.e.scripts.len() - 1) as u32)
    }

    /// The pre- and post-condition scripts of node `n`.
    fn guard(&mut self, n: &SNode, scope: &mut Scope) -> Result<u32, LoadError> {
        let mut all = n.scripts.clone();
        let mut g = Guard::default();
        for (k, attr) in NodeScripts::ATTRIBUTES.iter().enumerate() {
            if let Some(text) = all.slot(k).take() {
                let id = self.script(n, attr, &text, scope)?;
                if k < 4 {
                    g.pre[k] = Some(id);
                } else {
                    g.post[k - 4] = Some(id);
                }
            }
        }
        self.e.guards.push(g);
        Ok((self.e.guards.len() - 1) as u32)
    }

    /// A decorator's count: fixed, or the slot of the blackboard entry it reads.
    fn arg<T: Copy>(&mut self, a: &Amount<T>, scope: &mut Scope) -> Arg<T> {
        match a {
            Amount::Fixed(n) => Arg::Fixed(*n),
            Amount::Entry(key) => Arg::Slot(self.slot_in(scope, key)),
        }
    }

    fn slot_in(&mut self, scope: &mut Scope, key: &str) -> u32 {
        if let Some(&s) = scope.get(key) {
            return s;
        }
        let s = self
            .e
            .new_slot(format!("{}/{key}", self.tree), Value::Empty);
        scope.insert(key.to_owned(), s);
        s
    }

    fn bind_ports(
        &mut self,
        n: &SNode,
        ports: &[(String, PortValue)],
        types: &dyn Fn(&str) -> Option<&'d str>,
        scope: &mut Scope,
    ) -> Result<(u32, u32), LoadError> {
        let start = self.e.ports.len() as u32;
        for (k, v) in ports {
            let src = match v {
                PortValue::Param(p) => {
                    let p = if p == "=" { k.as_str() } else { p.as_str() };
                    Src::Slot(self.slot_in(scope, p))
                }
                other => {
                    let val = Value::from_port(other);
                    let val = match types(k) {
                        Some(ty) => val.typed(ty).map_err(|m| {
                            self.err(
                                codes::X_BAD_PORT,
                                n,
                                format!("port `{k}` of `{}`: {m}", default_name(&n.kind)),
                            )
                        })?,
                        None => val,
                    };
                    Src::Const(val)
                }
            };
            self.e.ports.push(PortBind {
                name: k.as_str().into(),
                src,
            });
        }
        Ok((start, self.e.ports.len() as u32))
    }

    /// A KB node's PDDL port: it must be written out.
    fn kb_port<'p>(
        &self,
        n: &SNode,
        ports: &'p [(String, PortValue)],
        key: &str,
    ) -> Result<&'p PortValue, LoadError> {
        match ports.iter().find(|(k, _)| k == key) {
            Some((_, PortValue::Param(p))) => Err(self.err(
                codes::X_BAD_PORT,
                n,
                format!("port `{key}` of `{}` must be written out, not read from the blackboard entry `{p}`", default_name(&n.kind)),
            )),
            Some((_, v)) => Ok(v),
            None => Err(self.err(
                codes::X_BAD_PORT,
                n,
                format!("`{}` needs the port `{key}`", default_name(&n.kind)),
            )),
        }
    }

    fn const_text(
        &self,
        n: &SNode,
        ports: &[(String, PortValue)],
        key: &str,
        need: bool,
    ) -> Result<Option<String>, LoadError> {
        match ports.iter().find(|(k, _)| k == key) {
            Some((_, PortValue::Param(p))) => Err(self
                .err(
                    codes::X_BAD_PORT,
                    n,
                    format!("port `{key}` of `{}` must be written out, not read from the blackboard entry `{p}`", default_name(&n.kind)),
                )),
            Some((_, v)) => Ok(Some(v.to_text())),
            None if need => Err(self.err(
                codes::X_BAD_PORT,
                n,
                format!("`{}` needs the port `{key}`", default_name(&n.kind)),
            )),
            None => Ok(None),
        }
    }

    /// A condition's formula compiled over the ports it names: its free
    /// variables are port names, each a slot filled from that port. With
    /// constant ports only, the objects are checked now.
    fn port_condition(
        &mut self,
        n: &SNode,
        id: &str,
        f: &Formula,
        range: (u32, u32),
    ) -> Result<(ConditionId, Box<[u32]>), LoadError> {
        let what = format!("the condition `{id}`");
        let vars = f.free_vars();
        let mut slots = Vec::with_capacity(vars.len());
        for v in &vars {
            let p = (range.0..range.1).find(|&p| *self.e.ports[p as usize].name == **v);
            match p {
                Some(p) => slots.push(p),
                None => {
                    return Err(self.err(
                        codes::X_KB,
                        n,
                        format!(
                            "{what}: its formula `{f}` reads `?{v}`, which is none of its ports"
                        ),
                    ))
                }
            }
        }
        let kb = self.e.need_kb(&what).map_err(|e| e.at_opt(n.at))?;
        let c = kb.condition(f, &vars).map_err(|m| {
            self.err(
                codes::X_KB,
                n,
                format!("{what}: `{f}` is not a condition of this problem: {m}"),
            )
        })?;
        let all_const = slots
            .iter()
            .all(|&p| matches!(self.e.ports[p as usize].src, Src::Const(_)));
        if all_const {
            if let Err(m) = self.e.port_objects(&slots) {
                return Err(self.err(codes::X_KB, n, format!("{what}: {m}")));
            }
        }
        Ok((c, slots.into()))
    }

    fn leaf(
        &mut self,
        n: &SNode,
        id: &str,
        kind: Option<LeafKind>,
        ports: &[(String, PortValue)],
        scope: &mut Scope,
    ) -> Result<Op, LoadError> {
        if !n.children.is_empty() {
            return Err(self.err(
                codes::X_UNKNOWN_NODE,
                n,
                format!("`{id}` has children, but it is not a control or decorator node the runtime knows"),
            ));
        }
        // Only the KB leaves name themselves in their errors; a string per
        // leaf was a fifth of loading a large tree.
        let what = || format!("`{id}`");
        match id {
            "AlwaysSuccess" => return Ok(Op::AlwaysSuccess),
            "Script" | "ScriptCondition" => {
                let code = self.const_text(n, ports, "code", true)?.unwrap_or_default();
                if let Some((k, _)) = ports.iter().find(|(k, _)| k != "code") {
                    return Err(self.err(
                        codes::X_BAD_PORT,
                        n,
                        format!("`{id}` has no port `{k}`; its script is the port `code`"),
                    ));
                }
                let k = self.script(n, "code", &code, scope)?;
                return Ok(if id == "Script" {
                    Op::Script(k)
                } else {
                    Op::ScriptCondition(k)
                });
            }
            "AlwaysFailure" => return Ok(Op::AlwaysFailure),
            "Sleep" => {
                self.const_text(n, ports, "msec", true)?;
                let (a, _) =
                    self.bind_ports(n, ports, &|k| (k == "msec").then_some("int"), scope)?;
                let p = ports.iter().position(|(k, _)| k == "msec").unwrap_or(0) as u32;
                return Ok(Op::Sleep(a + p));
            }
            "SetBlackboard" => {
                let key = match ports.iter().find(|(k, _)| k == "output_key") {
                    Some((_, PortValue::Param(p))) => p.clone(),
                    Some((_, v)) => v.to_text(),
                    None => {
                        return Err(self.err(
                            codes::X_BAD_PORT,
                            n,
                            "`SetBlackboard` needs the port `output_key`".into(),
                        ));
                    }
                };
                let Some(vi) = ports.iter().position(|(k, _)| k == "value") else {
                    return Err(self.err(
                        codes::X_BAD_PORT,
                        n,
                        "`SetBlackboard` needs the port `value`".into(),
                    ));
                };
                let slot = self.slot_in(scope, &key);
                let (a, _) = self.bind_ports(n, ports, &|_| None, scope)?;
                return Ok(Op::SetBlackboard {
                    value: a + vi as u32,
                    slot,
                });
            }
            "KbHolds" => {
                let f = match self.kb_port(n, ports, "formula")? {
                    PortValue::Formula(f) => self.e.kb_formula(Some(f), &what()),
                    other => Err(not_pddl(n, id, "formula", other, "condition")),
                }
                .map_err(|e| e.at_opt(n.at))?;
                return match f {
                    Some(f) => Ok(Op::KbHolds(f)),
                    None => Ok(Op::AlwaysSuccess),
                };
            }
            "KbApply" => {
                let e = match self.kb_port(n, ports, "effect")? {
                    PortValue::Effect(e) => self.e.kb_effect(Some(e), &what()),
                    other => Err(not_pddl(n, id, "effect", other, "effect")),
                }
                .map_err(|e| e.at_opt(n.at))?;
                return match e {
                    Some(e) => Ok(Op::KbApply(e)),
                    None => Ok(Op::AlwaysSuccess),
                };
            }
            "WaitForStep" => {
                let t = self.const_text(n, ports, "step", true)?.unwrap_or_default();
                let k: u32 = t.trim().parse().ok().filter(|k| *k >= 1).ok_or_else(|| {
                    self.err(
                        codes::X_BAD_PORT,
                        n,
                        format!("port `step` of `WaitForStep`: `{t}` is not a step number"),
                    )
                })?;
                return Ok(Op::WaitForStep(k - 1));
            }
            _ => {}
        }
        let model = self.models.get(id).copied();
        let kind = kind.or(model.map(|m| m.kind)).ok_or_else(|| {
            let known = self.doc.models.iter().map(|m| m.id.as_str()).chain(BUILTIN_LEAVES.iter().copied());
            let mut e = self.err(
                codes::X_UNKNOWN_NODE,
                n,
                format!("`{id}` is not a node the runtime knows: it is not built in and not declared in the tree's node models"),
            );
            e = e.hint(match did_you_mean(id, known) {
                Some(h) => h,
                None => "declare it in <TreeNodesModel> as an <Action> or a <Condition>".into(),
            });
            e
        })?;
        let types = |k: &str| -> Option<&'d str> {
            model.and_then(|m| m.ports.iter().find(|p| p.name == k).map(|p| p.ty.as_str()))
        };
        let range = self.bind_ports(n, ports, &types, scope)?;
        Ok(match kind {
            LeafKind::Condition => {
                let formula = model.and_then(|m| m.formula.clone());
                let c = self.e.conds.len() as u32;
                let (compiled, slot_ports) = match &formula {
                    Some(f) => {
                        let (c, slots) = self.port_condition(n, id, f, range)?;
                        (Some(c), slots)
                    }
                    None => (None, Box::default()),
                };
                self.e.conds.push(CondInfo {
                    formula: compiled,
                    slot_ports,
                    objects: Ok(Vec::new()),
                    generation: 0,
                });
                Op::Condition(c)
            }
            LeafKind::Action => {
                let a = self.e.actions.len() as u32;
                self.e.actions.push(ActionInfo {
                    id: id.into(),
                    ports: range,
                    handler: None,
                    on_halt: None,
                });
                Op::Action(a)
            }
        })
    }
}

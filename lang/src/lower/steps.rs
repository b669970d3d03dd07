//! The plan's steps lowered one by one: each matched to its first rule,
//! the rule's tree made once (parametric) and called with the step's
//! values, the rule's effect grounded, and what a repeated ground action or
//! call lowered to reused.

use super::inst::{count_in_range, Inst};
use super::*;

/// How a ground action lowers: the rule tree it calls (`None`: skipped),
/// its effects (a rule's `effect` replaces the action's) and the step's
/// node below its `Step` boundary.
#[derive(Clone)]
struct Lowered {
    logic: Arc<StepLogic>,
    child: Option<Arc<Node>>,
}

/// What the steps of one call (the same action and the same shared
/// argument list, as typing gives the steps that write the same call) have
/// in common: found at the call's first step, then looked up once a step.
struct CallParts {
    action: Arc<str>,
    args: Arc<[String]>,
    ground: action::Ground,
    lowered: Option<Lowered>,
}

/// What [`Steps::call`] finds for a step.
enum Call {
    /// The step repeats a ground action lowered before.
    Repeated(Lowered),
    /// The step's logic, its rule still to be found.
    New(StepLogic),
}

/// A step's call: its action and the address of its shared argument list.
type CallKey = (usize, *const u32);

fn call_key(g: &GroundStep) -> CallKey {
    (g.action, Arc::as_ptr(&g.args) as *const u32)
}

/// Remembers how the call of step `g` lowered, for the steps that repeat
/// it: by the call, and by its action and objects for steps that repeat
/// it in another call (written otherwise).
fn remember<'a>(
    calls: &mut rustc_hash::FxHashMap<CallKey, CallParts>,
    lowered: &mut rustc_hash::FxHashMap<(usize, &'a [u32]), Lowered>,
    g: &'a GroundStep,
    done: Lowered,
) {
    if let Some(parts) = calls.get_mut(&call_key(g)) {
        parts.lowered = Some(done.clone());
    }
    lowered.insert((g.action, &g.args[..]), done);
}

/// What lowering the steps keeps from one step to the next.
pub(super) struct Steps<'i> {
    input: &'i LowerInput<'i>,
    types: Types<'i>,
    grounder: Grounder,
    /// Each ground action's lowering, for the steps that repeat it: which
    /// rule, which tree call and guard, which effects depend on the action
    /// and its objects only, never on the step's place in the plan.
    lowered: FxHashMap<(usize, &'i [u32]), Lowered>,
    /// Steps with the same objects share their names, and with the same
    /// action its name.
    action_names: FxHashMap<usize, Arc<str>>,
    arg_names: FxHashMap<&'i [u32], Arc<[String]>>,
    /// The same, by call: one lookup a step instead of one a table.
    calls: FxHashMap<CallKey, CallParts>,
    rule_effects: BTreeMap<usize, RuleEffect>,
    /// By rule index.
    pub(super) rule_trees: Vec<(usize, RuleTree)>,
    taken: BTreeSet<String>,
    pub(super) used_nodes: BTreeSet<String>,
    pub(super) infos: Vec<StepInfo>,
    /// Names match once per (rule, action); steps repeat actions a lot.
    name_matches: BTreeMap<(usize, usize), Option<Captures>>,
    pub(super) step_nodes: Vec<Option<Node>>,
    object_names: Vec<Name>,
    pub(super) diags: Vec<Diagnostic>,
}

impl<'i> Steps<'i> {
    pub(super) fn new(input: &'i LowerInput<'i>) -> Steps<'i> {
        Steps {
            input,
            types: Types {
                dix: input.dix,
                pix: input.pix,
            },
            grounder: Grounder::default(),
            lowered: Default::default(),
            action_names: Default::default(),
            arg_names: Default::default(),
            calls: Default::default(),
            rule_effects: BTreeMap::new(),
            rule_trees: Vec::new(),
            taken: BTreeSet::new(),
            used_nodes: BTreeSet::new(),
            infos: Vec::with_capacity(input.steps.len()),
            name_matches: BTreeMap::new(),
            step_nodes: Vec::with_capacity(input.steps.len()),
            object_names: input
                .pix
                .object_names
                .iter()
                .map(|n| logic::name(n))
                .collect(),
            diags: Vec::new(),
        }
    }

    /// How step `g`'s call lowered when a step before it had the same
    /// ground action; else its names and ground logic, to lower it now.
    /// A repeat costs one lookup and the two shares its step keeps.
    fn call(&mut self, g: &'i GroundStep) -> Call {
        let input = self.input;
        let action = &input.domain.actions[g.action];
        let parts = self.calls.entry(call_key(g)).or_insert_with(|| CallParts {
            action: self
                .action_names
                .entry(g.action)
                .or_insert_with(|| action.name.name.as_str().into())
                .clone(),
            args: self
                .arg_names
                .entry(&g.args[..])
                .or_insert_with(|| {
                    g.args
                        .iter()
                        .map(|&o| input.pix.object_names[o as usize].clone())
                        .collect()
                })
                .clone(),
            ground: self
                .grounder
                .ground(input.domain, g.action, &g.args, &self.object_names),
            lowered: self.lowered.get(&(g.action, &g.args[..])).cloned(),
        });
        if let Some(done) = &parts.lowered {
            return Call::Repeated(done.clone());
        }
        let ground = parts.ground.clone();
        Call::New(StepLogic {
            action: parts.action.clone(),
            args: parts.args.clone(),
            rule: None,
            pre_start: ground.pre_start,
            pre_over_all: ground.pre_over_all,
            pre_end: ground.pre_end,
            eff_start: ground.eff_start,
            eff_end: ground.eff_end,
        })
    }

    /// Lowers step `k` (`g`); a problem is a diagnostic at its plan line.
    pub(super) fn step(&mut self, k: usize, g: &'i GroundStep) {
        let input = self.input;
        let step = &input.plan.steps[g.step];
        let action = &input.domain.actions[g.action];
        let place = |skipped: bool, logic: Arc<StepLogic>| StepInfo {
            index: k,
            line: step.line,
            skipped,
            time: step.time,
            duration: step.duration,
            after: Default::default(),
            logic,
        };
        let mut logic = match self.call(g) {
            Call::New(logic) => logic,
            Call::Repeated(r) => {
                self.infos.push(place(r.logic.rule.is_none(), r.logic));
                self.step_nodes
                    .push(r.child.map(|child| Node::Step { step: k, child }));
                return;
            }
        };
        let diags_before = self.diags.len();
        let args = logic.args.clone();
        let tables = |name: &str| input.decls.tables.get(name).cloned();
        let (name_matches, types) = (&mut self.name_matches, &self.types);
        let found = input.rules.iter().enumerate().find_map(|(ri, r)| {
            let caps = name_matches
                .entry((ri, g.action))
                .or_insert_with(|| match_name(&r.pattern.name, &action.name.name))
                .as_ref()?;
            match_args(r, caps, &args, &tables, types).map(|b| (ri, *r, b))
        });
        let Some((ri, rule, bindings)) = found else {
            self.diags.push(no_rule(input, k, g, &logic));
            self.infos.push(place(false, Arc::new(logic)));
            self.step_nodes.push(None);
            return;
        };
        let RuleBody::Template { body, effect } = &rule.body else {
            let logic = Arc::new(logic);
            let done = Lowered {
                logic: logic.clone(),
                child: None,
            };
            remember(&mut self.calls, &mut self.lowered, g, done);
            self.infos.push(place(true, logic));
            self.step_nodes.push(None);
            return;
        };
        // A rule's `effect` is the step's effect, in every target: it takes
        // the place of the PDDL action's (at start and at end), applied
        // when the step succeeds.
        if let Some(e) = effect {
            let lifted = self
                .rule_effects
                .entry(ri)
                .or_insert_with(|| RuleEffect::new(e));
            match lifted.ground(&bindings) {
                Ok(e) => {
                    logic.eff_start = None;
                    logic.eff_end = e.map(Arc::new);
                }
                Err(var) => {
                    self.diags.push(
                        Diagnostic::error(
                            codes::R_EFFECT_UNBOUND,
                            step.span,
                            format!(
                                "step {} `{}`: its rule's effect reads `?{var}`, which this step leaves out",
                                k + 1,
                                logic.display()
                            ),
                        )
                        .with_hint("an optional parameter the step does not give cannot stand in the rule's `effect`; write a rule for the shorter form"),
                    );
                }
            }
        }
        let pos = self.rule_tree(ri, rule, body);
        let rt = &self.rule_trees[pos].1;
        let captures = self.name_matches[&(ri, g.action)]
            .as_ref()
            .expect("the rule's name matched this action");
        let call_inst = Inst::new(input.decls, &bindings, captures, false);
        let ports: Vec<Port> = rt
            .params
            .iter()
            .map(|(name, expr)| Port {
                name: name.clone(),
                value: call_inst.eval(expr),
            })
            .collect();
        // A decorator count that depends on the step must be a number in
        // its range (a table may lack the key of this step's object).
        let diags = &mut self.diags;
        for (param, d, range) in &rt.counts {
            let Some(v) = ports.iter().find(|p| p.name == *param).map(|p| &p.value) else {
                continue;
            };
            if count_in_range(v, *range).is_none() {
                // A lookup is named with the key this step gives it.
                let lookup =
                    rt.params
                        .iter()
                        .find(|(n, _)| n == param)
                        .and_then(|(_, e)| match e {
                            Value::Lookup { table, key, .. } => {
                                Some((table.text.clone(), call_inst.eval(key).to_text()))
                            }
                            _ => None,
                        });
                let (got, hint) = match (v, &lookup) {
                    (PortValue::Text(t), Some((table, key))) if t.is_empty() => (
                        format!("no value: table `{table}` has no key `{key}`"),
                        format!("add `{key}: N` to table `{table}`"),
                    ),
                    (PortValue::Text(t), None) if t.is_empty() => (
                        "no value".to_owned(),
                        "a table lookup gives no value for a key the table does not have; add the key".to_owned(),
                    ),
                    (other, _) => (
                        format!("`{}`, which is not a number of {} from {} to {}", other.to_text(), range.what, range.min, range.max),
                        format!("give a number of {} from {} to {}", range.what, range.min, range.max),
                    ),
                };
                diags.push(
                    Diagnostic::error(
                        codes::R_BAD_ARGUMENT,
                        step.span,
                        format!(
                            "step {} `{}`: `{}` gets {got}",
                            k + 1,
                            logic.display(),
                            d.keyword(),
                        ),
                    )
                    .with_hint(hint),
                );
            }
        }
        // Objects bound to PDDL-typed ports must fit the port's type.
        check_port_types(
            &rt.typed,
            &ports,
            input,
            &self.types,
            &mut |port, node, obj, ty| {
                diags.push(
                Diagnostic::error(
                    codes::R_STEP_TYPE,
                    step.span,
                    format!("step {} `{}`: `{obj}` does not fit port `{port}` of `{node}`, which takes a `{ty}`", k + 1, logic.display()),
                )
                .with_hint("narrow the rule with a guard such as `where ?x - TYPE`, or widen the port's type"),
            );
            },
        );
        logic.rule = Some(rt.shared_id.clone());
        let mut child = Node::SubTree {
            scripts: Default::default(),
            id: rt.id.clone(),
            ports,
        };
        if let Some(over) = &logic.pre_over_all {
            child = Node::Control {
                scripts: Default::default(),
                control: ControlKind::ReactiveSequence,
                name: Some(format!("while {over}").into()),
                children: vec![kb_holds(over.clone(), None), child],
            };
        }
        let child = Arc::new(child);
        // A step with a diagnostic is not reused: each step reports its own.
        if self.diags.len() == diags_before {
            let logic = Arc::new(logic);
            let done = Lowered {
                logic: logic.clone(),
                child: Some(Arc::clone(&child)),
            };
            remember(&mut self.calls, &mut self.lowered, g, done);
            self.infos.push(place(false, logic));
        } else {
            self.infos.push(place(false, Arc::new(logic)));
        }
        self.step_nodes.push(Some(Node::Step { step: k, child }));
    }

    /// The index of rule `ri`'s tree, made (parametric) the first time a
    /// step matches the rule.
    fn rule_tree(&mut self, ri: usize, rule: &Rule, body: &[Template]) -> usize {
        if let Some(p) = self.rule_trees.iter().position(|(i, _)| *i == ri) {
            return p;
        }
        let input = self.input;
        let id = rule_id(rule, &self.taken);
        self.taken.insert(id.clone());
        let (no_bindings, no_captures) = (Bindings::new(), Captures::new());
        let mut inst = Inst::new(input.decls, &no_bindings, &no_captures, true);
        let mut nodes = inst.templates(body, &|_| Vec::new());
        let root = if nodes.len() == 1 {
            nodes.remove(0)
        } else {
            Node::sequence(nodes)
        };
        self.used_nodes.extend(inst.used_nodes);
        self.rule_trees.push((
            ri,
            RuleTree {
                shared_id: id.as_str().into(),
                id,
                params: inst.params.unwrap_or_default(),
                typed: typed_ports(&root, input),
                counts: inst.counts,
                root,
            },
        ));
        self.rule_trees.len() - 1
    }
}

/// R_NO_RULE for step `k` (`g`), which no rule matches, with what the
/// rules that name its action rule out.
fn no_rule(input: &LowerInput, k: usize, g: &GroundStep, logic: &StepLogic) -> Diagnostic {
    let step = &input.plan.steps[g.step];
    let action = &input.domain.actions[g.action];
    let named: Vec<&&Rule> = input
        .rules
        .iter()
        .filter(|r| match_name(&r.pattern.name, &action.name.name).is_some())
        .collect();
    let hint = if named.is_empty() {
        format!(
            "add a rule for it: `rule ({} {}) {{ ... }}`",
            action.name.name,
            action
                .params
                .iter()
                .map(|p| format!("?{}", p.name.name))
                .collect::<Vec<_>>()
                .join(" ")
        )
    } else {
        match named.len() {
                    1 => format!("the rule for `{}` does not fit this step: its parameter count or `where` guard rules it out", action.name.name),
                    n => format!("{n} rules for `{}` exist, but their parameter counts or `where` guards rule this step out", action.name.name),
                }
    };
    Diagnostic::error(
        codes::R_NO_RULE,
        step.span,
        format!("step {} `{}`: no rule matches it", k + 1, logic.display()),
    )
    .with_hint(hint)
}

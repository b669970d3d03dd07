//! Lowering: rules + a typed plan -> [`TreeIr`]. Each step is matched
//! against the rules (first match in file order), the rule's template
//! becomes a parametric tree called with the step's bindings, KB effects
//! and conditions are attached, and the `plan { ... }` template arranges the
//! steps (`steps`, `steps backchained`, `steps parallel`, `steps scheduled`).

use crate::rules::ast::*;
use crate::rules::check::Decls;
use crate::rules::matching::{match_args, match_name, Bindings, Captures, ObjectTypes};
use crate::rules::name::{capture_value, Key};
use btc_ir::format_float;
use btc_ir::*;
use btc_pddl::ast::{Domain, Problem};
use btc_pddl::check::{DomainIndex, ProblemIndex};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::logic::{self, Formula, Name};
use btc_pddl::plan::{GroundStep, Plan};
use btc_pddl::world::WorldModel;
use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;

mod action;
mod arrange;
mod backchain;
mod inst;
mod steps;

use action::{Grounder, RuleEffect};
use arrange::kb_holds;
use inst::Inst;
use rustc_hash::FxHashMap;
use steps::Steps;

pub struct LowerInput<'a> {
    pub decls: &'a Decls,
    /// Rules in match order (the file's own first, then imported ones).
    pub rules: Vec<&'a Rule>,
    pub plan_template: Option<&'a [Template]>,
    pub domain: &'a Domain,
    pub dix: &'a DomainIndex,
    pub problem: &'a Problem,
    pub pix: &'a ProblemIndex,
    pub plan: &'a Plan,
    pub steps: &'a [GroundStep],
    pub domain_path: String,
    pub problem_path: String,
    pub plan_path: String,
    pub rules_path: String,
}

struct Types<'a> {
    dix: &'a DomainIndex,
    pix: &'a ProblemIndex,
}

impl ObjectTypes for Types<'_> {
    fn object_is(&self, object: &str, ty: &str) -> bool {
        match (self.pix.objects.get(object), self.dix.types.id(ty)) {
            (Some(o), Some(t)) => self.dix.types.fits(&o.types, &[t]),
            _ => false,
        }
    }
}

/// A rule's template made parametric: its tree and, per parameter, the
/// value expression a call evaluates.
struct RuleTree {
    id: String,
    /// The id as the steps that call the tree hold it (one for all).
    shared_id: Arc<str>,
    params: Vec<(String, Value)>,
    root: Node,
    typed: Vec<TypedPort>,
    /// Parameters that are decorator counts, with their ranges.
    counts: Vec<(String, DecoratorName, DecoratorParam)>,
}

/// A BT.CPP-safe id for a rule: `rule_PICK_op`.
fn rule_id(r: &Rule, taken: &BTreeSet<String>) -> String {
    let base: String = format!("rule_{}", r.pattern.name_text())
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect::<String>()
        .replace("__", "_")
        .trim_end_matches('_')
        .to_owned();
    let mut id = base.clone();
    let mut n = 2;
    while taken.contains(&id) {
        id = format!("{base}_{n}");
        n += 1;
    }
    id
}

/// Lowers a plan; every problem is reported at the plan line of its step.
pub fn lower(input: &LowerInput) -> Result<TreeIr, Vec<Diagnostic>> {
    let mut steps = Steps::new(input);
    for (k, g) in input.steps.iter().enumerate() {
        steps.step(k, g);
    }
    if !steps.diags.is_empty() {
        return Err(steps.diags);
    }
    let Steps {
        mut infos,
        step_nodes,
        rule_trees,
        mut used_nodes,
        ..
    } = steps;
    let root = arrange_plan(input, &mut infos, step_nodes, &mut used_nodes)?;
    Ok(assemble(input, root, rule_trees, used_nodes, infos))
}

/// The plan's tree: the `plan { ... }` template with the step nodes
/// arranged where it says `steps` (in order, backchained, parallel or
/// scheduled), or
/// the steps in order without one.
fn arrange_plan(
    input: &LowerInput,
    infos: &mut [StepInfo],
    step_nodes: Vec<Option<Node>>,
    used_nodes: &mut BTreeSet<String>,
) -> Result<Node, Vec<Diagnostic>> {
    // Parallel mode needs the partial order.
    let template = input.plan_template;
    let uses_parallel = template.is_some_and(|t| uses_mode(t, StepsMode::Parallel));
    if uses_parallel {
        arrange::order_steps(infos);
    } else if template.is_some_and(|t| uses_mode(t, StepsMode::Scheduled)) {
        let unstated = unstated_durations(input, infos);
        if !unstated.is_empty() {
            return Err(unstated);
        }
        arrange::schedule_steps(infos, btc_pddl::validate::DEFAULT_EPSILON);
    }
    // The plan template holds `steps` once (R022): the step nodes move into
    // it instead of being copied.
    let step_nodes = std::cell::RefCell::new(step_nodes);
    let arrange_diags = std::cell::RefCell::new(Vec::new());
    let goal = input.problem.goal.as_ref().map(Formula::from_ast);
    let derived = backchain::derived_predicates(input.domain);
    let arranged = |mode: StepsMode| -> Vec<Node> {
        let nodes = std::mem::take(&mut *step_nodes.borrow_mut());
        match mode {
            StepsMode::InOrder => {
                // Collected in place (a `Node` is as wide as an
                // `Option<Node>`): `flatten` would copy every step's node
                // into a second, growing buffer.
                let mut nodes = nodes;
                nodes.retain(Option::is_some);
                nodes.into_iter().map(Option::unwrap).collect()
            }
            StepsMode::Backchained => {
                match backchain::stages(nodes, infos, goal.as_ref(), &derived) {
                    Ok(stages) => stages,
                    Err(e) => {
                        arrange_diags
                            .borrow_mut()
                            .push(backchain_diagnostic(e, input));
                        Vec::new()
                    }
                }
            }
            StepsMode::Parallel | StepsMode::Scheduled => vec![arrange::parallel(&nodes, infos)],
        }
    };
    let root = match template {
        Some(t) => {
            let (no_bindings, no_captures) = (Bindings::new(), Captures::new());
            let mut inst = Inst::new(input.decls, &no_bindings, &no_captures, false);
            let mut nodes = inst.templates(t, &arranged);
            used_nodes.extend(inst.used_nodes);
            if nodes.len() == 1 {
                nodes.remove(0)
            } else {
                Node::sequence(nodes)
            }
        }
        None => Node::sequence(arranged(StepsMode::InOrder)),
    };
    let arrange_diags = arrange_diags.into_inner();
    if !arrange_diags.is_empty() {
        return Err(arrange_diags);
    }
    Ok(root)
}

/// The IR: the plan's tree, the rules' trees, the node models of what the
/// trees use (KB leaves included), the steps and the world.
fn assemble(
    input: &LowerInput,
    root: Node,
    rule_trees: Vec<(usize, RuleTree)>,
    mut used_nodes: BTreeSet<String>,
    infos: Vec<StepInfo>,
) -> TreeIr {
    let mut used_kb = BTreeSet::new();
    root.walk_distinct(&mut |n| {
        if let Node::Leaf { id, .. } = n {
            used_kb.insert(id.clone());
        }
    });
    for (_, rt) in &rule_trees {
        rt.root.walk(&mut |n| {
            if let Node::Leaf { id, .. } = n {
                used_kb.insert(id.clone());
            }
        });
    }
    let trees: Vec<TreeDef> = rule_trees
        .into_iter()
        .map(|(_, rt)| TreeDef {
            id: rt.id,
            params: rt.params.into_iter().map(|(n, _)| n).collect(),
            root: rt.root,
        })
        .collect();
    used_nodes.extend(used_kb);
    let nodes = node_models(input.decls, &used_nodes);
    let mut ir = TreeIr {
        version: IR_VERSION,
        domain: input.domain_path.clone(),
        problem: input.problem_path.clone(),
        plan: input.plan_path.clone(),
        rules: input.rules_path.clone(),
        main_tree: "MainTree".into(),
        root,
        trees,
        nodes,
        steps: infos,
        world: WorldModel::from_checked(input.domain, input.dix, input.problem, input.pix),
    };
    let expand = ir.trees_timed_by_port();
    ir.expand_calls(&expand);
    ir
}

/// `steps backchained` on a plan it cannot regress the goal through, at the
/// step's plan line.
fn backchain_diagnostic(e: backchain::Breaks, input: &LowerInput) -> Diagnostic {
    let span = input.plan.steps[input.steps[e.step].step].span;
    Diagnostic::error(
        codes::R_BACKCHAIN,
        span,
        format!(
            "step {} makes `{}` false, which the goal or a later step needs: `steps backchained` cannot regress the goal through it",
            e.step + 1,
            e.what
        ),
    )
    .with_hint("the plan does not reach its goal from this step on; plan again, or use `steps` to run it as written")
}

/// `steps scheduled` on a timed plan needs each durative step's end, so
/// its stated duration (R035 at each step without one): the domain's
/// `:duration` may depend on the state, and guessing it would schedule
/// the plan differently from the planner that wrote it.
fn unstated_durations(input: &LowerInput, infos: &[StepInfo]) -> Vec<Diagnostic> {
    if infos.iter().any(|s| s.time.is_none()) {
        return Vec::new();
    }
    input
        .steps
        .iter()
        .zip(infos)
        .filter(|(g, s)| {
            !s.skipped && s.duration.is_none() && input.domain.actions[g.action].durative
        })
        .map(|(g, s)| {
            let span = input.plan.steps[g.step].span;
            Diagnostic::error(
                codes::R_SCHEDULE_DURATION,
                span,
                format!(
                    "step {} (`{}`) is durative and states no duration: `steps scheduled` cannot tell when it ends",
                    s.index + 1,
                    s.logic.action
                ),
            )
            .with_hint("write the step's duration after it, as temporal planners do (`0.000: (move r1 a b) [5.000]`)")
        })
        .collect()
}

fn uses_mode(ts: &[Template], mode: StepsMode) -> bool {
    let mut uses = false;
    Template::walk_all(ts, &mut |t| {
        uses |= matches!(t, Template::Steps { mode: m, .. } if *m == mode);
    });
    uses
}

/// A leaf port of a rule tree whose declared type is a PDDL type, with the
/// value bound to it (a parameter or a constant).
struct TypedPort {
    port: String,
    node: String,
    ty: String,
    value: PortValue,
}

/// The PDDL-typed ports of a rule tree, found once per rule.
fn typed_ports(root: &Node, input: &LowerInput) -> Vec<TypedPort> {
    let mut out = Vec::new();
    root.walk(&mut |n| {
        let Node::Leaf { id, ports, .. } = n else {
            return;
        };
        let Some(decl) = input.decls.nodes.get(id) else {
            return;
        };
        for p in ports {
            let Some(pd) = decl.ports.iter().find(|d| d.name.text == p.name) else {
                continue;
            };
            let ty = pd.ty.key.clone().into_string();
            if crate::rules::check::BASIC_TYPES.contains(&ty.as_str())
                || input.dix.types.id(&ty).is_none()
            {
                continue;
            }
            out.push(TypedPort {
                port: p.name.clone(),
                node: id.clone(),
                ty,
                value: p.value.clone(),
            });
        }
    });
    out
}

/// Reports objects bound to PDDL-typed ports that do not fit the port's type.
fn check_port_types(
    typed: &[TypedPort],
    call: &[Port],
    input: &LowerInput,
    types: &Types,
    report: &mut dyn FnMut(&str, &str, &str, &str),
) {
    for t in typed {
        let value = match &t.value {
            PortValue::Param(name) => call.iter().find(|c| c.name == *name).map(|c| &c.value),
            other => Some(other),
        };
        if let Some(PortValue::Text(obj)) = value {
            if input.pix.objects.contains_key(obj) && !types.object_is(obj, &t.ty) {
                report(&t.port, &t.node, obj, &t.ty);
            }
        }
    }
}

fn node_models(decls: &Decls, used: &BTreeSet<String>) -> Vec<NodeModel> {
    used.iter()
        .filter_map(|id| {
            let n = decls.nodes.get(id).cloned().or_else(|| kb_decl(id))?;
            Some(node_model(id, &n))
        })
        .collect()
}

/// The IR's model of a declared node: its kind, ports and formula.
pub fn node_model(id: &str, n: &NodeDecl) -> NodeModel {
    NodeModel {
        id: id.to_owned(),
        kind: match n.kind {
            NodeKind::Action => LeafKind::Action,
            NodeKind::Condition => LeafKind::Condition,
        },
        ports: n
            .ports
            .iter()
            .map(|p| PortModel {
                name: p.name.text.clone(),
                direction: if p.out {
                    PortDirection::Output
                } else {
                    PortDirection::Input
                },
                ty: p.ty.text.clone(),
            })
            .collect(),
        formula: n.formula.as_ref().map(Formula::from_ast),
    }
}

/// The `std::kb` declarations btc itself emits, available without import.
fn kb_decl(id: &str) -> Option<NodeDecl> {
    let parsed = crate::rules::parse_rules(include_str!("../stdlib/kb.btrules"), 0);
    parsed
        .items
        .into_iter()
        .find_map(|i| match std::sync::Arc::unwrap_or_clone(i.item) {
            Item::Node(n) if n.name.text == id => Some(n),
            _ => None,
        })
}

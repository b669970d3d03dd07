//! A PDDL action's conditions and effects, converted to logic once per
//! action and grounded per step by the fold.

use btc_pddl::ast::{Action, Domain};
use btc_pddl::logic::{ActionSchema, Binding, Effect, Formula, Name, Terms};
use rustc_hash::FxHashMap;
use std::sync::Arc;

/// An action's conditions and effects by when they apply, over its
/// parameters.
pub(super) struct ActionLogic {
    params: Vec<Name>,
    pre_start: Option<Formula>,
    pre_over_all: Option<Formula>,
    pre_end: Option<Formula>,
    eff_start: Option<Effect>,
    eff_end: Option<Effect>,
}

/// A step's ground conditions and effects, shared by the steps that
/// repeat the same ground action.
#[derive(Clone)]
pub(super) struct Ground {
    pub pre_start: Option<Arc<Formula>>,
    pub pre_over_all: Option<Arc<Formula>>,
    pub pre_end: Option<Arc<Formula>>,
    pub eff_start: Option<Arc<Effect>>,
    pub eff_end: Option<Arc<Effect>>,
}

/// Each action's logic, converted when a step first uses it, and each
/// ground action grounded once: a long plan repeats few ground actions
/// (the same moves between the same places), and its steps share them.
#[derive(Default)]
pub(super) struct Grounder {
    actions: FxHashMap<usize, (ActionLogic, ByObjects)>,
}

/// An action's ground forms, by the ids of their objects.
type ByObjects = FxHashMap<Box<[u32]>, Ground>;

impl Grounder {
    /// Action `action` of `domain` with the objects `args` (ids) whose
    /// names are `names`.
    pub fn ground(
        &mut self,
        domain: &Domain,
        action: usize,
        args: &[u32],
        names: &[Name],
    ) -> Ground {
        let (logic, grounded) = self.actions.entry(action).or_insert_with(|| {
            (
                ActionLogic::new(&domain.actions[action]),
                FxHashMap::default(),
            )
        });
        if let Some(g) = grounded.get(args) {
            return g.clone();
        }
        let objects: Vec<Name> = args.iter().map(|&o| names[o as usize].clone()).collect();
        let g = logic.ground(&objects);
        grounded.insert(Box::from(args), g.clone());
        g
    }
}

impl ActionLogic {
    pub fn new(a: &Action) -> ActionLogic {
        let s = ActionSchema::from_ast(a);
        ActionLogic {
            params: s.param_names(),
            pre_start: Formula::conjunction(s.pre_start),
            pre_over_all: Formula::conjunction(s.pre_over_all),
            pre_end: Formula::conjunction(s.pre_end),
            eff_start: Effect::conjunction(s.eff_start),
            eff_end: Effect::conjunction(s.eff_end),
        }
    }

    /// The step's conditions and effects with its objects for the
    /// parameters.
    pub fn ground(&self, objects: &[Name]) -> Ground {
        let b = Binding {
            params: &self.params,
            objects,
        };
        Ground {
            pre_start: self.pre_start.as_ref().map(|f| Arc::new(f.ground(&b))),
            pre_over_all: self.pre_over_all.as_ref().map(|f| Arc::new(f.ground(&b))),
            pre_end: self.pre_end.as_ref().map(|f| Arc::new(f.ground(&b))),
            eff_start: self.eff_start.as_ref().map(|e| Arc::new(e.ground(&b))),
            eff_end: self.eff_end.as_ref().map(|e| Arc::new(e.ground(&b))),
        }
    }
}

/// A rule's `effect`, in the rule's variables, converted once per rule.
pub(super) struct RuleEffect {
    effect: Effect,
}

impl RuleEffect {
    pub fn new(e: &btc_pddl::ast::Effect) -> RuleEffect {
        RuleEffect {
            effect: Effect::from_ast(e),
        }
    }

    /// The effect with the step's objects for the rule's variables (`None`
    /// when it changes nothing); `Err` names a variable the step leaves
    /// unbound (an optional parameter it does not give).
    pub fn ground(
        &self,
        bindings: &crate::rules::matching::Bindings,
    ) -> Result<Option<Effect>, Name> {
        let params: Vec<Name> = bindings
            .iter()
            .map(|(v, _)| btc_pddl::logic::name(v))
            .collect();
        let objects: Vec<Name> = bindings
            .iter()
            .map(|(_, o)| btc_pddl::logic::name(o))
            .collect();
        let e = self.effect.ground(&Binding {
            params: &params,
            objects: &objects,
        });
        if let Some(v) = e.free_vars().into_iter().next() {
            return Err(v);
        }
        Ok(Effect::conjunction(vec![e]))
    }
}

//! A PDDL action's conditions and effects, converted to logic once per
//! action and grounded per step by the fold.

use btc_pddl::ast::Action;
use btc_pddl::logic::{ActionSchema, Binding, Effect, Formula, Name, Terms};

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

/// A step's ground conditions and effects.
pub(super) struct Ground {
    pub pre_start: Option<Formula>,
    pub pre_over_all: Option<Formula>,
    pub pre_end: Option<Formula>,
    pub eff_start: Option<Effect>,
    pub eff_end: Option<Effect>,
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
            pre_start: self.pre_start.as_ref().map(|f| f.ground(&b)),
            pre_over_all: self.pre_over_all.as_ref().map(|f| f.ground(&b)),
            pre_end: self.pre_end.as_ref().map(|f| f.ground(&b)),
            eff_start: self.eff_start.as_ref().map(|e| e.ground(&b)),
            eff_end: self.eff_end.as_ref().map(|e| e.ground(&b)),
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

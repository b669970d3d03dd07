//! The simulated world's knowledge base: a PDDL state (from the world's
//! initial facts) with the formulas and effects the tree refers to,
//! compiled once. The semantics are `btc_pddl::state`'s, the validator's.

use btc_pddl::logic::{Atom, Effect, Formula, Name};
use btc_pddl::state::{Changes, Cond, Eff, Key, State, World};
use rustc_hash::FxHashMap;

/// Index of a compiled formula or effect in a [`Kb`].
pub type FormulaId = u32;
pub type EffectId = u32;
/// Index of a condition compiled over port slots ([`Kb::condition`]).
pub type ConditionId = u32;

pub struct Kb<'w> {
    pub world: &'w World,
    pub state: State,
    formulas: Vec<Registered>,
    effects: Vec<Eff>,
    conditions: Vec<Cond>,
    /// Formulas and effects by their text, so each is compiled once.
    formula_ids: FxHashMap<String, FormulaId>,
    effect_ids: FxHashMap<String, EffectId>,
    /// Goals added while running (a high-priority order).
    extra_goals: Vec<FormulaId>,
    /// A goal that replaces the problem's (replanning adjusts the goal).
    goal_override: Option<FormulaId>,
}

/// A ground formula as written and as compiled; for one that is a ground
/// literal (or a conjunction of them), its atom keys, so checking it
/// allocates nothing.
struct Registered {
    formula: Formula,
    cond: Cond,
    literals: Option<Vec<Literal>>,
}

struct Literal {
    key: Key,
    positive: bool,
    derived: bool,
}

impl<'w> Kb<'w> {
    /// The KB of a world: its initial state, derived atoms included.
    pub fn new(world: &'w World) -> Kb<'w> {
        Kb {
            world,
            state: world.initial_state(),
            formulas: Vec::new(),
            effects: Vec::new(),
            conditions: Vec::new(),
            formula_ids: FxHashMap::default(),
            effect_ids: FxHashMap::default(),
            extra_goals: Vec::new(),
            goal_override: None,
        }
    }

    /// A registered formula, as written.
    pub fn formula_of(&self, f: FormulaId) -> &Formula {
        &self.formulas[f as usize].formula
    }

    /// The goals added while running, in the order added.
    pub fn extra_goals(&self) -> Vec<Formula> {
        self.extra_goals
            .iter()
            .map(|&f| self.formula_of(f).clone())
            .collect()
    }

    /// The goals added while running that do not hold.
    pub fn unmet_extra_goals(&self) -> Vec<Formula> {
        self.extra_goals
            .iter()
            .filter(|&&f| !self.holds(f))
            .map(|&f| self.formula_of(f).clone())
            .collect()
    }

    /// Makes `f` the goal instead of the problem's (added goals still count).
    pub fn set_goal(&mut self, f: FormulaId) {
        self.goal_override = Some(f);
    }

    /// Compiles a ground condition, e.g. `(on p bin1)`, against the world.
    pub fn formula(&mut self, f: &Formula) -> Result<FormulaId, String> {
        let text = f.to_string();
        if let Some(&id) = self.formula_ids.get(&text) {
            return Ok(id);
        }
        let cond = self.world.compile(f, &[])?;
        let id = self.formulas.len() as FormulaId;
        let mut lits = Vec::new();
        let literals = self.literals_of(&cond, true, &mut lits).then_some(lits);
        self.formulas.push(Registered {
            formula: f.clone(),
            cond,
            literals,
        });
        self.formula_ids.insert(text, id);
        Ok(id)
    }

    /// Compiles a ground effect, e.g. `(and (a) (not (b)))`.
    pub fn effect(&mut self, e: &Effect) -> Result<EffectId, String> {
        let text = e.to_string();
        if let Some(&id) = self.effect_ids.get(&text) {
            return Ok(id);
        }
        let eff = self.world.compile_effect(e, &[])?;
        let id = self.effects.len() as EffectId;
        self.effects.push(eff);
        self.effect_ids.insert(text, id);
        Ok(id)
    }

    /// Compiles a condition over port variables: at tick time it is
    /// evaluated with the ports' objects in `ports`' order
    /// ([`Kb::holds_with`]).
    pub fn condition(&mut self, f: &Formula, ports: &[Name]) -> Result<ConditionId, String> {
        let c = self.world.compile(f, ports)?;
        self.conditions.push(c);
        Ok(self.conditions.len() as ConditionId - 1)
    }

    pub fn holds(&self, f: FormulaId) -> bool {
        let r = &self.formulas[f as usize];
        if let Some(lits) = &r.literals {
            return lits.iter().all(|l| {
                let set = if l.derived {
                    &self.state.derived
                } else {
                    &self.state.facts
                };
                set.contains(&l.key) == l.positive
            });
        }
        self.world
            .holds(&self.state, &r.cond, &mut Vec::new(), None)
    }

    /// Whether condition `c` holds with its ports bound to `objects`.
    pub fn holds_with(&self, c: ConditionId, objects: &[u32]) -> bool {
        let mut b = objects.to_vec();
        self.world
            .holds(&self.state, &self.conditions[c as usize], &mut b, None)
    }

    /// Why condition `c` does not hold with its ports bound to `objects`.
    pub fn why_not_with(&self, c: ConditionId, objects: &[u32]) -> String {
        let mut b = objects.to_vec();
        self.world
            .why_not(&self.state, &self.conditions[c as usize], &mut b, None)
            .0
    }

    /// Collects `c` as ground literals; false when it is anything else.
    fn literals_of(&self, c: &Cond, positive: bool, out: &mut Vec<Literal>) -> bool {
        match c {
            Cond::Atom {
                pred,
                derived,
                args,
            } => {
                let mut key = Vec::with_capacity(args.len() + 1);
                key.push(*pred);
                for a in args.iter() {
                    match a {
                        btc_pddl::state::CTerm::Obj(o) => key.push(*o),
                        btc_pddl::state::CTerm::Slot(_) => return false,
                    }
                }
                out.push(Literal {
                    key: key.into_boxed_slice(),
                    positive,
                    derived: *derived,
                });
                true
            }
            Cond::Not(x) if positive => self.literals_of(x, false, out),
            Cond::And(ps) if positive => ps.iter().all(|p| self.literals_of(p, true, out)),
            _ => false,
        }
    }

    /// Why `f` does not hold, in the user's terms.
    pub fn why_not(&self, f: FormulaId) -> String {
        self.world
            .why_not(
                &self.state,
                &self.formulas[f as usize].cond,
                &mut Vec::new(),
                None,
            )
            .0
    }

    /// The changes an effect would make now.
    pub fn changes(&self, e: EffectId) -> Changes {
        let mut c = Changes::default();
        self.world.collect(
            &self.state,
            &self.effects[e as usize],
            &mut Vec::new(),
            None,
            &mut c,
        );
        c
    }

    pub fn apply(&mut self, e: EffectId) {
        let c = self.changes(e);
        self.world.apply(&mut self.state, c);
    }

    /// Applies changes given as atom keys (faults use this).
    pub fn apply_keys(&mut self, add: Vec<Key>, delete: Vec<Key>) {
        self.world.apply(
            &mut self.state,
            Changes {
                add,
                delete,
                ..Changes::default()
            },
        );
    }

    /// The key of a ground atom, e.g. `(is_enabled r1)`.
    pub fn atom_key(&self, a: &Atom) -> Result<Key, String> {
        let k = self.world.atom_key(a)?;
        if self.world.is_derived(k[0]) {
            return Err(format!(
                "`{}` is a derived predicate: only the facts it is derived from change",
                a.pred
            ));
        }
        Ok(k)
    }

    pub fn object(&self, name: &str) -> Option<u32> {
        self.world.object_id(name)
    }

    /// Every fact that mentions object `o`.
    pub fn facts_mentioning(&self, o: u32) -> Vec<Key> {
        let mut v: Vec<Key> = self
            .state
            .facts
            .iter()
            .filter(|k| k[1..].contains(&o))
            .cloned()
            .collect();
        v.sort();
        v
    }

    pub fn show(&self, k: &[u32]) -> String {
        self.world.show_atom(k)
    }

    /// True facts and fluent values, sorted: a snapshot for fault records.
    pub fn snapshot(&self) -> Vec<String> {
        let mut v: Vec<String> = self
            .state
            .facts
            .iter()
            .map(|k| self.world.show_atom(k))
            .collect();
        v.extend(self.state.fluents.iter().map(|(k, x)| {
            format!(
                "(= {} {})",
                self.world.show_fluent(k),
                btc_ir::format_float(*x)
            )
        }));
        v.sort();
        v
    }

    pub fn add_goal(&mut self, f: FormulaId) {
        if !self.extra_goals.contains(&f) {
            self.extra_goals.push(f);
        }
    }

    /// Whether the problem's goal (and every added goal) holds; with the
    /// first part that does not.
    pub fn goal(&self) -> (bool, Option<String>) {
        if let Some(g) = self.goal_override {
            if !self.holds(g) {
                return (false, Some(self.why_not(g)));
            }
        } else if let Some(g) = self.world.goal() {
            let mut b = Vec::new();
            if !self.world.holds(&self.state, g, &mut b, None) {
                let (why, _) = self.world.why_not(&self.state, g, &mut b, None);
                return (false, Some(why));
            }
        }
        for &f in &self.extra_goals {
            if !self.holds(f) {
                return (false, Some(self.why_not(f)));
            }
        }
        (true, None)
    }

    /// Whether the world has a goal at all (its own or one set or added).
    pub fn has_goal(&self) -> bool {
        self.goal_override.is_some() || self.world.goal().is_some() || !self.extra_goals.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use btc_pddl::logic::decode;
    use btc_pddl::pipeline;

    fn world() -> World {
        let du = pipeline::domain_unit_from(include_str!("../tests/fixtures/flags/domain.pddl"), 0);
        let pu = pipeline::problem_unit_from(
            include_str!("../tests/fixtures/flags/problem.pddl"),
            1,
            du.domain.as_ref(),
            &du.index,
        );
        World::of_checked(
            du.domain.as_ref().unwrap(),
            &du.index,
            pu.problem.as_ref().unwrap(),
            &pu.index,
        )
        .unwrap()
    }

    #[test]
    fn ground_literals_take_the_fast_path_with_the_same_answers() {
        let w = world();
        let mut kb = Kb::new(&w);
        for (text, fast, expect) in [
            ("(at r1 bin1)", true, true),
            ("(and (at r1 bin1) (not (go)))", true, true),
            ("(and (at r1 bin2) (not (go)))", true, false),
            ("(or (go) (at r1 bin1))", false, true),
            ("(not (and (go) (done)))", false, true),
        ] {
            let f = kb.formula(&decode::formula(text).unwrap()).unwrap();
            assert_eq!(kb.formulas[f as usize].literals.is_some(), fast, "{text}");
            assert_eq!(kb.holds(f), expect, "{text}");
            let slow = kb.world.holds(
                &kb.state,
                &kb.formulas[f as usize].cond,
                &mut Vec::new(),
                None,
            );
            assert_eq!(slow, expect, "{text}");
        }
    }

    #[test]
    fn conditions_over_ports_are_evaluated_with_their_objects() {
        let w = world();
        let mut kb = Kb::new(&w);
        let ports = [btc_pddl::logic::name("r"), btc_pddl::logic::name("b")];
        let c = kb
            .condition(&decode::formula("(at ?r ?b)").unwrap(), &ports)
            .unwrap();
        let (r1, bin1, bin2) = (
            kb.object("r1").unwrap(),
            kb.object("bin1").unwrap(),
            kb.object("bin2").unwrap(),
        );
        assert!(kb.holds_with(c, &[r1, bin1]));
        assert!(!kb.holds_with(c, &[r1, bin2]));
        assert_eq!(kb.why_not_with(c, &[r1, bin2]), "`(at r1 bin2)` is false");
    }
}

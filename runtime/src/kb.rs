//! The simulated world's knowledge base: a PDDL state (from the problem's
//! `:init`) with the formulas and effects the tree refers to, parsed once.
//! The semantics are `btc_pddl::state`'s, the validator's.

use btc_pddl::ast::{Domain, Effect, Formula, Problem};
use btc_pddl::state::{Changes, Env, Key, State, World};
use btc_pddl::{lexer, parse, sexpr, DomainIndex, ProblemIndex};
use rustc_hash::FxHashMap;

/// Index of a parsed formula or effect in a [`Kb`].
pub type FormulaId = u32;
pub type EffectId = u32;

pub struct Kb<'w> {
    pub world: World<'w>,
    pub state: State,
    problem: &'w Problem,
    formulas: Vec<Formula>,
    /// For formulas that are ground literals (or a conjunction of them):
    /// the atom keys, so checking them allocates nothing.
    literals: Vec<Option<Vec<Literal>>>,
    effects: Vec<Effect>,
    formula_ids: FxHashMap<String, FormulaId>,
    effect_ids: FxHashMap<String, EffectId>,
    /// Goals added while running (a high-priority order).
    extra_goals: Vec<FormulaId>,
    /// A goal that replaces the problem's (replanning adjusts the goal).
    goal_override: Option<FormulaId>,
}

impl<'w> Kb<'w> {
    /// The KB of a problem: its initial state, derived atoms included.
    pub fn new(
        domain: &'w Domain,
        dix: &'w DomainIndex,
        problem: &'w Problem,
        pix: &'w ProblemIndex,
    ) -> Kb<'w> {
        let world = World::new(domain, dix, pix);
        let state = world.initial_state(problem);
        Kb {
            world,
            state,
            problem,
            formulas: Vec::new(),
            literals: Vec::new(),
            effects: Vec::new(),
            formula_ids: FxHashMap::default(),
            effect_ids: FxHashMap::default(),
            extra_goals: Vec::new(),
            goal_override: None,
        }
    }

    /// The problem the KB was made from.
    pub fn problem(&self) -> &'w Problem {
        self.problem
    }

    /// A parsed formula (from [`Kb::formula`]).
    pub fn formula_ast(&self, f: FormulaId) -> &Formula {
        &self.formulas[f as usize]
    }

    /// The text of a formula registered with [`Kb::formula`].
    pub fn formula_text(&self, f: FormulaId) -> Option<&str> {
        self.formula_ids
            .iter()
            .find(|(_, &id)| id == f)
            .map(|(t, _)| t.as_str())
    }

    /// The goals added while running, as their texts, in the order added.
    pub fn extra_goal_texts(&self) -> Vec<String> {
        self.extra_goals
            .iter()
            .filter_map(|&f| self.formula_text(f).map(str::to_owned))
            .collect()
    }

    /// The goals added while running that do not hold, as their texts.
    pub fn unmet_extra_goals(&self) -> Vec<String> {
        self.extra_goals
            .iter()
            .filter(|&&f| !self.holds(f))
            .filter_map(|&f| self.formula_text(f).map(str::to_owned))
            .collect()
    }

    /// Makes `f` the goal instead of the problem's (added goals still count).
    pub fn set_goal(&mut self, f: FormulaId) {
        self.goal_override = Some(f);
    }

    fn sexp(text: &str) -> Result<sexpr::Sexp, String> {
        let (tokens, diags) = lexer::lex(text, 0);
        if let Some(d) = diags.first() {
            return Err(d.message.clone());
        }
        let (mut forest, diags) = sexpr::build(tokens);
        if let Some(d) = diags.first() {
            return Err(d.message.clone());
        }
        if forest.len() != 1 {
            return Err(format!(
                "expected one parenthesised PDDL expression, found {}",
                forest.len()
            ));
        }
        Ok(forest.remove(0))
    }

    /// Parses and checks a ground PDDL condition, e.g. `(on p bin1)`.
    pub fn formula(&mut self, text: &str) -> Result<FormulaId, String> {
        if let Some(&id) = self.formula_ids.get(text) {
            return Ok(id);
        }
        let s = Self::sexp(text)?;
        let (f, diags) = parse::formula_of(&s);
        if let Some(d) = diags.first() {
            return Err(d.message.clone());
        }
        let f = f.ok_or_else(|| "not a PDDL condition".to_owned())?;
        let diags = btc_pddl::check::check_formula_in(
            self.world.domain,
            self.world.dix,
            Some(self.world.pix),
            &f,
            &[],
        );
        if let Some(d) = diags.iter().find(|d| d.is_error()) {
            return Err(d.message.clone());
        }
        let id = self.formulas.len() as FormulaId;
        let mut lits = Vec::new();
        let lits = self.literals_of(&f, true, &mut lits).then_some(lits);
        self.literals.push(lits);
        self.formulas.push(f);
        self.formula_ids.insert(text.to_owned(), id);
        Ok(id)
    }

    /// Parses and checks a ground PDDL effect, e.g. `(and (a) (not (b)))`.
    pub fn effect(&mut self, text: &str) -> Result<EffectId, String> {
        if let Some(&id) = self.effect_ids.get(text) {
            return Ok(id);
        }
        let s = Self::sexp(text)?;
        let (e, diags) = parse::effect_of(&s);
        if let Some(d) = diags.first() {
            return Err(d.message.clone());
        }
        let e = e.ok_or_else(|| "not a PDDL effect".to_owned())?;
        let diags = btc_pddl::check::check_effect_in(
            self.world.domain,
            self.world.dix,
            Some(self.world.pix),
            &e,
            &[],
        );
        if let Some(d) = diags.iter().find(|d| d.is_error()) {
            return Err(d.message.clone());
        }
        let id = self.effects.len() as EffectId;
        self.effects.push(e);
        self.effect_ids.insert(text.to_owned(), id);
        Ok(id)
    }

    pub fn holds(&self, f: FormulaId) -> bool {
        if let Some(lits) = &self.literals[f as usize] {
            return lits.iter().all(|l| {
                let set = if l.derived {
                    &self.state.derived
                } else {
                    &self.state.facts
                };
                set.contains(&l.key) == l.positive
            });
        }
        self.world.holds(
            &self.state,
            &self.formulas[f as usize],
            &mut Env::new(),
            None,
        )
    }

    /// Collects `f` as ground literals; false when it is anything else.
    fn literals_of(&self, f: &Formula, positive: bool, out: &mut Vec<Literal>) -> bool {
        match f {
            Formula::Atom { atom } => {
                let Some(sig) = self.world.dix.predicates.get(atom.pred.as_str()) else {
                    return false;
                };
                let Some(key) = self.world.atom_key(atom, &Env::new()) else {
                    return false;
                };
                out.push(Literal {
                    key,
                    positive,
                    derived: self.world.is_derived(sig.index as u32),
                });
                true
            }
            Formula::Not { formula, .. } if positive => self.literals_of(formula, false, out),
            Formula::And { parts, .. } if positive => {
                parts.iter().all(|p| self.literals_of(p, true, out))
            }
            _ => false,
        }
    }

    /// Why `f` does not hold, in the user's terms.
    pub fn why_not(&self, f: FormulaId) -> String {
        let (why, _) = self.world.why_not(
            &self.state,
            &self.formulas[f as usize],
            &mut Env::new(),
            None,
        );
        why
    }

    /// The changes an effect would make now.
    pub fn changes(&self, e: EffectId) -> Changes {
        let mut c = Changes::default();
        self.world.collect_effect(
            &self.state,
            &self.effects[e as usize],
            &mut Env::new(),
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

    /// The key of a ground atom written as text, e.g. `(is_enabled r1)`.
    pub fn atom_key(&mut self, text: &str) -> Result<Key, String> {
        let e = self.effect(text)?;
        let c = self.changes(e);
        match (c.add.as_slice(), c.delete.as_slice()) {
            ([k], []) => Ok(k.clone()),
            _ => Err(format!("`{text}` is not one positive ground atom")),
        }
    }

    pub fn object(&self, name: &str) -> Option<u32> {
        self.world.pix.objects.get(name).map(|o| o.id)
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
        } else if let Some(g) = &self.problem.goal {
            if !self.world.holds(&self.state, g, &mut Env::new(), None) {
                let (why, _) = self.world.why_not(&self.state, g, &mut Env::new(), None);
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
}

struct Literal {
    key: Key,
    positive: bool,
    derived: bool,
}

/// Fills `?var` occurrences in PDDL text from `value` (token-aware: `?a`
/// does not touch `?ab`); unknown variables stay.
pub fn substitute(text: &str, value: impl Fn(&str) -> Option<String>) -> String {
    let mut out = String::with_capacity(text.len() + 16);
    let mut rest = text;
    while let Some(q) = rest.find('?') {
        out.push_str(&rest[..q]);
        let after = &rest[q + 1..];
        let len = after
            .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == '-'))
            .unwrap_or(after.len());
        let var = &after[..len];
        match value(&var.to_lowercase()) {
            Some(v) if !var.is_empty() => out.push_str(&v),
            _ => {
                out.push('?');
                out.push_str(var);
            }
        }
        rest = &after[len..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use btc_pddl::pipeline;

    #[test]
    fn ground_literals_take_the_fast_path_with_the_same_answers() {
        let du = pipeline::domain_unit_from(include_str!("../tests/fixtures/flags/domain.pddl"), 0);
        let pu = pipeline::problem_unit_from(
            include_str!("../tests/fixtures/flags/problem.pddl"),
            1,
            du.domain.as_ref(),
            &du.index,
        );
        let mut kb = Kb::new(
            du.domain.as_ref().unwrap(),
            &du.index,
            pu.problem.as_ref().unwrap(),
            &pu.index,
        );
        for (text, fast, expect) in [
            ("(at r1 bin1)", true, true),
            ("(and (at r1 bin1) (not (go)))", true, true),
            ("(and (at r1 bin2) (not (go)))", true, false),
            ("(or (go) (at r1 bin1))", false, true),
            ("(not (and (go) (done)))", false, true),
        ] {
            let f = kb.formula(text).unwrap();
            assert_eq!(kb.literals[f as usize].is_some(), fast, "{text}");
            assert_eq!(kb.holds(f), expect, "{text}");
            let slow = kb
                .world
                .holds(&kb.state, &kb.formulas[f as usize], &mut Env::new(), None);
            assert_eq!(slow, expect, "{text}");
        }
    }

    #[test]
    fn substitution_is_token_aware() {
        let s = substitute("(and (at ?r ?rb) (ok ?r))", |v| {
            (v == "r").then(|| "robot1".to_owned())
        });
        assert_eq!(s, "(and (at robot1 ?rb) (ok robot1))");
    }
}

//! Grounding: a relaxed-reachability fixpoint finds the atoms and the action
//! (and derived-rule) instances that can ever matter, then each reachable
//! instance is instantiated, its formulas simplified against the static
//! facts, and turned into literal conjunctions. Disjunctions that remain
//! become auxiliary derived facts with one axiom per alternative.

use crate::lifted::*;
use crate::reach::{join_order, Part, Reach, Round, Step};
use crate::task::{Axiom, GroundEffect, Lit, Operator, Task};
use btc_pddl::ast::{Domain, Formula, NumOp};
use btc_pddl::check::{DomainIndex, ProblemIndex};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::source::Span;
use btc_pddl::state::State;
use rustc_hash::{FxHashMap, FxHashSet};
use std::cell::Cell;
use std::time::Instant;

mod formula;
mod joins;

use formula::{gand, gor, negate, regress, GF};
use joins::Joins;

/// What grounding found, for the statistics line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GroundStats {
    pub reachable_atoms: usize,
    pub operators: usize,
    pub axioms: usize,
    pub facts: usize,
}

struct Key {
    buf: [u32; MAX_ARITY + 1],
    len: usize,
}

impl Key {
    fn new(pred: u32, args: &[LTerm], env: &[u32]) -> Key {
        let mut k = Key {
            buf: [0; MAX_ARITY + 1],
            len: args.len().min(MAX_ARITY) + 1,
        };
        k.buf[0] = pred;
        for (i, a) in args.iter().take(MAX_ARITY).enumerate() {
            k.buf[i + 1] = match a {
                LTerm::Slot(s) => env[*s as usize],
                LTerm::Obj(o) => *o,
            };
        }
        k
    }
    fn get(&self) -> &[u32] {
        &self.buf[..self.len]
    }
}

fn val(t: LTerm, env: &[u32]) -> u32 {
    match t {
        LTerm::Slot(s) => env[s as usize],
        LTerm::Obj(o) => o,
    }
}

/// Calls `f` for each binding of `ranges` (written into `env`); stops at
/// the first `true`.
fn any_binding(ranges: &[Range], env: &mut [u32], f: &mut dyn FnMut(&mut [u32]) -> bool) -> bool {
    let Some(((slot, objs), rest)) = ranges.split_first() else {
        return f(env);
    };
    for &o in objs.iter() {
        env[*slot as usize] = o;
        if any_binding(rest, env, f) {
            return true;
        }
    }
    false
}

struct Grounder<'a> {
    /// Predicates some effect changes; others are static.
    fluent: Vec<bool>,
    derived: Vec<bool>,
    /// Reachable atoms (statics included).
    reach: Reach,
    facts: FxHashMap<Box<[u32]>, u32>,
    fact_keys: Vec<Box<[u32]>>,
    aux: FxHashMap<GF, u32>,
    axioms: Vec<Axiom>,
    state: &'a State,
    diags: Vec<Diagnostic>,
    deadline: Option<Instant>,
    ticks: Cell<u32>,
    timed_out: Cell<bool>,
}

impl Grounder<'_> {
    /// Whether the deadline has passed (the clock is read every 4096 calls).
    fn expired(&self) -> bool {
        if self.timed_out.get() {
            return true;
        }
        let t = self.ticks.get().wrapping_add(1);
        self.ticks.set(t);
        if t.is_multiple_of(4096) && self.deadline.is_some_and(|d| Instant::now() >= d) {
            self.timed_out.set(true);
        }
        self.timed_out.get()
    }

    fn is_static(&self, pred: u32) -> bool {
        !self.fluent[pred as usize] && !self.derived[pred as usize]
    }

    /// Whether `f` (with sign `pos`) may hold in some reachable state.
    fn relaxed(&self, f: &LF, env: &mut [u32], pos: bool) -> bool {
        match f {
            LF::Atom { pred, args } => {
                if pos {
                    self.reach.contains(Key::new(*pred, args, env).get())
                } else if self.is_static(*pred) {
                    !self.reach.contains(Key::new(*pred, args, env).get())
                } else {
                    true
                }
            }
            LF::Eq(a, b) => (val(*a, env) == val(*b, env)) == pos,
            LF::Not(g) => self.relaxed(g, env, !pos),
            LF::And(ps) if pos => ps.iter().all(|p| self.relaxed(p, env, true)),
            LF::And(ps) | LF::Or(ps) if !pos => {
                if matches!(f, LF::And(_)) {
                    ps.iter().any(|p| self.relaxed(p, env, false))
                } else {
                    ps.iter().all(|p| self.relaxed(p, env, false))
                }
            }
            LF::Or(ps) => ps.iter().any(|p| self.relaxed(p, env, true)),
            LF::And(_) => true,
            LF::Exists(r, b) | LF::Forall(r, b) => {
                let exists = matches!(f, LF::Exists(..));
                if exists == pos {
                    any_binding(r, env, &mut |env| self.relaxed(b, env, pos))
                } else {
                    !any_binding(r, env, &mut |env| !self.relaxed(b, env, pos))
                }
            }
        }
    }

    fn relaxed_adds(&self, e: &LE, env: &mut [u32], out: &mut Vec<Box<[u32]>>) {
        match e {
            LE::Add { pred, args } => {
                let k = Key::new(*pred, args, env);
                if !self.reach.contains(k.get()) {
                    out.push(k.get().into());
                }
            }
            LE::And(ps) => ps.iter().for_each(|p| self.relaxed_adds(p, env, out)),
            LE::Forall(r, b) => {
                any_binding(r, env, &mut |env| {
                    self.relaxed_adds(b, env, out);
                    false
                });
            }
            LE::When(c, b) => {
                if self.relaxed(c, env, true) {
                    self.relaxed_adds(b, env, out)
                }
            }
            LE::Del { .. } | LE::Cost(..) => {}
        }
    }

    // ---- instantiation ----

    fn fact(&mut self, k: &[u32]) -> u32 {
        if let Some(&f) = self.facts.get(k) {
            return f;
        }
        let f = self.fact_keys.len() as u32;
        self.fact_keys.push(k.into());
        self.facts.insert(k.into(), f);
        f
    }

    fn ground(&mut self, f: &LF, env: &mut [u32], pos: bool) -> GF {
        match f {
            LF::Atom { pred, args } => {
                let k = Key::new(*pred, args, env);
                if self.is_static(*pred) {
                    if self.reach.contains(k.get()) == pos {
                        GF::True
                    } else {
                        GF::False
                    }
                } else if let Some(&fact) = self.facts.get(k.get()) {
                    GF::Lit(Lit {
                        fact,
                        positive: pos,
                    })
                } else if pos {
                    GF::False
                } else {
                    GF::True
                }
            }
            LF::Eq(a, b) => {
                if (val(*a, env) == val(*b, env)) == pos {
                    GF::True
                } else {
                    GF::False
                }
            }
            LF::Not(g) => self.ground(g, env, !pos),
            LF::And(ps) | LF::Or(ps) => {
                let parts = ps.iter().map(|p| self.ground(p, env, pos)).collect();
                if matches!(f, LF::And(_)) == pos {
                    gand(parts)
                } else {
                    gor(parts)
                }
            }
            LF::Exists(r, b) | LF::Forall(r, b) => {
                let mut parts = Vec::new();
                any_binding(r, env, &mut |env| {
                    parts.push(self.ground(b, env, pos));
                    false
                });
                if matches!(f, LF::Forall(..)) == pos {
                    gand(parts)
                } else {
                    gor(parts)
                }
            }
        }
    }

    fn ground_effect(
        &mut self,
        e: &LE,
        env: &mut [u32],
        cond: &GF,
        out: &mut Vec<(GF, u32, bool)>,
    ) {
        match e {
            LE::Add { pred, args } => {
                let k = Key::new(*pred, args, env);
                let f = self.fact(k.get());
                out.push((cond.clone(), f, true));
            }
            LE::Del { pred, args } => {
                let k = Key::new(*pred, args, env);
                if let Some(&f) = self.facts.get(k.get()) {
                    out.push((cond.clone(), f, false));
                }
            }
            LE::And(ps) => {
                for p in ps {
                    self.ground_effect(p, env, cond, out)
                }
            }
            LE::Forall(r, b) => {
                any_binding(r, env, &mut |env| {
                    self.ground_effect(b, env, cond, out);
                    false
                });
            }
            LE::When(c, b) => {
                let g = self.ground(c, env, true);
                let c2 = gand(vec![cond.clone(), g]);
                if c2 != GF::False {
                    self.ground_effect(b, env, &c2, out)
                }
            }
            LE::Cost(..) => {}
        }
    }

    /// A conjunction of literals equivalent to `f`; `None` for false.
    fn conj(&mut self, f: GF) -> Option<Vec<Lit>> {
        let mut out = Vec::new();
        match f {
            GF::False => return None,
            GF::True => {}
            GF::Lit(l) => out.push(l),
            GF::And(ps) => {
                for p in ps {
                    out.extend(self.conj(p)?);
                }
            }
            GF::Or(_) => out.push(Lit::pos(self.aux(f))),
        }
        out.sort();
        out.dedup();
        if out
            .windows(2)
            .any(|w| w[0].fact == w[1].fact && w[0].positive != w[1].positive)
        {
            return None;
        }
        Some(out)
    }

    fn aux(&mut self, f: GF) -> u32 {
        if let Some(&a) = self.aux.get(&f) {
            return a;
        }
        let n = self.aux.len() as u32;
        let a = self.fact(&[u32::MAX, n]);
        self.aux.insert(f.clone(), a);
        self.axioms_for(a, f);
        a
    }

    fn axioms_for(&mut self, head: u32, f: GF) {
        match f {
            GF::Or(ps) => {
                for p in ps {
                    self.axioms_for(head, p)
                }
            }
            f => {
                if let Some(body) = self.conj(f) {
                    self.axioms.push(Axiom {
                        head,
                        body,
                        layer: 0,
                    })
                }
            }
        }
    }
}

fn has_when(e: &LE) -> bool {
    match e {
        LE::When(..) => true,
        LE::And(ps) => ps.iter().any(has_when),
        LE::Forall(_, b) => has_when(b),
        _ => false,
    }
}

/// Calls `leaf` for each completion of a join's bindings: parameters no
/// atom bound range over their type.
fn each_free(
    params: &[std::rc::Rc<[u32]>],
    env: &mut [Option<u32>],
    stop: &dyn Fn() -> bool,
    leaf: &mut dyn FnMut(&[u32]),
) {
    match env[..params.len()].iter().position(Option::is_none) {
        Some(s) => {
            for &o in params[s].iter() {
                if stop() {
                    break;
                }
                env[s] = Some(o);
                each_free(params, env, stop, leaf);
            }
            env[s] = None;
        }
        None => {
            let mut b = [0u32; MAX_PARAMS];
            let n = params.len().min(MAX_PARAMS);
            for (d, o) in b.iter_mut().zip(&env[..n]) {
                *d = o.unwrap_or(0);
            }
            leaf(&b[..n]);
        }
    }
}

fn num_value(e: &LNum, env: &[u32], state: &State) -> Option<f64> {
    Some(match e {
        LNum::Const(v) => *v,
        LNum::Fluent { func, args } => {
            let mut k = Vec::with_capacity(args.len() + 1);
            k.push(*func);
            k.extend(args.iter().map(|a| val(*a, env)));
            *state.fluents.get(&k[..])?
        }
        LNum::Bin(op, a, b) => {
            let (a, b) = (num_value(a, env, state)?, num_value(b, env, state)?);
            match op {
                NumOp::Add => a + b,
                NumOp::Sub => a - b,
                NumOp::Mul => a * b,
                NumOp::Div => a / b,
            }
        }
        LNum::Neg(a) => -num_value(a, env, state)?,
    })
}

fn costs<'e>(e: &'e LE, out: &mut Vec<(&'e LNum, Span)>) {
    match e {
        LE::Cost(n, s) => out.push((n, *s)),
        LE::And(ps) => ps.iter().for_each(|p| costs(p, out)),
        _ => {}
    }
}

/// The ground task for `goal` from `state` (any state of the problem's
/// objects, e.g. a knowledge base's), or the diagnostics that stop it.
pub fn ground(
    domain: &Domain,
    dix: &DomainIndex,
    pix: &ProblemIndex,
    state: &State,
    goal: Option<&Formula>,
    deadline: Option<Instant>,
) -> Result<Option<(Task, GroundStats)>, Vec<Diagnostic>> {
    ground_with(domain, dix, pix, state, goal, deadline, Fixpoint::SemiNaive)
}

/// How the reachability fixpoint joins: semi-naive where that is exact
/// (the default), or naive everywhere (what tests compare it with).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Fixpoint {
    SemiNaive,
    #[cfg_attr(not(test), allow(dead_code))]
    Naive,
}

fn ground_with(
    domain: &Domain,
    dix: &DomainIndex,
    pix: &ProblemIndex,
    state: &State,
    goal: Option<&Formula>,
    deadline: Option<Instant>,
    fixpoint: Fixpoint,
) -> Result<Option<(Task, GroundStats)>, Vec<Diagnostic>> {
    let mut c = Compiler::new(domain, dix, pix);
    let mut schemas: Vec<Schema> = (0..domain.actions.len()).map(|i| c.action(i)).collect();
    schemas.extend((0..domain.derived.len()).map(|i| c.derived(i)));
    let (goal_lf, goal_slots) = match goal {
        Some(g) => c.closed(g),
        None => (LF::And(Vec::new()), 0),
    };
    let mut diags = std::mem::take(&mut c.diags);
    let total_cost = dix.functions.get("total-cost").map(|s| s.index as u32);
    let base_cost = total_cost
        .and_then(|t| state.fluents.get(&[t][..]).copied())
        .unwrap_or(0.0);
    if let Some(t) = total_cost {
        let mut cs = Vec::new();
        for s in &schemas {
            costs(&s.eff_start, &mut cs);
            costs(&s.eff_end, &mut cs);
        }
        if let Some((_, span)) = cs.first() {
            if !state.fluents.contains_key(&[t][..]) {
                diags.push(
                    Diagnostic::error(
                        codes::PLAN_COST,
                        *span,
                        "actions increase `total-cost`, but the problem gives it no initial value",
                    )
                    .with_hint("add `(= (total-cost) 0)` to the problem's `:init`"),
                );
            }
        }
    }
    if !domain.derived.is_empty() && domain.actions.iter().any(|a| !a.eff_start.is_empty()) {
        if let Some(a) = domain.actions.iter().find(|a| !a.eff_start.is_empty()) {
            diags.push(unsupported(
                a.name.span,
                "durative actions with `at start` effects together with derived predicates",
            ));
        }
    }
    if diags.iter().any(Diagnostic::is_error) {
        return Err(diags);
    }

    let npred = domain.predicates.len();
    let mut fluent = vec![false; npred];
    for s in &schemas {
        if let SchemaKind::Action(_) = s.kind {
            let mut ps = Vec::new();
            changed_predicates(&s.eff_start, &mut ps);
            changed_predicates(&s.eff_end, &mut ps);
            for p in ps {
                fluent[p as usize] = true;
            }
        }
    }
    let mut derived = vec![false; npred];
    for s in &schemas {
        if let SchemaKind::Derived(_, h) = s.kind {
            derived[h as usize] = true;
        }
    }
    let mut g = Grounder {
        fluent,
        derived,
        reach: Reach::new(npred),
        facts: FxHashMap::default(),
        fact_keys: Vec::new(),
        aux: FxHashMap::default(),
        axioms: Vec::new(),
        state,
        diags: Vec::new(),
        deadline,
        ticks: Cell::new(0),
        timed_out: Cell::new(false),
    };
    let mut init: Vec<&Box<[u32]>> = state.facts.iter().collect();
    init.sort();
    for k in init {
        if (k[0] as usize) < npred && !g.derived[k[0] as usize] {
            g.reach.insert(k.clone());
        }
    }

    // Relaxed reachability fixpoint.
    let nobj = pix.object_names.len();
    let joins: Vec<Joins> = schemas
        .iter()
        .map(|s| Joins::new(&mut g.reach, s, nobj, fixpoint))
        .collect();
    let mut seen: Vec<FxHashSet<Box<[u32]>>> = vec![FxHashSet::default(); schemas.len()];
    let mut order: Vec<Vec<Box<[u32]>>> = vec![Vec::new(); schemas.len()];
    let mut before = vec![0usize; npred];
    for round in 0.. {
        let now = g.reach.sizes();
        let r = Round {
            before: &before,
            now: &now,
        };
        for (i, s) in schemas.iter().enumerate() {
            let j = &joins[i];
            if !j.naive && j.steps.len() == 1 && j.steps[0].is_empty() && round > 0 {
                continue;
            }
            let mut env = vec![None; s.slots.max(s.params.len())];
            let mut scratch = vec![0u32; s.slots.max(1)];
            let mut adds = Vec::new();
            let (seen, order) = (&mut seen[i], &mut order[i]);
            for steps in &j.steps {
                g.reach.join(
                    steps,
                    &r,
                    &j.allowed,
                    &mut env,
                    &|| g.expired(),
                    &mut |env| {
                        each_free(&s.params, env, &|| g.expired(), &mut |b| {
                            scratch[..b.len()].copy_from_slice(b);
                            if j.naive && seen.contains(b) {
                                // Its precondition held before and still does;
                                // a `when` may hold now that did not.
                                if j.conditional {
                                    g.relaxed_adds(&s.eff_start, &mut scratch, &mut adds);
                                    g.relaxed_adds(&s.eff_end, &mut scratch, &mut adds);
                                }
                                return;
                            }
                            if g.relaxed(&j.check, &mut scratch, true) {
                                if j.naive {
                                    seen.insert(b.into());
                                }
                                g.relaxed_adds(&s.eff_start, &mut scratch, &mut adds);
                                g.relaxed_adds(&s.eff_end, &mut scratch, &mut adds);
                                order.push(b.into());
                            }
                        })
                    },
                );
            }
            for k in adds {
                g.reach.insert(k);
            }
        }
        if g.timed_out.get() {
            return Ok(None);
        }
        if g.reach.sizes() == now {
            break;
        }
        before = now;
    }
    // A canonical operator order, whatever round found each binding.
    order.iter_mut().for_each(|o| o.sort_unstable());
    let reachable_atoms = g.reach.len();

    // Facts: reachable atoms of fluent and derived predicates.
    let mut keys: Vec<&Box<[u32]>> = g.reach.iter().filter(|k| !g.is_static(k[0])).collect();
    keys.sort();
    let keys: Vec<Box<[u32]>> = keys.into_iter().cloned().collect();
    for k in &keys {
        g.fact(k);
    }

    // Operators and axioms.
    let mut ops = Vec::new();
    for (i, s) in schemas.iter().enumerate() {
        let mut env = vec![0u32; s.slots.max(1)];
        for b in &order[i] {
            if g.expired() {
                return Ok(None);
            }
            env[..b.len()].copy_from_slice(b);
            match s.kind {
                SchemaKind::Derived(_, head) => {
                    let body = g.ground(&s.pre_start, &mut env, true);
                    let mut k = vec![head];
                    k.extend_from_slice(b);
                    let h = g.fact(&k);
                    g.axioms_for(h, body);
                }
                SchemaKind::Action(a) => {
                    if let Some(op) = instantiate(&mut g, s, a, &mut env, b, total_cost.is_some()) {
                        ops.push(op);
                    }
                }
            }
        }
    }
    if !g.diags.is_empty() {
        return Err(g.diags);
    }
    let mut genv = vec![0u32; goal_slots.max(1)];
    let goal_gf = g.ground(&goal_lf, &mut genv, true);
    let goal = g.conj(goal_gf);

    // Layers: a derived fact is in at least the layer of each derived fact
    // its axioms use, and above those they negate.
    let nf = g.fact_keys.len();
    let mut is_derived = vec![false; nf];
    for (f, k) in g.fact_keys.iter().enumerate() {
        is_derived[f] = k[0] == u32::MAX || g.derived[k[0] as usize];
    }
    let mut layer = vec![0u32; nf];
    let mut rounds = 0;
    loop {
        let mut changed = false;
        for a in &g.axioms {
            for l in &a.body {
                if is_derived[l.fact as usize] {
                    let need = layer[l.fact as usize] + u32::from(!l.positive);
                    if layer[a.head as usize] < need {
                        layer[a.head as usize] = need;
                        changed = true;
                    }
                }
            }
        }
        rounds += 1;
        if !changed {
            break;
        }
        if rounds > nf + 1 {
            let span = domain.derived.first().map_or(domain.span, |d| d.span);
            return Err(vec![Diagnostic::error(
                codes::NOT_STRATIFIED,
                span,
                "the derived predicates depend on their own negation once grounded",
            )]);
        }
    }
    let mut axioms = std::mem::take(&mut g.axioms);
    for a in &mut axioms {
        a.layer = layer[a.head as usize];
    }
    axioms.sort_by_key(|a| a.layer);
    let layers = axioms.iter().map(|a| a.layer + 1).max().unwrap_or(0);

    let words = nf.div_ceil(64).max(1);
    let mut init = vec![0u64; words];
    for k in state.facts.iter() {
        if let Some(&f) = g.facts.get(&k[..]) {
            if !is_derived[f as usize] {
                crate::task::set(&mut init, f);
            }
        }
    }
    let fact_preds = g.fact_keys.iter().map(|k| k[0]).collect();
    let fact_names = g
        .fact_keys
        .iter()
        .map(|k| {
            if k[0] == u32::MAX {
                return format!("(aux-{})", k[1]);
            }
            let mut s = format!("({}", domain.predicates[k[0] as usize].name.name);
            for &o in &k[1..] {
                s.push(' ');
                s.push_str(&pix.object_names[o as usize]);
            }
            s.push(')');
            s
        })
        .collect();
    let unit_cost = ops.iter().all(|o: &Operator| o.cost == 1);
    let stats = GroundStats {
        reachable_atoms,
        operators: ops.len(),
        axioms: axioms.len(),
        facts: nf,
    };
    let mut task = Task {
        fact_names,
        fact_preds,
        derived: is_derived,
        operators: ops,
        axioms,
        layers,
        init,
        goal: goal.clone().unwrap_or_default(),
        base_cost,
        unit_cost,
        words,
    };
    if goal.is_none() {
        // No reachable state satisfies the goal: a literal that never holds.
        task.goal = vec![Lit {
            fact: 0,
            positive: true,
        }];
        task.fact_names.push("(false)".into());
        task.fact_preds.push(u32::MAX);
        task.derived.push(true);
        task.goal[0].fact = (task.fact_names.len() - 1) as u32;
        task.words = task.fact_names.len().div_ceil(64);
        task.init.resize(task.words, 0);
    }
    let mut ax = crate::task::AxiomScratch::default();
    let mut s = std::mem::take(&mut task.init);
    task.close(&mut s, &mut ax);
    task.init = s;
    Ok(Some((task, stats)))
}

fn instantiate(
    g: &mut Grounder,
    s: &Schema,
    action: usize,
    env: &mut [u32],
    args: &[u32],
    has_total_cost: bool,
) -> Option<Operator> {
    let pre1 = g.ground(&s.pre_start, env, true);
    if pre1 == GF::False {
        return None;
    }
    let mut cost = 0.0;
    let mut cs = Vec::new();
    costs(&s.eff_start, &mut cs);
    costs(&s.eff_end, &mut cs);
    for (n, span) in cs {
        // An undefined cost makes the action inapplicable, as in validation.
        let v = num_value(n, env, g.state)?;
        if v < 0.0 || v.fract() != 0.0 || v > 1e15 {
            g.diags.push(
                Diagnostic::error(
                    codes::PLAN_COST,
                    span,
                    format!("an action cost of {v}: the planner needs whole numbers of at least 0"),
                )
                .with_hint("scale the costs to whole numbers"),
            );
            return None;
        }
        cost += v;
    }
    let cost = if has_total_cost { cost as u64 } else { 1 };
    let mut e1 = Vec::new();
    g.ground_effect(&s.eff_start, env, &GF::True, &mut e1);
    let pre2 = g.ground(&s.pre_mid, env, true);
    let mut e2 = Vec::new();
    g.ground_effect(&s.eff_end, env, &GF::True, &mut e2);
    let (pre, effects) = if e1.is_empty() {
        (gand(vec![pre1, pre2]), e2)
    } else {
        // Fold the start effects into one step: conditions after them are
        // regressed through them; end effects override start effects.
        if e1.iter().any(|(c, _, _)| *c != GF::True) {
            g.diags.push(unsupported(
                s.span,
                "conditional `at start` effects in a durative action",
            ));
            return None;
        }
        let mut value: FxHashMap<u32, bool> = FxHashMap::default();
        for (_, f, add) in &e1 {
            if !add {
                value.insert(*f, false);
            }
        }
        for (_, f, add) in &e1 {
            if *add {
                value.insert(*f, true);
            }
        }
        let pre = gand(vec![pre1, regress(pre2, &value)]);
        let mut effects: Vec<(GF, u32, bool)> = e2
            .into_iter()
            .map(|(c, f, a)| (regress(c, &value), f, a))
            .collect();
        for (f, v) in value {
            let end_dels: Vec<GF> = effects
                .iter()
                .filter(|(_, g2, a)| *g2 == f && !a)
                .map(|(c, _, _)| c.clone())
                .collect();
            if v {
                let c = gand(end_dels.into_iter().map(negate).collect());
                effects.push((c, f, true));
            } else {
                effects.push((GF::True, f, false));
            }
        }
        (pre, effects)
    };
    let pre = g.conj(pre)?;
    let mut ge = Vec::new();
    for (c, fact, add) in effects {
        if let Some(cond) = g.conj(c) {
            ge.push(GroundEffect { cond, fact, add });
        }
    }
    Some(Operator {
        action,
        args: args.to_vec(),
        pre,
        effects: ge,
        cost,
    })
}

#[cfg(test)]
mod tests;

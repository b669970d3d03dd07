//! Action schemas, derived rules and goals compiled from the PDDL model into
//! a slot-addressed form: variables become indexes into a binding array,
//! constants become object ids, `imply` becomes `or`, types become the list
//! of objects that fit. Features the planner cannot handle are refused here
//! with a diagnostic naming them.

use btc_pddl::ast::*;
use btc_pddl::check::{DomainIndex, ProblemIndex};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::source::Span;
use btc_pddl::types::TypeId;
use rustc_hash::FxHashMap;
use std::rc::Rc;

/// Ground atoms are keys `[predicate, objects...]`, as in `btc_pddl::state`;
/// the planner builds them in a fixed buffer, so arity is bounded.
pub const MAX_ARITY: usize = 15;

/// Bindings of action parameters are built in a fixed buffer too.
pub const MAX_PARAMS: usize = 32;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LTerm {
    Slot(u16),
    Obj(u32),
}

/// Objects a quantified variable or parameter ranges over.
pub type Range = (u16, Rc<[u32]>);

#[derive(Clone, Debug)]
pub enum LF {
    Atom { pred: u32, args: Vec<LTerm> },
    Eq(LTerm, LTerm),
    Not(Box<LF>),
    And(Vec<LF>),
    Or(Vec<LF>),
    Exists(Vec<Range>, Box<LF>),
    Forall(Vec<Range>, Box<LF>),
}

#[derive(Clone, Debug)]
pub enum LNum {
    Const(f64),
    Fluent { func: u32, args: Vec<LTerm> },
    Bin(NumOp, Box<LNum>, Box<LNum>),
    Neg(Box<LNum>),
}

#[derive(Clone, Debug)]
pub enum LE {
    Add {
        pred: u32,
        args: Vec<LTerm>,
    },
    Del {
        pred: u32,
        args: Vec<LTerm>,
    },
    And(Vec<LE>),
    Forall(Vec<Range>, Box<LE>),
    When(LF, Box<LE>),
    /// `(increase (total-cost) expr)`
    Cost(LNum, Span),
}

#[derive(Clone, Debug)]
pub enum SchemaKind {
    /// Index into `domain.actions`.
    Action(usize),
    /// Index into `domain.derived`; the head predicate.
    Derived(usize, u32),
}

/// An action (or a derived rule, whose effect adds its head) ready to be
/// instantiated. A plain action has only `pre_start` and `eff_end`; a
/// durative one is applied as validation does: start condition, start
/// effects, over-all and end conditions, end effects.
#[derive(Clone, Debug)]
pub struct Schema {
    pub kind: SchemaKind,
    pub params: Vec<Rc<[u32]>>,
    pub slots: usize,
    pub pre_start: LF,
    pub pre_mid: LF,
    pub eff_start: LE,
    pub eff_end: LE,
    pub span: Span,
}

pub struct Compiler<'a> {
    pub domain: &'a Domain,
    pub dix: &'a DomainIndex,
    pub pix: &'a ProblemIndex,
    types: FxHashMap<Vec<TypeId>, Rc<[u32]>>,
    scope: Vec<(&'a str, u16)>,
    slots: u16,
    max_slots: u16,
    pub diags: Vec<Diagnostic>,
    total_cost: Option<u32>,
}

pub fn unsupported(span: Span, what: &str) -> Diagnostic {
    Diagnostic::error(
        codes::PLAN_UNSUPPORTED,
        span,
        format!("the planner does not support {what}"),
    )
    .with_hint("btc plan handles STRIPS, typing, ADL conditions and effects, derived predicates, action costs (`(increase (total-cost) N)`) and durative actions planned one after another")
}

impl<'a> Compiler<'a> {
    pub fn new(domain: &'a Domain, dix: &'a DomainIndex, pix: &'a ProblemIndex) -> Self {
        Compiler {
            domain,
            dix,
            pix,
            types: FxHashMap::default(),
            scope: Vec::new(),
            slots: 0,
            max_slots: 0,
            diags: Vec::new(),
            total_cost: dix.functions.get("total-cost").map(|s| s.index as u32),
        }
    }

    pub fn objects(&mut self, spec: &TypeSpec) -> Rc<[u32]> {
        let ids = self.dix.types.resolve(spec, &mut Vec::new());
        if let Some(v) = self.types.get(&ids) {
            return v.clone();
        }
        let v: Rc<[u32]> = self.pix.objects_of(&self.dix.types, &ids).into();
        self.types.insert(ids, v.clone());
        v
    }

    fn bind(&mut self, vars: &'a [Typed]) -> Vec<Range> {
        vars.iter()
            .map(|v| {
                let objs = self.objects(&v.ty);
                let slot = self.slots;
                self.slots += 1;
                self.max_slots = self.max_slots.max(self.slots);
                self.scope.push((v.name.as_str(), slot));
                (slot, objs)
            })
            .collect()
    }

    fn unbind(&mut self, n: usize) {
        self.scope.truncate(self.scope.len() - n);
        self.slots -= n as u16;
    }

    fn term(&mut self, t: &Term) -> LTerm {
        match t {
            Term::Var { name } => match self.scope.iter().rev().find(|(v, _)| *v == name.name) {
                Some((_, s)) => LTerm::Slot(*s),
                None => {
                    self.diags.push(Diagnostic::error(
                        codes::UNBOUND_VARIABLE,
                        name.span,
                        format!("`?{}` is not bound here", name.name),
                    ));
                    LTerm::Obj(0)
                }
            },
            Term::Const { name } => match self.pix.objects.get(name.as_str()) {
                Some(o) => LTerm::Obj(o.id),
                None => {
                    self.diags.push(Diagnostic::error(
                        codes::UNKNOWN_OBJECT,
                        name.span,
                        format!("`{}` is not an object or constant", name.name),
                    ));
                    LTerm::Obj(0)
                }
            },
        }
    }

    fn atom(&mut self, a: &Atom) -> (u32, Vec<LTerm>) {
        let pred = match self.dix.predicates.get(a.pred.as_str()) {
            Some(s) => s.index as u32,
            None => {
                self.diags.push(Diagnostic::error(
                    codes::UNKNOWN_PREDICATE,
                    a.pred.span,
                    format!("`{}` is not a declared predicate", a.pred.name),
                ));
                0
            }
        };
        if a.args.len() > MAX_ARITY {
            self.diags.push(unsupported(
                a.span,
                &format!("atoms with more than {MAX_ARITY} arguments"),
            ));
        }
        (pred, a.args.iter().map(|t| self.term(t)).collect())
    }

    pub fn formula(&mut self, f: &'a Formula) -> LF {
        match f {
            Formula::Atom { atom } => {
                let (pred, args) = self.atom(atom);
                LF::Atom { pred, args }
            }
            Formula::Equal { left, right, .. } => LF::Eq(self.term(left), self.term(right)),
            Formula::Not { formula, .. } => LF::Not(Box::new(self.formula(formula))),
            Formula::And { parts, .. } => LF::And(parts.iter().map(|p| self.formula(p)).collect()),
            Formula::Or { parts, .. } => LF::Or(parts.iter().map(|p| self.formula(p)).collect()),
            Formula::Imply { left, right, .. } => LF::Or(vec![
                LF::Not(Box::new(self.formula(left))),
                self.formula(right),
            ]),
            Formula::Exists { vars, body, .. } => {
                let r = self.bind(vars);
                let b = self.formula(body);
                self.unbind(vars.len());
                LF::Exists(r, Box::new(b))
            }
            Formula::Forall { vars, body, .. } => {
                let r = self.bind(vars);
                let b = self.formula(body);
                self.unbind(vars.len());
                LF::Forall(r, Box::new(b))
            }
            Formula::Compare { span, .. } => {
                self.diags
                    .push(unsupported(*span, "numeric conditions (comparisons)"));
                LF::And(Vec::new())
            }
        }
    }

    fn num(&mut self, e: &NumExpr) -> LNum {
        match e {
            NumExpr::Number { value, .. } => LNum::Const(*value),
            NumExpr::Fluent { app } => {
                let func = match self.dix.functions.get(app.pred.as_str()) {
                    Some(s) => s.index as u32,
                    None => {
                        self.diags.push(Diagnostic::error(
                            codes::UNKNOWN_FUNCTION,
                            app.pred.span,
                            format!("`{}` is not a declared function", app.pred.name),
                        ));
                        0
                    }
                };
                LNum::Fluent {
                    func,
                    args: app.args.iter().map(|t| self.term(t)).collect(),
                }
            }
            NumExpr::Duration { span } => {
                self.diags
                    .push(unsupported(*span, "`?duration` in an action cost"));
                LNum::Const(0.0)
            }
            NumExpr::Binary {
                op, left, right, ..
            } => LNum::Bin(*op, Box::new(self.num(left)), Box::new(self.num(right))),
            NumExpr::Neg { expr, .. } => LNum::Neg(Box::new(self.num(expr))),
        }
    }

    fn effect(&mut self, e: &'a Effect, conditional: bool) -> LE {
        match e {
            Effect::Add { atom } => {
                let (pred, args) = self.atom(atom);
                LE::Add { pred, args }
            }
            Effect::Delete { atom, .. } => {
                let (pred, args) = self.atom(atom);
                LE::Del { pred, args }
            }
            Effect::And { parts, .. } => {
                LE::And(parts.iter().map(|p| self.effect(p, conditional)).collect())
            }
            Effect::Forall { vars, body, .. } => {
                let r = self.bind(vars);
                let b = self.effect(body, true);
                self.unbind(vars.len());
                LE::Forall(r, Box::new(b))
            }
            Effect::When {
                condition, body, ..
            } => {
                let c = self.formula(condition);
                LE::When(c, Box::new(self.effect(body, true)))
            }
            Effect::Numeric {
                op,
                fluent,
                value,
                span,
            } => {
                let is_total_cost = fluent.pred.name == "total-cost" && fluent.args.is_empty();
                if !is_total_cost || *op != AssignOp::Increase {
                    self.diags.push(unsupported(
                        *span,
                        "numeric effects other than `(increase (total-cost) ...)`",
                    ));
                } else if conditional {
                    self.diags.push(unsupported(
                        *span,
                        "an action cost inside a `when` or `forall` effect",
                    ));
                } else if self.total_cost.is_none() {
                    self.diags
                        .push(unsupported(*span, "an undeclared `total-cost`"));
                }
                LE::Cost(self.num(value), *span)
            }
        }
    }

    fn begin(&mut self, params: &'a [Typed]) -> Vec<Rc<[u32]>> {
        if params.len() > MAX_PARAMS {
            self.diags.push(unsupported(
                params[MAX_PARAMS].name.span,
                &format!("more than {MAX_PARAMS} parameters"),
            ));
        }
        self.scope.clear();
        self.slots = 0;
        self.max_slots = 0;
        self.bind(params).into_iter().map(|(_, o)| o).collect()
    }

    pub fn action(&mut self, index: usize) -> Schema {
        let a = &self.domain.actions[index];
        let params = self.begin(&a.params);
        let and =
            |c: &mut Self, fs: &'a [Formula]| LF::And(fs.iter().map(|f| c.formula(f)).collect());
        let effs = |c: &mut Self, es: &'a [Effect]| {
            LE::And(es.iter().map(|e| c.effect(e, false)).collect())
        };
        let pre_start = and(self, &a.pre_start);
        let pre_mid = LF::And(
            a.pre_over_all
                .iter()
                .chain(&a.pre_end)
                .map(|f| self.formula(f))
                .collect(),
        );
        let eff_start = effs(self, &a.eff_start);
        let eff_end = effs(self, &a.eff_end);
        Schema {
            kind: SchemaKind::Action(index),
            params,
            slots: self.max_slots as usize,
            pre_start,
            pre_mid,
            eff_start,
            eff_end,
            span: a.name.span,
        }
    }

    pub fn derived(&mut self, index: usize) -> Schema {
        let d = &self.domain.derived[index];
        let params = self.begin(&d.head.params);
        let head = self
            .dix
            .predicates
            .get(d.head.name.as_str())
            .map_or(0, |s| s.index as u32);
        let body = self.formula(&d.body);
        let args = (0..params.len() as u16).map(LTerm::Slot).collect();
        Schema {
            kind: SchemaKind::Derived(index, head),
            params,
            slots: self.max_slots as usize,
            pre_start: body,
            pre_mid: LF::And(Vec::new()),
            eff_start: LE::And(Vec::new()),
            eff_end: LE::Add { pred: head, args },
            span: d.span,
        }
    }

    /// A closed formula (the goal); returns it with the slots it needs.
    pub fn closed(&mut self, f: &'a Formula) -> (LF, usize) {
        self.begin(&[]);
        let lf = self.formula(f);
        (lf, self.max_slots as usize)
    }
}

/// Positive atoms every binding that satisfies `f` must make true: the
/// atoms of its top-level conjunction.
pub fn necessary_atoms(f: &LF, out: &mut Vec<(u32, Vec<LTerm>)>) {
    match f {
        LF::Atom { pred, args } => out.push((*pred, args.clone())),
        LF::And(parts) => parts.iter().for_each(|p| necessary_atoms(p, out)),
        _ => {}
    }
}

/// Predicates an effect adds or deletes.
pub fn changed_predicates(e: &LE, out: &mut Vec<u32>) {
    match e {
        LE::Add { pred, .. } | LE::Del { pred, .. } => out.push(*pred),
        LE::And(parts) => parts.iter().for_each(|p| changed_predicates(p, out)),
        LE::Forall(_, b) | LE::When(_, b) => changed_predicates(b, out),
        LE::Cost(..) => {}
    }
}

//! Logic values compiled against a [`World`]: every name resolved to an
//! id (or refused with a message in the user's terms), every variable a
//! slot of the binding, every quantifier's types the objects it ranges
//! over.

use super::{Key, World};
use crate::ast::{AssignOp, Comparison, NumOp};
use crate::logic::{self, ActionSchema, Atom, Effect, Formula, Name, NumExpr, Term, TypedVar};
use crate::types::TypeId;
use crate::world::WorldModel;
use rustc_hash::FxHashMap;
use std::sync::Arc;

/// A term: a slot of the binding (a parameter or a quantified variable) or
/// an object.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CTerm {
    Slot(u16),
    Obj(u32),
}

/// Variables a quantifier binds (their names, for messages) and the
/// objects each ranges over; they take the next slots of the binding.
#[derive(Clone, Debug, PartialEq)]
pub struct Quant {
    pub names: Vec<Name>,
    pub ranges: Vec<Arc<[u32]>>,
}

/// A compiled condition.
#[derive(Clone, Debug, PartialEq)]
pub enum Cond {
    Atom {
        pred: u32,
        derived: bool,
        args: Box<[CTerm]>,
    },
    Eq(CTerm, CTerm),
    Not(Box<Cond>),
    And(Vec<Cond>),
    Or(Vec<Cond>),
    Imply(Box<Cond>, Box<Cond>),
    Exists(Box<Quant>, Box<Cond>),
    Forall(Box<Quant>, Box<Cond>),
    Compare(Comparison, Box<Num>, Box<Num>),
}

/// A compiled numeric expression.
#[derive(Clone, Debug, PartialEq)]
pub enum Num {
    Const(f64),
    Fluent {
        func: u32,
        args: Box<[CTerm]>,
    },
    /// `(total-time)` in a domain that does not declare it: no value.
    Undefined,
    Duration,
    Bin(NumOp, Box<Num>, Box<Num>),
    Neg(Box<Num>),
}

/// A compiled effect.
#[derive(Clone, Debug, PartialEq)]
pub enum Eff {
    Add {
        pred: u32,
        args: Box<[CTerm]>,
    },
    Del {
        pred: u32,
        args: Box<[CTerm]>,
    },
    And(Vec<Eff>),
    Forall(Box<Quant>, Box<Eff>),
    When(Cond, Box<Eff>),
    Numeric {
        op: AssignOp,
        func: u32,
        args: Box<[CTerm]>,
        value: Num,
    },
}

/// An action schema compiled over its parameters (slots `0..n`).
#[derive(Clone, Debug, PartialEq)]
pub struct CompiledAction {
    pub pre_start: Vec<Cond>,
    pub pre_over_all: Vec<Cond>,
    pub pre_end: Vec<Cond>,
    pub eff_start: Vec<Eff>,
    pub eff_end: Vec<Eff>,
    pub duration: Option<Num>,
}

/// A derived rule: the head's predicate, the objects each head parameter
/// ranges over, the body over those parameters.
#[derive(Clone, Debug)]
pub(super) struct Rule {
    pub head: u32,
    pub params: Quant,
    pub body: Cond,
}

/// Names in scope while compiling: slot `i` is `vars[i]`.
struct Scope<'a> {
    world: &'a World,
    vars: Vec<Name>,
    /// Objects per type list, computed once per compilation.
    ranges: FxHashMap<Vec<TypeId>, Arc<[u32]>>,
}

impl World {
    /// Compiles a condition over the variables `vars` (slot `i` is
    /// `vars[i]`; a ground condition has none).
    pub fn compile(&self, f: &Formula, vars: &[Name]) -> Result<Cond, String> {
        Scope::new(self, vars).formula(f)
    }

    /// Compiles an effect over the variables `vars`.
    pub fn compile_effect(&self, e: &Effect, vars: &[Name]) -> Result<Eff, String> {
        Scope::new(self, vars).effect(e)
    }

    /// Compiles an action schema over its parameters.
    pub fn compile_action(&self, a: &ActionSchema) -> Result<CompiledAction, String> {
        let mut s = Scope::new(self, &a.param_names());
        let conds = |s: &mut Scope, fs: &[Formula]| -> Result<Vec<Cond>, String> {
            fs.iter().map(|f| s.formula(f)).collect()
        };
        let effs = |s: &mut Scope, es: &[Effect]| -> Result<Vec<Eff>, String> {
            es.iter().map(|e| s.effect(e)).collect()
        };
        Ok(CompiledAction {
            pre_start: conds(&mut s, &a.pre_start)?,
            pre_over_all: conds(&mut s, &a.pre_over_all)?,
            pre_end: conds(&mut s, &a.pre_end)?,
            eff_start: effs(&mut s, &a.eff_start)?,
            eff_end: effs(&mut s, &a.eff_end)?,
            duration: a.duration.as_ref().map(|d| s.num(d)).transpose()?,
        })
    }

    /// The ids of written types (none: `object`).
    pub fn type_ids(&self, types: &[Name]) -> Result<Vec<TypeId>, String> {
        if types.is_empty() {
            return Ok(vec![crate::types::OBJECT]);
        }
        types
            .iter()
            .map(|t| {
                self.types
                    .id(t)
                    .ok_or_else(|| format!("type `{t}` is not declared in the domain"))
            })
            .collect()
    }
}

impl<'a> Scope<'a> {
    fn new(world: &'a World, vars: &[Name]) -> Scope<'a> {
        Scope {
            world,
            vars: vars.to_vec(),
            ranges: FxHashMap::default(),
        }
    }

    fn term(&self, t: &Term) -> Result<CTerm, String> {
        match t {
            Term::Var(v) => match self.vars.iter().rposition(|x| x == v) {
                Some(i) => u16::try_from(i)
                    .map(CTerm::Slot)
                    .map_err(|_| "too many variables in one formula".to_owned()),
                None => Err(format!("variable `?{v}` is not bound here")),
            },
            Term::Obj(o) => self.world.object_id(o).map(CTerm::Obj).ok_or_else(|| {
                format!("`{o}` is not an object of the problem or a constant of the domain")
            }),
        }
    }

    /// The arguments of an atom, checked against a signature: arity, and
    /// the types of objects (variables are typed where they are bound).
    fn args(&self, what: &str, a: &Atom, params: &[Vec<TypeId>]) -> Result<Box<[CTerm]>, String> {
        if a.args.len() != params.len() {
            let n = params.len();
            return Err(format!(
                "{what} `{}` takes {n} argument{}, but {} {} given",
                a.pred,
                if n == 1 { "" } else { "s" },
                a.args.len(),
                if a.args.len() == 1 { "is" } else { "are" }
            ));
        }
        let t = &self.world.types;
        a.args
            .iter()
            .zip(params)
            .enumerate()
            .map(|(i, (arg, want))| {
                let c = self.term(arg)?;
                if let CTerm::Obj(o) = c {
                    let have = &self.world.object_types[o as usize];
                    if !t.fits(have, want) {
                        return Err(format!(
                            "`{arg}` has type `{}`, but argument {} of `{}` must be `{}`",
                            t.display(have),
                            i + 1,
                            a.pred,
                            t.display(want)
                        ));
                    }
                }
                Ok(c)
            })
            .collect()
    }

    fn predicate(&self, a: &Atom) -> Result<(u32, Box<[CTerm]>), String> {
        let w = self.world;
        let p = w
            .predicate_id(&a.pred)
            .ok_or_else(|| format!("predicate `{}` is not declared in the domain", a.pred))?;
        let args = self.args("predicate", a, &w.predicate_params[p as usize])?;
        Ok((p, args))
    }

    fn function(&self, a: &Atom) -> Result<(u32, Box<[CTerm]>), String> {
        let w = self.world;
        let f = w
            .function_id(&a.pred)
            .ok_or_else(|| format!("function `{}` is not declared in the domain", a.pred))?;
        let args = self.args("function", a, &w.function_params[f as usize])?;
        Ok((f, args))
    }

    /// Binds `vars` for `body`: their slots follow the ones in scope.
    fn quantified<T>(
        &mut self,
        vars: &[TypedVar],
        body: impl FnOnce(&mut Self) -> Result<T, String>,
    ) -> Result<(Box<Quant>, T), String> {
        let mut q = Quant {
            names: Vec::with_capacity(vars.len()),
            ranges: Vec::with_capacity(vars.len()),
        };
        for v in vars {
            let types = self.world.type_ids(&v.types)?;
            let range = match self.ranges.get(&types) {
                Some(r) => r.clone(),
                None => {
                    let r = self.world.objects_of(&types);
                    self.ranges.insert(types, r.clone());
                    r
                }
            };
            q.names.push(v.name.clone());
            q.ranges.push(range);
        }
        let mark = self.vars.len();
        self.vars.extend(vars.iter().map(|v| v.name.clone()));
        let out = body(self);
        self.vars.truncate(mark);
        Ok((Box::new(q), out?))
    }

    fn formula(&mut self, f: &Formula) -> Result<Cond, String> {
        Ok(match f {
            Formula::Atom(a) => {
                let (pred, args) = self.predicate(a)?;
                Cond::Atom {
                    pred,
                    derived: self.world.is_derived(pred),
                    args,
                }
            }
            Formula::Equal(l, r) => Cond::Eq(self.term(l)?, self.term(r)?),
            Formula::Not(x) => Cond::Not(Box::new(self.formula(x)?)),
            Formula::And(ps) => Cond::And(self.formulas(ps)?),
            Formula::Or(ps) => Cond::Or(self.formulas(ps)?),
            Formula::Imply(l, r) => {
                Cond::Imply(Box::new(self.formula(l)?), Box::new(self.formula(r)?))
            }
            Formula::Exists(vs, body) => {
                let (q, b) = self.quantified(vs, |s| s.formula(body))?;
                Cond::Exists(q, Box::new(b))
            }
            Formula::Forall(vs, body) => {
                let (q, b) = self.quantified(vs, |s| s.formula(body))?;
                Cond::Forall(q, Box::new(b))
            }
            Formula::Compare(op, l, r) => {
                Cond::Compare(*op, Box::new(self.num(l)?), Box::new(self.num(r)?))
            }
        })
    }

    fn formulas(&mut self, fs: &[Formula]) -> Result<Vec<Cond>, String> {
        fs.iter().map(|f| self.formula(f)).collect()
    }

    fn num(&mut self, e: &NumExpr) -> Result<Num, String> {
        Ok(match e {
            NumExpr::Number(v) => Num::Const(*v),
            NumExpr::Fluent(a)
                if &*a.pred == "total-time"
                    && a.args.is_empty()
                    && self.world.function_id("total-time").is_none() =>
            {
                Num::Undefined
            }
            NumExpr::Fluent(a) => {
                let (func, args) = self.function(a)?;
                Num::Fluent { func, args }
            }
            NumExpr::Duration => Num::Duration,
            NumExpr::Binary(op, l, r) => {
                Num::Bin(*op, Box::new(self.num(l)?), Box::new(self.num(r)?))
            }
            NumExpr::Neg(x) => Num::Neg(Box::new(self.num(x)?)),
        })
    }

    fn effect(&mut self, e: &Effect) -> Result<Eff, String> {
        Ok(match e {
            Effect::Add(a) | Effect::Delete(a) => {
                let (pred, args) = self.predicate(a)?;
                if self.world.is_derived(pred) {
                    return Err(format!(
                        "`{}` is a derived predicate: an effect cannot change it",
                        a.pred
                    ));
                }
                match e {
                    Effect::Add(_) => Eff::Add { pred, args },
                    _ => Eff::Del { pred, args },
                }
            }
            Effect::And(ps) => Eff::And(
                ps.iter()
                    .map(|p| self.effect(p))
                    .collect::<Result<_, _>>()?,
            ),
            Effect::Forall(vs, body) => {
                let (q, b) = self.quantified(vs, |s| s.effect(body))?;
                Eff::Forall(q, Box::new(b))
            }
            Effect::When(c, body) => Eff::When(self.formula(c)?, Box::new(self.effect(body)?)),
            Effect::Numeric(op, fl, v) => {
                let (func, args) = self.function(fl)?;
                Eff::Numeric {
                    op: *op,
                    func,
                    args,
                    value: self.num(v)?,
                }
            }
        })
    }
}

/// The key of a ground atom (`fluent`: of a function application).
pub(super) fn ground_key(w: &World, a: &Atom, fluent: bool) -> Result<Key, String> {
    let s = Scope::new(w, &[]);
    let (head, args) = if fluent {
        s.function(a)?
    } else {
        s.predicate(a)?
    };
    let mut k = Vec::with_capacity(args.len() + 1);
    k.push(head);
    for t in args.iter() {
        match t {
            CTerm::Obj(o) => k.push(*o),
            CTerm::Slot(_) => unreachable!("no variables in scope"),
        }
    }
    Ok(k.into_boxed_slice())
}

/// Builds a [`World`] from its model, checking that every part fits.
pub(super) fn build(model: WorldModel) -> Result<World, String> {
    let types = crate::types::TypeTable::from_parents(
        model
            .types
            .iter()
            .map(|t| (&*t.name, t.parents.iter().map(|p| &**p).collect())),
    )?;
    let ids = |ts: &[Name], what: &dyn Fn() -> String| -> Result<Vec<TypeId>, String> {
        if ts.is_empty() {
            return Ok(vec![crate::types::OBJECT]);
        }
        ts.iter()
            .map(|t| {
                types
                    .id(t)
                    .ok_or_else(|| format!("{}: type `{t}` is not declared", what()))
            })
            .collect()
    };
    let mut objects = FxHashMap::default();
    let mut object_types = Vec::with_capacity(model.objects.len());
    for (i, o) in model.objects.iter().enumerate() {
        if objects.insert(o.name.clone(), i as u32).is_some() {
            return Err(format!("object `{}` is declared twice", o.name));
        }
        object_types.push(ids(&o.types, &|| format!("object `{}`", o.name))?);
    }
    let signatures = |sigs: &[logic::Signature], what: &str| {
        let mut by_name = FxHashMap::default();
        let mut params = Vec::with_capacity(sigs.len());
        for (i, s) in sigs.iter().enumerate() {
            by_name.entry(s.name.clone()).or_insert(i as u32);
            params.push(
                s.params
                    .iter()
                    .map(|p| ids(&p.types, &|| format!("{what} `{}`", s.name)))
                    .collect::<Result<Vec<_>, _>>()?,
            );
        }
        Ok::<_, String>((by_name, params))
    };
    let (predicates, predicate_params) = signatures(&model.predicates, "predicate")?;
    let (functions, function_params) = signatures(&model.functions, "function")?;
    let mut derived_predicates = vec![false; model.predicates.len()];
    for r in &model.derived {
        let p = predicates.get(&r.head.name).ok_or_else(|| {
            format!(
                "derived predicate `{}` is not declared in the domain",
                r.head.name
            )
        })?;
        derived_predicates[*p as usize] = true;
    }
    let mut w = World {
        model,
        types,
        objects,
        object_types,
        predicates,
        predicate_params,
        derived_predicates,
        functions,
        function_params,
        rules: Vec::new(),
        strata: Vec::new(),
        goal: None,
    };
    let mut rules = Vec::with_capacity(w.model.derived.len());
    for r in &w.model.derived {
        let head = w.predicates[&r.head.name];
        let params: Vec<Name> = r.head.params.iter().map(|p| p.name.clone()).collect();
        let mut ranges = Vec::with_capacity(params.len());
        for p in &r.head.params {
            ranges.push(w.objects_of(&w.type_ids(&p.types)?));
        }
        let body = w
            .compile(&r.body, &params)
            .map_err(|m| format!("derived predicate `{}`: {m}", r.head.name))?;
        rules.push(Rule {
            head,
            params: Quant {
                names: params,
                ranges,
            },
            body,
        });
    }
    w.strata = stratify(&rules, &w.derived_predicates)
        .ok_or("derived predicates depend on their own negation")?;
    w.rules = rules;
    for f in &w.model.init {
        match f {
            logic::InitFact::Atom(a) => {
                let k = w
                    .atom_key(a)
                    .map_err(|m| format!("initial fact `{a}`: {m}"))?;
                if w.derived_predicates[k[0] as usize] {
                    return Err(format!(
                        "initial fact `{a}`: `{}` is a derived predicate",
                        a.pred
                    ));
                }
            }
            logic::InitFact::Value(a, _) => {
                w.fluent_key(a)
                    .map_err(|m| format!("initial value of `{a}`: {m}"))?;
            }
        }
    }
    if let Some(g) = &w.model.goal {
        w.goal = Some(w.compile(g, &[]).map_err(|m| format!("the goal: {m}"))?);
    }
    Ok(w)
}

/// Strata of derived rules: a rule that negates a derived predicate comes
/// after every rule deriving it. `None` when a predicate depends on its own
/// negation.
fn stratify(rules: &[Rule], derived: &[bool]) -> Option<Vec<Vec<usize>>> {
    let n = rules.len();
    if n == 0 {
        return Some(Vec::new());
    }
    // uses[i]: (rule j, through a negation) for each rule j deriving a
    // predicate rule i's body mentions.
    let uses: Vec<Vec<(usize, bool)>> = rules
        .iter()
        .map(|r| {
            let mut preds = Vec::new();
            mentions(&r.body, true, &mut preds);
            let mut out = Vec::new();
            for (p, positive) in preds {
                if derived[p as usize] {
                    for (j, other) in rules.iter().enumerate() {
                        if other.head == p {
                            out.push((j, !positive));
                        }
                    }
                }
            }
            out
        })
        .collect();
    crate::check::strata_of(&uses)
}

/// The predicates a condition mentions, with whether positively.
fn mentions(c: &Cond, positive: bool, out: &mut Vec<(u32, bool)>) {
    match c {
        Cond::Atom { pred, .. } => out.push((*pred, positive)),
        Cond::Not(x) => mentions(x, !positive, out),
        Cond::And(ps) | Cond::Or(ps) => ps.iter().for_each(|p| mentions(p, positive, out)),
        Cond::Imply(l, r) => {
            mentions(l, !positive, out);
            mentions(r, positive, out);
        }
        Cond::Exists(_, b) | Cond::Forall(_, b) => mentions(b, positive, out),
        Cond::Eq(..) | Cond::Compare(..) => {}
    }
}

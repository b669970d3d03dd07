//! The one fold over terms. Grounding (variables to objects) and renaming
//! (variables to variables) are both folds; quantified variables are
//! binders the fold keeps track of, so a substitution never touches a
//! variable a quantifier inside binds, and a renaming that would capture
//! one renames the binder first.

use super::*;

/// What a fold does with free terms and with the variables quantifiers bind.
pub trait TermFolder {
    /// A term no quantifier inside binds.
    fn free(&mut self, t: &Term) -> Term;

    /// The name a quantifier's variable gets (the same by default). A
    /// renaming that maps some free variable onto `v` renames `v` here.
    fn binder(&mut self, v: &Name) -> Name {
        v.clone()
    }
}

/// Values that contain terms: every logic type.
pub trait Terms: Sized {
    /// Rebuilds `self` with free terms mapped by `f`; `bound` holds the
    /// binders in scope (old name, new name), innermost last.
    fn fold_terms(&self, f: &mut dyn TermFolder, bound: &mut Vec<(Name, Name)>) -> Self;

    /// Rebuilds `self` with every free term mapped.
    fn map_terms(&self, f: &mut dyn TermFolder) -> Self {
        self.fold_terms(f, &mut Vec::new())
    }

    /// Variables bound by `binding` become its objects.
    fn ground(&self, binding: &Binding<'_>) -> Self {
        self.map_terms(&mut Grounding(binding))
    }

    /// The free variables, in the order they first occur.
    fn free_vars(&self) -> Vec<Name> {
        let mut c = Collect(Vec::new(), Vec::new());
        self.map_terms(&mut c);
        c.0
    }

    /// The objects it names, in the order they first occur.
    fn objects(&self) -> Vec<Name> {
        let mut c = Collect(Vec::new(), Vec::new());
        self.map_terms(&mut c);
        c.1
    }

    /// Objects replaced, `(from, to)` (a spare part for a lost one).
    fn replace_objects(&self, pairs: &[(Name, Name)]) -> Self {
        self.map_terms(&mut ReplaceObjects(pairs))
    }

    /// Variables renamed by `renaming`.
    fn rename(&self, renaming: &Renaming<'_>) -> Self {
        self.map_terms(&mut RenameFolder { renaming, fresh: 0 })
    }
}

/// Free variables and objects, each once, in order.
struct Collect(Vec<Name>, Vec<Name>);

impl TermFolder for Collect {
    fn free(&mut self, t: &Term) -> Term {
        let (list, n) = match t {
            Term::Var(v) => (&mut self.0, v),
            Term::Obj(o) => (&mut self.1, o),
        };
        if !list.contains(n) {
            list.push(n.clone());
        }
        t.clone()
    }
}

/// Parameters and the objects they are bound to, position by position.
pub struct Binding<'a> {
    pub params: &'a [Name],
    pub objects: &'a [Name],
}

impl Binding<'_> {
    fn get(&self, v: &str) -> Option<&Name> {
        let i = self.params.iter().position(|p| &**p == v)?;
        self.objects.get(i)
    }
}

struct Grounding<'a, 'b>(&'a Binding<'b>);

impl TermFolder for Grounding<'_, '_> {
    fn free(&mut self, t: &Term) -> Term {
        match t {
            Term::Var(v) => match self.0.get(v) {
                Some(o) => Term::Obj(o.clone()),
                None => t.clone(),
            },
            Term::Obj(_) => t.clone(),
        }
    }
}

struct ReplaceObjects<'a>(&'a [(Name, Name)]);

impl TermFolder for ReplaceObjects<'_> {
    fn free(&mut self, t: &Term) -> Term {
        match t {
            Term::Obj(o) => match self.0.iter().find(|(from, _)| from == o) {
                Some((_, to)) => Term::Obj(to.clone()),
                None => t.clone(),
            },
            Term::Var(_) => t.clone(),
        }
    }
}

/// Variable renames `(from, to)`, applied at once (so swaps work).
pub struct Renaming<'a> {
    pub pairs: &'a [(Name, Name)],
}

struct RenameFolder<'a, 'b> {
    renaming: &'a Renaming<'b>,
    fresh: usize,
}

impl TermFolder for RenameFolder<'_, '_> {
    fn free(&mut self, t: &Term) -> Term {
        match t {
            Term::Var(v) => match self.renaming.pairs.iter().find(|(from, _)| from == v) {
                Some((_, to)) => Term::Var(to.clone()),
                None => t.clone(),
            },
            Term::Obj(_) => t.clone(),
        }
    }

    fn binder(&mut self, v: &Name) -> Name {
        let clashes = |n: &str| self.renaming.pairs.iter().any(|(_, to)| &**to == n);
        if !clashes(v) {
            return v.clone();
        }
        loop {
            self.fresh += 1;
            let candidate = format!("{v}_{}", self.fresh);
            if !clashes(&candidate) {
                return name(&candidate);
            }
        }
    }
}

impl Terms for Term {
    fn fold_terms(&self, f: &mut dyn TermFolder, bound: &mut Vec<(Name, Name)>) -> Term {
        if let Term::Var(v) = self {
            if let Some((_, new)) = bound.iter().rev().find(|(old, _)| old == v) {
                return Term::Var(new.clone());
            }
        }
        f.free(self)
    }
}

impl Terms for Atom {
    fn fold_terms(&self, f: &mut dyn TermFolder, bound: &mut Vec<(Name, Name)>) -> Atom {
        Atom {
            pred: self.pred.clone(),
            args: self.args.iter().map(|t| t.fold_terms(f, bound)).collect(),
        }
    }
}

impl Terms for NumExpr {
    fn fold_terms(&self, f: &mut dyn TermFolder, bound: &mut Vec<(Name, Name)>) -> NumExpr {
        match self {
            NumExpr::Number(_) | NumExpr::Duration => self.clone(),
            NumExpr::Fluent(a) => NumExpr::Fluent(a.fold_terms(f, bound)),
            NumExpr::Binary(op, l, r) => NumExpr::Binary(
                *op,
                Box::new(l.fold_terms(f, bound)),
                Box::new(r.fold_terms(f, bound)),
            ),
            NumExpr::Neg(e) => NumExpr::Neg(Box::new(e.fold_terms(f, bound))),
        }
    }
}

/// Folds `body` with `vars` bound; returns the binders' new declarations.
fn under<T>(
    vars: &[TypedVar],
    f: &mut dyn TermFolder,
    bound: &mut Vec<(Name, Name)>,
    body: impl FnOnce(&mut dyn TermFolder, &mut Vec<(Name, Name)>) -> T,
) -> (Vec<TypedVar>, T) {
    let mark = bound.len();
    let vars: Vec<TypedVar> = vars
        .iter()
        .map(|v| {
            let new = f.binder(&v.name);
            bound.push((v.name.clone(), new.clone()));
            TypedVar {
                name: new,
                types: v.types.clone(),
            }
        })
        .collect();
    let out = body(f, bound);
    bound.truncate(mark);
    (vars, out)
}

impl Terms for Formula {
    fn fold_terms(&self, f: &mut dyn TermFolder, bound: &mut Vec<(Name, Name)>) -> Formula {
        match self {
            Formula::Atom(a) => Formula::Atom(a.fold_terms(f, bound)),
            Formula::Equal(l, r) => Formula::Equal(l.fold_terms(f, bound), r.fold_terms(f, bound)),
            Formula::Not(x) => Formula::Not(Box::new(x.fold_terms(f, bound))),
            Formula::And(ps) => Formula::And(ps.iter().map(|p| p.fold_terms(f, bound)).collect()),
            Formula::Or(ps) => Formula::Or(ps.iter().map(|p| p.fold_terms(f, bound)).collect()),
            Formula::Imply(l, r) => Formula::Imply(
                Box::new(l.fold_terms(f, bound)),
                Box::new(r.fold_terms(f, bound)),
            ),
            Formula::Exists(vs, body) => {
                let (vs, body) = under(vs, f, bound, |f, b| body.fold_terms(f, b));
                Formula::Exists(vs, Box::new(body))
            }
            Formula::Forall(vs, body) => {
                let (vs, body) = under(vs, f, bound, |f, b| body.fold_terms(f, b));
                Formula::Forall(vs, Box::new(body))
            }
            Formula::Compare(op, l, r) => Formula::Compare(
                *op,
                Box::new(l.fold_terms(f, bound)),
                Box::new(r.fold_terms(f, bound)),
            ),
        }
    }
}

impl Terms for Effect {
    fn fold_terms(&self, f: &mut dyn TermFolder, bound: &mut Vec<(Name, Name)>) -> Effect {
        match self {
            Effect::Add(a) => Effect::Add(a.fold_terms(f, bound)),
            Effect::Delete(a) => Effect::Delete(a.fold_terms(f, bound)),
            Effect::And(ps) => Effect::And(ps.iter().map(|p| p.fold_terms(f, bound)).collect()),
            Effect::Forall(vs, body) => {
                let (vs, body) = under(vs, f, bound, |f, b| body.fold_terms(f, b));
                Effect::Forall(vs, Box::new(body))
            }
            Effect::When(c, body) => Effect::When(
                Box::new(c.fold_terms(f, bound)),
                Box::new(body.fold_terms(f, bound)),
            ),
            Effect::Numeric(op, fl, v) => Effect::Numeric(
                *op,
                fl.fold_terms(f, bound),
                Box::new(v.fold_terms(f, bound)),
            ),
        }
    }
}

impl Terms for Literal {
    fn fold_terms(&self, f: &mut dyn TermFolder, bound: &mut Vec<(Name, Name)>) -> Literal {
        Literal {
            positive: self.positive,
            atom: self.atom.fold_terms(f, bound),
        }
    }
}

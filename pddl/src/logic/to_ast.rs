//! Logic values back to the AST, for the consumers that work on it (the
//! planner compiles goals from it). The logic layer has no spans: every
//! node gets the one span given, where diagnostics about it should point.

use super::*;
use crate::ast;
use crate::source::Span;

fn ast_name(n: &str, span: Span) -> ast::Name {
    ast::Name {
        name: n.into(),
        span,
    }
}

impl Term {
    pub fn to_ast(&self, span: Span) -> ast::Term {
        match self {
            Term::Var(v) => ast::Term::Var {
                name: ast_name(v, span),
            },
            Term::Obj(o) => ast::Term::Const {
                name: ast_name(o, span),
            },
        }
    }
}

impl Atom {
    pub fn to_ast(&self, span: Span) -> ast::Atom {
        ast::Atom {
            pred: ast_name(&self.pred, span),
            args: self.args.iter().map(|t| t.to_ast(span)).collect(),
            span,
        }
    }
}

impl TypedVar {
    pub fn to_ast(&self, span: Span) -> ast::Typed {
        let ty = match self.types.as_slice() {
            [] => ast::TypeSpec::Object,
            [one] => ast::TypeSpec::Named {
                name: ast_name(one, span),
            },
            many => ast::TypeSpec::Either {
                names: many.iter().map(|t| ast_name(t, span)).collect(),
                span,
            },
        };
        ast::Typed {
            name: ast_name(&self.name, span),
            ty,
        }
    }
}

fn vars(vs: &[TypedVar], span: Span) -> Vec<ast::Typed> {
    vs.iter().map(|v| v.to_ast(span)).collect()
}

impl NumExpr {
    pub fn to_ast(&self, span: Span) -> ast::NumExpr {
        match self {
            NumExpr::Number(value) => ast::NumExpr::Number {
                value: *value,
                span,
            },
            NumExpr::Fluent(a) => ast::NumExpr::Fluent {
                app: a.to_ast(span),
            },
            NumExpr::Duration => ast::NumExpr::Duration { span },
            NumExpr::Binary(op, l, r) => ast::NumExpr::Binary {
                op: *op,
                left: Box::new(l.to_ast(span)),
                right: Box::new(r.to_ast(span)),
                span,
            },
            NumExpr::Neg(e) => ast::NumExpr::Neg {
                expr: Box::new(e.to_ast(span)),
                span,
            },
        }
    }
}

impl Formula {
    pub fn to_ast(&self, span: Span) -> ast::Formula {
        let b = |f: &Formula| Box::new(f.to_ast(span));
        match self {
            Formula::Atom(a) => ast::Formula::Atom {
                atom: a.to_ast(span),
            },
            Formula::Equal(l, r) => ast::Formula::Equal {
                left: l.to_ast(span),
                right: r.to_ast(span),
                span,
            },
            Formula::Not(x) => ast::Formula::Not {
                formula: b(x),
                span,
            },
            Formula::And(ps) => ast::Formula::And {
                parts: ps.iter().map(|p| p.to_ast(span)).collect(),
                span,
            },
            Formula::Or(ps) => ast::Formula::Or {
                parts: ps.iter().map(|p| p.to_ast(span)).collect(),
                span,
            },
            Formula::Imply(l, r) => ast::Formula::Imply {
                left: b(l),
                right: b(r),
                span,
            },
            Formula::Exists(vs, body) => ast::Formula::Exists {
                vars: vars(vs, span),
                body: b(body),
                span,
            },
            Formula::Forall(vs, body) => ast::Formula::Forall {
                vars: vars(vs, span),
                body: b(body),
                span,
            },
            Formula::Compare(op, l, r) => ast::Formula::Compare {
                op: *op,
                left: l.to_ast(span),
                right: r.to_ast(span),
                span,
            },
        }
    }
}

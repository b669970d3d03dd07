//! Terms, atoms, formulas, effects, numeric expressions, initial facts and
//! the metric.

use super::*;

impl Parser {
    pub(super) fn term(&mut self, s: &Sexp) -> Option<Term> {
        if let Some(name) = var_of(s) {
            return Some(Term::Var { name });
        }
        if let Some(name) = name_of(s) {
            return Some(Term::Const { name });
        }
        self.expected("a variable or an object name", Some(s), s.span());
        None
    }

    pub(super) fn atom(&mut self, l: &List) -> Option<Atom> {
        let pred = name_of(&l.items[0])?;
        let args = l.items[1..].iter().filter_map(|s| self.term(s)).collect();
        Some(Atom {
            pred,
            args,
            span: l.span,
        })
    }

    pub(super) fn formula(&mut self, s: &Sexp) -> Option<Formula> {
        let Some(l) = s.as_list() else {
            self.expected("a formula such as `(on ?x ?y)`", Some(s), s.span());
            return None;
        };
        let span = l.span;
        let Some(head) = l.head() else {
            if l.items.is_empty() {
                return Some(Formula::truth(span)); // `()`: nothing required
            }
            self.expected(
                "a predicate or a connective such as `and`",
                l.items.first(),
                span,
            );
            return None;
        };
        let args = &l.items[1..];
        let arity = |p: &mut Parser, n: usize| {
            if args.len() != n {
                let msg = format!(
                    "`{head}` takes {n} argument{}, found {}",
                    if n == 1 { "" } else { "s" },
                    args.len()
                );
                p.error(codes::EXPECTED, span, msg);
                false
            } else {
                true
            }
        };
        if l.items[0].keyword().is_some() {
            self.expected("a formula", Some(&l.items[0]), l.items[0].span());
            return None;
        }
        Some(match head {
            "and" => Formula::And {
                parts: args.iter().filter_map(|a| self.formula(a)).collect(),
                span,
            },
            "or" => Formula::Or {
                parts: args.iter().filter_map(|a| self.formula(a)).collect(),
                span,
            },
            "not" => {
                if !arity(self, 1) {
                    return None;
                }
                Formula::Not {
                    formula: Box::new(self.formula(&args[0])?),
                    span,
                }
            }
            "imply" => {
                if !arity(self, 2) {
                    return None;
                }
                let left = self.formula(&args[0]);
                let right = self.formula(&args[1]);
                Formula::Imply {
                    left: Box::new(left?),
                    right: Box::new(right?),
                    span,
                }
            }
            "exists" | "forall" => {
                if !arity(self, 2) {
                    return None;
                }
                let vars = self.quantified_vars(&args[0])?;
                let body = Box::new(self.formula(&args[1])?);
                if head == "exists" {
                    Formula::Exists { vars, body, span }
                } else {
                    Formula::Forall { vars, body, span }
                }
            }
            "=" if args.iter().all(|a| a.as_list().is_none()) => {
                if !arity(self, 2) {
                    return None;
                }
                let left = self.term(&args[0]);
                let right = self.term(&args[1]);
                Formula::Equal {
                    left: left?,
                    right: right?,
                    span,
                }
            }
            "=" | "<" | "<=" | ">" | ">=" => {
                if !arity(self, 2) {
                    return None;
                }
                let op = match head {
                    "=" => Comparison::Eq,
                    "<" => Comparison::Lt,
                    "<=" => Comparison::Le,
                    ">" => Comparison::Gt,
                    _ => Comparison::Ge,
                };
                let left = self.num_expr(&args[0]);
                let right = self.num_expr(&args[1]);
                Formula::Compare {
                    op,
                    left: left?,
                    right: right?,
                    span,
                }
            }
            "preference" => {
                self.unsupported(span, "`preference` (PDDL3 preferences)");
                return None;
            }
            "at" | "over"
                if args.len() == 2
                    && name_of(&args[0])
                        .is_some_and(|n| matches!(n.name.as_str(), "start" | "end" | "all")) =>
            {
                self.error(codes::EXPECTED, span, "a timed condition is allowed only directly under a durative action's `:condition`");
                return None;
            }
            h if OPERATORS.contains(&h) => {
                self.expected("a formula", Some(s), span);
                return None;
            }
            _ => Formula::Atom {
                atom: self.atom(l)?,
            },
        })
    }

    pub(super) fn effect(&mut self, s: &Sexp) -> Option<Effect> {
        let Some(l) = s.as_list() else {
            self.expected("an effect such as `(on ?x ?y)`", Some(s), s.span());
            return None;
        };
        let span = l.span;
        let Some(head) = l.head() else {
            if l.items.is_empty() {
                return Some(Effect::empty(span));
            }
            self.expected(
                "a predicate or `and`, `not`, `forall`, `when`",
                l.items.first(),
                span,
            );
            return None;
        };
        if l.items[0].keyword().is_some() {
            self.expected("an effect", Some(&l.items[0]), l.items[0].span());
            return None;
        }
        let args = &l.items[1..];
        let count = |p: &mut Parser, n: usize| {
            if args.len() != n {
                p.error(
                    codes::EXPECTED,
                    span,
                    format!("`{head}` takes {n} arguments, found {}", args.len()),
                );
                false
            } else {
                true
            }
        };
        Some(match head {
            "and" => Effect::And {
                parts: args.iter().filter_map(|a| self.effect(a)).collect(),
                span,
            },
            "not" => {
                if !count(self, 1) {
                    return None;
                }
                match args[0]
                    .as_list()
                    .filter(|al| al.head().is_some() && al.items[0].keyword().is_none())
                {
                    Some(al) => Effect::Delete {
                        atom: self.atom(al)?,
                        span,
                    },
                    None => {
                        self.expected(
                            "an atom such as `(on ?x ?y)` inside `not`",
                            Some(&args[0]),
                            args[0].span(),
                        );
                        return None;
                    }
                }
            }
            "forall" => {
                if !count(self, 2) {
                    return None;
                }
                let vars = self.quantified_vars(&args[0])?;
                Effect::Forall {
                    vars,
                    body: Box::new(self.effect(&args[1])?),
                    span,
                }
            }
            "when" => {
                if !count(self, 2) {
                    return None;
                }
                let condition = self.formula(&args[0]);
                let body = self.effect(&args[1]);
                Effect::When {
                    condition: condition?,
                    body: Box::new(body?),
                    span,
                }
            }
            "assign" | "increase" | "decrease" | "scale-up" | "scale-down" => {
                if !count(self, 2) {
                    return None;
                }
                let op = match head {
                    "assign" => AssignOp::Assign,
                    "increase" => AssignOp::Increase,
                    "decrease" => AssignOp::Decrease,
                    "scale-up" => AssignOp::ScaleUp,
                    _ => AssignOp::ScaleDown,
                };
                let fluent = match args[0].as_list().filter(|fl| fl.head().is_some()) {
                    Some(fl) => self.atom(fl)?,
                    None => {
                        self.expected(
                            "a function such as `(total-cost)`",
                            Some(&args[0]),
                            args[0].span(),
                        );
                        return None;
                    }
                };
                Effect::Numeric {
                    op,
                    fluent,
                    value: self.num_expr(&args[1])?,
                    span,
                }
            }
            "at" if args.len() == 2
                && matches!(args[0].tok(), Some(Tok::Name(n)) if n == "start" || n == "end") =>
            {
                self.error(
                    codes::EXPECTED,
                    span,
                    "a timed effect is allowed only directly under a durative action's `:effect`",
                );
                return None;
            }
            h if OPERATORS.contains(&h) || h == "or" || h == "exists" || h == "imply" => {
                self.expected(
                    "an effect (`and`, `not`, `forall`, `when`, a numeric update or an atom)",
                    Some(s),
                    span,
                );
                return None;
            }
            _ => Effect::Add {
                atom: self.atom(l)?,
            },
        })
    }

    pub(super) fn num_expr(&mut self, s: &Sexp) -> Option<NumExpr> {
        match s {
            Sexp::Atom(t) => match &t.tok {
                Tok::Number(value) => Some(NumExpr::Number {
                    value: *value,
                    span: t.span,
                }),
                Tok::Var(v) if v == "duration" => Some(NumExpr::Duration { span: t.span }),
                _ => {
                    self.expected(
                        "a number or a function such as `(total-cost)`",
                        Some(s),
                        t.span,
                    );
                    None
                }
            },
            Sexp::List(l) => {
                let span = l.span;
                let op = match l.items.first().and_then(Sexp::tok) {
                    Some(Tok::Dash) => Some(NumOp::Sub),
                    Some(Tok::Name(n)) => match n.as_str() {
                        "+" => Some(NumOp::Add),
                        "*" => Some(NumOp::Mul),
                        "/" => Some(NumOp::Div),
                        _ => None,
                    },
                    _ => None,
                };
                match op {
                    Some(NumOp::Sub) if l.items.len() == 2 => {
                        let expr = Box::new(self.num_expr(&l.items[1])?);
                        Some(NumExpr::Neg { expr, span })
                    }
                    Some(op) if l.items.len() >= 3 => {
                        // (+ a b c) folds left: ((a + b) + c)
                        let mut acc = self.num_expr(&l.items[1])?;
                        for r in &l.items[2..] {
                            let right = self.num_expr(r)?;
                            acc = NumExpr::Binary {
                                op,
                                left: Box::new(acc),
                                right: Box::new(right),
                                span,
                            };
                        }
                        Some(acc)
                    }
                    Some(_) => {
                        self.expected("two operands", None, span);
                        None
                    }
                    None => match l.head() {
                        Some(_) if l.items[0].keyword().is_none() => {
                            Some(NumExpr::Fluent { app: self.atom(l)? })
                        }
                        _ => {
                            self.expected("a numeric expression", Some(s), span);
                            None
                        }
                    },
                }
            }
        }
    }

    pub(super) fn init_fact(&mut self, s: &Sexp) -> Option<InitFact> {
        let Some(l) = s
            .as_list()
            .filter(|l| l.head().is_some() && l.items[0].keyword().is_none())
        else {
            self.expected("a fact such as `(on a b)`", Some(s), s.span());
            return None;
        };
        match l.head() {
            Some("=") if l.items.len() == 3 && l.items[1].as_list().is_some() => {
                let fl = l.items[1].as_list().expect("checked");
                let fluent = match fl.head() {
                    Some(_) => self.atom(fl)?,
                    None => {
                        self.expected(
                            "a function such as `(total-cost)`",
                            Some(&l.items[1]),
                            fl.span,
                        );
                        return None;
                    }
                };
                match l.items[2].tok() {
                    Some(Tok::Number(value)) => Some(InitFact::Value {
                        fluent,
                        value: *value,
                        span: l.span,
                    }),
                    _ => {
                        self.expected("a number", Some(&l.items[2]), l.items[2].span());
                        None
                    }
                }
            }
            Some("at")
                if l.items.len() == 3 && matches!(l.items[1].tok(), Some(Tok::Number(_))) =>
            {
                self.unsupported(
                    l.span,
                    "a timed initial literal (`:timed-initial-literals`)",
                );
                None
            }
            Some("not") => {
                self.error(
                    codes::EXPECTED,
                    l.span,
                    "`:init` lists only what is true; leave out what is false",
                )
                .hint = Some("PDDL assumes that facts not listed in `:init` are false".into());
                None
            }
            Some(h) if OPERATORS.contains(&h) || h == "and" => {
                self.expected("a fact such as `(on a b)`", Some(s), l.span);
                None
            }
            _ => Some(InitFact::Atom {
                atom: self.atom(l)?,
            }),
        }
    }

    pub(super) fn metric(&mut self, l: &List) -> Option<Metric> {
        let optimize = match l
            .items
            .get(1)
            .and_then(name_of)
            .as_ref()
            .map(|n| n.name.as_str())
        {
            Some("minimize") => Optimize::Minimize,
            Some("maximize") => Optimize::Maximize,
            _ => {
                self.expected("`minimize` or `maximize`", l.items.get(1), l.span);
                return None;
            }
        };
        let Some(e) = l.items.get(2) else {
            self.expected("the expression to optimize", None, l.span);
            return None;
        };
        let expr = self.num_expr(e)?;
        Some(Metric {
            optimize,
            expr,
            span: l.span,
        })
    }
}

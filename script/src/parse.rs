//! Script text to expression trees: a Pratt parser with BT.CPP's binding
//! powers (assignment loosest, then `?:`, `||`, `&&`, comparisons, which
//! chain, `|` `^`, `&`, `+` `-` `..`, `*` `/`, and the prefix operators).

use super::lex::{tokens, Tok};
use super::{Problem, SyntaxError};
use std::ops::Range;
use std::rc::Rc;

/// How deeply a script may nest (brackets, prefix operators, right-hand
/// sides); deeper scripts are refused rather than recursed into.
pub const MAX_NESTING: usize = 64;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unary {
    Negate,
    Complement,
    Not,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Binary {
    Plus,
    Minus,
    Times,
    Div,
    Concat,
    BitAnd,
    BitOr,
    BitXor,
    And,
    Or,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compare {
    Eq,
    Ne,
    Lt,
    Gt,
    Le,
    Ge,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Assign {
    /// `:=` creates the entry.
    Create,
    /// `=` needs an existing entry.
    Existing,
    Plus,
    Minus,
    Times,
    Div,
}

/// A literal as BT.CPP reads it: integers stay integers until they meet
/// an operator; `true` and `false` are the doubles 1 and 0.
#[derive(Clone, Debug, PartialEq)]
pub enum Literal {
    Int(i64),
    Float(f64),
    /// Shared, so that evaluating the literal copies no text.
    Text(Rc<str>),
}

#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    Lit(Literal),
    /// A variable: an index into [`Script::vars`].
    Var(u32),
    Unary(Unary, Box<Expr>),
    Binary(Binary, Box<Expr>, Box<Expr>),
    /// `a < b <= c`: each pair compared, all must hold.
    Compare(Vec<Compare>, Vec<Expr>),
    If(Box<Expr>, Box<Expr>, Box<Expr>),
    /// The left side is a variable, or an error when evaluated (as BT.CPP).
    Assign(Assign, Box<Expr>, Box<Expr>),
}

/// A parsed script: its statements and the variables they name.
#[derive(Clone, Debug, PartialEq)]
pub struct Script {
    pub statements: Vec<Expr>,
    pub vars: Vec<String>,
}

/// Parses a script (statements separated by `;`).
pub fn parse(src: &str) -> Result<Script, SyntaxError> {
    let toks = tokens(src)?;
    let mut p = Parser {
        toks,
        pos: 0,
        vars: Vec::new(),
    };
    let mut statements = Vec::new();
    while p.peek() != &Tok::End {
        statements.push(p.expr(0, 0)?);
        while p.peek() == &Tok::Op(";") {
            p.pos += 1;
        }
    }
    if statements.is_empty() {
        return Err(SyntaxError {
            problem: Problem::Empty,
            span: 0..0,
        });
    }
    Ok(Script {
        statements,
        vars: p.vars,
    })
}

struct Parser {
    toks: Vec<(Tok, Range<usize>)>,
    pos: usize,
    vars: Vec<String>,
}

const PREFIX: u8 = 20;
const COMPARE: u8 = 10;
const TERNARY: u8 = 4;

fn infix(t: &Tok) -> Option<u8> {
    let Tok::Op(op) = t else { return None };
    Some(match *op {
        ":=" | "=" | "+=" | "-=" | "*=" | "/=" => 2,
        "?" => TERNARY,
        "||" => 6,
        "&&" => 8,
        "==" | "!=" | "<" | ">" | "<=" | ">=" => COMPARE,
        "|" | "^" => 12,
        "&" => 14,
        "+" | "-" | ".." => 16,
        "*" | "/" => 18,
        _ => return None,
    })
}

impl Parser {
    fn peek(&self) -> &Tok {
        &self.toks[self.pos].0
    }

    fn span(&self) -> Range<usize> {
        self.toks[self.pos].1.clone()
    }

    fn next(&mut self) -> Tok {
        let t = self.toks[self.pos].0.clone();
        if t != Tok::End {
            self.pos += 1;
        }
        t
    }

    fn error(&self, expected: &'static str) -> SyntaxError {
        let got = match self.peek() {
            Tok::End => None,
            t => Some(show(t)),
        };
        SyntaxError {
            problem: Problem::Unexpected { expected, got },
            span: self.span(),
        }
    }

    fn var(&mut self, name: String) -> u32 {
        match self.vars.iter().position(|v| *v == name) {
            Some(i) => i as u32,
            None => {
                self.vars.push(name);
                (self.vars.len() - 1) as u32
            }
        }
    }

    fn prefix(&mut self, depth: usize) -> Result<Expr, SyntaxError> {
        if depth > MAX_NESTING {
            return Err(SyntaxError {
                problem: Problem::TooDeep,
                span: self.span(),
            });
        }
        let unary = |p: &mut Parser, op| -> Result<Expr, SyntaxError> {
            p.pos += 1;
            Ok(Expr::Unary(op, Box::new(p.expr(PREFIX, depth + 1)?)))
        };
        match self.peek().clone() {
            Tok::Op("-") => unary(self, Unary::Negate),
            Tok::Op("~") => unary(self, Unary::Complement),
            Tok::Op("!") => unary(self, Unary::Not),
            Tok::Op("(") => {
                self.pos += 1;
                let e = self.expr(0, depth + 1)?;
                if self.peek() != &Tok::Op(")") {
                    return Err(self.error("expected `)`"));
                }
                self.pos += 1;
                Ok(e)
            }
            Tok::Bool(b) => {
                self.pos += 1;
                Ok(Expr::Lit(Literal::Float(if b { 1.0 } else { 0.0 })))
            }
            Tok::Int(n) => {
                self.pos += 1;
                Ok(Expr::Lit(Literal::Int(n)))
            }
            Tok::Real(f) => {
                self.pos += 1;
                Ok(Expr::Lit(Literal::Float(f)))
            }
            Tok::Str(s) => {
                self.pos += 1;
                Ok(Expr::Lit(Literal::Text(s.as_str().into())))
            }
            Tok::Ident(name) => {
                self.pos += 1;
                Ok(Expr::Var(self.var(name)))
            }
            _ => Err(self.error("expected an operand")),
        }
    }

    fn expr(&mut self, min: u8, depth: usize) -> Result<Expr, SyntaxError> {
        let mut left = self.prefix(depth)?;
        while let Some(bp) = infix(self.peek()) {
            if bp < min {
                break;
            }
            let Tok::Op(op) = self.next() else { break };
            match op {
                ":=" | "=" | "+=" | "-=" | "*=" | "/=" => {
                    let a = match op {
                        ":=" => Assign::Create,
                        "=" => Assign::Existing,
                        "+=" => Assign::Plus,
                        "-=" => Assign::Minus,
                        "*=" => Assign::Times,
                        _ => Assign::Div,
                    };
                    let right = self.expr(0, depth + 1)?;
                    return Ok(Expr::Assign(a, Box::new(left), Box::new(right)));
                }
                "?" => {
                    let then = self.expr(0, depth + 1)?;
                    if self.peek() != &Tok::Op(":") {
                        return Err(self.error("expected `:` in a `?:` expression"));
                    }
                    self.pos += 1;
                    let other = self.expr(TERNARY, depth + 1)?;
                    return Ok(Expr::If(Box::new(left), Box::new(then), Box::new(other)));
                }
                "==" | "!=" | "<" | ">" | "<=" | ">=" => {
                    let mut ops = Vec::new();
                    let mut operands = vec![left];
                    let mut op = op;
                    loop {
                        ops.push(compare(op));
                        operands.push(self.expr(COMPARE + 1, depth + 1)?);
                        match self.peek() {
                            Tok::Op(o) if infix(self.peek()) == Some(COMPARE) => {
                                op = o;
                                self.pos += 1;
                            }
                            _ => break,
                        }
                    }
                    left = Expr::Compare(ops, operands);
                }
                _ => {
                    let b = match op {
                        "+" => Binary::Plus,
                        "-" => Binary::Minus,
                        "*" => Binary::Times,
                        "/" => Binary::Div,
                        ".." => Binary::Concat,
                        "&" => Binary::BitAnd,
                        "|" => Binary::BitOr,
                        "^" => Binary::BitXor,
                        "&&" => Binary::And,
                        _ => Binary::Or,
                    };
                    let right = self.expr(bp + 1, depth + 1)?;
                    left = Expr::Binary(b, Box::new(left), Box::new(right));
                }
            }
        }
        Ok(left)
    }
}

fn compare(op: &str) -> Compare {
    match op {
        "==" => Compare::Eq,
        "!=" => Compare::Ne,
        "<" => Compare::Lt,
        ">" => Compare::Gt,
        "<=" => Compare::Le,
        _ => Compare::Ge,
    }
}

fn show(t: &Tok) -> String {
    match t {
        Tok::Int(n) => n.to_string(),
        Tok::Real(f) => f.to_string(),
        Tok::Str(s) => format!("'{s}'"),
        Tok::Bool(b) => b.to_string(),
        Tok::Ident(s) => s.clone(),
        Tok::Op(o) => (*o).to_owned(),
        Tok::End => String::new(),
    }
}

//! Evaluating compiled conditions, numeric expressions and effects in a
//! state. A binding holds one object id per slot; quantifiers push theirs
//! while they evaluate their body.

use super::compile::{CTerm, Cond, Eff, Num, Quant};
use super::{Changes, Key, NumericError, State, World};
use crate::ast::{AssignOp, Comparison, NumOp};

/// Atoms of more arguments are keyed through the heap.
const INLINE_KEY: usize = 16;

impl World {
    fn object(t: CTerm, b: &[u32]) -> u32 {
        match t {
            CTerm::Obj(o) => o,
            CTerm::Slot(s) => b[s as usize],
        }
    }

    /// Calls `f` with the key `[head, args...]` under binding `b`.
    fn with_key<R>(head: u32, args: &[CTerm], b: &[u32], f: impl FnOnce(&[u32]) -> R) -> R {
        if args.len() < INLINE_KEY {
            let mut buf = [0u32; INLINE_KEY];
            buf[0] = head;
            for (i, a) in args.iter().enumerate() {
                buf[i + 1] = Self::object(*a, b);
            }
            f(&buf[..=args.len()])
        } else {
            let k: Vec<u32> = std::iter::once(head)
                .chain(args.iter().map(|a| Self::object(*a, b)))
                .collect();
            f(&k)
        }
    }

    fn key(head: u32, args: &[CTerm], b: &[u32]) -> super::Key {
        Self::with_key(head, args, b, |k| k.into())
    }

    /// Calls `f` with `b` extended by each binding of `q`; stops (and
    /// returns true) when `f` returns true.
    pub(crate) fn any_binding(
        q: &Quant,
        b: &mut Vec<u32>,
        f: &mut dyn FnMut(&mut Vec<u32>) -> bool,
    ) -> bool {
        fn go(
            ranges: &[std::sync::Arc<[u32]>],
            b: &mut Vec<u32>,
            f: &mut dyn FnMut(&mut Vec<u32>) -> bool,
        ) -> bool {
            let Some((first, rest)) = ranges.split_first() else {
                return f(b);
            };
            for &o in first.iter() {
                b.push(o);
                let stop = go(rest, b, f);
                b.pop();
                if stop {
                    return true;
                }
            }
            false
        }
        go(&q.ranges, b, f)
    }

    /// Whether `c` holds in `s` under binding `b`; `duration` is a durative
    /// step's `?duration`.
    pub fn holds(&self, s: &State, c: &Cond, b: &mut Vec<u32>, duration: Option<f64>) -> bool {
        match c {
            Cond::Atom {
                pred,
                derived,
                args,
            } => Self::with_key(*pred, args, b, |k| {
                if *derived {
                    s.derived.contains(k)
                } else {
                    s.facts.contains(k)
                }
            }),
            Cond::Eq(l, r) => Self::object(*l, b) == Self::object(*r, b),
            Cond::Not(x) => !self.holds(s, x, b, duration),
            Cond::And(ps) => ps.iter().all(|p| self.holds(s, p, b, duration)),
            Cond::Or(ps) => ps.iter().any(|p| self.holds(s, p, b, duration)),
            Cond::Imply(l, r) => !self.holds(s, l, b, duration) || self.holds(s, r, b, duration),
            Cond::Exists(q, body) => {
                Self::any_binding(q, b, &mut |b| self.holds(s, body, b, duration))
            }
            Cond::Forall(q, body) => {
                !Self::any_binding(q, b, &mut |b| !self.holds(s, body, b, duration))
            }
            Cond::Compare(op, l, r) => {
                match (self.value(s, l, b, duration), self.value(s, r, b, duration)) {
                    (Some(x), Some(y)) => match op {
                        Comparison::Lt => x < y,
                        Comparison::Le => x <= y,
                        Comparison::Gt => x > y,
                        Comparison::Ge => x >= y,
                        Comparison::Eq => x == y,
                    },
                    _ => false,
                }
            }
        }
    }

    /// A numeric expression's value; `None` when a fluent is undefined.
    pub fn value(&self, s: &State, e: &Num, b: &[u32], duration: Option<f64>) -> Option<f64> {
        Some(match e {
            Num::Const(v) => *v,
            Num::Fluent { func, args } => {
                Self::with_key(*func, args, b, |k| s.fluents.get(k).copied())?
            }
            Num::Undefined => return None,
            Num::Duration => duration?,
            Num::Bin(op, l, r) => {
                let (x, y) = (
                    self.value(s, l, b, duration)?,
                    self.value(s, r, b, duration)?,
                );
                match op {
                    NumOp::Add => x + y,
                    NumOp::Sub => x - y,
                    NumOp::Mul => x * y,
                    NumOp::Div => x / y,
                }
            }
            Num::Neg(x) => -self.value(s, x, b, duration)?,
        })
    }

    /// Why a condition that does not hold fails, in the user's terms: the
    /// first failing literal with its arguments filled in, and the path to
    /// it (child positions: `and`/`or` parts, `imply` 0 and 1, the body of
    /// `not` and quantifiers 0), which [`crate::logic::span_at`] turns
    /// into a span of the formula it was compiled from.
    pub fn why_not(
        &self,
        s: &State,
        c: &Cond,
        b: &mut Vec<u32>,
        duration: Option<f64>,
    ) -> (String, Vec<usize>) {
        let mut path = Vec::new();
        let why = self.why(s, c, b, duration, &mut path);
        (why, path)
    }

    fn why(
        &self,
        s: &State,
        c: &Cond,
        b: &mut Vec<u32>,
        duration: Option<f64>,
        path: &mut Vec<usize>,
    ) -> String {
        match c {
            Cond::Atom { pred, args, .. } => {
                format!("`{}` is false", self.show_ground(*pred, args, b))
            }
            Cond::Eq(l, r) => format!(
                "`{}` and `{}` are different objects",
                self.object_name(Self::object(*l, b)),
                self.object_name(Self::object(*r, b))
            ),
            Cond::Not(x) => match &**x {
                Cond::Atom { pred, args, .. } => format!(
                    "`{}` is true, but must be false",
                    self.show_ground(*pred, args, b)
                ),
                Cond::Eq(l, r) => format!(
                    "`{}` and `{}` are the same object, but must differ",
                    self.object_name(Self::object(*l, b)),
                    self.object_name(Self::object(*r, b))
                ),
                _ => "a negated condition holds".to_owned(),
            },
            Cond::And(ps) => match ps.iter().position(|p| !self.holds(s, p, b, duration)) {
                Some(i) => {
                    path.push(i);
                    self.why(s, &ps[i], b, duration, path)
                }
                None => String::new(),
            },
            Cond::Or(ps) => {
                // Each alternative's reason, once: a long disjunction (the
                // remaining-plan conditions of `steps backchained`) often
                // fails for a handful of facts.
                let mut whys: Vec<String> = Vec::new();
                for p in ps {
                    let why = self.why(s, p, b, duration, &mut Vec::new());
                    if !whys.contains(&why) {
                        whys.push(why);
                    }
                }
                const SHOWN: usize = 12;
                let more = whys.len().saturating_sub(SHOWN);
                whys.truncate(SHOWN);
                let mut out = "none of the alternatives of an `or` holds".to_owned();
                if !whys.is_empty() {
                    out.push_str(": ");
                    out.push_str(&whys.join("; "));
                }
                if more > 0 {
                    out.push_str(&format!("; and {more} more"));
                }
                out
            }
            Cond::Imply(_, r) => {
                path.push(1);
                let why = self.why(s, r, b, duration, path);
                format!("the condition of an `imply` holds, but {why}")
            }
            Cond::Exists(q, _) => {
                let vs: Vec<String> = q.names.iter().map(|v| format!("?{v}")).collect();
                format!("no choice of {} satisfies an `exists`", vs.join(" "))
            }
            Cond::Forall(q, body) => {
                let mut found = None;
                let mark = b.len();
                Self::any_binding(q, b, &mut |b| {
                    if self.holds(s, body, b, duration) {
                        return false;
                    }
                    let bound: Vec<String> = q
                        .names
                        .iter()
                        .zip(&b[mark..])
                        .map(|(v, o)| format!("?{v} = {}", self.object_name(*o)))
                        .collect();
                    let mut inner = vec![0];
                    let why = self.why(s, body, b, duration, &mut inner);
                    found = Some((format!("for {}: {why}", bound.join(", ")), inner));
                    true
                });
                match found {
                    Some((why, inner)) => {
                        path.extend(inner);
                        why
                    }
                    None => String::new(),
                }
            }
            Cond::Compare(..) => "a numeric comparison does not hold".to_owned(),
        }
    }

    /// `(pred a b)` under a binding.
    fn show_ground(&self, pred: u32, args: &[crate::state::CTerm], b: &[u32]) -> String {
        Self::with_key(pred, args, b, |k| self.show_atom(k))
    }

    /// Collects the changes of an effect, evaluated in `s` (the state before).
    pub fn collect(
        &self,
        s: &State,
        e: &Eff,
        b: &mut Vec<u32>,
        duration: Option<f64>,
        changes: &mut Changes,
    ) {
        let mut collect = Collect {
            world: self,
            s,
            duration,
            changes,
        };
        self.walk_effect(s, e, b, duration, &mut collect);
    }

    /// Walks the parts of effect `e` that apply in `s` under binding `b`:
    /// each atom it adds or deletes and each fluent it assigns, through
    /// `and`, every binding of a `forall`, and the `when`s whose condition
    /// holds (every `when`'s condition is shown to `v` first).
    pub fn walk_effect(
        &self,
        s: &State,
        e: &Eff,
        b: &mut Vec<u32>,
        duration: Option<f64>,
        v: &mut dyn EffectVisitor,
    ) {
        match e {
            Eff::Add { pred, args } => v.atom(true, Self::key(*pred, args, b)),
            Eff::Del { pred, args } => v.atom(false, Self::key(*pred, args, b)),
            Eff::And(ps) => {
                for p in ps {
                    self.walk_effect(s, p, b, duration, v);
                }
            }
            Eff::Forall(q, body) => {
                Self::any_binding(q, b, &mut |b| {
                    self.walk_effect(s, body, b, duration, v);
                    false
                });
            }
            Eff::When(c, body) => {
                v.condition(c, b);
                if self.holds(s, c, b, duration) {
                    self.walk_effect(s, body, b, duration, v);
                }
            }
            Eff::Numeric {
                op,
                func,
                args,
                value,
            } => v.numeric(*op, Self::key(*func, args, b), value, b),
        }
    }

    /// Recomputes every derived atom, stratum by stratum, to a fixpoint.
    pub fn close_derived(&self, s: &mut State) {
        if self.strata.is_empty() {
            return;
        }
        s.derived.clear();
        let mut b = Vec::new();
        let mut key: Vec<u32> = Vec::new();
        for stratum in &self.strata {
            loop {
                let mut found: Vec<super::Key> = Vec::new();
                for &r in stratum {
                    let rule = &self.rules[r];
                    b.clear();
                    Self::any_binding(&rule.params, &mut b, &mut |b| {
                        key.clear();
                        key.push(rule.head);
                        key.extend_from_slice(b);
                        if !s.derived.contains(&key[..]) && self.holds(s, &rule.body, b, None) {
                            found.push(key.as_slice().into());
                        }
                        false
                    });
                }
                if found.is_empty() {
                    break;
                }
                s.derived.extend(found);
            }
        }
    }
}

/// What an effect does, part by part, as [`World::walk_effect`] meets the
/// parts: applying it ([`World::collect`]) and finding what it touches
/// (the interference of timed plans) are two visitors.
pub trait EffectVisitor {
    /// An atom added (`positive`) or deleted.
    fn atom(&mut self, positive: bool, atom: Key);
    /// A fluent assigned or updated by `op` with `value` under binding `b`.
    fn numeric(&mut self, op: AssignOp, fluent: Key, value: &Num, b: &mut Vec<u32>);
    /// A `when`'s condition, before it is evaluated.
    fn condition(&mut self, _c: &Cond, _b: &mut Vec<u32>) {}
}

/// The changes of an effect in a state, collected as they are met.
struct Collect<'a> {
    world: &'a World,
    s: &'a State,
    duration: Option<f64>,
    changes: &'a mut Changes,
}

impl EffectVisitor for Collect<'_> {
    fn atom(&mut self, positive: bool, atom: Key) {
        if positive {
            self.changes.add.push(atom);
        } else {
            self.changes.delete.push(atom);
        }
    }

    fn numeric(&mut self, op: AssignOp, key: Key, value: &Num, b: &mut Vec<u32>) {
        let old = self.s.fluents.get(&key).copied();
        let v = self.world.value(self.s, value, b, self.duration);
        let new = match (op, old, v) {
            (AssignOp::Assign, _, Some(v)) => Some(v),
            (AssignOp::Increase, Some(o), Some(v)) => Some(o + v),
            (AssignOp::Decrease, Some(o), Some(v)) => Some(o - v),
            (AssignOp::ScaleUp, Some(o), Some(v)) => Some(o * v),
            (AssignOp::ScaleDown, Some(o), Some(v)) => Some(o / v),
            _ => None,
        };
        match new {
            Some(n) => self.changes.numeric.push((key, n)),
            None => self.changes.numeric_errors.push(NumericError {
                fluent: self.world.show_fluent(&key),
            }),
        }
    }
}

//! The reader's primitives: a mapping's fields (asked for, needed, left
//! over), scalars checked against what they should be, part kinds, lists of
//! parts, and the fields btc reads but does not simulate.

use super::*;

pub(super) struct Reader {
    pub(super) file: FileId,
    pub(super) diags: Vec<Diagnostic>,
    /// Fields read but not simulated: name -> (first place, count, why).
    pub(super) unsimulated: BTreeMap<&'static str, (Range, usize, &'static str)>,
}

/// One entry of a list of parts: its kind (`None` when it did not read),
/// what its own fields gave, and where it is.
pub(super) struct Part<'a, X> {
    pub(super) kind: Option<PartKind>,
    pub(super) own: X,
    pub(super) node: &'a Node,
}

/// A mapping being read: which keys were asked for.
pub(super) struct Fields<'a> {
    pub(super) node: &'a Node,
    pub(super) items: &'a [(Node, Node)],
    pub(super) used: Vec<bool>,
    pub(super) what: String,
}

impl<'a> Fields<'a> {
    pub(super) fn get(&mut self, key: &str) -> Option<&'a Node> {
        let k = self
            .items
            .iter()
            .position(|(k, _)| k.as_text() == Some(key))?;
        self.used[k] = true;
        Some(&self.items[k].1)
    }

    pub(super) fn has(&self, key: &str) -> bool {
        self.items.iter().any(|(k, _)| k.as_text() == Some(key))
    }
}

impl Reader {
    pub(super) fn span(&self, r: Range) -> Span {
        Span::new(self.file, r.start, r.end)
    }

    pub(super) fn error(
        &mut self,
        code: Code,
        r: Range,
        msg: impl Into<String>,
    ) -> &mut Diagnostic {
        self.diags
            .push(Diagnostic::error(code, self.span(r), msg.into()));
        self.diags.last_mut().expect("just pushed")
    }

    /// T006 for something given twice, labelled where it was given first.
    pub(super) fn twice(&mut self, r: Range, msg: impl Into<String>, first: Range, label: &str) {
        let first = self.span(first);
        self.error(codes::TRIAL_DUPLICATE, r, msg)
            .labels
            .push(btc_pddl::diagnostic::Label {
                span: first,
                message: label.into(),
            });
    }

    pub(super) fn warn(&mut self, code: Code, r: Range, msg: impl Into<String>) -> &mut Diagnostic {
        self.diags
            .push(Diagnostic::warning(code, self.span(r), msg.into()));
        self.diags.last_mut().expect("just pushed")
    }

    /// `node` as a mapping, or a T003 error.
    pub(super) fn fields<'a>(&mut self, node: &'a Node, what: &str) -> Option<Fields<'a>> {
        match node.as_map() {
            Some(items) => Some(Fields {
                node,
                items,
                used: vec![false; items.len()],
                what: what.to_owned(),
            }),
            None => {
                self.error(
                    codes::TRIAL_VALUE,
                    node.range,
                    format!(
                        "{what} must be a mapping (`key: value` lines), not {}",
                        node.kind()
                    ),
                );
                None
            }
        }
    }

    /// A field that must be there (T002 on the mapping otherwise).
    pub(super) fn need<'a>(&mut self, f: &mut Fields<'a>, key: &str) -> Option<&'a Node> {
        let v = f.get(key);
        if v.is_none() {
            let message = format!(
                "{} has no `{key}`, which the ARIAC 2023 trial format requires",
                f.what
            );
            self.missing(f.node, message);
        }
        v
    }

    /// T002 at the start of `node`: something it should have is not there.
    pub(super) fn missing(&mut self, node: &Node, msg: impl Into<String>) {
        let at = Range {
            start: node.range.start,
            end: node.range.start,
        };
        self.error(codes::TRIAL_MISSING, at, msg);
    }

    /// Keys nobody asked for: not in the format (T004, a warning).
    pub(super) fn done(&mut self, f: Fields<'_>, known: &[&str]) {
        for ((k, _), used) in f.items.iter().zip(&f.used) {
            if *used {
                continue;
            }
            let name = k.as_text().unwrap_or("?").to_owned();
            let hint = did_you_mean(&name, known.iter().copied())
                .unwrap_or_else(|| format!("{} has {}", f.what, quote_all(known)));
            self.warn(
                codes::TRIAL_UNKNOWN_FIELD,
                k.range,
                format!(
                    "`{name}` is not a field of {} in the ARIAC 2023 trial format; btc ignores it",
                    f.what
                ),
            )
            .hint = Some(hint);
        }
    }

    pub(super) fn unsimulated(&mut self, name: &'static str, node: &Node, why: &'static str) {
        let e = self.unsimulated.entry(name).or_insert((node.range, 0, why));
        e.1 += 1;
    }

    pub(super) fn report_unsimulated(&mut self) {
        let all = std::mem::take(&mut self.unsimulated);
        for (name, (r, n, why)) in all {
            let times = if n == 1 {
                "once".to_owned()
            } else {
                format!("{n} times")
            };
            self.warn(
                codes::TRIAL_NOT_SIMULATED,
                r,
                format!("`{name}` (given {times}) is read but not simulated: {why}"),
            );
        }
    }

    pub(super) fn wrong(&mut self, node: &Node, what: &str, expected: &str) {
        self.error(
            codes::TRIAL_VALUE,
            node.range,
            format!("{what} must be {expected}, not {}", describe(node)),
        );
    }

    /// A tray quadrant (1 to 4) and where it is written.
    pub(super) fn quadrant(&mut self, f: &mut Fields<'_>) -> Option<(u8, Range)> {
        let n = self.need(f, "quadrant")?;
        self.int(n, "a quadrant", 1, 4).map(|q| (q as u8, n.range))
    }

    /// A part's quadrant, when no part before it (`used`: their quadrants)
    /// has it; otherwise `message` as an error at it.
    pub(super) fn free_quadrant(
        &mut self,
        quadrant: Option<(u8, Range)>,
        mut used: impl Iterator<Item = u8>,
        message: impl FnOnce(u8) -> String,
    ) -> Option<u8> {
        let (q, at) = quadrant?;
        if used.any(|u| u == q) {
            self.error(codes::TRIAL_DUPLICATE, at, message(q));
            return None;
        }
        Some(q)
    }

    pub(super) fn int(&mut self, node: &Node, what: &str, lo: i64, hi: i64) -> Option<i64> {
        match node.scalar() {
            Some(ScalarKind::Int(n)) if (lo..=hi).contains(&n) => Some(n),
            Some(ScalarKind::Float(x))
                if x.fract() == 0.0 && (lo as f64..=hi as f64).contains(&x) =>
            {
                Some(x as i64)
            }
            _ => {
                self.wrong(node, what, &format!("a whole number from {lo} to {hi}"));
                None
            }
        }
    }

    pub(super) fn number(&mut self, node: &Node, what: &str) -> Option<f64> {
        match node.scalar() {
            Some(ScalarKind::Int(n)) => Some(n as f64),
            Some(ScalarKind::Float(x)) if x.is_finite() => Some(x),
            // ARIAC's reader calls float() on these, which takes quoted numbers.
            Some(ScalarKind::Text) => {
                match node.as_text().and_then(|t| t.trim().parse::<f64>().ok()) {
                    Some(x) if x.is_finite() => Some(x),
                    _ => {
                        self.wrong(node, what, "a number");
                        None
                    }
                }
            }
            _ => {
                self.wrong(node, what, "a number");
                None
            }
        }
    }

    pub(super) fn seconds(&mut self, node: &Node, what: &str) -> Option<f64> {
        let x = self.number(node, what)?;
        if x < 0.0 {
            self.wrong(node, what, "a number of seconds, 0 or more");
            return None;
        }
        Some(x)
    }

    pub(super) fn boolean(&mut self, node: &Node, what: &str) -> Option<bool> {
        match node.scalar() {
            Some(ScalarKind::Bool(b)) => Some(b),
            _ => {
                self.wrong(node, what, "`true` or `false`");
                None
            }
        }
    }

    pub(super) fn text<'a>(&mut self, node: &'a Node, what: &str) -> Option<&'a str> {
        match node.scalar() {
            Some(ScalarKind::Null) | None => {
                self.wrong(node, what, "text");
                None
            }
            _ => node.as_text(),
        }
    }

    /// One of `names`; a did-you-mean hint otherwise.
    pub(super) fn choice<'n>(
        &mut self,
        node: &Node,
        what: &str,
        names: &[&'n str],
    ) -> Option<&'n str> {
        let t = self.text(node, what)?;
        if let Some(n) = names.iter().find(|n| **n == t) {
            return Some(n);
        }
        let hint = did_you_mean(t, names.iter().copied())
            .unwrap_or_else(|| format!("the choices are {}", quote_all(names)));
        self.error(
            codes::TRIAL_VALUE,
            node.range,
            format!("`{t}` is not {what}"),
        )
        .hint = Some(hint);
        None
    }

    pub(super) fn part_type(&mut self, node: &Node) -> Option<PartType> {
        let names = PartType::ALL.map(PartType::name);
        let n = self.choice(node, "a part type", &names)?;
        PartType::ALL.into_iter().find(|t| t.name() == n)
    }

    pub(super) fn color(&mut self, node: &Node) -> Option<Color> {
        let names = Color::ALL.map(Color::name);
        let n = self.choice(node, "a part colour", &names)?;
        Color::ALL.into_iter().find(|c| c.name() == n)
    }

    /// `type` and `color` of a part entry.
    pub(super) fn kind(&mut self, f: &mut Fields<'_>) -> Option<PartKind> {
        let ty = self.need(f, "type");
        let color = self.need(f, "color");
        let ty = ty.and_then(|n| self.part_type(n));
        let color = color.and_then(|n| self.color(n));
        Some(PartKind {
            ty: ty?,
            color: color?,
        })
    }

    pub(super) fn list<'a>(&mut self, node: &'a Node, what: &str) -> Option<&'a [Node]> {
        match node.as_seq() {
            Some(s) => Some(s),
            None => {
                self.wrong(node, what, "a list");
                None
            }
        }
    }

    /// Each mapping of a list of parts (`what` names one entry): its `type`
    /// and `color`, then its own fields (`own`, which reads the `fields`
    /// besides the kind, in the order they are reported), then a warning for
    /// each field no one read; `make` turns the entry into a value, given
    /// the values made from the entries before it, or drops it.
    pub(super) fn parts<'a, T, X>(
        &mut self,
        list: &'a [Node],
        what: &str,
        fields: &[&str],
        mut own: impl FnMut(&mut Reader, &mut Fields<'a>) -> X,
        mut make: impl FnMut(&mut Reader, Part<'a, X>, &[T]) -> Option<T>,
    ) -> Vec<T> {
        let known: Vec<&str> = ["type", "color"].iter().chain(fields).copied().collect();
        let mut out = Vec::new();
        for node in list {
            let Some(mut f) = self.fields(node, what) else {
                continue;
            };
            let kind = self.kind(&mut f);
            let own = own(self, &mut f);
            self.done(f, &known);
            if let Some(v) = make(self, Part { kind, own, node }, &out) {
                out.push(v);
            }
        }
        out
    }

    /// The pose fields of a part that lies somewhere: its `rotation` (not
    /// simulated) and whether it is `flipped`.
    pub(super) fn placed(&mut self, f: &mut Fields<'_>) -> bool {
        if let Some(r) = f.get("rotation") {
            self.rotation(r);
        }
        f.get("flipped")
            .and_then(|n| self.boolean(n, "`flipped`"))
            .unwrap_or(false)
    }

    /// A rotation: a number, or `pi`, `pi/N`, `-pi/N`, `N*pi`... as text.
    /// Rotations are not simulated, so a bad one is a warning.
    pub(super) fn rotation(&mut self, node: &Node) {
        self.unsimulated(
            "rotation",
            node,
            "btc's world is symbolic; parts have no pose",
        );
        let ok = match node.scalar() {
            Some(ScalarKind::Int(_) | ScalarKind::Float(_)) => true,
            Some(ScalarKind::Text) => node.as_text().is_some_and(is_angle),
            _ => false,
        };
        if !ok {
            self.warn(
                codes::TRIAL_VALUE,
                node.range,
                format!("{} is not an angle", describe(node)),
            )
            .hint = Some("write a number of radians or `pi`, `pi/2`, `-pi/4`, `2*pi/3`; the rotation is not simulated, so the trial still runs".into());
        }
    }
}

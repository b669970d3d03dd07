//! What is read of the tokens before chumsky sees them: the file cut into
//! items, a PDDL group (a condition's formula, a rule's effect) read by the
//! PDDL front end, and a rule's name pattern, each into a token of its own.

use super::*;

/// Cuts a file into items as its tokens come: an item starts at an item
/// keyword outside brackets or at the start of a line, and runs from its
/// first token's start to its last token's end.
pub(super) struct Cutter<'t> {
    text: &'t str,
    depth: usize,
    /// The current item's start, and the end of its last token so far.
    current: Option<(u32, u32)>,
    items: Vec<(u32, u32)>,
}

impl<'t> Cutter<'t> {
    pub(super) fn new(text: &'t str) -> Cutter<'t> {
        Cutter {
            text,
            depth: 0,
            current: None,
            items: Vec::new(),
        }
    }

    pub(super) fn token(&mut self, t: &Tok, span: Span) {
        let is_kw = matches!(t, Tok::Ident(k) if ITEM_KEYWORDS.contains(&k.as_str()));
        if is_kw && (self.depth == 0 || at_line_start(self.text, span.start)) {
            if let Some(item) = self.current.take() {
                self.items.push(item);
            }
            self.depth = 0;
        }
        // Text before the first keyword is an item of its own (an error).
        let item = self.current.get_or_insert((span.start, span.end));
        item.1 = span.end;
        match t {
            Tok::Punct("(" | "{" | "[") => self.depth += 1,
            Tok::Punct(")" | "}" | "]") => self.depth = self.depth.saturating_sub(1),
            _ => {}
        }
    }

    /// Each item's start and end.
    pub(super) fn finish(mut self) -> Vec<(u32, u32)> {
        self.items.extend(self.current);
        self.items
    }
}

pub(super) fn rel(span: Span, offset: u32) -> SimpleSpan {
    SimpleSpan::from((span.start - offset) as usize..(span.end - offset) as usize)
}

/// Reads the PDDL group starting at `tokens[i]` (a `(`) with the PDDL
/// front end; returns the replacement token and the index after the group.
pub(super) fn read_pddl_group(
    tokens: &[(Tok, Span)],
    i: usize,
    offset: u32,
    file: FileId,
    effect: bool,
    diags: &mut Vec<Diagnostic>,
) -> ((Tok, SimpleSpan), usize) {
    let mut depth = 0usize;
    let mut j = i;
    let mut ptoks = Vec::new();
    while j < tokens.len() {
        let (t, span) = &tokens[j];
        let s = Span::new(
            file,
            (span.start - offset) as usize,
            (span.end - offset) as usize,
        );
        let pt = match t {
            Tok::Punct("(") => {
                depth += 1;
                PTok::LParen
            }
            Tok::Punct(")") => {
                depth -= 1;
                PTok::RParen
            }
            Tok::Ident(n) => PTok::Name(Key::new(n).into_string()),
            Tok::Var(v) => PTok::Var(Key::new(v).into_string()),
            Tok::Int(n) => PTok::Number(*n as f64),
            Tok::Float(n) => PTok::Number(*n),
            Tok::Punct("-") => PTok::Dash,
            Tok::Punct("=") => PTok::Name("=".into()),
            other => {
                diags.push(Diagnostic::error(
                    codes::R_SYNTAX,
                    s,
                    format!("{other} cannot appear in a PDDL formula"),
                ));
                PTok::Invalid(other.to_string())
            }
        };
        ptoks.push(PToken { tok: pt, span: s });
        j += 1;
        if depth == 0 {
            break;
        }
    }
    let start = rel(tokens[i].1, offset).start;
    let end = rel(tokens[j - 1].1, offset).end;
    let (forest, sdiags) = sexpr::build(ptoks);
    diags.extend(sdiags);
    let tok = match forest.first() {
        Some(sx) if effect => match effect_of(sx) {
            (Some(e), d) => {
                diags.extend(d);
                Tok::Effect(Box::new(e))
            }
            (None, d) => {
                diags.extend(d);
                Tok::BadPddl
            }
        },
        Some(sx) => match formula_of(sx) {
            (Some(f), d) => {
                diags.extend(d);
                Tok::Formula(Box::new(f))
            }
            (None, d) => {
                diags.extend(d);
                Tok::BadPddl
            }
        },
        None => Tok::BadPddl,
    };
    ((tok, SimpleSpan::from(start..end)), j)
}

/// Characters that may stand in the literal parts of an action-name
/// pattern: those of PDDL names.
fn is_name_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == '-'
}

/// Reads the action-name pattern that starts at `tokens[i]` (just after
/// `rule (`): the run of touching name tokens, hyphens, numbers and
/// `{capture}`s, split into parts from the item's text. Returns the
/// replacement token (`None` when no name starts here) and the index after
/// the run.
pub(super) fn read_name_pattern(
    tokens: &[(Tok, Span)],
    i: usize,
    text: &str,
    offset: u32,
    file: FileId,
    diags: &mut Vec<Diagnostic>,
) -> (Option<(Tok, SimpleSpan)>, usize) {
    let part_of_name =
        |t: &Tok| matches!(t, Tok::Ident(_) | Tok::Int(_) | Tok::Punct("-" | "{" | "}"));
    if !tokens
        .get(i)
        .is_some_and(|(t, _)| matches!(t, Tok::Ident(_) | Tok::Punct("{")))
    {
        return (None, i);
    }
    let mut j = i + 1;
    while j < tokens.len() && part_of_name(&tokens[j].0) && tokens[j].1.start == tokens[j - 1].1.end
    {
        j += 1;
    }
    // Spans relative to the item, as everything the parser makes.
    let (start, end) = (
        (tokens[i].1.start - offset) as usize,
        (tokens[j - 1].1.end - offset) as usize,
    );
    let span = |a: usize, b: usize| Span::new(file, a, b);
    if let Some((t, s)) = tokens.get(j) {
        if matches!(t, Tok::Ident(_) | Tok::Punct("{")) {
            let r = rel(*s, offset);
            diags.push(Diagnostic::error(
                codes::R_SYNTAX,
                span(r.start, r.end),
                "the parts of an action-name pattern must touch: write `move-{src}-to-curb`, without spaces",
            ));
        }
    }
    let raw = &text[start..end];
    let mut parts = Vec::new();
    let mut lit_start = None::<usize>;
    let mut k = 0;
    let flush = |parts: &mut Vec<NamePart>, from: Option<usize>, to: usize| {
        if let Some(a) = from {
            let t = &raw[a..to];
            parts.push(NamePart::Lit {
                text: t.to_owned(),
                key: Key::new(t),
                span: span(start + a, start + to),
            });
        }
    };
    while k < raw.len() {
        let c = raw[k..].chars().next().expect("in bounds");
        match c {
            '{' => {
                flush(&mut parts, lit_start.take(), k);
                let Some(close) = raw[k..].find('}').map(|n| k + n) else {
                    diags.push(
                        Diagnostic::error(
                            codes::R_SYNTAX,
                            span(start + k, end),
                            "this `{` opens a capture that is never closed",
                        )
                        .with_hint("a capture is a name in braces, such as `{op}`"),
                    );
                    return (Some((Tok::BadPddl, rel_range(start, end))), j);
                };
                let inner = &raw[k + 1..close];
                let ok = inner.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
                    && inner.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
                if !ok {
                    diags.push(
                        Diagnostic::error(
                            codes::R_SYNTAX,
                            span(start + k, start + close + 1),
                            format!("`{{{inner}}}` is not a capture: a capture is a name in braces, such as `{{op}}`"),
                        ),
                    );
                    return (Some((Tok::BadPddl, rel_range(start, end))), j);
                }
                parts.push(NamePart::Capture {
                    name: Ident::new(inner.to_owned(), span(start + k + 1, start + close)),
                });
                k = close + 1;
            }
            '}' => {
                diags.push(Diagnostic::error(
                    codes::R_SYNTAX,
                    span(start + k, start + k + 1),
                    "this `}` closes no capture",
                ));
                return (Some((Tok::BadPddl, rel_range(start, end))), j);
            }
            c if is_name_char(c) => {
                lit_start.get_or_insert(k);
                k += c.len_utf8();
            }
            c => {
                diags.push(Diagnostic::error(
                    codes::R_SYNTAX,
                    span(start + k, start + k + c.len_utf8()),
                    format!("`{c}` cannot stand in an action name"),
                ));
                return (Some((Tok::BadPddl, rel_range(start, end))), j);
            }
        }
    }
    flush(&mut parts, lit_start.take(), raw.len());
    (Some((Tok::NamePattern(parts), rel_range(start, end))), j)
}

fn rel_range(start: usize, end: usize) -> SimpleSpan {
    SimpleSpan::from(start..end)
}

//! The data of a py_trees module btc wrote (`--emit pytrees --runtime
//! import`), read into Python values here, in Rust, for `to_py_trees`.
//!
//! The module is the one encoding of a tree for py_trees (the emitter's,
//! tested against real py_trees), so the package reads that rather than
//! encoding the tree a second way. Reading it with Python's `ast` cost
//! four times the planning of a round; this reader takes the few forms the
//! emitter writes — assignments of literals, `World(...)` with keyword
//! arguments, leaf classes with their attributes — and refuses anything
//! else with an error that names the line, so a change to the emitter
//! cannot be misread. No generated code runs.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};
use pyo3::IntoPyObjectExt;

/// The assignments whose values the tree is built from.
const LITERALS: &[&str] = &[
    "SHAPES",
    "STEPS",
    "TREES",
    "ROOT",
    "STEP_NODES",
    "MAX_TICKS",
    "NODE_CLASS_NAMES",
];

/// A module's data as the keyword arguments of `btc._pytrees.TreeData`:
/// `world` (`World`'s keywords), `classes` (`(node id, class name)`
/// pairs), `defined` (class name -> `(base, attributes)`) and `literals`.
pub(crate) fn read<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyDict>> {
    let world = PyDict::new(py);
    let classes = PyList::empty(py);
    let defined = PyDict::new(py);
    let literals = PyDict::new(py);
    let mut r = Reader::new(py, text);
    while !r.at_end() {
        if r.line_start() && r.eat_word("class ") {
            let (name, base, attrs) = r.class_def()?;
            defined.set_item(name, (base, attrs))?;
        } else if r.line_start() && r.eat_word("WORLD = World(") {
            r.keywords_into(&world)?;
            r.end_of_statement()?;
        } else if r.line_start() && r.eat_word("CLASSES = ") {
            r.class_pairs_into(&classes)?;
            r.end_of_statement()?;
        } else if let Some(name) = r.line_start().then(|| r.assignment_of(LITERALS)).flatten() {
            let value = r.value()?;
            r.end_of_statement()?;
            literals.set_item(name, value)?;
        }
        r.next_line();
    }
    let out = PyDict::new(py);
    out.set_item("world", world)?;
    out.set_item("classes", classes)?;
    out.set_item("defined", defined)?;
    out.set_item("literals", literals)?;
    Ok(out)
}

struct Reader<'py, 't> {
    py: Python<'py>,
    text: &'t str,
    at: usize,
}

impl<'py, 't> Reader<'py, 't> {
    fn new(py: Python<'py>, text: &'t str) -> Self {
        Reader { py, text, at: 0 }
    }

    fn at_end(&self) -> bool {
        self.at >= self.text.len()
    }

    fn rest(&self) -> &'t str {
        &self.text[self.at..]
    }

    fn peek(&self) -> Option<u8> {
        self.text.as_bytes().get(self.at).copied()
    }

    fn line_start(&self) -> bool {
        self.at == 0 || self.text.as_bytes()[self.at - 1] == b'\n'
    }

    fn next_line(&mut self) {
        match self.rest().find('\n') {
            Some(i) => self.at += i + 1,
            None => self.at = self.text.len(),
        }
    }

    fn eat_word(&mut self, word: &str) -> bool {
        let found = self.rest().starts_with(word);
        if found {
            self.at += word.len();
        }
        found
    }

    /// `NAME = ` for one of `names`, consumed.
    fn assignment_of(&mut self, names: &[&'static str]) -> Option<&'static str> {
        let rest = self.rest();
        let name = names
            .iter()
            .find(|n| rest.starts_with(**n) && rest[n.len()..].starts_with(" = "))?;
        self.at += name.len() + 3;
        Some(name)
    }

    /// Spaces, newlines and `#` comments.
    fn skip_blank(&mut self) {
        while let Some(c) = self.peek() {
            match c {
                b' ' | b'\n' | b'\r' | b'\t' => self.at += 1,
                b'#' => self.next_line(),
                _ => break,
            }
        }
    }

    /// Nothing but spaces before the end of the line: a value read in
    /// full, not the start of an expression this reader does not know.
    fn end_of_statement(&mut self) -> PyResult<()> {
        while self.peek() == Some(b' ') {
            self.at += 1;
        }
        match self.peek() {
            None | Some(b'\n') | Some(b'\r') => Ok(()),
            _ => Err(self.error("unexpected text after a value")),
        }
    }

    fn error(&self, what: &str) -> PyErr {
        let line = self.text[..self.at.min(self.text.len())]
            .bytes()
            .filter(|b| *b == b'\n')
            .count()
            + 1;
        PyValueError::new_err(format!(
            "btc cannot read line {line} of the py_trees module it wrote: {what} \
             (a btc bug: please report it)"
        ))
    }

    fn expect(&mut self, c: u8) -> PyResult<()> {
        self.skip_blank();
        if self.peek() == Some(c) {
            self.at += 1;
            Ok(())
        } else {
            Err(self.error(&format!("expected `{}`", c as char)))
        }
    }

    fn identifier(&mut self) -> &'t str {
        let start = self.at;
        while self
            .peek()
            .is_some_and(|c| c.is_ascii_alphanumeric() || c == b'_')
        {
            self.at += 1;
        }
        &self.text[start..self.at]
    }

    /// `class Name(Base):`, its docstring, then `    ATTR = literal` lines.
    fn class_def(&mut self) -> PyResult<(&'t str, &'t str, Bound<'py, PyDict>)> {
        let name = self.identifier();
        self.expect(b'(')?;
        let base = self.identifier();
        self.expect(b')')?;
        self.expect(b':')?;
        let attrs = PyDict::new(self.py);
        self.next_line();
        loop {
            let rest = self.rest();
            if rest.starts_with("    \"\"\"") {
                self.at += 7;
                match self.rest().find("\"\"\"") {
                    Some(i) => self.at += i + 3,
                    None => return Err(self.error("a docstring that does not end")),
                }
                self.next_line();
            } else if rest.starts_with("    ") {
                self.at += 4;
                let attr = self.identifier();
                if attr.is_empty() {
                    self.next_line();
                    continue;
                }
                if !self.eat_word(" = ") {
                    return Err(self.error("expected an attribute's value"));
                }
                let value = self.value()?;
                self.end_of_statement()?;
                attrs.set_item(attr, value)?;
                self.next_line();
            } else if rest.starts_with('\n') {
                self.at += 1;
            } else {
                // The class ends at the next line that is not indented;
                // the caller's `next_line` must not skip it.
                self.at -= 1;
                return Ok((name, base, attrs));
            }
            if self.at_end() {
                return Ok((name, base, attrs));
            }
        }
    }

    /// `key=literal,` ... `)`.
    fn keywords_into(&mut self, out: &Bound<'py, PyDict>) -> PyResult<()> {
        loop {
            self.skip_blank();
            if self.peek() == Some(b')') {
                self.at += 1;
                return Ok(());
            }
            let key = self.identifier();
            if key.is_empty() {
                return Err(self.error("expected a keyword argument"));
            }
            self.expect(b'=')?;
            let value = self.value()?;
            out.set_item(key, value)?;
            self.skip_blank();
            if self.peek() == Some(b',') {
                self.at += 1;
            }
        }
    }

    /// `(("id", ClassName), ...)`: the class is a name, not a literal.
    fn class_pairs_into(&mut self, out: &Bound<'py, PyList>) -> PyResult<()> {
        self.expect(b'(')?;
        loop {
            self.skip_blank();
            if self.peek() == Some(b')') {
                self.at += 1;
                return Ok(());
            }
            self.expect(b'(')?;
            self.skip_blank();
            let ident = self.string()?;
            self.expect(b',')?;
            self.skip_blank();
            let class = self.identifier();
            if class.is_empty() {
                return Err(self.error("expected a class name"));
            }
            self.expect(b')')?;
            out.append((ident, class))?;
            self.skip_blank();
            if self.peek() == Some(b',') {
                self.at += 1;
            }
        }
    }

    /// A literal: a tuple, a dict, a string, a number, `None`, `True`,
    /// `False` or `float("inf" | "-inf" | "nan")`.
    fn value(&mut self) -> PyResult<Bound<'py, PyAny>> {
        self.skip_blank();
        match self.peek() {
            Some(b'(') => self.tuple(),
            Some(b'{') => self.dict(),
            Some(b'"') => self.string()?.into_bound_py_any(self.py),
            Some(c) if c == b'-' || c.is_ascii_digit() => self.number(),
            _ => {
                let word = self.identifier();
                match word {
                    "None" => Ok(self.py.None().into_bound(self.py)),
                    "True" => true.into_bound_py_any(self.py),
                    "False" => false.into_bound_py_any(self.py),
                    "float" => {
                        self.expect(b'(')?;
                        self.skip_blank();
                        let which = self.string()?;
                        self.expect(b')')?;
                        let f = match which.as_str() {
                            "inf" => f64::INFINITY,
                            "-inf" => f64::NEG_INFINITY,
                            "nan" => f64::NAN,
                            _ => return Err(self.error("an unknown float")),
                        };
                        f.into_bound_py_any(self.py)
                    }
                    _ => Err(self.error("expected a literal")),
                }
            }
        }
    }

    /// `(a, b, ...)` with an optional trailing comma; `(a)` is `a`, as
    /// Python reads it.
    fn tuple(&mut self) -> PyResult<Bound<'py, PyAny>> {
        self.at += 1;
        let mut items = Vec::new();
        let mut comma = false;
        loop {
            self.skip_blank();
            if self.peek() == Some(b')') {
                self.at += 1;
                break;
            }
            items.push(self.value()?);
            self.skip_blank();
            match self.peek() {
                Some(b',') => {
                    self.at += 1;
                    comma = true;
                }
                Some(b')') => {}
                _ => return Err(self.error("expected `,` or `)` in a tuple")),
            }
        }
        if items.len() == 1 && !comma {
            return Ok(items.pop().unwrap());
        }
        Ok(PyTuple::new(self.py, items)?.into_any())
    }

    fn dict(&mut self) -> PyResult<Bound<'py, PyAny>> {
        self.at += 1;
        let out = PyDict::new(self.py);
        loop {
            self.skip_blank();
            if self.peek() == Some(b'}') {
                self.at += 1;
                return Ok(out.into_any());
            }
            let key = self.value()?;
            self.expect(b':')?;
            let value = self.value()?;
            out.set_item(key, value)?;
            self.skip_blank();
            match self.peek() {
                Some(b',') => self.at += 1,
                Some(b'}') => {}
                _ => return Err(self.error("expected `,` or `}` in a dict")),
            }
        }
    }

    fn number(&mut self) -> PyResult<Bound<'py, PyAny>> {
        let start = self.at;
        if self.peek() == Some(b'-') {
            self.at += 1;
        }
        let mut float = false;
        while let Some(c) = self.peek() {
            match c {
                b'0'..=b'9' => {}
                b'.' | b'e' | b'E' => float = true,
                b'+' | b'-' if float => {}
                _ => break,
            }
            self.at += 1;
        }
        let text = &self.text[start..self.at];
        if float {
            match text.parse::<f64>() {
                Ok(f) => f.into_bound_py_any(self.py),
                Err(_) => Err(self.error("a malformed number")),
            }
        } else {
            match text.parse::<i64>() {
                Ok(n) => n.into_bound_py_any(self.py),
                Err(_) => Err(self.error("a malformed number")),
            }
        }
    }

    /// A double-quoted string with the escapes `push_py_str` writes.
    fn string(&mut self) -> PyResult<String> {
        if self.peek() != Some(b'"') {
            return Err(self.error("expected a string"));
        }
        self.at += 1;
        let rest = self.rest();
        // Almost every string is a plain name: no escapes, one slice.
        if let Some(end) = rest.find(['"', '\\']) {
            if rest.as_bytes()[end] == b'"' {
                self.at += end + 1;
                return Ok(rest[..end].to_owned());
            }
        }
        let mut out = String::new();
        let mut chars = rest.char_indices();
        while let Some((i, c)) = chars.next() {
            match c {
                '"' => {
                    self.at += i + 1;
                    return Ok(out);
                }
                '\\' => {
                    let (_, e) = chars
                        .next()
                        .ok_or_else(|| self.error("a string that does not end"))?;
                    let hex = match e {
                        '\\' | '"' => {
                            out.push(e);
                            continue;
                        }
                        'n' => {
                            out.push('\n');
                            continue;
                        }
                        'r' => {
                            out.push('\r');
                            continue;
                        }
                        't' => {
                            out.push('\t');
                            continue;
                        }
                        'x' => 2,
                        'u' => 4,
                        'U' => 8,
                        _ => return Err(self.error("an unknown escape in a string")),
                    };
                    let digits: String = chars.by_ref().take(hex).map(|(_, c)| c).collect();
                    let c = u32::from_str_radix(&digits, 16)
                        .ok()
                        .filter(|_| digits.len() == hex)
                        .and_then(char::from_u32)
                        .ok_or_else(|| self.error("a malformed escape in a string"))?;
                    out.push(c);
                }
                c => out.push(c),
            }
        }
        Err(self.error("a string that does not end"))
    }
}

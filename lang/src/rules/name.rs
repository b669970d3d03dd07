//! Names folded once. PDDL is case-insensitive, and so are the parts of a
//! rules file that name PDDL things (action-name patterns, types, objects)
//! and table keys. Each such name is folded to a [`Key`] once, where it is
//! read (the parser, or the PDDL front end, which lower-cases every name),
//! and compared by key from then on. This module is the only place on the
//! rules side that changes the case of text: `lang/clippy.toml` and
//! `lsp/clippy.toml` forbid `to_lowercase` and its relatives elsewhere.

use serde::{Deserialize, Serialize};
use smol_str::{SmolStr, StrExt};
use std::fmt;

/// A name folded for comparison: lower-cased exactly as the PDDL lexer
/// lower-cases names, so a key compares equal to the PDDL front end's name.
#[derive(Clone, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Key(SmolStr);

impl Key {
    /// Folds `text`.
    #[allow(clippy::disallowed_methods)] // the one place that folds
    pub fn new(text: &str) -> Key {
        // Short keys live inline (no allocation): most names are short,
        // and a huge file has hundreds of thousands of them.
        if text.is_ascii() {
            Key(text.to_ascii_lowercase_smolstr())
        } else {
            Key(text.to_lowercase_smolstr())
        }
    }

    /// A name the PDDL front end produced (already folded by its lexer).
    pub fn of_pddl(name: &str) -> Key {
        debug_assert_eq!(Key::new(name).0, name, "PDDL names are folded");
        Key(SmolStr::new(name))
    }

    pub fn as_str(&self) -> &str {
        &self.0
    }

    pub fn into_string(self) -> String {
        self.0.into()
    }
}

impl fmt::Display for Key {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::borrow::Borrow<str> for Key {
    fn borrow(&self) -> &str {
        &self.0
    }
}

/// Whether two texts name the same thing, folded (for callers that hold
/// two written texts, such as a query and a candidate in the editor).
pub fn same(a: &str, b: &str) -> bool {
    Key::new(a) == Key::new(b)
}

/// Whether `text` contains `query`, both folded (the editor's symbol search).
pub fn contains_folded(text: &str, query: &str) -> bool {
    Key::new(text).0.contains(Key::new(query).as_str())
}

/// Where `needle` stands in `haystack`, ignoring ASCII case (byte offsets,
/// without overlaps). Folds only ASCII, so offsets into the text stay
/// right: for the names in a rules file, whose identifiers are ASCII.
#[allow(clippy::disallowed_methods)] // the one place that folds
pub fn find_folded(haystack: &str, needle: &str) -> Vec<usize> {
    let (h, n) = (haystack.as_bytes(), needle.as_bytes());
    let mut out = Vec::new();
    if n.is_empty() {
        return out;
    }
    let mut i = 0;
    while i + n.len() <= h.len() {
        if h[i..i + n.len()].eq_ignore_ascii_case(n) {
            out.push(i);
            i += n.len();
        } else {
            i += 1;
        }
    }
    out
}

/// The value a capture takes when it is used as a value or a table key:
/// the captured part of the action name, upper-cased (`pick_op1` with
/// `PICK_{op}` gives `OP1`), as the language reference says.
#[allow(clippy::disallowed_methods)] // a rule of the language, not a comparison
pub fn capture_value(captured: &str) -> String {
    captured.to_uppercase()
}

/// A CamelCase node name made from a PDDL action name (`pick-up` ->
/// `PickUp`), for the stubs the editor writes.
#[allow(clippy::disallowed_methods)] // builds a new name; nothing is compared
pub fn camel_case(pddl_name: &str) -> String {
    pddl_name
        .split(['-', '_'])
        .filter(|w| !w.is_empty())
        .map(|w| {
            let mut c = w.chars();
            match c.next() {
                Some(f) => f
                    .to_uppercase()
                    .chain(c.flat_map(char::to_lowercase))
                    .collect(),
                None => String::new(),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_fold_like_the_pddl_lexer() {
        assert_eq!(Key::new("PICK_Op1").as_str(), "pick_op1");
        assert_eq!(Key::new("İs").as_str(), "i\u{307}s");
        assert!(same("Floor_Robot", "floor_robot"));
        assert!(contains_folded("MoveTo", "ETO"));
        assert_eq!(capture_value("op1"), "OP1");
        assert_eq!(camel_case("pick-up_part"), "PickUpPart");
        assert_eq!(find_folded("x {?Robot} {?robot}", "{?robot}"), vec![2, 11]);
    }
}

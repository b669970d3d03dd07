//! Every bound btc puts on what a user feeds it, in one place, so that each
//! reader (PDDL, plans, `.btrules`, BT.CPP XML, TOML scenarios, trial YAML)
//! refuses the same things at the same sizes. A bound is checked where the
//! input is read and refused with a diagnostic; everything after the reader
//! may then rely on it (no pass needs more stack than the nesting allows).

/// Largest file btc reads. Spans are `u32`, and nothing real comes close.
pub const MAX_FILE_BYTES: usize = 1 << 30;

/// Deepest nesting of a user's text that btc reads: parentheses in PDDL,
/// templates (brackets and chained decorators) in `.btrules`, elements in
/// tree XML, tables and arrays in TOML and YAML. Real files stay below 30.
/// Readers refuse deeper input with a diagnostic; passes after them may
/// recurse this deep.
pub const MAX_NESTING: usize = 200;

/// Diagnostics kept per file and per kind of problem before the rest are
/// counted into one summary ("and 12,345 more"). Nobody reads past the
/// first hundred, and keeping millions costs memory proportional to them.
pub const MAX_DIAGNOSTICS_PER_FILE: usize = 100;

/// "did you mean" compares names of at most this many characters: the
/// edit distance is quadratic in the length, and a name this long is no
/// typo.
pub const MAX_SUGGESTION_NAME: usize = 64;

/// Characters of a source line shown around a diagnostic's span; longer
/// lines are cut (rendering a 10 MB line per diagnostic is quadratic).
pub const MAX_RENDERED_LINE: usize = 240;

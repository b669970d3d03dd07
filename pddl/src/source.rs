//! Source files, spans and decoding of raw bytes into text.

use serde::{Deserialize, Serialize};

/// Index of a file in a [`Sources`] set.
pub type FileId = u32;

/// A byte range in one source file. Byte offsets everywhere; editors' UTF-16
/// columns are computed only at the LSP boundary.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Span {
    pub file: FileId,
    pub start: u32,
    pub end: u32,
}

impl Span {
    pub fn new(file: FileId, start: usize, end: usize) -> Span {
        Span {
            file,
            start: start as u32,
            end: end as u32,
        }
    }

    /// The smallest span covering both.
    pub fn to(self, other: Span) -> Span {
        Span {
            file: self.file,
            start: self.start.min(other.start),
            end: self.end.max(other.end),
        }
    }

    pub fn range(self) -> std::ops::Range<usize> {
        self.start as usize..self.end as usize
    }
}

/// One loaded file: its name as the user gave it and its decoded text.
#[derive(Clone, Debug)]
pub struct SourceFile {
    pub path: String,
    pub text: String,
    /// Found on the first [`SourceFile::line_col`]: every file of a
    /// project is added for rendering, but most render no diagnostic, and
    /// a long plan's lines cost more to find than the rest of its copy.
    line_starts: std::sync::OnceLock<Vec<u32>>,
}

impl SourceFile {
    pub fn new(path: impl Into<String>, text: impl Into<String>) -> SourceFile {
        SourceFile {
            path: path.into(),
            text: text.into(),
            line_starts: std::sync::OnceLock::new(),
        }
    }

    fn line_starts(&self) -> &[u32] {
        self.line_starts.get_or_init(|| {
            let mut starts = vec![0u32];
            starts.extend(
                self.text
                    .bytes()
                    .enumerate()
                    .filter(|(_, b)| *b == b'\n')
                    .map(|(i, _)| i as u32 + 1),
            );
            starts
        })
    }

    /// 1-based line and 1-based column (in characters) of a byte offset.
    pub fn line_col(&self, offset: u32) -> (u32, u32) {
        let offset = offset.min(self.text.len() as u32);
        let line_starts = self.line_starts();
        let line = line_starts.partition_point(|&s| s <= offset) - 1;
        let start = line_starts[line] as usize;
        let mut end = offset as usize;
        while !self.text.is_char_boundary(end) {
            end -= 1;
        }
        let col = self.text[start..end].chars().count() as u32 + 1;
        (line as u32 + 1, col)
    }
}

/// The set of files one command works on. Diagnostics refer to files by id.
#[derive(Clone, Debug, Default)]
pub struct Sources {
    files: std::collections::BTreeMap<FileId, SourceFile>,
}

impl Sources {
    pub fn new() -> Sources {
        Sources::default()
    }

    /// Adds a file under the next free id.
    pub fn add(&mut self, path: impl Into<String>, text: impl Into<String>) -> FileId {
        let id = self.files.keys().next_back().map_or(0, |k| k + 1);
        self.insert(id, path, text);
        id
    }

    /// Adds (or replaces) a file under a given id, e.g. the database's.
    pub fn insert(&mut self, id: FileId, path: impl Into<String>, text: impl Into<String>) {
        self.files.insert(id, SourceFile::new(path, text));
    }

    /// The file with this id. Panics for an id never added: ids come from
    /// the same `Sources` (or database) as the diagnostics that carry them.
    pub fn get(&self, id: FileId) -> &SourceFile {
        &self.files[&id]
    }

    pub fn text(&self, id: FileId) -> &str {
        &self.get(id).text
    }

    pub fn iter(&self) -> impl Iterator<Item = (FileId, &SourceFile)> {
        self.files.iter().map(|(i, f)| (*i, f))
    }
}

pub use crate::limits::MAX_FILE_BYTES;

/// What went wrong while turning bytes into text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DecodeProblem {
    /// Bytes that are not UTF-8, first one at this offset of the decoded text.
    InvalidUtf8 {
        offset: usize,
        byte: u8,
    },
    /// A UTF-16 file with an odd number of bytes or a lone surrogate.
    BadUtf16,
    TooLarge {
        bytes: usize,
    },
}

/// Decodes a file's bytes. UTF-8 (with or without BOM) and UTF-16 with a BOM
/// are accepted; anything else is decoded lossily so that parsing can go on,
/// and the problem is returned to be reported.
pub fn decode(bytes: &[u8]) -> (String, Option<DecodeProblem>) {
    if bytes.len() > MAX_FILE_BYTES {
        return (
            String::new(),
            Some(DecodeProblem::TooLarge { bytes: bytes.len() }),
        );
    }
    if let Some(rest) = bytes.strip_prefix(&[0xEF, 0xBB, 0xBF]) {
        return decode_utf8(rest);
    }
    let utf16 = |rest: &[u8], le: bool| {
        if !rest.len().is_multiple_of(2) {
            return (String::new(), Some(DecodeProblem::BadUtf16));
        }
        let units = rest.chunks_exact(2).map(|c| {
            if le {
                u16::from_le_bytes([c[0], c[1]])
            } else {
                u16::from_be_bytes([c[0], c[1]])
            }
        });
        match char::decode_utf16(units).collect::<Result<String, _>>() {
            Ok(s) => (s, None),
            Err(_) => (String::new(), Some(DecodeProblem::BadUtf16)),
        }
    };
    if let Some(rest) = bytes.strip_prefix(&[0xFF, 0xFE]) {
        return utf16(rest, true);
    }
    if let Some(rest) = bytes.strip_prefix(&[0xFE, 0xFF]) {
        return utf16(rest, false);
    }
    decode_utf8(bytes)
}

fn decode_utf8(bytes: &[u8]) -> (String, Option<DecodeProblem>) {
    match std::str::from_utf8(bytes) {
        Ok(s) => (s.to_owned(), None),
        Err(e) => {
            let offset = e.valid_up_to();
            (
                String::from_utf8_lossy(bytes).into_owned(),
                Some(DecodeProblem::InvalidUtf8 {
                    offset,
                    byte: bytes[offset],
                }),
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_col_counts_characters() {
        let f = SourceFile::new("x", "ab\ncá d\n");
        assert_eq!(f.line_col(0), (1, 1));
        assert_eq!(f.line_col(3), (2, 1));
        // 'd' is after the two-byte 'á' and a space
        assert_eq!(f.line_col(7), (2, 4));
        assert_eq!(f.line_col(100), (3, 1));
    }

    #[test]
    fn decodes_boms_and_reports_bad_bytes() {
        assert_eq!(decode(b"\xEF\xBB\xBF(a)").0, "(a)");
        assert_eq!(decode(b"\xFF\xFE(\x00a\x00)\x00").0, "(a)");
        let (text, problem) = decode(b"(a \xFF)");
        assert_eq!(text, "(a \u{FFFD})");
        assert_eq!(
            problem,
            Some(DecodeProblem::InvalidUtf8 {
                offset: 3,
                byte: 0xFF
            })
        );
    }
}

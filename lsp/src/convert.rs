//! Byte offsets (what btc's spans hold) to LSP positions (lines and UTF-16
//! columns) and back. The only place that knows about UTF-16.

use btc_pddl::source::Span;
use tower_lsp::lsp_types::{Position, Range};

/// Line starts of one text, for converting positions both ways.
pub struct LineIndex<'a> {
    text: &'a str,
    /// Byte offset of the first character of each line.
    starts: Vec<usize>,
}

impl<'a> LineIndex<'a> {
    pub fn new(text: &'a str) -> LineIndex<'a> {
        let mut starts = vec![0];
        starts.extend(memchr::memchr_iter(b'\n', text.as_bytes()).map(|i| i + 1));
        LineIndex { text, starts }
    }

    /// The position of a byte offset. Offsets past the end clamp to the
    /// end; offsets inside a character count as its start.
    pub fn position(&self, offset: usize) -> Position {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = self.starts.partition_point(|&s| s <= offset) - 1;
        let col: usize = self.text[self.starts[line]..offset]
            .chars()
            .map(char::len_utf16)
            .sum();
        Position::new(line as u32, col as u32)
    }

    pub fn range(&self, span: Span) -> Range {
        Range::new(
            self.position(span.start as usize),
            self.position(span.end as usize),
        )
    }

    /// The byte offset of a position. A column past the line's end means
    /// the line's end; a line past the last means the text's end; a column
    /// inside a surrogate pair means the character's start.
    pub fn offset(&self, p: Position) -> usize {
        let Some(&start) = self.starts.get(p.line as usize) else {
            return self.text.len();
        };
        let mut end = self
            .starts
            .get(p.line as usize + 1)
            .map_or(self.text.len(), |&next| next - 1);
        // A line's end is before its `\r\n`.
        if self.text[start..end].ends_with('\r') {
            end -= 1;
        }
        let mut units = 0usize;
        for (i, c) in self.text[start..end].char_indices() {
            if units + c.len_utf16() > p.character as usize {
                return start + i;
            }
            units += c.len_utf16();
        }
        end
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_round_trips() {
        let text = "ab\ncd\n";
        let ix = LineIndex::new(text);
        for off in 0..=text.len() {
            assert_eq!(ix.offset(ix.position(off)), off, "offset {off}");
        }
        assert_eq!(ix.position(4), Position::new(1, 1));
    }

    #[test]
    fn utf16_columns_count_surrogate_pairs_as_two() {
        // `é` is 2 bytes and 1 UTF-16 unit; `𝄞` is 4 bytes and 2 units.
        let text = "// é𝄞x\nrule";
        let ix = LineIndex::new(text);
        let x = text.find('x').unwrap();
        assert_eq!(ix.position(x), Position::new(0, 3 + 1 + 2));
        assert_eq!(ix.offset(Position::new(0, 6)), x);
        // Inside the surrogate pair: the character's start.
        let clef = text.find('𝄞').unwrap();
        assert_eq!(ix.offset(Position::new(0, 5)), clef);
        assert_eq!(ix.offset(Position::new(1, 2)), text.len() - 2);
    }

    #[test]
    fn out_of_range_positions_clamp() {
        let text = "ab\r\ncd";
        let ix = LineIndex::new(text);
        assert_eq!(ix.offset(Position::new(0, 99)), 2);
        assert_eq!(ix.offset(Position::new(7, 0)), text.len());
        assert_eq!(ix.position(999), Position::new(1, 2));
        // An offset inside a multi-byte character maps to its start.
        let t = "é";
        assert_eq!(LineIndex::new(t).position(1), Position::new(0, 0));
    }
}

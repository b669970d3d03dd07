//! Streaming an emitter's text to a writer as it is produced.
//!
//! A long plan's output is tens of megabytes (a hundred for JSON). Built
//! whole, it doubles what a compile holds and its fresh pages cost more
//! than writing it; streamed, the emitter's buffer is handed to the writer
//! in chunks at step boundaries and reused.

use crate::sizing::StepSizer;
use std::io::{self, Write};

/// About how much text is handed to the writer at once.
pub(crate) const CHUNK: usize = 1 << 20;

/// What takes an emitter's full buffer and gives back an empty one to
/// fill: the buffer is handed over whole, not copied (`btc compile -o`
/// writes it on whichever core is free; see `btc_files::relay`).
pub type Handover<'a> = dyn FnMut(Vec<u8>) -> Vec<u8> + 'a;

/// Where the buffer goes.
enum To<'w> {
    Writer(&'w mut dyn Write),
    Hand(&'w mut Handover<'w>),
}

/// Where an emitter's buffer goes at step boundaries: nowhere (the text
/// is returned whole), to a writer, or handed over.
pub(crate) struct Sink<'w> {
    to: Option<To<'w>>,
    /// The first write error; later chunks are dropped, and the emit
    /// returns it.
    error: Option<io::Error>,
    /// Captures in progress (a shared node's text being recorded from its
    /// start in the buffer): the buffer is not handed over under one.
    held: usize,
}

impl<'w> Sink<'w> {
    /// The text stays in the buffer, returned whole.
    pub fn none() -> Sink<'w> {
        Sink {
            to: None,
            error: None,
            held: 0,
        }
    }

    pub fn to(w: &'w mut dyn Write) -> Sink<'w> {
        Sink {
            to: Some(To::Writer(w)),
            error: None,
            held: 0,
        }
    }

    pub fn hand(h: &'w mut Handover<'w>) -> Sink<'w> {
        Sink {
            to: Some(To::Hand(h)),
            error: None,
            held: 0,
        }
    }

    pub fn streams(&self) -> bool {
        self.to.is_some()
    }

    /// A buffer's first capacity: room for a chunk when streaming, else
    /// `whole` (room for the first steps, the rest sized by them).
    pub fn capacity(&self, whole: usize) -> usize {
        match self.streams() {
            true => CHUNK + 65_536,
            false => whole,
        }
    }

    /// A sizer for `steps` steps of text; one that never reserves when
    /// streaming (the buffer holds a chunk, not the output).
    pub fn sizer(&self, steps: usize) -> StepSizer {
        StepSizer::new(if self.streams() { 0 } else { steps })
    }

    /// A capture of the buffer starts: no hand-over until it ends.
    pub fn hold(&mut self) {
        self.held += 1;
    }

    pub fn release(&mut self) {
        self.held -= 1;
    }

    /// At a step boundary: hands the buffer over once it holds a chunk.
    pub fn step_done(&mut self, out: &mut String) {
        if self.held == 0 && out.len() >= CHUNK {
            self.hand_over(out);
        }
    }

    fn hand_over(&mut self, out: &mut String) {
        match self.to.as_mut() {
            Some(To::Writer(w)) => {
                if self.error.is_none() {
                    if let Err(e) = w.write_all(out.as_bytes()) {
                        self.error = Some(e);
                    }
                }
                out.clear();
            }
            Some(To::Hand(h)) => {
                let mut empty = h(std::mem::take(out).into_bytes());
                empty.clear();
                *out = String::from_utf8(empty).expect("an empty buffer is text");
            }
            None => {}
        }
    }

    /// The end of the emit: a streaming sink writes the rest and returns
    /// an empty text (or the first error); otherwise the text is returned.
    pub fn finish(mut self, mut out: String) -> io::Result<String> {
        self.hand_over(&mut out);
        match self.error {
            Some(e) => Err(e),
            None => Ok(out),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Writes 200,000 numbered lines through `sink`, holding it from line
    /// `hold_from` on; returns what is left in the buffer, and every line.
    fn feed(sink: &mut Sink, hold_from: Option<usize>) -> (String, String) {
        let (mut out, mut expected) = (String::new(), String::new());
        for i in 0..200_000 {
            let line = format!("step {i}\n");
            out.push_str(&line);
            expected.push_str(&line);
            if Some(i) == hold_from {
                sink.hold();
            }
            sink.step_done(&mut out);
            assert!(out.len() < CHUNK + 64 || hold_from.is_some_and(|h| i >= h));
        }
        (out, expected)
    }

    /// Streamed text arrives whole and in order, in chunks of about
    /// [`CHUNK`]; none is handed over under a hold.
    #[test]
    fn chunks_arrive_in_order_and_not_under_a_hold() {
        let mut got = Vec::new();
        let mut sink = Sink::to(&mut got);
        let (out, expected) = feed(&mut sink, Some(150_000));
        assert!(out.len() > CHUNK, "held text stays in the buffer");
        sink.release();
        assert_eq!(sink.finish(out).unwrap(), "");
        assert_eq!(String::from_utf8(got).unwrap(), expected);
    }

    /// Handed over, the buffers arrive whole and in order, and the
    /// emitter fills the empty buffer it gets back.
    #[test]
    fn handed_over_buffers_arrive_in_order() {
        let mut got = Vec::new();
        let mut returned = 0;
        let mut hand = |full: Vec<u8>| {
            got.extend_from_slice(&full);
            returned += 1;
            Vec::with_capacity(full.capacity())
        };
        let mut sink = Sink::hand(&mut hand);
        let (out, expected) = feed(&mut sink, None);
        assert_eq!(sink.finish(out).unwrap(), "");
        assert!(returned > 1, "handed over in chunks");
        assert_eq!(String::from_utf8(got).unwrap(), expected);
    }

    /// Without a writer the text is returned whole.
    #[test]
    fn without_a_writer_the_text_is_returned() {
        let mut sink = Sink::none();
        let mut out = "x".repeat(CHUNK + 1);
        sink.step_done(&mut out);
        assert_eq!(sink.finish(out).unwrap().len(), CHUNK + 1);
    }

    /// A failing writer's error is returned, not lost.
    #[test]
    fn a_write_error_is_returned() {
        struct Full;
        impl Write for Full {
            fn write(&mut self, _: &[u8]) -> io::Result<usize> {
                Err(io::Error::other("disk full"))
            }
            fn flush(&mut self) -> io::Result<()> {
                Ok(())
            }
        }
        let mut w = Full;
        let mut sink = Sink::to(&mut w);
        let mut out = "x".repeat(CHUNK);
        sink.step_done(&mut out);
        assert!(out.is_empty());
        let err = sink.finish("rest".into()).unwrap_err();
        assert_eq!(err.to_string(), "disk full");
    }
}

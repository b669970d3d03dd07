//! An output written in order by whichever of two threads is free.
//!
//! `btc compile -o` makes a long plan's output on a second core while the
//! main thread replays the plan; once the replay is over, the main thread
//! has nothing to do but wait. Writing a buffer into the page cache costs
//! about as much as formatting it (a 36 MB BT.CPP XML: two thirds of its
//! emit), so the maker hands full buffers to the relay, and the waiting
//! thread, once it offers to [`Relay::help`], writes them while the maker
//! formats the next. Before anyone helps, the maker writes its buffers
//! itself, as a plain writer would.
//!
//! The buffers are written in the order they were handed over, one at a
//! time, through one open file: the bytes are those a plain writer would
//! write. At most [`MAX_QUEUED`] wait to be written, and written buffers
//! go back to the maker to be filled again, so the relay holds a few
//! megabytes however long the output.

use std::collections::VecDeque;
use std::fs::File;
use std::io::{self, Write};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};

/// How many full buffers may wait while a helper writes: the maker waits
/// beyond that, so that a slow disk does not fill memory.
pub const MAX_QUEUED: usize = 2;

/// See the module's documentation. One relay carries one output.
#[derive(Default)]
pub struct Relay {
    state: Mutex<State>,
    changed: Condvar,
}

#[derive(Default)]
struct State {
    /// Where the buffers go; `None` before [`Relay::relay`] and after it.
    file: Option<Arc<File>>,
    /// Full buffers, in the order they are to be written.
    queue: VecDeque<Vec<u8>>,
    /// Written buffers, emptied, for the maker to fill again.
    spare: Vec<Vec<u8>>,
    /// A buffer is being written (by either thread): no other may start.
    writing: bool,
    /// A thread has offered to write.
    helped: bool,
    /// The maker hands over no more buffers (it finished, or never began).
    done: bool,
    /// The first write that failed; later buffers are dropped.
    error: Option<io::Error>,
}

/// The maker's side: while it is held, a helper waits for buffers;
/// dropped (even by a panic, or an early return that makes nothing), it
/// tells the helper that none will come.
pub struct Making<'r> {
    relay: &'r Relay,
}

impl Drop for Making<'_> {
    fn drop(&mut self) {
        self.relay.lock().done = true;
        self.relay.changed.notify_all();
    }
}

impl Relay {
    pub fn new() -> Relay {
        Relay::default()
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn wait<'g>(&self, s: MutexGuard<'g, State>) -> MutexGuard<'g, State> {
        self.changed.wait(s).unwrap_or_else(|e| e.into_inner())
    }

    /// Called by the maker before it may hand over anything; see [`Making`].
    pub fn making(&self) -> Making<'_> {
        Making { relay: self }
    }

    /// Runs `produce`, which hands its full buffers to the function it is
    /// given (and gets an empty one back to fill), and writes them to
    /// `file` in order; returns once all are written, with the first
    /// error of `produce` or of a write.
    pub fn relay(
        &self,
        file: &File,
        produce: impl FnOnce(&mut dyn FnMut(Vec<u8>) -> Vec<u8>) -> io::Result<()>,
    ) -> io::Result<()> {
        // A second handle on the same open file: the writes share its
        // offset, so they land one after the other wherever they are made.
        self.lock().file = Some(Arc::new(file.try_clone()?));
        let made = produce(&mut |full| self.pass(full));
        let mut s = self.lock();
        loop {
            s = self.write_queued(s);
            if s.queue.is_empty() && !s.writing {
                break;
            }
            s = self.wait(s);
        }
        s.file = None;
        let written = s.error.take().map_or(Ok(()), Err);
        drop(s);
        made.and(written)
    }

    /// The maker's hand-over: `full` joins the queue; without a helper the
    /// maker writes it now. Returns an empty buffer of the same capacity.
    fn pass(&self, full: Vec<u8>) -> Vec<u8> {
        let capacity = full.capacity();
        let mut s = self.lock();
        s.queue.push_back(full);
        if s.helped {
            self.changed.notify_all();
            while s.queue.len() > MAX_QUEUED {
                s = self.wait(s);
            }
        } else {
            s = self.write_queued(s);
        }
        s.spare
            .pop()
            .unwrap_or_else(|| Vec::with_capacity(capacity))
    }

    /// Offered by a thread that has nothing else to do: writes the maker's
    /// buffers as they come, and returns once the maker is done and all
    /// are written (at once if nothing is being made).
    pub fn help(&self) {
        let mut s = self.lock();
        s.helped = true;
        loop {
            s = self.write_queued(s);
            if s.done && s.queue.is_empty() && !s.writing {
                return;
            }
            s = self.wait(s);
        }
    }

    /// Writes the queued buffers in order, unless another thread is
    /// writing one; the lock is let go during each write.
    fn write_queued<'g>(&'g self, mut s: MutexGuard<'g, State>) -> MutexGuard<'g, State> {
        while !s.writing {
            let Some(mut buffer) = s.queue.pop_front() else {
                break;
            };
            let file = s.file.clone().filter(|_| s.error.is_none());
            s.writing = true;
            drop(s);
            let written = file.map_or(Ok(()), |f| (&*f).write_all(&buffer));
            buffer.clear();
            s = self.lock();
            s.writing = false;
            if let Err(e) = written {
                s.error.get_or_insert(e);
            }
            s.spare.push(buffer);
            self.changed.notify_all();
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::{Read, Seek};

    /// Buffers of `n` lines each, numbered across buffers.
    fn lines(from: usize, n: usize) -> Vec<u8> {
        (from..from + n)
            .map(|i| format!("line {i}\n"))
            .collect::<String>()
            .into_bytes()
    }

    fn contents(mut f: &File) -> String {
        let mut text = String::new();
        f.rewind().unwrap();
        f.read_to_string(&mut text).unwrap();
        text
    }

    fn make(relay: &Relay, file: &File, buffers: usize) -> io::Result<()> {
        let _making = relay.making();
        relay.relay(file, |hand| {
            for b in 0..buffers {
                let mut buffer = hand(lines(b * 100, 100));
                assert!(buffer.is_empty(), "a buffer comes back empty");
                buffer.extend_from_slice(b"reused\n");
                buffer.clear();
            }
            Ok(())
        })
    }

    /// Without a helper the maker writes every buffer itself, in order.
    #[test]
    fn the_maker_writes_alone_in_order() {
        let file = tempfile::tempfile().unwrap();
        let relay = Relay::new();
        make(&relay, &file, 50).unwrap();
        assert_eq!(contents(&file), String::from_utf8(lines(0, 5000)).unwrap());
    }

    /// With a helper from the start or from half way, the file holds the
    /// same bytes in the same order, and the helper returns once they are
    /// written.
    #[test]
    fn a_helper_writes_the_same_bytes_in_order() {
        for delay_ms in [0, 2, 20] {
            let file = tempfile::tempfile().unwrap();
            let relay = Relay::new();
            std::thread::scope(|s| {
                s.spawn(|| make(&relay, &file, 400).unwrap());
                std::thread::sleep(std::time::Duration::from_millis(delay_ms));
                relay.help();
            });
            assert_eq!(
                contents(&file),
                String::from_utf8(lines(0, 40_000)).unwrap()
            );
        }
    }

    /// A helper whose maker makes nothing (or has not begun and gives up)
    /// is not left waiting.
    #[test]
    fn a_helper_returns_when_nothing_is_made() {
        let relay = Relay::new();
        std::thread::scope(|s| {
            s.spawn(|| drop(relay.making()));
            relay.help();
        });
        let relay = Relay::new();
        drop(relay.making());
        relay.help();
    }

    /// A failing write is returned by the maker's `relay`, and the buffers
    /// after it are dropped, not written half.
    #[test]
    fn a_write_error_is_returned() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("read-only");
        std::fs::write(&path, "").unwrap();
        // Open for reading only: every write fails.
        let file = File::open(&path).unwrap();
        let relay = Relay::new();
        let got = std::thread::scope(|s| {
            let maker = s.spawn(|| make(&relay, &file, 10));
            relay.help();
            maker.join().unwrap()
        });
        assert!(got.is_err());
        assert_eq!(std::fs::read(&path).unwrap(), b"");
    }

    /// The maker's own error comes back too.
    #[test]
    fn the_makers_error_is_returned() {
        let file = tempfile::tempfile().unwrap();
        let relay = Relay::new();
        let _making = relay.making();
        let got = relay.relay(&file, |hand| {
            hand(lines(0, 10));
            Err(io::Error::other("the emit failed"))
        });
        assert_eq!(got.unwrap_err().to_string(), "the emit failed");
    }
}

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
//!
//! An output may come in two parts that need not be made in order (a
//! py_trees module's plan, then its tree): the maker makes the first and
//! offers the second ([`Relay::relay_parts`]). A helper that comes while
//! the second is still offered makes it, into buffers of its own, while
//! the maker makes the first: its bytes are written after the first's.
//! Otherwise the maker makes it after the first.

use std::collections::VecDeque;
use std::fs::File;
use std::io::{self, Write};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};

/// How many full buffers may wait while a helper writes: the maker waits
/// beyond that, so that a slow disk does not fill memory.
pub const MAX_QUEUED: usize = 2;

/// See the module's documentation. One relay carries one output; `'a`
/// is what a second part may borrow.
#[derive(Default)]
pub struct Relay<'a> {
    state: Mutex<State<'a>>,
    changed: Condvar,
}

/// What makes a part of the output: it hands its full buffers to the
/// function it is given, and gets an empty one back to fill.
pub type Produce<'p> = dyn FnMut(Vec<u8>) -> Vec<u8> + 'p;

/// An output's second part, for whichever thread is free to make it.
pub type Later<'a> = Box<dyn FnOnce(&mut Produce<'_>) -> io::Result<()> + Send + 'a>;

/// Where the second part is.
#[derive(Default)]
enum Second<'a> {
    /// None offered, or taken by the maker.
    #[default]
    None,
    Offered(Later<'a>),
    /// A helper is making it.
    Making,
    /// A helper made it: its buffers, to be written after the first part.
    Made(io::Result<Vec<Vec<u8>>>),
}

#[derive(Default)]
struct State<'a> {
    second: Second<'a>,
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
pub struct Making<'r, 'a> {
    relay: &'r Relay<'a>,
}

impl Drop for Making<'_, '_> {
    fn drop(&mut self) {
        self.relay.lock().done = true;
        self.relay.changed.notify_all();
    }
}

/// A helper making the second part: dropped before it is made (a panic),
/// it tells the maker that the part failed, so the maker is not left
/// waiting for it.
struct MakingSecond<'r, 'a> {
    relay: &'r Relay<'a>,
}

impl Drop for MakingSecond<'_, '_> {
    fn drop(&mut self) {
        let mut s = self.relay.lock();
        if matches!(s.second, Second::Making) {
            s.second = Second::Made(Err(io::Error::other(
                "the output's second part was not made",
            )));
        }
        self.relay.changed.notify_all();
    }
}

impl<'a> Relay<'a> {
    pub fn new() -> Relay<'a> {
        Relay::default()
    }

    fn lock(&self) -> MutexGuard<'_, State<'a>> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn wait<'g>(&self, s: MutexGuard<'g, State<'a>>) -> MutexGuard<'g, State<'a>> {
        self.changed.wait(s).unwrap_or_else(|e| e.into_inner())
    }

    /// Called by the maker before it may hand over anything; see [`Making`].
    pub fn making(&self) -> Making<'_, 'a> {
        Making { relay: self }
    }

    /// Runs `produce`, which hands its full buffers to the function it is
    /// given (and gets an empty one back to fill), and writes them to
    /// `file` in order; returns once all are written, with the first
    /// error of `produce` or of a write.
    pub fn relay(
        &self,
        file: &File,
        produce: impl FnOnce(&mut Produce<'_>) -> io::Result<()>,
    ) -> io::Result<()> {
        self.relay_parts(file, produce, None)
    }

    /// [`Relay::relay`] of an output in two parts: `first`, made here, then
    /// `second`, made by a helper meanwhile if one comes in time, else here
    /// after `first`. The file holds `first`'s bytes, then `second`'s.
    pub fn relay_parts(
        &self,
        file: &File,
        first: impl FnOnce(&mut Produce<'_>) -> io::Result<()>,
        second: Option<Later<'a>>,
    ) -> io::Result<()> {
        {
            let mut s = self.lock();
            // A second handle on the same open file: the writes share its
            // offset, so they land one after the other wherever they are
            // made.
            s.file = Some(Arc::new(file.try_clone()?));
            if let Some(later) = second {
                s.second = Second::Offered(later);
                self.changed.notify_all();
            }
        }
        let made = first(&mut |full| self.pass(full)).and_then(|()| self.second_part());
        let mut s = self.lock();
        if matches!(s.second, Second::Offered(_)) {
            // The first part failed: no one need make the second.
            s.second = Second::None;
        }
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

    /// The maker's hand-over: `full` joins the queue; without a helper (or
    /// while the helper makes the second part) the maker writes it now.
    /// Returns an empty buffer of the same capacity.
    fn pass(&self, full: Vec<u8>) -> Vec<u8> {
        let capacity = full.capacity();
        let mut s = self.lock();
        s.queue.push_back(full);
        loop {
            if !s.helped {
                s = self.write_queued(s);
                break;
            }
            self.changed.notify_all();
            if s.queue.len() <= MAX_QUEUED {
                break;
            }
            s = self.wait(s);
        }
        s.spare
            .pop()
            .unwrap_or_else(|| Vec::with_capacity(capacity))
    }

    /// The maker's second part, after its first: made here if it is still
    /// offered, else the helper's buffers queued once it has made them.
    fn second_part(&self) -> io::Result<()> {
        let mut s = self.lock();
        loop {
            match std::mem::take(&mut s.second) {
                Second::None => return Ok(()),
                Second::Offered(later) => {
                    drop(s);
                    return later(&mut |full| self.pass(full));
                }
                Second::Making => {
                    s.second = Second::Making;
                    s = self.wait(s);
                }
                Second::Made(made) => {
                    s.queue.extend(made?);
                    self.changed.notify_all();
                    return Ok(());
                }
            }
        }
    }

    /// Offered by a thread that has nothing else to do: makes the second
    /// part if it is offered, writes the maker's buffers as they come, and
    /// returns once the maker is done and all are written (at once if
    /// nothing is being made).
    pub fn help(&self) {
        let mut s = self.lock();
        loop {
            if let Second::Offered(_) = s.second {
                s = self.make_second(s);
            }
            s.helped = true;
            s = self.write_queued(s);
            if s.done && s.queue.is_empty() && !s.writing {
                return;
            }
            s = self.wait(s);
        }
    }

    /// The helper makes the offered second part into buffers of its own;
    /// meanwhile the maker writes its buffers itself.
    fn make_second<'g>(&'g self, mut s: MutexGuard<'g, State<'a>>) -> MutexGuard<'g, State<'a>> {
        let Second::Offered(later) = std::mem::replace(&mut s.second, Second::Making) else {
            return s;
        };
        s.helped = false;
        self.changed.notify_all();
        drop(s);
        let guard = MakingSecond { relay: self };
        let mut buffers = Vec::new();
        let made = later(&mut |full: Vec<u8>| {
            let capacity = full.capacity();
            buffers.push(full);
            Vec::with_capacity(capacity)
        });
        self.lock().second = Second::Made(made.map(|()| buffers));
        // Tells the maker, which may be waiting for the part.
        drop(guard);
        self.lock()
    }

    /// Writes the queued buffers in order, unless another thread is
    /// writing one; the lock is let go during each write.
    fn write_queued<'g>(&'g self, mut s: MutexGuard<'g, State<'a>>) -> MutexGuard<'g, State<'a>> {
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

    /// The maker makes `first_buffers` buffers, numbered from 0, and offers
    /// a second part of `second_buffers` buffers numbered after them.
    fn make_in_two<'a>(
        relay: &Relay<'a>,
        file: &File,
        first_buffers: usize,
        second: Later<'a>,
    ) -> io::Result<()> {
        let _making = relay.making();
        relay.relay_parts(
            file,
            |hand| {
                for b in 0..first_buffers {
                    hand(lines(b * 100, 100));
                }
                Ok(())
            },
            Some(second),
        )
    }

    /// Two buffers, after time enough for a waiting helper to take the
    /// second part.
    fn slow_first_part(hand: &mut Produce<'_>) -> io::Result<()> {
        std::thread::sleep(std::time::Duration::from_millis(20));
        hand(lines(0, 100));
        hand(lines(100, 100));
        Ok(())
    }

    fn second_part(from_buffer: usize, buffers: usize) -> Later<'static> {
        Box::new(move |hand: &mut Produce<'_>| {
            for b in from_buffer..from_buffer + buffers {
                hand(lines(b * 100, 100));
            }
            Ok(())
        })
    }

    /// Whoever makes the second part (the helper from the start, the maker
    /// when the helper comes late or never), its bytes follow the first's.
    #[test]
    fn a_second_part_follows_the_first_whoever_makes_it() {
        for delay_ms in [None, Some(0), Some(2), Some(30)] {
            let file = tempfile::tempfile().unwrap();
            let relay = Relay::new();
            std::thread::scope(|s| {
                let maker = s.spawn(|| make_in_two(&relay, &file, 300, second_part(300, 100)));
                if let Some(ms) = delay_ms {
                    std::thread::sleep(std::time::Duration::from_millis(ms));
                    relay.help();
                }
                maker.join().unwrap().unwrap();
            });
            assert_eq!(
                contents(&file),
                String::from_utf8(lines(0, 40_000)).unwrap(),
                "helper after {delay_ms:?} ms"
            );
        }
    }

    /// A helper that is already waiting when the parts are offered makes
    /// the second: the maker never runs it.
    #[test]
    fn a_waiting_helper_makes_the_second_part() {
        let file = tempfile::tempfile().unwrap();
        let relay = Relay::new();
        let helper = std::thread::current().id();
        std::thread::scope(|s| {
            let maker = s.spawn(|| {
                std::thread::sleep(std::time::Duration::from_millis(20));
                let second: Later<'_> = Box::new(move |hand: &mut Produce<'_>| {
                    assert_eq!(std::thread::current().id(), helper);
                    hand(lines(200, 100));
                    Ok(())
                });
                let _making = relay.making();
                relay.relay_parts(&file, slow_first_part, Some(second))
            });
            relay.help();
            maker.join().unwrap().unwrap();
        });
        assert_eq!(contents(&file), String::from_utf8(lines(0, 300)).unwrap());
    }

    /// The second part's error, and its panic on the helper, come back
    /// through the maker's `relay_parts`, which is not left waiting.
    #[test]
    fn a_failing_second_part_is_returned() {
        let failing: Later<'static> =
            Box::new(|_: &mut Produce<'_>| Err(io::Error::other("the tree failed")));
        let file = tempfile::tempfile().unwrap();
        let relay = Relay::new();
        let got = make_in_two(&relay, &file, 3, failing);
        assert_eq!(got.unwrap_err().to_string(), "the tree failed");

        let panicking: Later<'static> = Box::new(|_: &mut Produce<'_>| panic!("in the tree"));
        let file = tempfile::tempfile().unwrap();
        let relay = Relay::new();
        let got = std::thread::scope(|s| {
            let maker = s.spawn(|| {
                std::thread::sleep(std::time::Duration::from_millis(20));
                let _making = relay.making();
                relay.relay_parts(&file, slow_first_part, Some(panicking))
            });
            let helper = s.spawn(|| relay.help());
            assert!(
                helper.join().is_err(),
                "the panic reaches the helper's thread"
            );
            maker.join().unwrap()
        });
        assert!(got.is_err());
    }

    /// A first part that fails leaves the second unmade.
    #[test]
    fn a_failing_first_part_leaves_the_second_unmade() {
        let file = tempfile::tempfile().unwrap();
        let relay = Relay::new();
        let _making = relay.making();
        let second: Later<'_> =
            Box::new(|_: &mut Produce<'_>| panic!("the second part is not made"));
        let got = relay.relay_parts(
            &file,
            |_| Err(io::Error::other("the plan failed")),
            Some(second),
        );
        assert_eq!(got.unwrap_err().to_string(), "the plan failed");
        drop(_making);
        relay.help();
        assert_eq!(contents(&file), "");
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

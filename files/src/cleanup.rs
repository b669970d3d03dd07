//! What an interrupted btc leaves behind: nothing but complete files.
//! Temporary files of writes in progress are removed and open streams are
//! flushed when SIGINT, SIGTERM or SIGHUP arrives; then the process dies of
//! the signal as it would have without the handler.
//!
//! The handler is a thread of its own (signal-hook's iterator), installed
//! the first time something registers, so it may take locks and do IO.

use std::io::Write;
use std::path::PathBuf;
use std::sync::{Arc, Mutex, Once, Weak};

/// A stream the handler flushes: anything that can be written out.
pub type Flushable = Mutex<dyn Write + Send>;

#[derive(Default)]
struct Registry {
    next: u64,
    temps: Vec<(u64, PathBuf)>,
    streams: Vec<(u64, Weak<Flushable>)>,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    next: 0,
    temps: Vec::new(),
    streams: Vec::new(),
});
static INSTALL: Once = Once::new();

fn registry() -> std::sync::MutexGuard<'static, Registry> {
    // A panic elsewhere while holding the lock leaves the lists usable.
    REGISTRY.lock().unwrap_or_else(|e| e.into_inner())
}

fn install() {
    INSTALL.call_once(|| {
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        // Without a handler the default action (dying) is kept.
        let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
            return;
        };
        let _ = std::thread::Builder::new()
            .name("btc-signals".into())
            .spawn(move || {
                if let Some(sig) = signals.forever().next() {
                    tidy();
                    let _ = signal_hook::low_level::emulate_default_handler(sig);
                    std::process::exit(128 + sig);
                }
            });
    });
}

/// Removes every registered temporary file and flushes every stream.
fn tidy() {
    let mut r = registry();
    for (_, path) in r.temps.drain(..) {
        let _ = std::fs::remove_file(path);
    }
    for (_, s) in r.streams.drain(..) {
        if let Some(s) = s.upgrade() {
            if let Ok(mut w) = s.lock() {
                let _ = w.flush();
            }
        }
    }
}

/// A temporary file that is removed on a signal, and on drop unless
/// [`TempGuard::keep`] was called (it was renamed into place).
pub struct TempGuard {
    id: u64,
    path: PathBuf,
    keep: bool,
}

impl TempGuard {
    pub fn path(&self) -> &std::path::Path {
        &self.path
    }

    /// The file became the real one: do not remove it.
    pub fn keep(mut self) {
        self.keep = true;
    }
}

impl Drop for TempGuard {
    fn drop(&mut self) {
        registry().temps.retain(|(i, _)| *i != self.id);
        if !self.keep {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Registers a temporary file (before it is created, so that a signal
/// between creating and registering cannot leave it behind).
pub fn temp(path: PathBuf) -> TempGuard {
    install();
    let mut r = registry();
    r.next += 1;
    let id = r.next;
    r.temps.push((id, path.clone()));
    TempGuard {
        id,
        path,
        keep: false,
    }
}

/// Keeps a stream flushed on a signal while it lives; unregistered on drop
/// of the returned guard.
pub fn stream(s: &Arc<Flushable>) -> StreamGuard {
    install();
    let mut r = registry();
    r.next += 1;
    let id = r.next;
    r.streams.push((id, Arc::downgrade(s)));
    StreamGuard { id }
}

pub struct StreamGuard {
    id: u64,
}

impl Drop for StreamGuard {
    fn drop(&mut self) {
        registry().streams.retain(|(i, _)| *i != self.id);
    }
}

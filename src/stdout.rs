//! A command's main output on standard output. A reader that stops early
//! (`btc plan ... | head`) closes the pipe; the next write then fails with
//! `Closed`, which `main` turns into a quiet, successful end: the reader
//! has what it wanted, and there is nothing to report.

use std::fmt;
use std::io::{self, Write};

/// Standard output's reader has gone away.
#[derive(Debug)]
pub struct Closed;

impl fmt::Display for Closed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("standard output was closed by its reader")
    }
}

impl std::error::Error for Closed {}

/// Runs `produce` on standard output and flushes it; a closed pipe is
/// `Closed`, any other failure an error that says where it happened.
pub fn with(produce: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> anyhow::Result<()> {
    let mut out = io::stdout().lock();
    match produce(&mut out).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == io::ErrorKind::BrokenPipe => Err(Closed.into()),
        Err(e) => Err(anyhow::anyhow!("cannot write to standard output: {e}")),
    }
}

/// What `out!` and `outln!` call.
pub fn print(args: fmt::Arguments<'_>) -> anyhow::Result<()> {
    with(|w| w.write_fmt(args))
}

/// `print!` that returns `Closed` instead of panicking on a closed pipe.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::stdout::print(format_args!($($arg)*))
    };
}

/// `println!` that returns `Closed` instead of panicking on a closed pipe.
macro_rules! outln {
    () => {
        $crate::stdout::print(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::stdout::print(format_args!("{}\n", format_args!($($arg)*)))
    };
}

pub(crate) use {out, outln};

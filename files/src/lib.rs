//! How btc touches its users' files. Every command reads its inputs through
//! [`read`] and writes its outputs through [`write`] (or streams them with
//! [`Stream`]), so that no input can make btc grow without bound and no
//! output can damage what was there: modes, owners, hard and symbolic links
//! and special files (`/dev/null`, a FIFO) are kept, and a regular file is
//! replaced atomically. [`cleanup`] removes temporary files and flushes
//! streams when the process is interrupted. [`compare`] says whether an
//! output would change a file, without writing it (`--check`).
//!
//! The language server reads domains and imports from disk with [`read`]
//! too; nothing else in btc's libraries touches the file system.

pub mod cleanup;
pub mod compare;
pub mod read;
pub mod relay;
pub mod write;

pub use compare::{would_change, Comparison};
pub use read::{read, ReadError};
pub use relay::Relay;
pub use write::{stage, stage_file, write, write_with, Staged, Stream};

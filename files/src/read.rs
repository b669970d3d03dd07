//! The bounded reader: what is not a regular file or a stream is refused,
//! and nothing is read past the limit.

use std::io::Read;
use std::path::Path;

/// Why a path could not be read.
#[derive(Debug)]
pub enum ReadError {
    /// A folder, a device or something else that is not a file's contents.
    NotAFile {
        what: &'static str,
    },
    /// More bytes than the limit; reading stopped at `limit + 1`.
    TooLarge {
        limit: usize,
        known: Option<u64>,
    },
    Io(std::io::Error),
}

impl std::fmt::Display for ReadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReadError::NotAFile { what } => {
                write!(
                    f,
                    "it is {what}, not a file (btc reads regular files and pipes)"
                )
            }
            ReadError::TooLarge {
                limit,
                known: Some(n),
            } => write!(f, "it has {n} bytes; btc reads at most {limit}"),
            ReadError::TooLarge { limit, known: None } => {
                write!(f, "it goes on past {limit} bytes, the most btc reads")
            }
            ReadError::Io(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for ReadError {}

/// What kind of thing a path is, for the refusal message.
fn refused(ft: std::fs::FileType) -> Option<&'static str> {
    use std::os::unix::fs::FileTypeExt;
    if ft.is_dir() {
        Some("a folder")
    } else if ft.is_char_device() {
        Some("a character device")
    } else if ft.is_block_device() {
        Some("a block device")
    } else {
        None
    }
}

/// Reads at most `limit` bytes of `path`. Regular files, FIFOs and sockets
/// (a shell's `<(command)`) are read; folders and devices are refused
/// (`/dev/zero` never ends). A file that is, or grows, larger than `limit`
/// is refused after reading `limit + 1` bytes, so memory stays bounded
/// whatever the path is.
pub fn read(path: &Path, limit: usize) -> Result<Vec<u8>, ReadError> {
    let meta = std::fs::metadata(path).map_err(ReadError::Io)?;
    if let Some(what) = refused(meta.file_type()) {
        return Err(ReadError::NotAFile { what });
    }
    if meta.is_file() && meta.len() > limit as u64 {
        return Err(ReadError::TooLarge {
            limit,
            known: Some(meta.len()),
        });
    }
    let file = std::fs::File::open(path).map_err(ReadError::Io)?;
    // Check again on the open file: the path may have been swapped.
    let meta = file.metadata().map_err(ReadError::Io)?;
    if let Some(what) = refused(meta.file_type()) {
        return Err(ReadError::NotAFile { what });
    }
    let expect = if meta.is_file() {
        (meta.len() as usize).min(limit)
    } else {
        0
    };
    let mut bytes = Vec::with_capacity(expect.saturating_add(1));
    file.take(limit as u64 + 1)
        .read_to_end(&mut bytes)
        .map_err(ReadError::Io)?;
    if bytes.len() > limit {
        return Err(ReadError::TooLarge {
            limit,
            known: meta
                .is_file()
                .then_some(meta.len())
                .filter(|n| *n > limit as u64),
        });
    }
    Ok(bytes)
}

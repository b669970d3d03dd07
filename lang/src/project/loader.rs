//! Where a project's files come from: a [`FileLoader`]. The database reads
//! nothing itself; the loaders are [`super::DiskLoader`] (the language server
//! and the library facade), the CLI's own disk, and [`MemoryLoader`] (texts,
//! tests).

use crate::path::FilePath;
use btc_pddl::source::{decode, DecodeProblem};
use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

/// A file's text as a loader read it, and what was wrong with its bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Loaded {
    pub text: String,
    pub decode: Option<DecodeProblem>,
}

impl Loaded {
    /// Decodes raw bytes (UTF-8, or UTF-16 with a byte-order mark).
    pub fn from_bytes(bytes: &[u8]) -> Loaded {
        let (text, decode) = decode(bytes);
        Loaded { text, decode }
    }
}

/// Why a loader gives no text for a path.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ReadFailure {
    NotFound,
    /// A folder, a device: nothing that has a file's contents.
    NotAFile {
        reason: String,
    },
    /// It exists but cannot be read (permissions, too large for the reader...).
    Unreadable {
        reason: String,
    },
}

impl fmt::Display for ReadFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReadFailure::NotFound => f.write_str("no such file"),
            ReadFailure::NotAFile { reason } | ReadFailure::Unreadable { reason } => {
                f.write_str(reason)
            }
        }
    }
}

pub trait FileLoader {
    fn read(&self, path: &Path) -> Result<Loaded, ReadFailure>;

    /// The files directly inside a folder, sorted (pairing a plan with a
    /// problem looks at the files beside it). Empty when it cannot be read.
    fn list(&self, dir: &Path) -> Vec<PathBuf>;
}

/// Files held in memory, by normalised path.
#[derive(Clone, Debug, Default)]
pub struct MemoryLoader {
    files: BTreeMap<FilePath, Vec<u8>>,
}

impl MemoryLoader {
    pub fn new() -> MemoryLoader {
        MemoryLoader::default()
    }

    pub fn insert(&mut self, path: impl AsRef<Path>, bytes: impl Into<Vec<u8>>) {
        self.files.insert(FilePath::new(path), bytes.into());
    }

    pub fn with(mut self, path: impl AsRef<Path>, bytes: impl Into<Vec<u8>>) -> MemoryLoader {
        self.insert(path, bytes);
        self
    }
}

impl FileLoader for MemoryLoader {
    fn read(&self, path: &Path) -> Result<Loaded, ReadFailure> {
        self.files
            .get(&FilePath::new(path))
            .map(|b| Loaded::from_bytes(b))
            .ok_or(ReadFailure::NotFound)
    }

    fn list(&self, dir: &Path) -> Vec<PathBuf> {
        let dir = FilePath::new(dir);
        self.files
            .keys()
            .filter(|p| p.dir().as_ref() == Some(&dir))
            .filter_map(|p| p.as_path().map(Path::to_path_buf))
            .collect()
    }
}

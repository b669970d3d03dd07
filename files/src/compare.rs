//! Whether writing an output would change a file, found without writing
//! it (`btc compile --check`): the output is compared with the file's bytes
//! as it is produced, so a long output is never whole in memory, and the
//! file is never opened for writing.

use crate::write::{resolve, Produce};
use std::fs::File;
use std::io::{self, BufReader, Read, Write};
use std::path::Path;

/// What [`would_change`] found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Comparison {
    /// The file holds exactly these bytes.
    Same,
    /// The file holds other bytes.
    Differs,
    /// There is no such file.
    Missing,
}

/// A writer that reads the file alongside what is written to it and
/// remembers whether the two ever disagreed.
struct Comparer {
    file: BufReader<File>,
    differs: bool,
    buf: Vec<u8>,
}

impl Write for Comparer {
    fn write(&mut self, bytes: &[u8]) -> io::Result<usize> {
        if !self.differs {
            self.buf.resize(bytes.len(), 0);
            let mut got = 0;
            while got < bytes.len() {
                match self.file.read(&mut self.buf[got..])? {
                    0 => break,
                    n => got += n,
                }
            }
            self.differs = got < bytes.len() || self.buf[..got] != *bytes;
        }
        Ok(bytes.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// Compares what `produce` writes with the file at `path` (after symbolic
/// links); reads the file, writes nothing.
pub fn would_change(path: &Path, produce: &mut Produce<'_>) -> io::Result<Comparison> {
    let target = resolve(path)?;
    let file = match File::open(&target) {
        Ok(f) => f,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Comparison::Missing),
        Err(e) => return Err(e),
    };
    if file.metadata()?.is_dir() {
        return Err(io::Error::other("it is a folder"));
    }
    let mut c = Comparer {
        file: BufReader::new(file),
        differs: false,
        buf: Vec::new(),
    };
    produce(&mut c)?;
    // Bytes left in the file after the output's last: it would shrink.
    let longer = !c.differs && c.file.read(&mut [0u8; 1])? > 0;
    Ok(if c.differs || longer {
        Comparison::Differs
    } else {
        Comparison::Same
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn compare(old: Option<&[u8]>, chunks: &[&[u8]]) -> Comparison {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        if let Some(old) = old {
            std::fs::write(&path, old).unwrap();
        }
        let r = would_change(&path, &mut |w| {
            chunks.iter().try_for_each(|c| w.write_all(c))
        })
        .unwrap();
        // Nothing was written, whatever was found.
        assert_eq!(std::fs::read(&path).ok().as_deref(), old);
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            usize::from(old.is_some())
        );
        r
    }

    #[test]
    fn equal_bytes_in_any_chunks_are_the_same() {
        assert_eq!(
            compare(Some(b"abcdef"), &[b"abc", b"def"]),
            Comparison::Same
        );
        assert_eq!(compare(Some(b""), &[]), Comparison::Same);
    }

    #[test]
    fn other_shorter_or_longer_bytes_differ() {
        assert_eq!(
            compare(Some(b"abcdef"), &[b"abc", b"dXf"]),
            Comparison::Differs
        );
        assert_eq!(compare(Some(b"abcdef"), &[b"abc"]), Comparison::Differs);
        assert_eq!(compare(Some(b"abc"), &[b"abc", b"d"]), Comparison::Differs);
    }

    #[test]
    fn a_missing_file_is_missing() {
        assert_eq!(compare(None, &[b"abc"]), Comparison::Missing);
    }
}

//! The writer. A regular file is replaced atomically: the new contents go
//! to a temporary file in the target's folder, which then takes the
//! target's name in one step (the two names are exchanged and the old file
//! removed, or it is renamed over the target). A reader, or a failed emit,
//! never meets half a file. The temporary file takes the old file's mode
//! and owner (or the umask's mode for a new file); when the old file is 1
//! MB or more, blocks for as many bytes are allocated at once, and cut to
//! the new length after. Nothing is synced to disk: as compilers do,
//! btc leaves durability to the file system (an `fsync` cost 7-14 ms of a
//! 100,000-step compile), so a power cut right after a compile can leave
//! an empty output; compile again. What a rename would damage is written
//! in place instead: special files (`/dev/null`, `/dev/stdout`, a FIFO),
//! files with several hard links, files whose owner btc cannot give the
//! temporary file, and files in folders btc may not create files in. A
//! symbolic link is followed: its target is written, the link stays.

use crate::cleanup;
use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// How deep a chain of symbolic links btc follows (as Linux does).
const MAX_LINKS: usize = 40;

/// The file a path names after following symbolic links; the path itself
/// when it is not a link (or does not exist yet).
pub fn resolve(path: &Path) -> io::Result<PathBuf> {
    let mut p = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let to = std::fs::read_link(&p)?;
                p = match p.parent() {
                    Some(dir) if to.is_relative() => dir.join(to),
                    _ => to,
                };
            }
            _ => return Ok(p),
        }
    }
    Err(io::Error::other(format!(
        "more than {MAX_LINKS} symbolic links lead from `{}`",
        path.display()
    )))
}

/// How a target is to be written.
enum Plan {
    /// Through a temporary file and a rename, with the old file's mode and
    /// owner (`None`: a new file, the umask's mode, btc's owner).
    Atomic(Option<Old>),
    /// Opened and overwritten where it is.
    InPlace { truncate: bool },
}

/// What a new output takes from the file it replaces.
#[derive(Clone, Copy)]
struct Old {
    mode: u32,
    uid: u32,
    gid: u32,
    /// Its length: the new output is likely about as long (a compile run
    /// again), so its blocks are allocated at once.
    len: u64,
}

/// The shortest old file whose length is allocated ahead for the new one:
/// fewer blocks are not worth the call.
const ALLOCATE_AHEAD_FROM: u64 = 1 << 20;

fn plan(target: &Path) -> io::Result<Plan> {
    match std::fs::metadata(target) {
        Ok(m) if m.is_dir() => Err(io::Error::other("it is a folder")),
        Ok(m) if !m.is_file() => Ok(Plan::InPlace { truncate: false }),
        Ok(m) if m.nlink() > 1 => Ok(Plan::InPlace { truncate: true }),
        Ok(m) => Ok(Plan::Atomic(Some(Old {
            mode: m.mode() & 0o7777,
            uid: m.uid(),
            gid: m.gid(),
            len: m.len(),
        }))),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(Plan::Atomic(None)),
        Err(e) => Err(e),
    }
}

/// Writes `bytes` to `path` (see the module's documentation for how).
pub fn write(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_with(path, &mut |w| w.write_all(bytes))
}

/// What writes an output's bytes to the file [`write_with`] opened: called
/// once, or once more when the atomic way was refused before any byte.
pub type Produce<'a> = dyn FnMut(&mut dyn Write) -> io::Result<()> + 'a;

/// [`write`] of the bytes `produce` writes as it makes them (a long
/// output need never be whole in memory). If it fails, a file replaced
/// atomically is left as it was.
pub fn write_with(path: &Path, produce: &mut Produce<'_>) -> io::Result<()> {
    let target = resolve(path)?;
    match plan(&target)? {
        Plan::InPlace { truncate } => in_place(&target, produce, truncate),
        Plan::Atomic(old) => match atomic(&target, produce, old)? {
            Done::Written(()) => Ok(()),
            // The folder is read-only (or the owner cannot be kept), but
            // the file itself may well be writable.
            Done::Refused(e) if old.is_some() => in_place(&target, produce, true).map_err(|_| e),
            Done::Refused(e) => Err(e),
        },
    }
}

fn in_place(target: &Path, produce: &mut Produce<'_>, truncate: bool) -> io::Result<()> {
    let mut f = OpenOptions::new()
        .write(true)
        .truncate(truncate)
        .open(target)?;
    produce(&mut f)?;
    f.flush()
}

enum Done<T> {
    Written(T),
    /// The atomic way is closed (no temporary file, no owner): the caller
    /// may write in place.
    Refused(io::Error),
}

fn temp_path(target: &Path, attempt: u32) -> PathBuf {
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = format!(".{name}.{}-{attempt}.btc-tmp", std::process::id());
    match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.join(tmp),
        _ => PathBuf::from(tmp),
    }
}

/// An output written in full to a temporary file beside its target, not
/// yet in the target's place: [`Staged::commit`] renames it there, and
/// dropping it removes it. A command can so make an output while it is
/// still checking whether it may write one (`btc compile` emits while it
/// replays the plan) and leave nothing behind when it may not.
pub struct Staged {
    guard: cleanup::TempGuard,
    target: PathBuf,
}

impl Staged {
    /// Puts the output in its target's place.
    pub fn commit(self) -> io::Result<()> {
        if exchange(self.guard.path(), &self.target).is_ok() {
            // The old file now has the temporary name: the guard removes it.
            drop(self.guard);
            return Ok(());
        }
        std::fs::rename(self.guard.path(), &self.target)?;
        self.guard.keep();
        Ok(())
    }

    /// The file the output will replace.
    pub fn target(&self) -> &Path {
        &self.target
    }
}

/// Writes what `produce` makes to a temporary file beside `path`, for
/// [`Staged::commit`] to put in place. `Ok(None)` when `path` is not
/// replaced atomically (a special file, several hard links, a folder btc
/// may not create files in): then [`write_with`] is the way, at the time
/// the output may be written. If `produce` fails, nothing is left behind.
pub fn stage(path: &Path, produce: &mut Produce<'_>) -> io::Result<Option<Staged>> {
    stage_file(path, &mut |mut f: &File| produce(&mut f))
}

/// [`stage`], with `produce` given the temporary file itself (for a
/// [`crate::Relay`], which writes to it from two threads).
pub fn stage_file(
    path: &Path,
    produce: &mut dyn FnMut(&File) -> io::Result<()>,
) -> io::Result<Option<Staged>> {
    let target = resolve(path)?;
    let Plan::Atomic(old) = plan(&target)? else {
        return Ok(None);
    };
    Ok(match staged(&target, produce, old)? {
        Done::Written(s) => Some(s),
        Done::Refused(_) => None,
    })
}

/// Allocates `len` bytes of blocks for `file` before it is written: ext4
/// then maps each page to a block as it is written instead of reserving
/// one (a 17 MB output: 2.8 -> 1.7 ms of writing). False where the file
/// system cannot (the output is written as it would be otherwise).
#[cfg(target_os = "linux")]
fn allocate(file: &File, len: u64) -> bool {
    rustix::fs::fallocate(file, rustix::fs::FallocateFlags::empty(), 0, len).is_ok()
}

#[cfg(not(target_os = "linux"))]
fn allocate(_: &File, _: u64) -> bool {
    false
}

/// Swaps the names of `new` and `target` in one step, where `target` is a
/// regular file and the file system can. A rename over an existing file
/// would do the same for readers, but ext4 then writes the new file's
/// blocks out before it returns (its `auto_da_alloc`, for programs that
/// replace files without syncing): 5-7 ms for a 17 MB output, for a
/// durability btc does not promise (see the module's documentation).
/// Anything else (no such target, a folder put there meanwhile, no
/// support) is an error, and the caller renames.
#[cfg(target_os = "linux")]
fn exchange(new: &Path, target: &Path) -> io::Result<()> {
    use rustix::fs::{renameat_with, RenameFlags, CWD};
    if !std::fs::symlink_metadata(target)?.is_file() {
        return Err(io::Error::other("not a regular file"));
    }
    Ok(renameat_with(CWD, new, CWD, target, RenameFlags::EXCHANGE)?)
}

#[cfg(not(target_os = "linux"))]
fn exchange(_: &Path, _: &Path) -> io::Result<()> {
    Err(io::Error::other("no exchange of names here"))
}

fn atomic(target: &Path, produce: &mut Produce<'_>, old: Option<Old>) -> io::Result<Done<()>> {
    Ok(
        match staged(target, &mut |mut f: &File| produce(&mut f), old)? {
            Done::Written(s) => Done::Written(s.commit()?),
            Done::Refused(e) => Done::Refused(e),
        },
    )
}

fn staged(
    target: &Path,
    produce: &mut dyn FnMut(&File) -> io::Result<()>,
    old: Option<Old>,
) -> io::Result<Done<Staged>> {
    let (guard, mut file) = {
        let mut attempt = 0;
        loop {
            let guard = cleanup::temp(temp_path(target, attempt));
            // 0o666 less the umask for a new file, as any tool creates one.
            match OpenOptions::new()
                .write(true)
                .create_new(true)
                .mode(if old.is_some() { 0o600 } else { 0o666 })
                .open(guard.path())
            {
                Ok(f) => break (guard, f),
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists && attempt < 100 => {
                    guard.keep(); // someone else's file: leave it
                    attempt += 1;
                }
                Err(e)
                    if matches!(
                        e.kind(),
                        io::ErrorKind::PermissionDenied | io::ErrorKind::ReadOnlyFilesystem
                    ) =>
                {
                    guard.keep(); // never created
                    return Ok(Done::Refused(e));
                }
                Err(e) => {
                    guard.keep();
                    return Err(e);
                }
            }
        }
    };
    if let Some(Old { mode, uid, gid, .. }) = old {
        let meta = file.metadata()?;
        if (meta.uid(), meta.gid()) != (uid, gid) {
            if let Err(e) = std::os::unix::fs::fchown(&file, Some(uid), Some(gid)) {
                return Ok(Done::Refused(e));
            }
        }
        file.set_permissions(std::fs::Permissions::from_mode(mode))?;
    }
    let ahead = old.map_or(0, |o| o.len);
    let allocated = ahead >= ALLOCATE_AHEAD_FROM && allocate(&file, ahead);
    produce(&file)?;
    if allocated {
        // Shorter than the old file: the blocks past its end go.
        let end = io::Seek::stream_position(&mut file)?;
        if end < ahead {
            file.set_len(end)?;
        }
    }
    drop(file);
    Ok(Done::Written(Staged {
        guard,
        target: target.to_path_buf(),
    }))
}

/// An output written as it is produced (a run's trace): every line handed
/// over reaches the file at the next [`Stream::flush`], and on SIGINT or
/// SIGTERM. Not atomic, by design: a killed run leaves what it wrote. The
/// target is truncated in place (mode, owner and links kept; special files
/// written as they are).
pub struct Stream {
    inner: Arc<Mutex<BufWriter<File>>>,
    /// The first write error: writers that cannot return one (a closed
    /// loop's trace) still have it reported by [`Stream::finish`].
    error: Mutex<Option<io::Error>>,
    _guard: cleanup::StreamGuard,
}

impl Stream {
    pub fn create(path: &Path) -> io::Result<Stream> {
        let target = resolve(path)?;
        let special = matches!(std::fs::metadata(&target), Ok(m) if !m.is_file());
        if std::fs::metadata(&target).is_ok_and(|m| m.is_dir()) {
            return Err(io::Error::other("it is a folder"));
        }
        let file = OpenOptions::new()
            .write(true)
            .create(!special)
            .truncate(!special)
            .mode(0o666)
            .open(&target)?;
        let inner = Arc::new(Mutex::new(BufWriter::with_capacity(64 << 10, file)));
        let flushable: Arc<cleanup::Flushable> = inner.clone();
        let guard = cleanup::stream(&flushable);
        Ok(Stream {
            inner,
            error: Mutex::new(None),
            _guard: guard,
        })
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, BufWriter<File>> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    pub fn write_all(&self, bytes: &[u8]) -> io::Result<()> {
        let r = self.lock().write_all(bytes);
        self.note(r)
    }

    pub fn flush(&self) -> io::Result<()> {
        let r = self.lock().flush();
        self.note(r)
    }

    fn note(&self, r: io::Result<()>) -> io::Result<()> {
        if let Err(e) = &r {
            let mut first = self.error.lock().unwrap_or_else(|e| e.into_inner());
            if first.is_none() {
                *first = Some(io::Error::new(e.kind(), e.to_string()));
            }
        }
        r
    }

    /// Flushes, and reports the first error any write met.
    pub fn finish(self) -> io::Result<()> {
        let flushed = self.flush();
        let first = self.error.lock().unwrap_or_else(|e| e.into_inner()).take();
        match first {
            Some(e) => Err(e),
            None => flushed,
        }
    }
}

/// Lines can be written to a shared stream (`&Stream`), as to a file.
impl Write for &Stream {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        Stream::write_all(self, buf).map(|()| buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Stream::flush(self)
    }
}

impl Drop for Stream {
    fn drop(&mut self) {
        let _ = self.lock().flush();
    }
}

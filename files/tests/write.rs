//! The writer keeps what a rename would destroy: modes, owners, links,
//! special files; and it is atomic for regular files.

use btc_files::{stage, write, write_with, Stream};
use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::Path;
use std::process::Command;

fn mode(p: &Path) -> u32 {
    std::fs::metadata(p).unwrap().permissions().mode() & 0o7777
}

/// The umask, read from a shell (std cannot read it without setting it).
fn umask() -> u32 {
    let out = Command::new("sh").arg("-c").arg("umask").output().unwrap();
    u32::from_str_radix(String::from_utf8_lossy(&out.stdout).trim(), 8).unwrap()
}

fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("btc-tmp"))
        .collect()
}

#[test]
fn a_new_file_gets_the_umask_mode() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("out.xml");
    write(&p, b"<root/>").unwrap();
    assert_eq!(std::fs::read(&p).unwrap(), b"<root/>");
    assert_eq!(mode(&p), 0o666 & !umask());
    assert!(leftovers(dir.path()).is_empty());
}

/// An output written piece by piece as it is made lands whole.
#[test]
fn a_produced_output_lands_whole() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("out.xml");
    write_with(&p, &mut |w| {
        (0..1000).try_for_each(|i| writeln!(w, "<step n=\"{i}\"/>"))
    })
    .unwrap();
    let expected: String = (0..1000).map(|i| format!("<step n=\"{i}\"/>\n")).collect();
    assert_eq!(std::fs::read_to_string(&p).unwrap(), expected);
    assert!(leftovers(dir.path()).is_empty());
}

/// A long old file's length is allocated ahead for the new output: one
/// shorter or longer than it ends where its bytes end, without the old
/// file's blocks past them, and one that fails leaves the old file.
#[test]
fn an_output_replacing_a_long_file_ends_where_it_ends() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("tree.py");
    std::fs::write(&p, vec![b'x'; 3 << 20]).unwrap();
    for (len, byte) in [
        (2 << 20, b'a'),
        (3 << 20, b'b'),
        (5 << 20, b'c'),
        (1000, b'd'),
    ] {
        write_with(&p, &mut |w| w.write_all(&vec![byte; len])).unwrap();
        let got = std::fs::read(&p).unwrap();
        assert_eq!(got.len(), len);
        assert!(got.iter().all(|&b| b == byte));
        let allocated = std::fs::metadata(&p).unwrap().blocks() * 512;
        assert!(
            allocated < len as u64 + (64 << 10),
            "{allocated} bytes of blocks for {len}"
        );
        assert!(leftovers(dir.path()).is_empty());
    }
    std::fs::write(&p, vec![b'x'; 3 << 20]).unwrap();
    let failed = write_with(&p, &mut |w| {
        w.write_all(&[b'y'; 1 << 20])?;
        Err(std::io::Error::other("disk full"))
    });
    assert!(failed.is_err());
    assert_eq!(std::fs::read(&p).unwrap(), vec![b'x'; 3 << 20]);
    assert!(leftovers(dir.path()).is_empty());
}

/// A producer that fails half-way (a full disk, a broken emitter) leaves
/// the old file as it was, and no temporary file beside it.
#[test]
fn a_failed_output_leaves_the_old_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("out.xml");
    std::fs::write(&p, b"old").unwrap();
    let err = write_with(&p, &mut |w| {
        w.write_all(b"half of the new")?;
        Err(std::io::Error::other("disk full"))
    })
    .unwrap_err();
    assert_eq!(err.to_string(), "disk full");
    assert_eq!(std::fs::read(&p).unwrap(), b"old");
    assert!(leftovers(dir.path()).is_empty());
}

/// A staged output waits beside its target: the old file stays as it was
/// until the commit, and an output never committed leaves nothing.
#[test]
fn a_staged_output_lands_on_commit_and_is_gone_if_dropped() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("out.xml");
    std::fs::write(&p, b"old").unwrap();
    let dropped = stage(&p, &mut |w| w.write_all(b"refused"))
        .unwrap()
        .unwrap();
    assert_eq!(leftovers(dir.path()).len(), 1);
    assert_eq!(std::fs::read(&p).unwrap(), b"old");
    drop(dropped);
    assert!(leftovers(dir.path()).is_empty());
    assert_eq!(std::fs::read(&p).unwrap(), b"old");

    let staged = stage(&p, &mut |w| w.write_all(b"new")).unwrap().unwrap();
    assert_eq!(staged.target(), p);
    assert_eq!(std::fs::read(&p).unwrap(), b"old");
    staged.commit().unwrap();
    assert_eq!(std::fs::read(&p).unwrap(), b"new");
    assert!(leftovers(dir.path()).is_empty());

    let failed = stage(&p, &mut |_| Err(std::io::Error::other("disk full")));
    assert_eq!(
        failed.err().map(|e| e.to_string()).as_deref(),
        Some("disk full")
    );
    assert!(leftovers(dir.path()).is_empty());
    // What a rename would damage is not staged: it is written at the end.
    assert!(stage(Path::new("/dev/null"), &mut |w| w.write_all(b"x"))
        .unwrap()
        .is_none());
}

#[test]
fn rewriting_keeps_the_mode() {
    let dir = tempfile::tempdir().unwrap();
    for m in [0o644, 0o755, 0o600, 0o640] {
        let p = dir.path().join(format!("f{m:o}"));
        std::fs::write(&p, b"old").unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(m)).unwrap();
        write(&p, b"new").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"new");
        assert_eq!(mode(&p), m);
    }
}

#[test]
fn a_symbolic_link_writes_its_target_and_stays_a_link() {
    let dir = tempfile::tempdir().unwrap();
    let real = dir.path().join("real.btrules");
    let link = dir.path().join("link.btrules");
    std::fs::write(&real, b"old").unwrap();
    std::os::unix::fs::symlink("real.btrules", &link).unwrap();
    write(&link, b"new").unwrap();
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(std::fs::read(&real).unwrap(), b"new");
}

#[test]
fn hard_links_are_not_split() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a");
    let b = dir.path().join("b");
    std::fs::write(&a, b"old").unwrap();
    std::fs::hard_link(&a, &b).unwrap();
    write(&a, b"new").unwrap();
    assert_eq!(std::fs::read(&b).unwrap(), b"new");
    assert_eq!(
        std::fs::metadata(&a).unwrap().ino(),
        std::fs::metadata(&b).unwrap().ino()
    );
}

#[test]
fn special_files_are_written_in_place() {
    write(Path::new("/dev/null"), b"gone").unwrap();
    let meta = std::fs::metadata("/dev/null").unwrap();
    assert!(!meta.is_file(), "/dev/null is still a device");
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("fifo");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let f2 = fifo.clone();
    let reader = std::thread::spawn(move || std::fs::read(f2).unwrap());
    write(&fifo, b"through the pipe").unwrap();
    assert_eq!(reader.join().unwrap(), b"through the pipe");
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    assert!(leftovers(dir.path()).is_empty());
}

#[test]
fn a_writable_file_in_a_read_only_folder_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("out.txt");
    std::fs::write(&p, b"old").unwrap();
    std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o555)).unwrap();
    // Root may create files anywhere; then the atomic way works and this
    // test says nothing, but it must still write.
    let r = write(&p, b"new");
    std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o755)).unwrap();
    r.unwrap();
    assert_eq!(std::fs::read(&p).unwrap(), b"new");
    assert!(leftovers(dir.path()).is_empty());
}

#[test]
fn the_owner_is_kept_when_btc_may_give_it() {
    // Only root can give a file to someone else; elsewhere this is the
    // plain case (owner unchanged).
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("owned");
    std::fs::write(&p, b"old").unwrap();
    let is_root = std::fs::metadata(&p).unwrap().uid() == 0;
    if is_root {
        std::os::unix::fs::chown(&p, Some(65534), Some(65534)).unwrap();
    }
    let before = std::fs::metadata(&p).unwrap();
    write(&p, b"new").unwrap();
    let after = std::fs::metadata(&p).unwrap();
    assert_eq!((before.uid(), before.gid()), (after.uid(), after.gid()));
    assert_eq!(std::fs::read(&p).unwrap(), b"new");
}

#[test]
fn a_folder_is_not_written() {
    let dir = tempfile::tempdir().unwrap();
    assert!(write(dir.path(), b"x").is_err());
}

#[test]
fn a_stream_writes_as_it_goes_and_keeps_the_mode() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("trace.jsonl");
    std::fs::write(&p, b"old contents that are longer").unwrap();
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o640)).unwrap();
    let s = Stream::create(&p).unwrap();
    s.write_all(b"{\"tick\":1}\n").unwrap();
    s.flush().unwrap();
    assert_eq!(std::fs::read(&p).unwrap(), b"{\"tick\":1}\n");
    s.write_all(b"{\"tick\":2}\n").unwrap();
    drop(s);
    assert_eq!(std::fs::read(&p).unwrap(), b"{\"tick\":1}\n{\"tick\":2}\n");
    assert_eq!(mode(&p), 0o640);
    let dev = Stream::create(Path::new("/dev/null")).unwrap();
    dev.write_all(b"x").unwrap();
    drop(dev);
    assert!(!std::fs::metadata("/dev/null").unwrap().is_file());
}

#[test]
fn a_shared_stream_is_a_writer() {
    use std::io::Write;
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("t");
    let s = Stream::create(&p).unwrap();
    let mut w: &Stream = &s;
    writeln!(w, "one").unwrap();
    w.write_all(b"two\n").unwrap();
    s.finish().unwrap();
    assert_eq!(std::fs::read(&p).unwrap(), b"one\ntwo\n");
}

/// A regular file is replaced, not overwritten: a reader that opened the
/// old file (an executor loading the last tree) reads it whole, and the
/// folder holds the new file alone.
#[test]
fn a_reader_of_the_old_file_keeps_reading_it_whole() {
    use std::io::Read;
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("tree.xml");
    std::fs::write(&p, b"old tree").unwrap();
    let mut reader = std::fs::File::open(&p).unwrap();
    let staged = stage(&p, &mut |w| w.write_all(b"new tree, longer"))
        .unwrap()
        .unwrap();
    staged.commit().unwrap();
    let mut old = String::new();
    reader.read_to_string(&mut old).unwrap();
    assert_eq!(old, "old tree");
    assert_eq!(std::fs::read(&p).unwrap(), b"new tree, longer");
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, ["tree.xml"]);
}

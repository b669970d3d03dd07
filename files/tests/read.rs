//! The bounded reader: devices and folders are refused at once, streams
//! and growing files are cut at the limit, regular files read whole.

use btc_files::{read, ReadError};
use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};

#[test]
fn a_regular_file_is_read_whole() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("a.pddl");
    std::fs::write(&p, b"(define)").unwrap();
    assert_eq!(read(&p, 100).unwrap(), b"(define)");
}

#[test]
fn devices_and_folders_are_refused_without_reading() {
    for (path, what) in [
        ("/dev/zero", "a character device"),
        ("/dev/null", "a character device"),
        ("/", "a folder"),
    ] {
        match read(Path::new(path), 1 << 30) {
            Err(ReadError::NotAFile { what: w }) => assert_eq!(w, what, "{path}"),
            other => panic!("{path}: {other:?}"),
        }
    }
}

#[test]
fn a_file_over_the_limit_is_refused_by_its_size() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("big");
    std::fs::write(&p, vec![b'x'; 101]).unwrap();
    match read(&p, 100) {
        Err(ReadError::TooLarge {
            limit: 100,
            known: Some(101),
        }) => {}
        other => panic!("{other:?}"),
    }
    assert_eq!(read(&p, 101).unwrap().len(), 101);
}

#[test]
fn an_endless_stream_is_cut_at_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("fifo");
    let ok = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(ok.success());
    // A writer that never stops (until the pipe closes).
    let mut writer = Command::new("sh")
        .arg("-c")
        .arg(format!("yes > '{}'", fifo.display()))
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let r = read(&fifo, 1 << 20);
    let _ = writer.kill();
    let _ = writer.wait();
    match r {
        Err(ReadError::TooLarge { limit, known: None }) => assert_eq!(limit, 1 << 20),
        other => panic!("{:?}", other.map(|b| b.len())),
    }
}

#[test]
fn a_short_stream_is_read_whole() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("fifo");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let f2 = fifo.clone();
    let t = std::thread::spawn(move || {
        let mut w = std::fs::OpenOptions::new().write(true).open(f2).unwrap();
        w.write_all(b"move a b\n").unwrap();
    });
    assert_eq!(read(&fifo, 100).unwrap(), b"move a b\n");
    t.join().unwrap();
}

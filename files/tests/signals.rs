//! SIGTERM and SIGINT remove registered temporary files and flush streams,
//! then the process dies of the signal. The test runs itself as the child:
//! with `BTC_FILES_CHILD` set, the child test registers a temporary file
//! and a stream and waits to be killed.

use std::io::{BufRead, BufReader};
use std::os::unix::process::ExitStatusExt;
use std::process::{Command, Stdio};

#[test]
fn child() {
    let Some(dir) = std::env::var_os("BTC_FILES_CHILD") else {
        return; // run as a child only
    };
    let dir = std::path::PathBuf::from(dir);
    let tmp = dir.join(".out.btc-tmp");
    let guard = btc_files::cleanup::temp(tmp.clone());
    std::fs::write(&tmp, b"half").unwrap();
    let s = btc_files::Stream::create(&dir.join("trace.jsonl")).unwrap();
    s.write_all(b"line 1\n").unwrap(); // buffered, not flushed
    println!("ready");
    std::thread::sleep(std::time::Duration::from_secs(30));
    drop((guard, s));
}

fn interrupted_by(signal: &str, number: i32) {
    let dir = tempfile::tempdir().unwrap();
    let mut child = Command::new(std::env::current_exe().unwrap())
        .args(["--exact", "child", "--nocapture", "--test-threads=1"])
        .env("BTC_FILES_CHILD", dir.path())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    assert!(lines.any(|l| l.unwrap().contains("ready")));
    assert!(dir.path().join(".out.btc-tmp").exists());
    let ok = Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .unwrap();
    assert!(ok.success());
    let status = child.wait().unwrap();
    assert_eq!(status.signal(), Some(number), "{status:?}");
    assert!(
        !dir.path().join(".out.btc-tmp").exists(),
        "temporary file left"
    );
    assert_eq!(
        std::fs::read(dir.path().join("trace.jsonl")).unwrap(),
        b"line 1\n",
        "the stream was not flushed"
    );
}

#[test]
fn sigterm_removes_temporary_files_and_flushes_streams() {
    interrupted_by("TERM", 15);
}

#[test]
fn sigint_removes_temporary_files_and_flushes_streams() {
    interrupted_by("INT", 2);
}

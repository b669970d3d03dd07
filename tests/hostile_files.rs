//! What a command does with paths that are not plain files: devices and
//! folders as inputs are refused at once (never read: `/dev/zero` never
//! ends); outputs keep their mode, owner, links and file type, whatever
//! command writes them (`-o`, `plan -o`, `--trace`, `fmt`).

mod support;
use std::os::unix::fs::{FileTypeExt, MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};
use support::btc;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn ariac(file: &str) -> String {
    repo()
        .join("examples/ariac")
        .join(file)
        .display()
        .to_string()
}

/// The ARIAC example's rules, domain, problem and plan, and a trial.
fn inputs() -> [String; 5] {
    [
        ariac("rules.btrules"),
        ariac("domain.pddl"),
        ariac("problem.pddl"),
        ariac("plan.txt"),
        repo()
            .join("examples/ariac_cell/trials/mixed.yaml")
            .display()
            .to_string(),
    ]
}

fn words(v: &[&str]) -> Vec<String> {
    v.iter().map(|x| x.to_string()).collect()
}

/// Every input flag of every command, with `PATH` standing for the hostile
/// input.
fn input_commands() -> Vec<Vec<String>> {
    let [r, d, p, l, t] = inputs();
    let s = words;
    vec![
        s(&["check", "PATH"]),
        s(&["compile", "PATH", "--plan", &l, "--emit", "json"]),
        s(&["compile", &r, "--plan", "PATH", "--emit", "json"]),
        s(&[
            "compile",
            &r,
            "--plan",
            &l,
            "--problem",
            "PATH",
            "--emit",
            "json",
        ]),
        s(&[
            "compile", &r, "--plan", &l, "--domain", "PATH", "--emit", "json",
        ]),
        s(&["fmt", "--check", "PATH"]),
        s(&["pddl", "PATH"]),
        s(&["pddl", &p, "--domain", "PATH"]),
        s(&["validate", "PATH", &p, &l]),
        s(&["validate", &d, "PATH", &l]),
        s(&["validate", &d, &p, "PATH"]),
        s(&["plan", "PATH", &p]),
        s(&["plan", &d, "PATH"]),
        s(&["run", "PATH", "--plan", &l]),
        s(&["run", &r, "--plan", "PATH"]),
        s(&["run", &r, "--plan", &l, "--faults", "PATH"]),
        s(&["run", "--tree", "PATH", "--problem", &p]),
        s(&["run", &r, "--problem", &p, "--replan", "--faults", "PATH"]),
        s(&["trial", "PATH"]),
        s(&["trial", &t, "--cell", "PATH"]),
    ]
}

#[test]
fn devices_and_folders_are_refused_by_every_command_at_once() {
    for path in ["/dev/zero", "/dev/urandom", "/"] {
        for cmd in input_commands() {
            let args: Vec<String> = cmd
                .iter()
                .map(|a| {
                    if a == "PATH" {
                        path.to_owned()
                    } else {
                        a.clone()
                    }
                })
                .collect();
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let t = Instant::now();
            let out = btc(&args);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert!(
                t.elapsed() < Duration::from_secs(10),
                "{args:?} took {:?}",
                t.elapsed()
            );
            assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
            assert!(stderr.contains("[F004]"), "{args:?}: {stderr}");
        }
    }
}

/// A device node of our own (a copy of /dev/null: major 1, minor 3), so a
/// broken writer cannot damage the machine's. Needs root; `None` otherwise.
fn own_null(dir: &Path) -> Option<PathBuf> {
    let p = dir.join("null");
    let ok = Command::new("mknod")
        .arg(&p)
        .args(["c", "1", "3"])
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    ok.then_some(p)
}

fn fifo(dir: &Path, name: &str) -> PathBuf {
    let p = dir.join(name);
    assert!(Command::new("mkfifo").arg(&p).status().unwrap().success());
    p
}

/// Every command that writes a file, with `OUT` standing for the output.
fn output_commands() -> Vec<Vec<String>> {
    let [r, d, p, l, t] = inputs();
    let s = words;
    vec![
        s(&["compile", &r, "--plan", &l, "--emit", "btcpp", "-o", "OUT"]),
        s(&["plan", &d, &p, "-o", "OUT", "--quiet"]),
        s(&["run", &r, "--plan", &l, "--trace", "OUT"]),
        s(&["run", &r, "--problem", &p, "--replan", "--trace", "OUT"]),
        s(&["trial", &t, "--trace", "OUT"]),
    ]
}

fn with_out(cmd: &[String], out: &Path) -> Vec<String> {
    cmd.iter()
        .map(|a| {
            if a == "OUT" {
                out.display().to_string()
            } else {
                a.clone()
            }
        })
        .collect()
}

fn run(args: &[String]) -> Output {
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = btc(&args);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("tmp"))
        .collect()
}

#[test]
fn outputs_keep_their_mode_and_owner_and_follow_symbolic_links() {
    for cmd in output_commands() {
        let dir = tempfile::tempdir().unwrap();
        // An existing file: its mode stays.
        let out = dir.path().join("out");
        std::fs::write(&out, b"old").unwrap();
        std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o754)).unwrap();
        let ino = std::fs::metadata(&out).unwrap().uid();
        run(&with_out(&cmd, &out));
        let meta = std::fs::metadata(&out).unwrap();
        assert_eq!(meta.permissions().mode() & 0o7777, 0o754, "{cmd:?}");
        assert_eq!(meta.uid(), ino, "{cmd:?}");
        assert_ne!(std::fs::read(&out).unwrap(), b"old", "{cmd:?}");
        // A new file: the umask's mode (0o666 less the umask), not 0600.
        let new = dir.path().join("new");
        run(&with_out(&cmd, &new));
        let m = std::fs::metadata(&new).unwrap().permissions().mode() & 0o777;
        assert_eq!(m & 0o044, 0o044 & m, "{cmd:?}");
        assert_ne!(
            m, 0o600,
            "{cmd:?}: a new file must not be 0600 whatever the umask"
        );
        // A symbolic link: the target is written, the link stays a link.
        let real = dir.path().join("real");
        std::fs::write(&real, b"old").unwrap();
        let link = dir.path().join("link");
        std::os::unix::fs::symlink("real", &link).unwrap();
        run(&with_out(&cmd, &link));
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_ne!(std::fs::read(&real).unwrap(), b"old", "{cmd:?}");
        // A hard link: both names see the new contents.
        let twin = dir.path().join("twin");
        std::fs::hard_link(&out, &twin).unwrap();
        run(&with_out(&cmd, &out));
        assert_eq!(std::fs::read(&twin).unwrap(), std::fs::read(&out).unwrap());
        assert!(
            leftovers(dir.path()).is_empty(),
            "{:?}",
            leftovers(dir.path())
        );
    }
}

#[test]
fn special_files_stay_special() {
    for cmd in output_commands() {
        let dir = tempfile::tempdir().unwrap();
        if let Some(null) = own_null(dir.path()) {
            run(&with_out(&cmd, &null));
            let ft = std::fs::metadata(&null).unwrap().file_type();
            assert!(ft.is_char_device(), "{cmd:?} replaced the device node");
        }
        let pipe = fifo(dir.path(), "pipe");
        let p2 = pipe.clone();
        let reader = std::thread::spawn(move || std::fs::read(p2).unwrap());
        run(&with_out(&cmd, &pipe));
        let got = reader.join().unwrap();
        assert!(!got.is_empty(), "{cmd:?}: nothing came through the pipe");
        assert!(
            std::fs::metadata(&pipe).unwrap().file_type().is_fifo(),
            "{cmd:?}"
        );
        assert!(
            leftovers(dir.path()).is_empty(),
            "{:?}",
            leftovers(dir.path())
        );
    }
}

#[test]
fn fmt_keeps_mode_and_formats_through_a_symbolic_link() {
    let dir = tempfile::tempdir().unwrap();
    let real = dir.path().join("rules.btrules");
    std::fs::write(&real, "action   A()\n").unwrap();
    std::fs::set_permissions(&real, std::fs::Permissions::from_mode(0o755)).unwrap();
    let link = dir.path().join("link.btrules");
    std::os::unix::fs::symlink("rules.btrules", &link).unwrap();
    let out = btc(&["fmt", link.to_str().unwrap()]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(std::fs::read_to_string(&real).unwrap(), "action A()\n");
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(
        std::fs::metadata(&real).unwrap().permissions().mode() & 0o7777,
        0o755
    );
}

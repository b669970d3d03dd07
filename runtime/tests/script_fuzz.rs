//! Expression fuzzing against BT.CPP's own evaluator: seeded random
//! scripts are evaluated by btc (`btc_runtime::script`) and by real
//! BehaviorTree.CPP 4.10 (`runtime/peer/peer.cpp eval`, each on a fresh
//! blackboard); both must give the same value, or errors of the same class
//! (syntax, not found, not initialized, type). Needs a BT.CPP build
//! (`integrations/btcpp/build-btcpp.sh`); skipped without one, required
//! under CI=true.

use btc_runtime::script::{self, Env};
use btc_runtime::Value;
use std::io::Write;
use std::process::{Command, Stdio};

/// splitmix64: a seeded stream, so a failure names its seed.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    fn pick<'a>(&mut self, xs: &[&'a str]) -> &'a str {
        xs[self.below(xs.len())]
    }
}

const ATOMS: &[&str] = &[
    "0", "1", "2", "3", "7", "10", "0x1F", "2.5", "0.5", "1e2", "true", "false", "'a'", "'b'",
    "'3'", "''", "'true'", "x", "y",
];
const BINARY: &[&str] = &[
    "+", "-", "*", "/", "..", "&", "|", "^", "&&", "||", "==", "!=", "<", ">", "<=", ">=",
];
const UNARY: &[&str] = &["-", "!", "~"];
const ASSIGN: &[&str] = &[":=", "=", "+=", "-=", "*=", "/="];

fn expr(r: &mut Rng, depth: usize) -> String {
    if depth == 0 || r.below(10) < 3 {
        return r.pick(ATOMS).to_owned();
    }
    match r.below(10) {
        0..=4 => format!(
            "{} {} {}",
            expr(r, depth - 1),
            r.pick(BINARY),
            expr(r, depth - 1)
        ),
        5 => format!("{}{}", r.pick(UNARY), expr(r, depth - 1)),
        6 => format!(
            "{} ? {} : {}",
            expr(r, depth - 1),
            expr(r, depth - 1),
            expr(r, depth - 1)
        ),
        7 => format!("({})", expr(r, depth - 1)),
        8 => format!(
            "{} {} {} {} {}",
            expr(r, 0),
            r.pick(&BINARY[10..]),
            expr(r, depth - 1),
            r.pick(&BINARY[10..]),
            expr(r, 0)
        ),
        _ => format!("x {} {}", r.pick(ASSIGN), expr(r, depth - 1)),
    }
}

/// A script: sometimes with entries made first, sometimes mangled.
fn script(r: &mut Rng) -> String {
    let mut s = String::new();
    if r.below(3) == 0 {
        s.push_str(&format!("x := {}; ", r.pick(ATOMS)));
    }
    if r.below(4) == 0 {
        s.push_str(&format!("y := {}; ", expr(r, 1)));
    }
    s.push_str(&expr(r, 4));
    if r.below(12) == 0 {
        // A syntax error: a character dropped, or one added.
        let cut = r.below(s.len().max(1));
        if r.below(2) == 0 {
            s.remove(cut.min(s.len() - 1));
        } else {
            s.insert(cut, *[')', '(', '?', '.', '\''].get(r.below(5)).unwrap());
        }
    }
    s
}

struct Fresh(Vec<Option<Value>>);

impl Env for Fresh {
    fn get(&self, var: u32) -> Option<&Value> {
        self.0[var as usize].as_ref()
    }
    fn entry(&mut self, var: u32, create: bool) -> Option<&mut Value> {
        let v = &mut self.0[var as usize];
        if v.is_none() && create {
            *v = Some(Value::Empty);
        }
        v.as_mut()
    }
}

/// btc's answer, in the peer's words.
fn ours(src: &str) -> String {
    let parsed = match script::parse(src) {
        Ok(s) => s,
        Err(e) => return format!("err {}", e.class.name()),
    };
    let mut env = Fresh(vec![None; parsed.vars.len()]);
    match parsed.run(&mut env) {
        Ok(Value::Empty) => "ok empty".into(),
        Ok(Value::Int(n)) => format!("ok int {n}"),
        Ok(Value::Float(f)) => format!("ok num {f}"),
        Ok(Value::Bool(b)) => format!("ok bool {}", u8::from(b)),
        Ok(Value::Text(s)) => format!("ok str {s}"),
        Err(e) => format!("err {}", e.class.name()),
    }
}

/// The same answer: numbers compared as numbers.
fn agree(a: &str, b: &str) -> bool {
    match (a.strip_prefix("ok num "), b.strip_prefix("ok num ")) {
        (Some(x), Some(y)) => match (x.parse::<f64>(), y.parse::<f64>()) {
            (Ok(x), Ok(y)) => x == y || (x.is_nan() && y.is_nan()),
            _ => false,
        },
        _ => a == b,
    }
}

#[test]
fn random_scripts_evaluate_as_in_bt_cpp() {
    let Some(peer) = btc_testkit::btcpp_harness().map(|d| d.join("btc_peer")) else {
        return;
    };
    let mut scripts = Vec::new();
    for seed in 1..=4u64 {
        let mut r = Rng(seed);
        scripts.extend((0..5000).map(|_| script(&mut r)));
    }
    let mut child = Command::new(&peer)
        .arg("eval")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("the peer runs");
    // Written from a thread: the peer answers as it reads, and both pipes
    // would fill up otherwise.
    let mut input = child.stdin.take().unwrap();
    let text: String = scripts.iter().map(|s| format!("{s}\n")).collect();
    let writer = std::thread::spawn(move || input.write_all(text.as_bytes()));
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap().unwrap();
    let theirs: Vec<String> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(str::to_owned)
        .collect();
    assert_eq!(
        theirs.len(),
        scripts.len(),
        "the peer answered every script"
    );
    let mut differ = Vec::new();
    let mut errors = 0;
    for (s, t) in scripts.iter().zip(&theirs) {
        let o = ours(s);
        errors += usize::from(t.starts_with("err"));
        if !agree(&o, t) {
            differ.push(format!("{s:?}\n    btc:    {o}\n    BT.CPP: {t}"));
        }
    }
    // The fuzzing reaches both sides: values and errors.
    assert!(
        errors > 100 && errors < scripts.len() - 100,
        "{errors} errors"
    );
    assert!(
        differ.is_empty(),
        "{} of {} scripts differ:\n{}",
        differ.len(),
        scripts.len(),
        differ
            .iter()
            .take(25)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n")
    );
}

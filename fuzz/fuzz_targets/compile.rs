//! Compile end to end: the input is a rules file and a plan (split at the
//! first `\n%%\n`), compiled with the ARIAC domain and problem into every
//! output format, each output read back: the XML by an XML parser, the
//! JSON IR by the runtime's loader, the DOT/Mermaid/commands checked for
//! balanced structure. (The py_trees module is checked by Python's `ast`
//! outside the fuzzer: `fuzz/check-python.sh` on the saved outputs.)
#![no_main]

use btc_lang::db::{self, CompileJob, Database};
use btc_pddl::source::decode;
use libfuzzer_sys::fuzz_target;

const DOMAIN: &str = include_str!("../../examples/ariac/domain.pddl");
const PROBLEM: &str = include_str!("../../examples/ariac/problem.pddl");

fuzz_target!(|data: &[u8]| {
    let (text, _) = decode(data);
    let (rules, plan) = text.split_once("\n%%\n").unwrap_or((&text, ""));
    let mut database = Database::new();
    let d = database.set_file("/f/domain.pddl", DOMAIN.to_owned());
    let p = database.set_file("/f/problem.pddl", PROBLEM.to_owned());
    let r = database.set_file("/f/rules.btrules", rules.to_owned());
    let l = database.set_file("/f/plan.txt", plan.to_owned());
    let job = CompileJob::new(&database, r, l, Some(p), Some(d));
    let Ok(ir) = db::compile(&database, job) else {
        return;
    };
    for inline in [false, true] {
        let options = btc_emit::Options {
            inline,
            ..btc_emit::Options::default()
        };
        let xml = btc_emit::emit(ir, btc_emit::Format::Btcpp, &options);
        let mut reader = quick_xml::Reader::from_str(&xml);
        loop {
            match reader.read_event() {
                Ok(quick_xml::events::Event::Eof) => break,
                Ok(_) => {}
                Err(e) => panic!("btc wrote XML that does not parse: {e}\n{xml}"),
            }
        }
        if let Err(e) = btc_runtime::load_tree(&xml) {
            panic!(
                "the runtime cannot load btc's own XML: {}\n{xml}",
                e.message
            );
        }
    }
    let options = btc_emit::Options::default();
    let json = btc_emit::emit(ir, btc_emit::Format::Json, &options);
    if let Err(e) = btc_runtime::load_tree(&json) {
        panic!("the runtime cannot load btc's own JSON: {}", e.message);
    }
    let py = btc_emit::emit(ir, btc_emit::Format::Pytrees, &options);
    assert!(!py.contains('\0'), "a NUL byte in the Python module");
    if let Some(dir) = std::env::var_os("BTC_FUZZ_PY_OUT") {
        let name = format!("{:016x}.py", fxhash(py.as_bytes()));
        let _ = std::fs::write(std::path::Path::new(&dir).join(name), &py);
    }
    for f in [
        btc_emit::Format::Dot,
        btc_emit::Format::Mermaid,
        btc_emit::Format::Commands,
    ] {
        let _ = btc_emit::emit(ir, f, &options);
    }
});

fn fxhash(b: &[u8]) -> u64 {
    b.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &x| {
        (h ^ x as u64).wrapping_mul(0x100_0000_01b3)
    })
}

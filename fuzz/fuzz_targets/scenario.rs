//! Any bytes as a fault scenario (`btc run --faults`): parse the TOML, add
//! its faults to an engine over the ARIAC world, run a few ticks.
#![no_main]

#[path = "common/ariac.rs"]
mod ariac;

use btc_pddl::source::decode;
use btc_agent::faults::{FaultsOnEngine, Scenario};
use btc_runtime::{Engine, Kb, Options};
use libfuzzer_sys::fuzz_target;

const TREE: &str = r#"<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M"><Sequence><Sleep msec="50"/><AlwaysSuccess/></Sequence></BehaviorTree></root>"#;

fuzz_target!(|data: &[u8]| {
    let (text, _) = decode(data);
    let Ok(s) = Scenario::parse(&text) else {
        return;
    };
    let Some(world) = ariac::world() else {
        return;
    };
    let kb = Kb::new(&world);
    let Ok(btc_runtime::Loaded::Xml(doc)) = btc_runtime::load_tree(TREE) else {
        panic!("the fixed tree loads as XML");
    };
    let mut e = Engine::build(&doc, Some(kb), Options::default()).expect("builds");
    if e.add_faults(&s).is_ok() {
        e.run(100, |_| {});
    }
});

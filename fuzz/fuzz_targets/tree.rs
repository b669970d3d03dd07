//! Any bytes as a tree file for `btc run --tree` (BT.CPP XML or JSON IR):
//! load, build the engine against the ARIAC world, tick a bounded run.
#![no_main]

#[path = "common/ariac.rs"]
mod ariac;

use btc_pddl::source::decode;
use btc_pddl::state::World;
use btc_runtime::btlog::BtlogRecorder;
use btc_runtime::observers::{EventLog, JsonlTrace};
use btc_runtime::{Engine, Kb, Loaded, Options, TreeDoc};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let (text, _) = decode(data);
    let Ok(loaded) = btc_runtime::load_tree(&text) else {
        return;
    };
    // As `btc run --tree` does: a current IR runs in the world it carries,
    // XML and a version-1 IR in the ARIAC world.
    let Some(ariac) = ariac::world() else {
        return;
    };
    let (doc, own) = match loaded {
        Loaded::Xml(doc) => match &ariac::units().0.domain {
            Some(d) => (doc.with_actions(d), None),
            None => return,
        },
        Loaded::Ir(ir) => (TreeDoc::from_ir(&ir), World::new(ir.world.clone()).ok()),
        Loaded::IrV1(v1) => match v1.upgrade(ariac.model().clone()) {
            Ok(ir) => (TreeDoc::from_ir(&ir), None),
            Err(_) => return,
        },
    };
    let world = own.as_ref().unwrap_or(&ariac);
    let kb = Kb::new(world);
    let built = Engine::build(&doc, Some(kb), Options::default());
    if let Ok(mut e) = built {
        // Every observer btc has renders what it is told of.
        e.observe(JsonlTrace::default());
        e.observe(EventLog::default());
        e.observe(BtlogRecorder::new(10));
        let status = e.run(200, |e| {
            if let Some(t) = e.observer_mut::<JsonlTrace>() {
                let _ = t.drain(&mut std::io::sink());
            }
        });
        if let Some(r) = e.take_observer::<BtlogRecorder>() {
            let _ = r.finish(&doc, &e, status, 0);
        }
        let _ = e.summary(btc_runtime::Status::Running);
    }
});

//! The score formulas against hand-computed cases (`fixtures/scores.toml`).

use btc_agent::sim::scoring::{self, Insert, Quadrant, Slot};
use serde::Deserialize;

#[derive(Deserialize)]
struct Cases {
    kit: Vec<KitCase>,
    insert: Vec<InsertCase>,
}

#[derive(Deserialize)]
struct KitCase {
    name: String,
    tray: bool,
    destination: bool,
    parts_on_tray: usize,
    quadrants: Vec<String>,
    score: i64,
}

#[derive(Deserialize)]
struct InsertCase {
    name: String,
    kind: String,
    station: bool,
    slots: Vec<String>,
    score: i64,
}

fn quadrant(q: usize, what: &str) -> Quadrant {
    let mut x = Quadrant {
        quadrant: q as u8 + 1,
        present: true,
        correct_type: true,
        correct_color: true,
        flipped: false,
        faulty: false,
    };
    match what {
        "ok" => {}
        "wrong_color" => x.correct_color = false,
        "flipped" => x.flipped = true,
        "wrong_color_flipped" => {
            x.correct_color = false;
            x.flipped = true;
        }
        "faulty" => x.faulty = true,
        "missing" => x.present = false,
        "wrong_type" => x.correct_type = false,
        o => panic!("unknown quadrant case {o}"),
    }
    x
}

fn slot(what: &str) -> Slot {
    let (assembled, correct_color, correct_pose) = match what {
        "ok" => (true, true, true),
        "wrong_color" => (true, false, true),
        "wrong_pose" => (true, true, false),
        "wrong_both" => (true, false, false),
        "missing" => (false, false, false),
        o => panic!("unknown slot case {o}"),
    };
    Slot {
        assembled,
        correct_color,
        correct_pose,
    }
}

#[test]
fn scores_match_the_hand_computed_cases() {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/scores.toml"),
    )
    .unwrap();
    let cases: Cases = toml::from_str(&text).unwrap();
    assert!(cases.kit.len() >= 5 && cases.insert.len() >= 5);
    for c in &cases.kit {
        let qs: Vec<Quadrant> = c
            .quadrants
            .iter()
            .enumerate()
            .map(|(k, q)| quadrant(k, q))
            .collect();
        let s = scoring::kitting(c.tray, &qs, c.parts_on_tray, c.destination);
        assert_eq!(s.score, c.score, "{}: {s:?}", c.name);
    }
    for c in &cases.insert {
        let kind = if c.kind == "assembly" {
            Insert::Assembly
        } else {
            Insert::Combined
        };
        let slots: Vec<Slot> = c.slots.iter().map(|s| slot(s)).collect();
        let s = scoring::insert(kind, &slots, c.station);
        assert_eq!(s.score, c.score, "{}: {s:?}", c.name);
    }
}

//! The paper's Figure 5: each task type under each agility challenge and
//! under none, several seeded runs each (the paper ran five), the mean
//! score and order time against the no-challenge baseline, as a table and
//! as an SVG chart.

use crate::random::{experiment, Scenario, TASK_TYPES};
use crate::sim::{Runner, TrialError, TrialOptions};
use crate::trial::OrderType;
use serde::Serialize;
use std::fmt::Write;

#[derive(Clone, Debug, Serialize)]
pub struct Cell {
    #[serde(rename = "type")]
    pub ty: OrderType,
    pub scenario: Scenario,
    /// `false` where the challenge does not occur for the task type.
    pub applies: bool,
    pub runs: usize,
    /// Mean completion score and its best.
    pub score: f64,
    pub best: f64,
    /// Mean order time: from the first announcement to the last submission.
    pub time: f64,
    /// Runs in which every order was submitted.
    pub submitted: usize,
}

#[derive(Clone, Debug, Serialize)]
pub struct Matrix {
    pub seed: u64,
    pub runs: usize,
    pub cells: Vec<Cell>,
}

impl Matrix {
    pub fn get(&self, ty: OrderType, sc: Scenario) -> Option<&Cell> {
        self.cells.iter().find(|c| c.ty == ty && c.scenario == sc)
    }
}

/// The (task type, scenario) pairs that run, each `runs` times.
pub fn cells(runs: usize) -> Vec<(OrderType, Scenario, usize)> {
    let mut v = Vec::new();
    for ty in TASK_TYPES {
        for sc in Scenario::ALL {
            if sc.applies(ty) {
                for k in 0..runs {
                    v.push((ty, sc, k));
                }
            }
        }
    }
    v
}

/// Runs the matrix; `on_run` is called after each trial (a progress bar).
pub fn run(
    runner: &mut Runner<'_>,
    seed: u64,
    runs: usize,
    check: bool,
    on_run: &mut dyn FnMut(usize),
) -> Result<Matrix, TrialError> {
    let mut out = Vec::new();
    let mut done = 0;
    for ty in TASK_TYPES {
        for sc in Scenario::ALL {
            if !sc.applies(ty) {
                out.push(Cell {
                    ty,
                    scenario: sc,
                    applies: false,
                    runs: 0,
                    score: 0.0,
                    best: 0.0,
                    time: 0.0,
                    submitted: 0,
                });
                continue;
            }
            let (mut score, mut best, mut time, mut submitted) = (0.0, 0.0, 0.0, 0);
            for k in 0..runs {
                let s = seed + k as u64;
                let t = experiment(ty, sc, s);
                let opts = TrialOptions {
                    seed: s,
                    check,
                    ..TrialOptions::default()
                };
                let name = format!("{}_{:?}_{s}", ty.name(), sc);
                let r = runner.run(&t, &name, &opts)?;
                score += r.score as f64;
                best += r.best as f64;
                let first = r
                    .orders
                    .iter()
                    .filter_map(|o| o.announced)
                    .fold(f64::INFINITY, f64::min);
                let last = r
                    .orders
                    .iter()
                    .filter_map(|o| o.submitted)
                    .fold(0.0, f64::max);
                time += if first.is_finite() {
                    last - first
                } else {
                    r.seconds
                };
                if r.orders.iter().all(|o| o.submitted.is_some()) {
                    submitted += 1;
                }
                done += 1;
                on_run(done);
            }
            let n = runs.max(1) as f64;
            out.push(Cell {
                ty,
                scenario: sc,
                applies: true,
                runs,
                score: score / n,
                best: best / n,
                time: time / n,
                submitted,
            });
        }
    }
    Ok(Matrix {
        seed,
        runs,
        cells: out,
    })
}

fn delta(x: f64, base: f64) -> String {
    let d = x - base;
    if d.abs() < 0.05 {
        "±0".to_owned()
    } else {
        format!("{d:+.1}")
    }
}

/// The Figure 5 table: score and order time per task type and challenge,
/// with the difference to the baseline.
pub fn table(m: &Matrix) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Figure 5 (Liu et al. 2024): trial score and order time per task type and challenge;"
    );
    let _ = writeln!(
        s,
        "mean of {} runs (seeds {}..{}), the difference to the no-challenge baseline in brackets",
        m.runs,
        m.seed,
        m.seed + m.runs as u64 - 1
    );
    let _ = writeln!(s);
    let _ = write!(s, "{:<22}", "challenge");
    for ty in TASK_TYPES {
        let _ = write!(s, "{:<30}", ty.name());
    }
    let _ = writeln!(s);
    let _ = write!(s, "{:<22}", "");
    for _ in TASK_TYPES {
        let _ = write!(s, "{:<15}{:<15}", "score", "time (s)");
    }
    let _ = writeln!(s);
    for sc in Scenario::ALL {
        let _ = write!(s, "{:<22}", sc.title());
        for ty in TASK_TYPES {
            let base = m.get(ty, Scenario::Normal);
            match (m.get(ty, sc), base) {
                (Some(c), Some(b)) if c.applies => {
                    let (sd, td) = if sc == Scenario::Normal {
                        (String::new(), String::new())
                    } else {
                        (
                            format!(" ({})", delta(c.score, b.score)),
                            format!(" ({})", delta(c.time, b.time)),
                        )
                    };
                    let _ = write!(
                        s,
                        "{:<15}{:<15}",
                        format!("{:.1}{sd}", c.score),
                        format!("{:.0}{td}", c.time)
                    );
                }
                _ => {
                    let _ = write!(s, "{:<15}{:<15}", "n/a", "n/a");
                }
            }
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "n/a: faulty and flipped parts do not occur in assembly (its parts start on the AGVs)."
    );
    s
}

/// What a chart panel shows of a cell.
type Measure = fn(&Cell) -> f64;

/// A grouped bar chart per measure (score, time): one group per task type,
/// one bar per challenge, the baseline dashed across each group.
pub fn svg(m: &Matrix) -> String {
    let (w, h) = (900.0_f64, 620.0_f64);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="11">"#
    );
    let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    let colors = [
        "#999999", "#e41a1c", "#377eb8", "#4daf4a", "#984ea3", "#ff7f00", "#a65628", "#f781bf",
        "#17becf",
    ];
    let panels: [(&str, Measure); 2] = [
        ("(a) trial score", |c| c.score),
        ("(b) order time (s)", |c| c.time),
    ];
    for (p, (title, value)) in panels.iter().enumerate() {
        let top = 30.0 + p as f64 * 280.0;
        let (left, plot_w, plot_h) = (60.0, 640.0, 200.0);
        let max = m
            .cells
            .iter()
            .filter(|c| c.applies)
            .map(value)
            .fold(1.0_f64, f64::max)
            * 1.1;
        let _ = writeln!(
            s,
            r#"<text x="{left}" y="{}" font-size="13" font-weight="bold">{title}</text>"#,
            top - 8.0
        );
        let base_y = top + plot_h;
        let _ = writeln!(
            s,
            r#"<line x1="{left}" y1="{base_y}" x2="{}" y2="{base_y}" stroke="black"/>"#,
            left + plot_w
        );
        let _ = writeln!(
            s,
            r#"<line x1="{left}" y1="{top}" x2="{left}" y2="{base_y}" stroke="black"/>"#
        );
        for k in 0..=4 {
            let v = max * k as f64 / 4.0;
            let y = base_y - plot_h * k as f64 / 4.0;
            let _ = writeln!(
                s,
                r#"<text x="{}" y="{}" text-anchor="end">{v:.0}</text>"#,
                left - 4.0,
                y + 4.0
            );
        }
        let group_w = plot_w / TASK_TYPES.len() as f64;
        let bar_w = (group_w - 20.0) / Scenario::ALL.len() as f64;
        for (g, ty) in TASK_TYPES.iter().enumerate() {
            let gx = left + g as f64 * group_w + 10.0;
            for (b, sc) in Scenario::ALL.iter().enumerate() {
                let Some(c) = m.get(*ty, *sc).filter(|c| c.applies) else {
                    continue;
                };
                let v = value(c);
                let bh = plot_h * v / max;
                let x = gx + b as f64 * bar_w;
                let _ = writeln!(
                    s,
                    r#"<rect x="{x:.1}" y="{:.1}" width="{:.1}" height="{bh:.1}" fill="{}"><title>{} / {}: {v:.1}</title></rect>"#,
                    base_y - bh,
                    bar_w - 2.0,
                    colors[b],
                    ty.name(),
                    sc.title()
                );
            }
            if let Some(b) = m.get(*ty, Scenario::Normal) {
                let y = base_y - plot_h * value(b) / max;
                let _ = writeln!(
                    s,
                    r#"<line x1="{gx:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="black" stroke-dasharray="4 3"/>"#,
                    gx + group_w - 20.0
                );
            }
            let _ = writeln!(
                s,
                r#"<text x="{:.1}" y="{}" text-anchor="middle">{}</text>"#,
                gx + (group_w - 20.0) / 2.0,
                base_y + 16.0,
                ty.name()
            );
        }
    }
    // The legend.
    for (b, sc) in Scenario::ALL.iter().enumerate() {
        let y = 40.0 + b as f64 * 18.0;
        let _ = writeln!(
            s,
            r#"<rect x="720" y="{}" width="12" height="12" fill="{}"/>"#,
            y - 10.0,
            colors[b]
        );
        let _ = writeln!(s, r#"<text x="738" y="{y}">{}</text>"#, sc.title());
    }
    let _ = writeln!(
        s,
        r#"<line x1="720" y1="{0}" x2="732" y2="{0}" stroke="black" stroke-dasharray="4 3"/><text x="738" y="{1}">baseline</text>"#,
        40.0 + 9.0 * 18.0 - 4.0,
        40.0 + 9.0 * 18.0
    );
    let _ = writeln!(
        s,
        r#"<text x="60" y="{}">mean of {} runs per bar; faulty and flipped parts do not occur in assembly</text>"#,
        h - 12.0,
        m.runs
    );
    s.push_str("</svg>\n");
    s
}

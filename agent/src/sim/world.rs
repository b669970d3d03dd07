//! The cell's world as one value: the shared PDDL state the agents act on,
//! the parts with what the simulation knows of them (belt schedule, faulty,
//! gone, reserved), the AGVs on their way, and who holds what. Its own
//! events are the belt's and the AGVs' arrivals.

use super::events::{AgvMove, Belt, Event, Holder, Trace};
use super::facts::{Facts, Place};
use super::options::TrialError;
use super::tasks::{Resource, TaskId};
use crate::cell::{AtomTemplate, Cell, Literal, Origin, PartInfo, TrialProblem, Var};
use crate::trial::{PartKind, SpawnOrder, Trial};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::source::Span;
use btc_pddl::state::Key;
use btc_pddl::ProblemIndex;
use btc_runtime::Kb;
use rustc_hash::{FxHashMap, FxHashSet};

pub use super::tasks::PartId;

pub struct PartRt {
    pub info: PartInfo,
    pub obj: u32,
    /// Conveyor parts: the ticks they arrive on and leave the belt.
    pub spawn: Option<u64>,
    pub leave: Option<u64>,
    /// Why it is out of the cell (fell off the belt, dropped on the floor).
    pub gone: Option<String>,
    pub faulty: bool,
    /// The task that holds it.
    pub reserved: Option<TaskId>,
}

/// The trial's parts, by id.
pub struct Parts(Vec<PartRt>);

impl Parts {
    pub fn iter(&self) -> impl Iterator<Item = &PartRt> {
        self.0.iter()
    }

    /// Each part with its id.
    pub fn with_ids(&self) -> impl Iterator<Item = (PartId, &PartRt)> {
        self.0.iter().enumerate().map(|(k, p)| (PartId(k), p))
    }

    pub fn ids(&self) -> impl Iterator<Item = PartId> {
        (0..self.0.len()).map(PartId)
    }
}

impl std::ops::Index<PartId> for Parts {
    type Output = PartRt;

    fn index(&self, k: PartId) -> &PartRt {
        &self.0[k.0]
    }
}

impl std::ops::IndexMut<PartId> for Parts {
    fn index_mut(&mut self, k: PartId) -> &mut PartRt {
        &mut self.0[k.0]
    }
}

/// An AGV on its way to `to`.
pub struct Travel {
    pub agv: u8,
    pub to: u32,
    pub arrive: u64,
    /// The order it submits on arrival.
    pub order: Option<usize>,
}

/// Object ids of the cell's places and things.
pub struct Objects {
    pub conveyor: u32,
    pub agv: [u32; 4],
    pub kitting_station: [u32; 4],
    pub station: [u32; 4],
    pub quadrant: [u32; 4],
    pub warehouse: u32,
    pub bins: [u32; 8],
}

pub fn id(pix: &ProblemIndex, name: &str) -> Result<u32, TrialError> {
    pix.objects.get(name).map(|o| o.id).ok_or_else(|| {
        TrialError::Cell(vec![Diagnostic::error(
            codes::CELL_MAPPING,
            Span::new(0, 0, 0),
            format!("the trial's problem has no object `{name}`"),
        )])
    })
}

impl Objects {
    fn new(cell: &Cell, pix: &ProblemIndex) -> Result<Objects, TrialError> {
        let four = |f: &dyn Fn(u8) -> String| -> Result<[u32; 4], TrialError> {
            Ok([
                id(pix, &f(1))?,
                id(pix, &f(2))?,
                id(pix, &f(3))?,
                id(pix, &f(4))?,
            ])
        };
        let mut bins = [0; 8];
        for (k, slot) in bins.iter_mut().enumerate() {
            *slot = id(pix, &cell.bin(k as u8 + 1))?;
        }
        Ok(Objects {
            conveyor: id(pix, &cell.conveyor())?,
            agv: four(&|n| cell.agv(n))?,
            kitting_station: four(&|n| cell.kitting_station(n))?,
            station: four(&|n| cell.station(n))?,
            quadrant: four(&|n| cell.quadrant(n))?,
            warehouse: id(pix, &cell.warehouse())?,
            bins,
        })
    }

    pub fn agv(&self, n: u8) -> u32 {
        self.agv[n as usize - 1]
    }

    /// An AGV's number from its object.
    pub fn agv_number(&self, obj: u32) -> Option<u8> {
        self.agv.iter().position(|&x| x == obj).map(|n| n as u8 + 1)
    }

    pub fn quadrant_number(&self, obj: u32) -> Option<u8> {
        self.quadrant
            .iter()
            .position(|&x| x == obj)
            .map(|n| n as u8 + 1)
    }
}

pub struct CellWorld<'w> {
    pub kb: Kb<'w>,
    pub facts: Facts,
    pub obj: Objects,
    pub pix: &'w ProblemIndex,
    pub parts: Parts,
    pub part_of: FxHashMap<u32, PartId>,
    pub travels: Vec<Travel>,
    /// Resources held, and by whom.
    pub held: Vec<(Resource, Holder)>,
}

impl<'w> CellWorld<'w> {
    /// The world at the start of a trial; `rng` orders a random belt.
    /// `between` runs after the parts are found and before the places
    /// (the order in which a cell's missing objects are reported).
    pub fn new<A>(
        (cell, trial, tp): (&Cell, &Trial, &TrialProblem),
        kb: Kb<'w>,
        pix: &'w ProblemIndex,
        rng: &mut fastrand::Rng,
        between: impl FnOnce() -> Result<A, TrialError>,
    ) -> Result<(CellWorld<'w>, A), TrialError> {
        let facts = Facts::new(cell, pix).map_err(|m| {
            TrialError::Cell(vec![Diagnostic::error(
                codes::CELL_MAPPING,
                Span::new(0, 0, 0),
                m,
            )])
        })?;
        let time = &cell.spec.time;
        let mut parts: Vec<PartRt> = Vec::new();
        for p in &tp.parts {
            parts.push(PartRt {
                obj: id(pix, &p.name)?,
                info: p.clone(),
                spawn: None,
                leave: None,
                gone: None,
                faulty: false,
                reserved: None,
            });
        }
        // The belt's schedule: one part every `spawn_rate` seconds from the
        // start, in the file's order or shuffled.
        if let Some(c) = trial.conveyor.as_ref().filter(|c| c.active) {
            let mut order: Vec<usize> = (0..parts.len())
                .filter(|&k| matches!(parts[k].info.origin, Origin::Conveyor { .. }))
                .collect();
            if c.order == SpawnOrder::Random {
                rng.shuffle(&mut order);
            }
            for (n, k) in order.into_iter().enumerate() {
                let at = time.ticks(n as f64 * c.spawn_rate) + 1;
                parts[k].spawn = Some(at);
                parts[k].leave = Some(at + time.ticks(time.conveyor_seconds).max(1));
            }
        }
        let part_of = parts
            .iter()
            .enumerate()
            .map(|(k, p)| (p.obj, PartId(k)))
            .collect();
        let a = between()?;
        let world = CellWorld {
            kb,
            facts,
            obj: Objects::new(cell, pix)?,
            pix,
            parts: Parts(parts),
            part_of,
            travels: Vec::new(),
            held: Vec::new(),
        };
        Ok((world, a))
    }

    pub fn name(&self, o: u32) -> &str {
        &self.pix.object_names[o as usize]
    }

    pub fn apply(&mut self, add: Vec<Key>, del: Vec<Key>) {
        self.kb.apply_keys(add, del);
    }

    pub fn holds(&self, k: &Key) -> bool {
        self.kb.state.facts.contains(k)
    }

    pub fn kind_of(&self, p: u32) -> Option<PartKind> {
        self.part_of.get(&p).map(|&k| self.parts[k].info.kind)
    }

    pub fn place(&self, p: PartId) -> Place {
        self.facts.place(&self.kb.state, self.parts[p].obj)
    }

    pub fn is_flipped(&self, obj: u32) -> bool {
        self.holds(&self.facts.flipped.key(&[(Var::Part, obj)]))
    }

    /// Whether a part of `kind` that no task holds lies on the belt now.
    pub fn on_conveyor(&self, kind: PartKind) -> bool {
        self.parts.iter().any(|p| {
            p.info.kind == kind
                && p.reserved.is_none()
                && self.facts.place(&self.kb.state, p.obj) == Place::At(self.obj.conveyor)
        })
    }

    /// The facts of one template now true.
    pub fn facts_of(&self, t: &super::facts::KeyTemplate) -> FxHashSet<Key> {
        self.kb
            .state
            .facts
            .iter()
            .filter(|k| t.is(k))
            .cloned()
            .collect()
    }

    /// Whether none of `res` conflicts with a held resource.
    pub fn free(&self, res: &[Resource]) -> bool {
        res.iter()
            .all(|r| !self.held.iter().any(|(h, _)| h.conflicts(*r)))
    }

    /// Task `t` takes `res`; its parts are reserved for it.
    pub fn hold(&mut self, t: TaskId, res: &[Resource]) {
        for r in res {
            if let Resource::Part(k) = r {
                self.parts[*k].reserved = Some(t);
            }
            self.held.push((*r, Holder::Task(t)));
        }
    }

    /// Task `t` lets go of everything, `res` its resources.
    pub fn release(&mut self, t: TaskId, res: Vec<Resource>) {
        self.held.retain(|(_, who)| *who != Holder::Task(t));
        for r in res {
            if let Resource::Part(k) = r {
                if self.parts[k].reserved == Some(t) {
                    self.parts[k].reserved = None;
                }
            }
        }
    }

    pub fn lit(&self, t: &AtomTemplate, vals: &[(Var, u32)], positive: bool) -> Literal {
        let named: Vec<(Var, &str)> = vals.iter().map(|(v, o)| (*v, self.name(*o))).collect();
        Literal {
            positive,
            atom: t.ground(&named),
        }
    }

    /// The part lies in the AGV's quadrant, the right way up.
    pub fn lits_kit(&self, cell: &Cell, part: u32, agv: u32, q: u32) -> Vec<Literal> {
        let f = &cell.spec.facts;
        let (p, a, qq) = (self.name(part), self.name(agv), self.name(q));
        vec![
            Literal {
                positive: true,
                atom: f
                    .in_kit
                    .ground(&[(Var::Part, p), (Var::Agv, a), (Var::Quadrant, qq)]),
            },
            Literal {
                positive: false,
                atom: f.flipped.ground(&[(Var::Part, p)]),
            },
        ]
    }

    /// Sends an AGV to `to`: it holds itself on the way and arrives after
    /// one action's ticks.
    pub fn send(&mut self, agv: u8, to: u32, arrive: u64, order: Option<usize>) {
        self.held.push((Resource::Agv(agv), Holder::Travel));
        self.travels.push(Travel {
            agv,
            to,
            arrive,
            order,
        });
    }

    /// The belt at `tick`: parts arrive on it and ride off its end.
    pub fn belt(&mut self, tick: u64, trace: &mut Trace) {
        for k in self.parts.ids() {
            if self.parts[k].spawn == Some(tick) {
                let p = self.parts[k].obj;
                let mut add = vec![self
                    .facts
                    .part_at
                    .key(&[(Var::Part, p), (Var::Place, self.obj.conveyor)])];
                if self.parts[k].info.flipped {
                    add.push(self.facts.flipped.key(&[(Var::Part, p)]));
                }
                self.apply(add, Vec::new());
                let name = self.parts[k].info.name.clone();
                trace.event(
                    tick,
                    &Event::Conveyor {
                        part: name,
                        what: Belt::Arrives,
                    },
                );
            }
            // A part a task has reserved is tracked by its robot and does
            // not ride off the belt (the symbolic world has no belt speed).
            if self.parts[k].leave == Some(tick) && self.parts[k].reserved.is_some() {
                self.parts[k].leave = Some(tick + 1);
            } else if self.parts[k].leave == Some(tick) {
                let p = self.parts[k].obj;
                let on = self
                    .facts
                    .part_at
                    .key(&[(Var::Part, p), (Var::Place, self.obj.conveyor)]);
                if self.holds(&on) {
                    let del = vec![on, self.facts.flipped.key(&[(Var::Part, p)])];
                    self.apply(Vec::new(), del);
                    self.parts[k].gone = Some("it rode off the end of the conveyor belt".into());
                    let name = self.parts[k].info.name.clone();
                    trace.event(
                        tick,
                        &Event::Conveyor {
                            part: name,
                            what: Belt::FallsOff,
                        },
                    );
                }
            }
        }
    }

    /// The AGVs that arrive at `tick`, latest sent first.
    pub fn arrivals(&mut self, tick: u64) -> Vec<Travel> {
        let arrived: Vec<usize> = (0..self.travels.len())
            .filter(|&k| self.travels[k].arrive <= tick)
            .collect();
        arrived
            .into_iter()
            .rev()
            .map(|k| self.travels.remove(k))
            .collect()
    }

    /// An AGV arrives: it is at its place and holds itself no more.
    pub fn arrive(&mut self, t: &Travel, tick: u64, trace: &mut Trace) {
        let agv = self.obj.agv(t.agv);
        if let Some(from) = self.facts.agv_place(&self.kb.state, agv) {
            let del = vec![self
                .facts
                .agv_at
                .key(&[(Var::Agv, agv), (Var::Place, from)])];
            let add = vec![self
                .facts
                .agv_at
                .key(&[(Var::Agv, agv), (Var::Place, t.to)])];
            self.apply(add, del);
        }
        self.held
            .retain(|(r, who)| !(*who == Holder::Travel && *r == Resource::Agv(t.agv)));
        let to = self.name(t.to).to_owned();
        trace.event(
            tick,
            &Event::Agv {
                agv: format!("agv{}", t.agv),
                what: AgvMove::Arrives { arrives: to },
            },
        );
    }
}

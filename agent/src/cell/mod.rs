//! The workcell: its PDDL domain, a rules file per robot, simulated time,
//! and the mapping from trial concepts to PDDL objects and facts
//! ([`spec`], [`template`]); the trial's PDDL problem built from a trial
//! and a cell ([`problem`]).

pub mod bundled;
pub mod load;
pub mod problem;
pub mod spec;
pub mod template;

pub use problem::{Origin, PartInfo, TrialProblem};
pub use spec::{CellSpec, RobotSpec, Time};
pub use template::{conjunction, AtomTemplate, GroundAtom, Literal, Var};

use crate::trial::{PartType, Robot};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::pipeline::{self, DomainUnit};
use btc_pddl::source::{FileId, Span};

/// A cell ready for trials: the spec, and its domain parsed and checked.
pub struct Cell {
    pub spec: CellSpec,
    pub domain: DomainUnit,
    /// The domain's text (the rules database gets its own copy).
    pub domain_text: String,
    pub domain_path: String,
    /// Each robot's rules file: path and text.
    pub rules: Vec<(Robot, String, String)>,
}

impl Cell {
    /// The cell from its spec and the texts of the files it names. The
    /// domain must check without errors, and the spec's facts must fit it
    /// (T011, on the cell file `cell_file`).
    pub fn new(
        spec: CellSpec,
        cell_file: FileId,
        domain_path: String,
        domain_text: String,
        domain_file: FileId,
        rules: Vec<(Robot, String, String)>,
    ) -> Result<Cell, Vec<Diagnostic>> {
        let domain = pipeline::domain_unit_from(&domain_text, domain_file);
        let mut diags: Vec<Diagnostic> = domain
            .diagnostics
            .iter()
            .filter(|d| d.is_error())
            .cloned()
            .collect();
        if domain.domain.is_none() || !diags.is_empty() {
            return Err(diags);
        }
        let mut cell = Cell {
            spec,
            domain,
            domain_text,
            domain_path,
            rules,
        };
        diags.extend(cell.check(cell_file));
        if diags.is_empty() {
            // Order the rules as the robots are ordered.
            cell.rules.sort_by_key(|(r, _, _)| *r);
            Ok(cell)
        } else {
            Err(diags)
        }
    }

    pub fn domain_name(&self) -> &str {
        self.domain
            .domain
            .as_ref()
            .map_or("domain", |d| d.name.name.as_str())
    }

    pub fn robot(&self, r: Robot) -> &RobotSpec {
        self.spec
            .robots
            .iter()
            .find(|x| x.robot == r)
            .expect("the spec has every robot")
    }

    /// The facts' predicates and arities, and the types, against the domain.
    fn check(&self, file: FileId) -> Vec<Diagnostic> {
        let dix = &self.domain.index;
        let mut out = Vec::new();
        let span = |key: &str| {
            let r = self.spec.spans.get(key).cloned().unwrap_or(0..0);
            Span::new(file, r.start, r.end)
        };
        let hint = "the cell's `[facts]`, `[types]` and `[always]` must use the predicates and types of its domain";
        let mut atoms: Vec<(String, String, &str, usize)> = self
            .spec
            .facts
            .each()
            .iter()
            .map(|(n, t, _)| {
                (
                    format!("the `{n}` fact"),
                    (*n).to_owned(),
                    t.pred.as_str(),
                    t.args.len(),
                )
            })
            .collect();
        for a in &self.spec.always {
            atoms.push((
                format!("`{a}` in `[always]`"),
                a.to_string(),
                a.pred.as_str(),
                a.args.len(),
            ));
        }
        for (what, key, pred, n) in atoms {
            let msg = match dix.predicates.get(pred) {
                None => format!(
                    "{what} uses `{pred}`, which the domain `{}` does not declare",
                    self.domain_name()
                ),
                Some(sig) if sig.params.len() != n => format!(
                    "{what} gives `{pred}` {n} argument{}; the domain declares {}",
                    if n == 1 { "" } else { "s" },
                    sig.params.len()
                ),
                Some(_) => continue,
            };
            out.push(Diagnostic::error(codes::CELL_MAPPING, span(&key), msg).with_hint(hint));
        }
        let t = &self.spec.types;
        let mut types: Vec<&str> = vec![
            &t.robot,
            &t.place,
            &t.agv,
            &t.tray,
            &t.quadrant,
            &t.insert_slot,
        ];
        types.extend(t.parts.iter().map(String::as_str));
        for ty in types {
            if ty != "object" && dix.types.id(ty).is_none() {
                out.push(
                    Diagnostic::error(
                        codes::CELL_MAPPING,
                        Span::new(file, 0, 0),
                        format!(
                            "`[types]` names `{ty}`, which the domain `{}` does not declare",
                            self.domain_name()
                        ),
                    )
                    .with_hint(hint),
                );
            }
        }
        out
    }

    pub fn part_type_name(&self, t: PartType) -> &str {
        &self.spec.types.parts[PartType::ALL.iter().position(|x| *x == t).unwrap_or(0)]
    }

    // Object names of trial concepts.

    pub fn bin(&self, n: u8) -> String {
        self.spec.names.bin.fill(Some(n.into()), None, None, None)
    }
    pub fn conveyor(&self) -> String {
        self.spec.names.conveyor.fill(None, None, None, None)
    }
    /// The tray table of a tray slot: slots 1–3 are table 1, 4–6 table 2.
    pub fn tray_table(&self, slot: u8) -> String {
        let table = if slot <= 3 { 1 } else { 2 };
        self.spec
            .names
            .tray_table
            .fill(Some(table), None, None, None)
    }
    pub fn kitting_station(&self, agv: u8) -> String {
        self.spec
            .names
            .kitting_station
            .fill(Some(agv.into()), None, None, None)
    }
    pub fn station(&self, n: u8) -> String {
        self.spec
            .names
            .assembly_station
            .fill(Some(n.into()), None, None, None)
    }
    pub fn warehouse(&self) -> String {
        self.spec.names.warehouse.fill(None, None, None, None)
    }
    pub fn disposal(&self) -> String {
        self.spec.names.disposal.fill(None, None, None, None)
    }
    pub fn agv(&self, n: u8) -> String {
        self.spec.names.agv.fill(Some(n.into()), None, None, None)
    }
    pub fn tray(&self, n: u8) -> String {
        self.spec.names.tray.fill(Some(n.into()), None, None, None)
    }
    pub fn quadrant(&self, n: u8) -> String {
        self.spec
            .names
            .quadrant
            .fill(Some(n.into()), None, None, None)
    }
    pub fn insert_slot(&self, t: PartType) -> String {
        self.spec
            .names
            .insert_slot
            .fill(None, Some(t.name()), None, None)
    }
}

//! Where each name of a rules file is declared, in salsa: per item, the
//! checker's [`resolve_item`] with every name's declaration placed in its
//! file (this one, an import, the stdlib, the PDDL domain or problem).
//! Go-to-definition, references, rename, highlights, hovers and semantic
//! tokens read [`item_resolutions`]; nothing else resolves names.
//!
//! A declaration in a rules file is placed by its item and an
//! item-relative span, so an edit that moves items leaves the places (and
//! every other item's resolutions) equal: salsa does not run them again.

use crate::db::{
    checked_domain, checked_problem, declarations, domain_ctx, domain_file, file_id,
    import_closure, problem_file, resolve, rules_items, Db, ProblemOf, RulesItem, SourceFile,
};
use crate::path::FilePath;
use crate::rules::resolve::{resolve_item, Target};
use crate::rules::Item;
use btc_pddl::source::Span;
use std::collections::BTreeMap;

/// Where a declaration is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, salsa::SalsaValue)]
pub enum Site<'db> {
    /// In a rules item, relative to the item's start.
    Item { item: RulesItem<'db>, span: Span },
    /// In any file (a PDDL file, or the start of a named file), absolute.
    File { file: SourceFile, span: Span },
}

impl Site<'_> {
    pub fn file(self, db: &dyn Db) -> SourceFile {
        match self {
            Site::Item { item, .. } => item.file(db),
            Site::File { file, .. } => file,
        }
    }

    /// The span in its file.
    pub fn span(self, db: &dyn Db) -> Span {
        match self {
            Site::Item { item, span } => {
                let o = item.offset(db);
                Span {
                    start: span.start + o,
                    end: span.end + o,
                    ..span
                }
            }
            Site::File { span, .. } => span,
        }
    }
}

/// One name of an item with its declaration's place (`None`: a basic
/// type, or a path that names no file the database has).
#[derive(Clone, Debug, PartialEq, Eq, salsa::SalsaValue)]
pub struct Resolved<'db> {
    /// Relative to the item.
    pub span: Span,
    pub target: Target,
    pub declaration: bool,
    pub site: Option<Site<'db>>,
}

/// The declarations a rules file sees (its own first, then its imports';
/// the first of a name wins, as in [`declarations`]).
#[derive(Clone, Debug, Default, PartialEq, Eq, salsa::SalsaValue)]
pub struct DeclSites<'db> {
    pub callables: BTreeMap<String, Site<'db>>,
    pub tables: BTreeMap<String, Site<'db>>,
    /// By (callable, port).
    pub ports: BTreeMap<(String, String), Site<'db>>,
}

#[salsa::tracked(returns(ref))]
pub fn declaration_sites(db: &dyn Db, file: SourceFile) -> DeclSites<'_> {
    let mut sites = DeclSites::default();
    for f in &import_closure(db, file).0 {
        for &item in rules_items(db, *f) {
            let at = |span| Site::Item { item, span };
            let (name, ports) = match item.item(db) {
                Item::Node(n) => (&n.name, n.ports.as_slice()),
                Item::Tree(t) => (&t.name, t.ports.as_slice()),
                Item::Table(t) => {
                    sites
                        .tables
                        .entry(t.name.text.clone())
                        .or_insert(at(t.name.span));
                    continue;
                }
                _ => continue,
            };
            if sites.callables.contains_key(&name.text) {
                continue;
            }
            sites.callables.insert(name.text.clone(), at(name.span));
            for p in ports {
                sites
                    .ports
                    .entry((name.text.clone(), p.name.text.clone()))
                    .or_insert(at(p.name.span));
            }
        }
    }
    sites
}

/// Every name of one item that refers to something, with where it is
/// declared, in the order written.
#[salsa::tracked(returns(ref))]
pub fn item_resolutions<'db>(db: &'db dyn Db, item: RulesItem<'db>) -> Vec<Resolved<'db>> {
    let file = item.file(db);
    let refs = resolve_item(item.item(db), declarations(db, file), domain_ctx(db, file));
    refs.into_iter()
        .map(|r| {
            let site = if r.declaration {
                Some(Site::Item { item, span: r.span })
            } else {
                site_of(db, file, item, &r.target)
            };
            Resolved {
                span: r.span,
                target: r.target,
                declaration: r.declaration,
                site,
            }
        })
        .collect()
}

fn site_of<'db>(
    db: &'db dyn Db,
    file: SourceFile,
    item: RulesItem<'db>,
    target: &Target,
) -> Option<Site<'db>> {
    let in_file = |f: SourceFile, span: Span| Some(Site::File { file: f, span });
    let whole = |f: SourceFile| in_file(f, Span::new(file_id(db, f), 0, 0));
    let domain = || {
        let d = domain_file(db, file)?;
        Some((d, checked_domain(db, d).domain.as_ref()?))
    };
    match target {
        Target::Callable { name } => declaration_sites(db, file).callables.get(name).copied(),
        Target::Table { name } => declaration_sites(db, file).tables.get(name).copied(),
        Target::Port { owner, name } => declaration_sites(db, file)
            .ports
            .get(&(owner.clone(), name.clone()))
            .copied(),
        Target::Var { binding, .. } | Target::Capture { binding, .. } => Some(Site::Item {
            item,
            span: *binding,
        }),
        Target::Action { name } => {
            let (f, d) = domain()?;
            let a = d.actions.iter().find(|a| a.name.name == *name)?;
            in_file(f, a.name.span)
        }
        Target::Predicate { name } => {
            let (f, d) = domain()?;
            let span = d
                .predicates
                .iter()
                .map(|p| &p.name)
                .chain(d.functions.iter().map(|p| &p.name))
                .find(|n| n.name == *name)?
                .span;
            in_file(f, span)
        }
        Target::Type { name } => {
            let (f, d) = domain()?;
            let t = d.types.iter().find(|t| t.name.name == *name)?;
            in_file(f, t.name.span)
        }
        Target::Object { name } => {
            let (f, d) = domain()?;
            if let Some(c) = d.constants.iter().find(|c| c.name.name == *name) {
                return in_file(f, c.name.span);
            }
            let p = problem_file(db, file)?;
            let problem = checked_problem(db, ProblemOf::new(db, p, f))
                .problem
                .as_ref()?;
            let o = problem.objects.iter().find(|o| o.name.name == *name)?;
            in_file(p, o.name.span)
        }
        Target::File { written } => whole(resolve(db, file, written)?),
        Target::Std { module } => whole(*db.workspace().files(db).get(&FilePath::std(module))?),
        Target::BasicType { .. } => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::db::tests::load;
    use crate::db::Database;

    /// Each name of a file as `text -> target @ file:text-at-site`.
    fn described(db: &Database, f: SourceFile) -> Vec<String> {
        let text = f.text(db);
        let mut out = Vec::new();
        for &item in rules_items(db, f) {
            let o = item.offset(db) as usize;
            for r in item_resolutions(db, item) {
                let at = &text[o + r.span.start as usize..o + r.span.end as usize];
                let site = r.site.map(|s| {
                    let (sf, sp) = (s.file(db), s.span(db));
                    let name = sf.path(db).to_string();
                    let name = name.rsplit('/').next().unwrap_or_default().to_owned();
                    let t = &sf.text(db)[sp.start as usize..sp.end as usize];
                    format!("{name}:{t}@{}", sp.start)
                });
                out.push(format!(
                    "{at} -> {:?}{} @ {}",
                    r.target,
                    if r.declaration { " (declared)" } else { "" },
                    site.unwrap_or_else(|| "-".into())
                ));
            }
        }
        out
    }

    #[test]
    fn names_resolve_into_the_file_its_imports_and_the_domain() {
        let mut db = Database::new();
        load(&mut db, "examples/ariac/domain.pddl");
        load(&mut db, "examples/ariac/problem.pddl");
        let f = load(&mut db, "examples/ariac/rules.btrules");
        let all = described(&db, f);
        let has = |s: &str| all.iter().any(|l| l.starts_with(s));
        // A call, its port, a variable, a predicate of an effect, a head.
        assert!(
            has("MoveTo -> Callable { name: \"MoveTo\" } @ rules.btrules:MoveTo@"),
            "{all:#?}"
        );
        assert!(
            has("target -> Port { owner: \"MoveTo\", name: \"target\" } @ rules.btrules:target@"),
            "{all:#?}"
        );
        assert!(
            has("on -> Predicate { name: \"on\" } @ domain.pddl:on@"),
            "{all:#?}"
        );
        assert!(
            has("grasp -> Action { name: \"grasp\" } @ domain.pddl:grasp@"),
            "{all:#?}"
        );
        assert!(has("\"domain.pddl\" -> File"), "{all:#?}");
        // A condition's formula reads its ports.
        assert!(
            has(
                "?robot -> Port { owner: \"RobotNormal\", name: \"robot\" } @ rules.btrules:robot@"
            ),
            "{all:#?}"
        );
        // An object in the plan block's string is the problem's.
        let vars: Vec<&String> = all
            .iter()
            .filter(|l| l.starts_with("?bin -> Var"))
            .collect();
        assert!(
            !vars.is_empty() && vars.iter().all(|l| l.contains("rules.btrules:?bin@")),
            "{vars:#?}"
        );
    }

    #[test]
    fn an_import_and_the_stdlib_resolve_across_files() {
        let mut db = Database::new();
        db.set_file("lib.btrules", "action Beep(times: int)\n".into());
        let f = db.set_file(
            "main.btrules",
            "import \"lib.btrules\"\nimport std::kb\nplan { sequence { Beep(times: 2) steps } }\n"
                .into(),
        );
        let all = described(&db, f);
        assert!(
            all.contains(&"Beep -> Callable { name: \"Beep\" } @ lib.btrules:Beep@7".to_owned()),
            "{all:#?}"
        );
        assert!(
            all.contains(
                &"times -> Port { owner: \"Beep\", name: \"times\" } @ lib.btrules:times@12"
                    .to_owned()
            ),
            "{all:#?}"
        );
        assert!(
            all.iter()
                .any(|l| l.starts_with("kb -> Std { module: \"kb\" } @ std::kb:@0")),
            "{all:#?}"
        );
        assert!(
            all.iter().any(|l| l.starts_with(
                "\"lib.btrules\" -> File { written: \"lib.btrules\" } @ lib.btrules:@0"
            )),
            "{all:#?}"
        );
    }

    #[test]
    fn editing_one_rule_resolves_only_that_rule_again() {
        let mut db = Database::new();
        load(&mut db, "examples/ariac/domain.pddl");
        let f = load(&mut db, "lang/tests/fixtures/large.btrules");
        let resolve_all = |db: &Database| -> usize {
            rules_items(db, f)
                .iter()
                .map(|i| item_resolutions(db, *i).len())
                .sum()
        };
        let before = resolve_all(&db);
        assert!(before > 5000, "{before}");
        db.start_logging();
        // One rule's body changes, and the text's length with it: every
        // later item moves.
        let text = f.text(&db).replacen(
            "retry(3) MoveTo(robot: ?r, target: ?b)",
            "retry(30) MoveTo(robot: ?r, target: ?destination)",
            1,
        );
        db.set_file(&f.path(&db).clone(), text);
        let after = resolve_all(&db);
        let log = db.take_log();
        let count = |q: &str| log.iter().filter(|l| l.starts_with(q)).count();
        assert_eq!(count("item_resolutions"), 1, "{log:#?}");
        // `?destination` is unbound: one name fewer resolves.
        assert_eq!(after, before - 1);
        // The declarations' places are by item, so they stay equal.
        let sites = declaration_sites(&db, f);
        let move_to = sites.callables["MoveTo"];
        assert_eq!(
            &f.text(&db)[move_to.span(&db).start as usize..][..6],
            "MoveTo"
        );
    }
}

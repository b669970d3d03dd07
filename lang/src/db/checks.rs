//! A rules file's imports and declarations, each item's checks, and the
//! file-level checks over per-item summaries.

use super::*;

/// A rules file and every file it imports, transitively, in order; import
/// errors with absolute spans. Iterative, so import cycles are harmless.
#[salsa::tracked(returns(ref))]
pub fn import_closure(db: &dyn Db, file: SourceFile) -> (Vec<SourceFile>, Vec<Diagnostic>) {
    let mut order = vec![file];
    let mut diags = Vec::new();
    let mut i = 0;
    while i < order.len() {
        let f = order[i];
        i += 1;
        for n in &parsed_rules(db, f).items {
            let Item::Import { target, span } = &*n.item else {
                continue;
            };
            let found = match target {
                ImportTarget::Std { module } => db
                    .workspace()
                    .files(db)
                    .get(&FilePath::std(&module.text))
                    .copied(),
                ImportTarget::Path { path, .. } => path.plain().and_then(|p| resolve(db, f, &p)),
            };
            match found {
                Some(g) if !order.contains(&g) => order.push(g),
                Some(_) => {}
                None if f == file => {
                    let (what, hint) = match target {
                        ImportTarget::Std { module } => (
                            format!("there is no stdlib module `std::{}`", module.text),
                            format!(
                                "the stdlib modules are {}",
                                STDLIB
                                    .iter()
                                    .map(|(n, _)| format!("`std::{n}`"))
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            ),
                        ),
                        ImportTarget::Path { path, .. } => (
                            format!("cannot find `{}`", path.plain().unwrap_or_default()),
                            "import paths are relative to the importing file".to_owned(),
                        ),
                    };
                    let d = Diagnostic::error(codes::R_IMPORT, *span, what).with_hint(hint);
                    diags.push(shift(d, file_id(db, file), n.offset));
                }
                None => {}
            }
        }
    }
    (order, diags)
}

/// Declarations visible in a rules file: its own first, then its imports',
/// then the trees of the BT.CPP files it and its imports import (typed
/// from the nodes declared before them).
#[salsa::tracked(returns(ref))]
pub fn declarations(db: &dyn Db, file: SourceFile) -> Decls {
    let mut decls = Decls::default();
    for f in &import_closure(db, file).0 {
        decls.add_items(&parsed_rules(db, *f).items);
    }
    for imp in xml_imports(db, file) {
        let x = xml_trees(db, imp.xml);
        if let Ok(names) = tree_names(x, imp.alias.as_ref()) {
            let trees = imported_trees(x, &names, &decls);
            decls.add_imported(trees);
        }
    }
    decls
}

/// An `import "FILE.xml" [as NAME]` of a rules file in the import closure.
#[derive(Clone, Debug, PartialEq)]
pub struct XmlImport {
    pub xml: SourceFile,
    pub alias: Option<Ident>,
    /// The importing file and the import item's offset in it (the alias's
    /// span is relative to it).
    pub from: SourceFile,
    pub offset: u32,
}

/// The BT.CPP files imported by a rules file and its imports, in order.
#[salsa::tracked(returns(ref))]
pub fn xml_imports(db: &dyn Db, file: SourceFile) -> Vec<XmlImport> {
    let mut out = Vec::new();
    for &f in &import_closure(db, file).0 {
        for n in &parsed_rules(db, f).items {
            let Item::Import {
                target: ImportTarget::Path { path, alias },
                ..
            } = &*n.item
            else {
                continue;
            };
            if let Some(xml) = path.plain().and_then(|p| resolve(db, f, &p)) {
                if is_palette(xml.path(db)) {
                    out.push(XmlImport {
                        xml,
                        alias: alias.clone(),
                        from: f,
                        offset: n.offset,
                    });
                }
            }
        }
    }
    out
}

/// A BT.CPP file's trees, read once.
#[salsa::tracked(returns(ref))]
pub fn xml_trees(db: &dyn Db, file: SourceFile) -> XmlTrees {
    crate::rules::btxml::read_trees(file.text(db), file_id(db, file))
}

/// What is wrong with the BT.CPP trees a rules file imports: the files'
/// own problems, an `as` name that picks no tree (R074, at the name), an
/// `as` on a rules file, and each imported tree checked against the
/// importing file's declarations.
fn imported_tree_diagnostics(db: &dyn Db, file: SourceFile) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    let id = file_id(db, file);
    let mut seen = Vec::new();
    for imp in xml_imports(db, file) {
        let x = xml_trees(db, imp.xml);
        if !seen.contains(&imp.xml) {
            seen.push(imp.xml);
            out.extend(x.diagnostics.iter().cloned());
        }
        if let (Err(why), Some(alias), true) = (
            tree_names(x, imp.alias.as_ref()),
            &imp.alias,
            imp.from == file,
        ) {
            let d = Diagnostic::error(codes::R_XML_TREE_NAME, alias.span, why).with_hint(
                "set `main_tree_to_execute` on the file's <root>, or import it without `as` and call its trees by their IDs",
            );
            out.push(shift(d, id, imp.offset));
        }
    }
    for n in own_items(db, file) {
        if let Item::Import {
            target:
                ImportTarget::Path {
                    path,
                    alias: Some(alias),
                },
            ..
        } = &*n.item
        {
            let xml = path
                .plain()
                .and_then(|p| resolve(db, file, &p))
                .is_none_or(|f| is_palette(f.path(db)));
            if !xml {
                let d = Diagnostic::error(
                    codes::R_XML_TREE_NAME,
                    alias.span,
                    format!(
                        "`as {}` names a BT.CPP file's main tree; this import is a rules file",
                        alias.text
                    ),
                )
                .with_hint("a rules file's declarations keep their own names: remove `as ...`");
                out.push(shift(d, id, n.offset));
            }
        }
    }
    let decls = declarations(db, file);
    let ctx = domain_ctx(db, file);
    for name in &decls.imported {
        if let Some(t) = decls.trees.get(name) {
            out.extend(check_imported_tree(t, decls, ctx));
        }
    }
    out
}

/// The domain's action names indexed for matching patterns.
#[salsa::tracked(returns(ref))]
pub fn action_index(db: &dyn Db, domain: SourceFile) -> ActionIndex {
    match &checked_domain(db, domain).domain {
        Some(d) => ActionIndex::new(d),
        None => ActionIndex::default(),
    }
}

/// The PDDL side a rules file's items are checked against: its domain
/// (when it can be read) and problem.
pub fn domain_ctx(db: &dyn Db, file: SourceFile) -> Option<DomainCtx<'_>> {
    let domain = domain_file(db, file)?;
    let cd = checked_domain(db, domain);
    let problem =
        problem_file(db, file).map(|p| checked_problem(db, ProblemOf::new(db, p, domain)));
    Some(DomainCtx {
        domain: cd.domain.as_ref()?,
        index: &cd.index,
        problem: problem.map(|p| &p.index),
        actions: action_index(db, domain),
    })
}

/// Diagnostics of one item, relative to its start. Reads only the item's
/// tree, the declarations and the PDDL files, so edits elsewhere in the file
/// leave it alone.
#[salsa::tracked(returns(ref))]
pub fn item_diagnostics<'db>(db: &'db dyn Db, item: RulesItem<'db>) -> Vec<Diagnostic> {
    let file = item.file(db);
    let decls = declarations(db, file);
    check_item(
        item.item(db),
        decls,
        domain_ctx(db, file),
        file_id(db, file),
    )
}

/// A rule's variables with the types the checker gives them (empty for
/// items that are no rules): what the language server shows for a
/// `?variable` in hovers, completions and inlay hints.
#[salsa::tracked(returns(ref))]
pub fn rule_var_types<'db>(db: &'db dyn Db, item: RulesItem<'db>) -> Vec<VarTypes> {
    let Item::Rule(r) = item.item(db) else {
        return Vec::new();
    };
    let file = item.file(db);
    crate::rules::check::rule_var_types(r, declarations(db, file), domain_ctx(db, file))
}

/// What the file-level checks need of an item's head (nothing of a body).
#[salsa::tracked(returns(ref))]
pub fn item_head<'db>(db: &'db dyn Db, item: RulesItem<'db>) -> ItemHead {
    file_checks::head(item.item(db))
}

/// The names an item uses, for R014.
#[salsa::tracked(returns(ref))]
pub fn item_uses<'db>(db: &'db dyn Db, item: RulesItem<'db>) -> ItemUses {
    file_checks::uses(item.item(db))
}

/// The actions a rule can match, for R012 and R013 (`None` for items that
/// are no rules, or without a domain).
#[salsa::tracked(returns(ref))]
pub fn rule_facts<'db>(db: &'db dyn Db, item: RulesItem<'db>) -> Option<RuleFacts> {
    let Item::Rule(r) = item.item(db) else {
        return None;
    };
    let file = item.file(db);
    let ctx = domain_ctx(db, file)?;
    Some(file_checks::rule_facts(r, declarations(db, file), ctx))
}

/// The heads of a file's items, in order.
#[salsa::tracked(returns(ref))]
pub fn item_heads(db: &dyn Db, file: SourceFile) -> Vec<ItemHead> {
    rules_items(db, file)
        .iter()
        .map(|i| item_head(db, *i).clone())
        .collect()
}

/// One `domain`, one `plan`, names declared once.
#[salsa::tracked(returns(ref))]
pub fn file_structure(db: &dyn Db, file: SourceFile) -> Vec<Finding> {
    file_checks::structure(item_heads(db, file))
}

/// R012 and R013 over the file's rules.
#[salsa::tracked(returns(ref))]
pub fn file_coverage(db: &dyn Db, file: SourceFile) -> Vec<Finding> {
    let Some(domain) = domain_file(db, file) else {
        return Vec::new();
    };
    let Some(d) = &checked_domain(db, domain).domain else {
        return Vec::new();
    };
    let items = rules_items(db, file);
    let facts: Vec<(usize, &RuleFacts)> = items
        .iter()
        .enumerate()
        .filter_map(|(k, i)| rule_facts(db, *i).as_ref().map(|f| (k, f)))
        .collect();
    // A file with no rule, nor an import with one, is a file being started
    // (unless an import could not be read: it may have rules).
    let no_rules = facts.is_empty()
        && !d.actions.is_empty()
        && import_closure(db, file).1.is_empty()
        && import_closure(db, file).0.iter().all(|f| {
            !parsed_rules(db, *f)
                .items
                .iter()
                .any(|n| matches!(&*n.item, Item::Rule(_)))
        });
    if no_rules {
        return vec![Finding::NoRules {
            actions: d.actions.len(),
            file_name: file.path(db).file_name().unwrap_or("FILE").to_owned(),
        }];
    }
    file_checks::coverage(&facts, d.actions.len())
}

/// R014 over the file's declarations.
#[salsa::tracked(returns(ref))]
pub fn file_unused(db: &dyn Db, file: SourceFile) -> Vec<Finding> {
    let items = rules_items(db, file);
    let mut uses: Vec<&ItemUses> = items.iter().map(|i| item_uses(db, *i)).collect();
    uses.push(imported_uses(db, file));
    file_checks::unused(item_heads(db, file), &uses)
}

/// The names the imported BT.CPP trees use: a node declared in the rules
/// for an imported tree is used.
#[salsa::tracked(returns(ref))]
pub fn imported_uses(db: &dyn Db, file: SourceFile) -> ItemUses {
    let decls = declarations(db, file);
    let mut out = ItemUses::default();
    for t in decls.imported.iter().filter_map(|n| decls.trees.get(n)) {
        let u = file_checks::uses(&Item::Tree(t.clone()));
        out.names.extend(u.names);
        out.broken |= u.broken;
    }
    out
}

/// Every diagnostic of a rules file itself (not of its PDDL files), with
/// absolute spans.
#[salsa::tracked(returns(ref))]
pub fn rules_diagnostics(db: &dyn Db, file: SourceFile) -> Vec<Diagnostic> {
    let id = file_id(db, file);
    let parsed = parsed_rules(db, file);
    let mut out = parsed.diagnostics.clone();
    out.extend(import_closure(db, file).1.iter().cloned());
    // A palette's problems are reported with the file that imports it.
    for &f in import_closure(db, file).0.iter().skip(1) {
        if is_palette(f.path(db)) {
            out.extend(parsed_rules(db, f).diagnostics.iter().cloned());
        }
    }
    out.extend(imported_tree_diagnostics(db, file));
    for item in rules_items(db, file) {
        let offset = item.offset(db);
        out.extend(
            item_diagnostics(db, *item)
                .iter()
                .cloned()
                .map(|d| shift(d, id, offset)),
        );
    }
    let domain = domain_file(db, file);
    if let Some((path, span, offset)) = declared_path(db, file, false) {
        if domain.is_none() {
            out.push(shift(
                Diagnostic::error(
                    codes::R_NO_DOMAIN,
                    span,
                    format!("cannot find the domain file `{path}`"),
                )
                .with_hint("the path is relative to this rules file"),
                id,
                offset,
            ));
        } else if let Some(d) = domain {
            let errors = checked_domain(db, d)
                .diagnostics
                .iter()
                .filter(|d| d.is_error())
                .count();
            if errors > 0 {
                out.push(shift(
                    Diagnostic::error(codes::R_NO_DOMAIN, span, format!("the domain `{path}` has {errors} error{}; rules are checked against what could be read", if errors == 1 { "" } else { "s" })),
                    id,
                    offset,
                ));
            }
        }
    }
    if let Some((path, span, offset)) = declared_path(db, file, true) {
        if problem_file(db, file).is_none() {
            out.push(shift(
                Diagnostic::error(
                    codes::R_NO_DOMAIN,
                    span,
                    format!("cannot find the problem file `{path}`"),
                ),
                id,
                offset,
            ));
        }
    }
    let heads = item_heads(db, file);
    let offsets: Vec<u32> = rules_items(db, file).iter().map(|i| i.offset(db)).collect();
    let d = domain.and_then(|d| checked_domain(db, d).domain.as_ref());
    for f in file_structure(db, file)
        .iter()
        .chain(file_coverage(db, file))
        .chain(file_unused(db, file))
    {
        out.extend(file_checks::render(f, heads, &offsets, d, id));
    }
    out.sort_by_key(|d| (d.span.file != id, d.span.start));
    out
}

/// The items of a parsed rules file (own items only).
pub fn own_items(db: &dyn Db, file: SourceFile) -> &[ItemNode] {
    &parsed_rules(db, file).items
}

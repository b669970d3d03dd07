//! The domain's type hierarchy: ids, parents, ancestor sets, and whether an
//! object or variable of one type may stand where another is expected.

use super::ast::{Domain, Name, TypeSpec};
use crate::diagnostic::{codes, did_you_mean, Diagnostic};
use rustc_hash::FxHashMap;

pub type TypeId = u32;

/// `object`, the root every type descends from.
pub const OBJECT: TypeId = 0;

#[derive(Clone, Debug, Default, PartialEq)]
pub struct TypeTable {
    names: Vec<String>,
    ids: FxHashMap<String, TypeId>,
    /// Every type's declared parents (none: `object`).
    parents: Vec<Vec<TypeId>>,
    /// Every type's ancestors, itself and `object` included, sorted.
    ancestors: Vec<Vec<TypeId>>,
}

impl TypeTable {
    /// Builds the table from `:types`, reporting unknown parents, duplicates
    /// and cycles.
    pub fn build(domain: &Domain, diags: &mut Vec<Diagnostic>) -> TypeTable {
        let mut t = TypeTable::default();
        t.intern("object");
        let mut first: FxHashMap<&str, &Name> = FxHashMap::default();
        for decl in &domain.types {
            if let Some(prev) = first.get(decl.name.as_str()) {
                // `a - t` repeated with another parent is multiple inheritance;
                // the same name listed twice in a row is only a duplicate.
                if matches!(decl.ty, TypeSpec::Object) {
                    diags.push(
                        Diagnostic::warning(
                            codes::DUPLICATE,
                            decl.name.span,
                            format!("type `{}` is declared twice", decl.name.name),
                        )
                        .with_label(prev.span, "first declared here"),
                    );
                }
            } else {
                first.insert(decl.name.as_str(), &decl.name);
            }
            t.intern(&decl.name.name);
        }
        let n = t.names.len();
        let mut parents: Vec<Vec<TypeId>> = vec![Vec::new(); n];
        for decl in &domain.types {
            let child = t.ids[decl.name.as_str()];
            for p in spec_names(&decl.ty) {
                match t.ids.get(p.as_str()) {
                    Some(&pid) if pid != child => parents[child as usize].push(pid),
                    Some(_) if child == OBJECT => {}
                    Some(_) => diags.push(Diagnostic::error(
                        codes::TYPE_CYCLE,
                        p.span,
                        format!("type `{}` cannot be its own parent", p.name),
                    )),
                    None => diags.push(unknown_type(p, &t)),
                }
            }
        }
        t.parents = parents;
        t.close();
        for decl in &domain.types {
            let id = t.ids[decl.name.as_str()];
            let cyclic = t.parents[id as usize]
                .iter()
                .any(|&p| t.ancestors[p as usize].binary_search(&id).is_ok());
            if cyclic && first.get(decl.name.as_str()).map(|n| n.span) == Some(decl.name.span) {
                diags.push(
                    Diagnostic::error(
                        codes::TYPE_CYCLE,
                        decl.name.span,
                        format!("type `{}` is its own ancestor", decl.name.name),
                    )
                    .with_hint("the `:types` hierarchy must be a tree (or a DAG) under `object`"),
                );
            }
        }
        t
    }

    /// A table from type names and their parents' names (`object` is
    /// implied); names of unknown parents are returned as errors.
    pub fn from_parents<'a>(
        types: impl IntoIterator<Item = (&'a str, Vec<&'a str>)>,
    ) -> Result<TypeTable, String> {
        let mut t = TypeTable::default();
        t.intern("object");
        let types: Vec<(&str, Vec<&str>)> = types.into_iter().collect();
        for (name, _) in &types {
            t.intern(name);
        }
        let mut parents: Vec<Vec<TypeId>> = vec![Vec::new(); t.names.len()];
        for (name, ps) in &types {
            let child = t.ids[*name];
            for p in ps {
                match t.ids.get(*p) {
                    Some(&pid) if pid != child => parents[child as usize].push(pid),
                    Some(_) => {}
                    None => return Err(format!("type `{name}` has an undeclared parent `{p}`")),
                }
            }
        }
        t.parents = parents;
        t.close();
        Ok(t)
    }

    /// Computes every type's ancestors from the parents.
    fn close(&mut self) {
        let n = self.names.len();
        self.ancestors = (0..n as TypeId)
            .map(|id| {
                let mut seen = vec![false; n];
                let mut stack = vec![id];
                while let Some(x) = stack.pop() {
                    if !std::mem::replace(&mut seen[x as usize], true) {
                        stack.extend(&self.parents[x as usize]);
                    }
                }
                seen[OBJECT as usize] = true;
                (0..n as TypeId).filter(|&i| seen[i as usize]).collect()
            })
            .collect();
    }

    /// The declared parents of a type (empty: `object`).
    pub fn parents(&self, id: TypeId) -> &[TypeId] {
        &self.parents[id as usize]
    }

    fn intern(&mut self, name: &str) -> TypeId {
        if let Some(&id) = self.ids.get(name) {
            return id;
        }
        let id = self.names.len() as TypeId;
        self.names.push(name.to_owned());
        self.ids.insert(name.to_owned(), id);
        self.ancestors.push(vec![OBJECT, id]);
        self.parents.push(Vec::new());
        id
    }

    pub fn id(&self, name: &str) -> Option<TypeId> {
        self.ids.get(name).copied()
    }

    pub fn name(&self, id: TypeId) -> &str {
        &self.names[id as usize]
    }

    pub fn len(&self) -> usize {
        self.names.len()
    }

    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    pub fn is_subtype(&self, a: TypeId, b: TypeId) -> bool {
        a == b || b == OBJECT || self.ancestors[a as usize].binary_search(&b).is_ok()
    }

    /// Whether something of one of the types `have` can stand where one of
    /// `want` is expected: each type it may have must fit some wanted type.
    pub fn fits(&self, have: &[TypeId], want: &[TypeId]) -> bool {
        have.iter()
            .all(|&h| want.iter().any(|&w| self.is_subtype(h, w)))
    }

    /// Resolves a written type to ids, reporting unknown names. Unknown
    /// names resolve to `object` so checking can go on.
    pub fn resolve(&self, spec: &TypeSpec, diags: &mut Vec<Diagnostic>) -> Vec<TypeId> {
        match spec {
            TypeSpec::Object => vec![OBJECT],
            _ => spec_names(spec)
                .into_iter()
                .map(|n| match self.id(n.as_str()) {
                    Some(id) => id,
                    None => {
                        diags.push(unknown_type(n, self));
                        OBJECT
                    }
                })
                .collect(),
        }
    }

    pub fn display(&self, ids: &[TypeId]) -> String {
        match ids {
            [one] => self.name(*one).to_owned(),
            many => format!(
                "(either {})",
                many.iter()
                    .map(|&i| self.name(i))
                    .collect::<Vec<_>>()
                    .join(" ")
            ),
        }
    }

    /// All type names, for "did you mean".
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.names.iter().map(String::as_str)
    }
}

fn spec_names(spec: &TypeSpec) -> Vec<&Name> {
    match spec {
        TypeSpec::Object => Vec::new(),
        TypeSpec::Named { name } => vec![name],
        TypeSpec::Either { names, .. } => names.iter().collect(),
    }
}

fn unknown_type(n: &Name, t: &TypeTable) -> Diagnostic {
    let d = Diagnostic::error(
        codes::UNKNOWN_TYPE,
        n.span,
        format!("type `{}` is not declared in the domain's `:types`", n.name),
    );
    match did_you_mean(&n.name, t.names()) {
        Some(h) => d.with_hint(h),
        None => d.with_hint(format!("declare it: `(:types ... {} - object)`", n.name)),
    }
}

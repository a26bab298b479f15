//! RAPID's `RECORD` types: a record is its components' leaves, one after another, each
//! leaf's WSL name the component's path (`part.pick` and `part.count` of a `VAR partdata
//! part;`, `part.pick` being a robtarget's one pose). Components are read (`part.count`),
//! assigned (`part.count := 3;`, `part.pick.trans.z := 50;`), and a whole record is
//! written as an aggregate (`[pHome, 3, "left"]`), passed to a routine and assigned.

use std::collections::BTreeMap;

use vworks_vm::Type;

use super::data::Ty;
use super::{Data, Tr, Val};
use crate::diag::Code;
use crate::rapid::syntax as r;

/// A record type of the task.
#[derive(Clone, Debug)]
pub(crate) struct Record {
    /// Its name as written.
    pub(crate) name: String,
    /// Its components: (name in lower case, name as written, type), in order.
    pub(crate) fields: Vec<(String, String, Ty)>,
}

/// The task's record types: by index (`Ty::Record`), and the index of each name (lower
/// case).
#[derive(Debug, Default)]
pub(crate) struct Records {
    pub(crate) list: Vec<Record>,
    pub(crate) index: BTreeMap<String, usize>,
}

/// How deep records may nest (a record of a record of …).
const MAX_NESTING: usize = 16;

impl Tr<'_> {
    /// Declares the task's record types: every name first, so that a component may be a
    /// record declared later, then each component's type. A record that contains itself,
    /// directly or not, is E0025.
    pub(crate) fn collect_records(&mut self, modules: &[r::RapidModule]) {
        let mut index: BTreeMap<String, usize> = BTreeMap::new();
        let decls: Vec<&r::RecordDecl> = modules
            .iter()
            .flat_map(|m| &m.items)
            .filter_map(|it| match it {
                r::Item::Record(rec) => Some(rec),
                _ => None,
            })
            .collect();
        for rec in &decls {
            let key = rec.name.key();
            if index.contains_key(&key) || Ty::from_name(&key).is_some() {
                self.error(
                    Code::E0012,
                    format!("the data type `{}` is declared twice", rec.name.text),
                    rec.name.span,
                );
                continue;
            }
            index.insert(key, self.records.list.len());
            self.records.list.push(Record {
                name: rec.name.text.clone(),
                fields: Vec::new(),
            });
        }
        self.records.index = index;
        for rec in decls {
            let Some(&k) = self.records.index.get(&rec.name.key()) else {
                continue;
            };
            if !self.records.list[k].fields.is_empty() {
                continue; // The second of a name declared twice.
            }
            let mut fields = Vec::new();
            for (ty, name) in &rec.fields {
                let t = self.type_of(ty).unwrap_or(Ty::Num);
                if fields.iter().any(|(key, _, _)| *key == name.key()) {
                    self.error(
                        Code::E0012,
                        format!("the component `{}` is declared twice", name.text),
                        name.span,
                    );
                    continue;
                }
                fields.push((name.key(), name.text.clone(), t));
            }
            self.records.list[k].fields = fields;
        }
        for rec in modules.iter().flat_map(|m| &m.items) {
            if let r::Item::Record(rec) = rec
                && let Some(&k) = self.records.index.get(&rec.name.key())
                && self.nesting(Ty::Record(k as u16), 0).is_none()
            {
                self.error(
                    Code::E0025,
                    format!(
                        "the record `{}` contains itself (or nests more than {MAX_NESTING} deep)",
                        rec.name.text
                    ),
                    rec.name.span,
                )
                .help = Some(
                    "a component may be another record, but not one that holds this one".into(),
                );
                self.records.list[k].fields.clear();
            }
        }
    }

    /// How deep `ty` nests, or `None` past [`MAX_NESTING`] (a record holding itself).
    fn nesting(&self, ty: Ty, depth: usize) -> Option<usize> {
        if depth > MAX_NESTING {
            return None;
        }
        match ty {
            Ty::Record(k) => self
                .records
                .list
                .get(k as usize)?
                .fields
                .iter()
                .map(|(_, _, t)| self.nesting(*t, depth + 1))
                .try_fold(depth, |m, d| Some(m.max(d?))),
            _ => Some(depth),
        }
    }

    /// The type of the data an assignment target names (a name, an element, a record's
    /// component), if it names data: without diagnostics.
    pub(crate) fn place_type(&self, e: &r::Expr) -> Option<Ty> {
        match &e.kind {
            r::ExprKind::Name(n) => match self.lookup(&n.key())? {
                super::Sym::Data(d) => Some(d.ty),
                super::Sym::Routine(_) => None,
            },
            r::ExprKind::Index(x, _) => self.place_type(x),
            r::ExprKind::Field(x, f) => {
                let t = self.place_type(x)?;
                self.component(t, &f.key()).map(|(_, _, t)| t)
            }
            _ => None,
        }
    }

    /// The record type named `key` (lower case).
    pub(crate) fn record_named(&self, key: &str) -> Option<Ty> {
        self.records.index.get(key).map(|&k| Ty::Record(k as u16))
    }

    /// A type's WSL leaves: (suffix of the WSL name, type). A record's are its
    /// components' leaves, each suffixed with `.component`.
    pub(crate) fn leaves(&self, ty: Ty) -> Vec<(String, Type)> {
        let mut out = Vec::new();
        self.push_leaves(ty, String::new(), 0, &mut out);
        out
    }

    fn push_leaves(&self, ty: Ty, prefix: String, depth: usize, out: &mut Vec<(String, Type)>) {
        match ty {
            Ty::Record(k) if depth <= MAX_NESTING => {
                if let Some(rec) = self.records.list.get(k as usize) {
                    for (key, _, t) in &rec.fields {
                        self.push_leaves(*t, format!("{prefix}.{key}"), depth + 1, out);
                    }
                }
            }
            Ty::Record(_) => {}
            t => out.extend(t.leaves().iter().map(|(s, w)| (format!("{prefix}{s}"), *w))),
        }
    }

    /// The single leaf's type of a type held in one WSL value.
    pub(crate) fn leaf_type(&self, ty: Ty) -> Option<Type> {
        match self.leaves(ty).as_slice() {
            [(_, t)] => Some(*t),
            _ => None,
        }
    }

    /// The component `key` of record type `ty`: its first leaf, how many leaves it has,
    /// its type.
    pub(crate) fn component(&self, ty: Ty, key: &str) -> Option<(usize, usize, Ty)> {
        let Ty::Record(k) = ty else { return None };
        let rec = self.records.list.get(k as usize)?;
        let mut at = 0;
        for (name, _, t) in &rec.fields {
            let n = self.leaves(*t).len();
            if name == key {
                return Some((at, n, *t));
            }
            at += n;
        }
        None
    }

    /// The record's name and components, for messages.
    pub(crate) fn record_components(&self, ty: Ty) -> Option<(String, Vec<String>)> {
        let Ty::Record(k) = ty else { return None };
        let rec = self.records.list.get(k as usize)?;
        Some((
            rec.name.clone(),
            rec.fields.iter().map(|(_, s, _)| s.clone()).collect(),
        ))
    }

    /// E0022 for a component `f` a record does not have.
    pub(crate) fn no_component(&mut self, ty: Ty, f: &r::Name) {
        let Some((name, comps)) = self.record_components(ty) else {
            return;
        };
        let lower: Vec<String> = comps.iter().map(|c| c.to_ascii_lowercase()).collect();
        let near = crate::suggest::nearest(&f.key(), lower.iter().map(String::as_str))
            .and_then(|k| comps.iter().find(|c| c.eq_ignore_ascii_case(k)))
            .map(|c| format!("did you mean `{c}`? "))
            .unwrap_or_default();
        self.error(
            Code::E0022,
            format!("the record `{name}` has no component `{}`", f.text),
            f.span,
        )
        .help = Some(format!("{near}its components: {}", comps.join(", ")));
    }

    /// The value of component `f` of the record value `v`.
    pub(crate) fn record_field(&mut self, v: Val, f: &r::Name) -> Option<Val> {
        let Some((at, n, t)) = self.component(v.ty, &f.key()) else {
            self.no_component(v.ty, f);
            return None;
        };
        Some(Val {
            ty: t,
            parts: v.parts.into_iter().skip(at).take(n).collect(),
            text: None,
        })
    }

    /// The data of component `f` of record data `d` (element `idx`): data whose leaves are
    /// that component's, for assignments to it and its own components.
    pub(crate) fn record_component_data(
        &mut self,
        d: &Data,
        idx: Option<u32>,
        f: &r::Name,
    ) -> Option<Data> {
        let Some((_, _, t)) = self.component(d.ty, &f.key()) else {
            self.no_component(d.ty, f);
            return None;
        };
        let base = match idx {
            Some(i) => format!("{}{{{i}}}.{}", d.base, f.key()),
            None => format!("{}.{}", d.base, f.key()),
        };
        Some(Data {
            ty: t,
            len: None,
            dims: Vec::new(),
            base,
            text: None,
            inline: None,
            tasks: Vec::new(),
            optional: false,
            ..d.clone()
        })
    }

    /// A record aggregate `[a, b, …]` of type `ty`: each value of its component's type.
    pub(crate) fn record_aggregate(
        &mut self,
        items: &[r::Expr],
        ty: Ty,
        span: crate::syntax::Span,
    ) -> Option<Val> {
        let Ty::Record(k) = ty else { return None };
        let fields = self.records.list.get(k as usize)?.fields.clone();
        if items.len() != fields.len() {
            let name = self.records.list[k as usize].name.clone();
            self.error(
                Code::E0013,
                format!(
                    "a `{name}` is written with {} values in `[…]`, not {}",
                    fields.len(),
                    items.len()
                ),
                span,
            );
            return None;
        }
        let mut parts = Vec::new();
        for (e, (_, _, t)) in items.iter().zip(fields) {
            parts.extend(self.value(e, t)?.parts);
        }
        Some(Val {
            ty,
            parts,
            text: None,
        })
    }
}

//! RAPID syntax trees to a WSL syntax tree, which the WSL compiler's checking and code
//! generation then turn into bytecode: the same instructions, the same events, the same
//! rules for conditions and handlers whichever language a robot is programmed in.
//!
//! This pass owns everything RAPID means that WSL does not say the same way: names are
//! case-insensitive (the WSL names are the RAPID names in lower case), numbers carry
//! RAPID's units (mm, degrees, seconds, mm/s) and become WSL quantities, records
//! (`robtarget`, `speeddata`, `tooldata`, …) become their WSL leaves (see [`data`]), arrays
//! become one WSL variable per element with generated accessors for a variable index, and
//! RAPID's instructions (`MoveL`, `WaitUntil`, `TPWrite`, …) become WSL statements. It
//! checks RAPID's types itself, so that the WSL it produces is well typed; a problem is a
//! diagnostic at the RAPID text. Constructs it does not run are E0300, never skipped.
//!
//! Every WSL node gets the span of the RAPID construct it comes from, so the bytecode's
//! line table, the event trace and runtime errors name RAPID lines.

mod arrays;
mod clocks;
pub(crate) mod data;
mod expr;
mod functions;
mod goto;
mod io;
mod records;
mod refs;
mod stmt;
mod strings;
pub(crate) mod table;

use std::collections::{BTreeMap, BTreeSet};

use super::catalog::{self, Kind};
use super::syntax::{self as r, Storage};
use crate::diag::{Code, Diagnostic};
use crate::syntax::{self as w, Span};
use data::{Ty, build as b};

/// Translates a task's RAPID modules into one WSL module.
pub(crate) fn translate(
    modules: &[r::RapidModule],
    signals: Option<&[super::IoSignal]>,
    diags: &mut Vec<Diagnostic>,
) -> w::SourceModule {
    let mut t = Tr {
        diags,
        scope: BTreeMap::new(),
        module_scope: BTreeMap::new(),
        module: 0,
        module_names: modules.iter().map(|m| m.name.clone()).collect(),
        items: Vec::new(),
        helpers: BTreeSet::new(),
        locals: Vec::new(),
        used: BTreeSet::new(),
        temps: 0,
        routine: None,
        spelled: BTreeMap::new(),
        io: signals.map(<[super::IoSignal]>::to_vec),
        signals: BTreeMap::new(),
        connects: BTreeMap::new(),
        ordered: BTreeSet::new(),
        orders: BTreeMap::new(),
        grip_parts: Vec::new(),
        named_signals: Vec::new(),
        records: records::Records::default(),
    };
    t.collect_records(modules);
    t.collect(modules);
    t.collect_connects(modules);
    for (k, m) in modules.iter().enumerate() {
        t.module = k;
        for it in &m.items {
            if let r::Item::Data(d) = it {
                t.module_data(d);
            }
        }
    }
    for (k, m) in modules.iter().enumerate() {
        t.module = k;
        for it in &m.items {
            if let r::Item::Routine(rt) = it {
                t.routine(rt);
            }
        }
    }
    t.declare_signals();
    w::SourceModule {
        items: t.items,
        texts: true,
    }
}

/// Data the front-end knows by name.
#[derive(Clone, Debug)]
pub(crate) struct Data {
    pub(crate) ty: Ty,
    /// Elements of an array (1-based in RAPID), `None` for a scalar.
    pub(crate) len: Option<u32>,
    /// An array's dimensions (`a{3, 4}`: 3 and 4; elements are held row after row, so
    /// `a{i, j}` is element `(i - 1) · 4 + j`); empty for a scalar.
    pub(crate) dims: Vec<u32>,
    pub(crate) storage: Storage,
    /// The WSL name the leaves' names start with.
    pub(crate) base: String,
    pub(crate) span: Span,
    /// An optional parameter of the routine (`\num x`): `Present(x)` reads its flag.
    pub(crate) optional: bool,
    /// A `CONST string`'s text.
    pub(crate) text: Option<String>,
    /// Predefined data (`v100`, `fine`, `tool0`): its leaves as WSL constants.
    pub(crate) inline: Option<Vec<w::Expr>>,
    /// Declared inside a routine.
    pub(crate) local: bool,
    /// Cannot be assigned (a `CONST`, a `FOR` variable).
    pub(crate) readonly: bool,
    /// A task list's task names (`["T_ROB1"]`), in its order.
    pub(crate) tasks: Vec<String>,
}

/// A routine's signature.
#[derive(Clone, Debug)]
pub(crate) struct Sig {
    pub(crate) kind: r::RoutineKind,
    /// The required parameters' types, in order.
    pub(crate) params: Vec<Ty>,
    /// For each required parameter passed by reference (`VAR`, `PERS`, `INOUT`), the
    /// WSL name its module variable starts with (`pick'p`); `None` for one by value.
    pub(crate) by_ref: Vec<Option<String>>,
    /// The optional parameters (`\num x`, `\switch On`), in order: each is its leaves
    /// (none for a switch) and a flag of whether the caller gave it.
    pub(crate) optional: Vec<OptParam>,
    pub(crate) ret: Option<Ty>,
    pub(crate) wsl: String,
    pub(crate) span: Span,
}

/// An optional parameter of a routine.
#[derive(Clone, Debug)]
pub(crate) struct OptParam {
    /// Its name, lower case.
    pub(crate) key: String,
    /// As written.
    pub(crate) spelled: String,
    pub(crate) ty: Ty,
}

#[derive(Clone, Debug)]
pub(crate) enum Sym {
    Data(Data),
    Routine(Sig),
}

/// The routine being translated.
pub(crate) struct RoutineCx {
    pub(crate) kind: r::RoutineKind,
    pub(crate) ret: Option<Ty>,
    /// It has an `ERROR` handler: each statement is one for `RETRY` and `TRYNEXT`.
    pub(crate) has_handler: bool,
    /// Translating its error handler.
    pub(crate) in_handler: bool,
    /// Its labels (lower case, in order) and the WSL variable of the one to go on from,
    /// when it has `GOTO`s (see `goto.rs`).
    pub(crate) labels: Option<(Vec<String>, String)>,
    /// How many RAPID loops (`WHILE`, `FOR`) the statement being translated is in.
    pub(crate) loops: u32,
}

/// A translated RAPID value: its type and its WSL leaves.
#[derive(Clone, Debug)]
pub(crate) struct Val {
    pub(crate) ty: Ty,
    pub(crate) parts: Vec<w::Expr>,
    /// The text of a string known at compile time.
    pub(crate) text: Option<String>,
}

impl Val {
    pub(crate) fn one(ty: Ty, e: w::Expr) -> Val {
        Val {
            ty,
            parts: vec![e],
            text: None,
        }
    }
    /// A text known when compiling.
    pub(crate) fn text(s: String, span: Span) -> Val {
        Val {
            ty: Ty::Str,
            parts: vec![b::expr(w::ExprKind::Str(s.clone()), span)],
            text: Some(s),
        }
    }
    /// The single leaf (types of one leaf only).
    pub(crate) fn leaf(mut self) -> w::Expr {
        let span = self.parts.first().map(|e| e.span).unwrap_or_default();
        self.parts
            .pop()
            .unwrap_or_else(|| b::expr(w::ExprKind::Error, span))
    }
}

pub(crate) struct Tr<'d> {
    pub(crate) diags: &'d mut Vec<Diagnostic>,
    /// Module-level names (lower case) of every module of the task, but `LOCAL` ones.
    pub(crate) scope: BTreeMap<String, Sym>,
    /// `LOCAL` names by (module index, name): seen only in their own module, where they
    /// hide a task-wide name of the same spelling.
    pub(crate) module_scope: BTreeMap<(usize, String), Sym>,
    /// The module being translated (its index in the task).
    pub(crate) module: usize,
    /// The modules' names, by index.
    pub(crate) module_names: Vec<r::Name>,
    pub(crate) items: Vec<w::Item>,
    /// Generated helper functions already emitted.
    pub(crate) helpers: BTreeSet<String>,
    /// The routine's local scopes, innermost last.
    pub(crate) locals: Vec<BTreeMap<String, Data>>,
    /// WSL local names used in the routine.
    pub(crate) used: BTreeSet<String>,
    pub(crate) temps: u32,
    pub(crate) routine: Option<RoutineCx>,
    /// Each declared name (lower case) as it was first written, for messages.
    pub(crate) spelled: BTreeMap<String, String>,
    /// The robot's wired I/O signals (`None`: any signal an I/O instruction names).
    pub(crate) io: Option<Vec<super::IoSignal>>,
    /// The signals the task uses: global name → initial value.
    pub(crate) signals: BTreeMap<String, i64>,
    /// Each interrupt variable (lower case) and the TRAP its `CONNECT` names.
    pub(crate) connects: BTreeMap<String, Sig>,
    /// Each interrupt variable's orders (`ISignalDI …`, `ITimer …`: the instruction and
    /// its arguments), for `IWatch` to order it again.
    pub(crate) orders: BTreeMap<String, Vec<(r::Name, Vec<r::Arg>)>>,
    /// The handlers some interrupt order enables (a TRAP, or its `'single` wrapper).
    pub(crate) ordered: BTreeSet<String>,
    /// The workcell parts the task's `GripLoad`s name (loaddata names, lower case), sorted.
    pub(crate) grip_parts: Vec<String>,
    /// The names the task's I/O instructions give as their signal (`WaitDI di1, 1`), in
    /// order (lower case): without the workcell's I/O (`io` is `None`), these alone are
    /// signals where an expression reads a bare name.
    pub(crate) named_signals: Vec<String>,
    /// The task's `RECORD` types.
    pub(crate) records: records::Records,
}

/// The WSL name of a RAPID name: lower case (RAPID is case-insensitive).
pub(crate) fn wsl_name(n: &r::Name) -> String {
    let k = n.key();
    // Names WSL's own built-in functions take get a `'`.
    if crate::lower::BUILTINS.iter().any(|b| b.name == k) {
        format!("{k}'")
    } else {
        k
    }
}

impl Data {
    /// The WSL name of an optional parameter's flag: whether the caller gave it.
    pub(crate) fn present(&self) -> String {
        format!("{}'present", self.base)
    }
}

impl Tr<'_> {
    pub(crate) fn error(
        &mut self,
        code: Code,
        msg: impl Into<String>,
        span: Span,
    ) -> &mut Diagnostic {
        self.diags.push(Diagnostic::error(code, msg, span));
        let n = self.diags.len() - 1;
        &mut self.diags[n]
    }

    /// E0300: a construct the front-end does not run.
    pub(crate) fn unsupported(&mut self, what: &str, span: Span, help: &str) {
        let d = Diagnostic::error(
            Code::E0300,
            format!("{what} is not supported by vworks's RAPID front-end"),
            span,
        )
        .with_help(help.to_string())
        .with_note("docs/rapid.md lists what RAPID vworks runs");
        self.diags.push(d);
    }

    /// E0300 for a RAPID built-in of `kinds` that vworks does not run, naming it and its
    /// part of RobotWare (the catalogue, [`crate::rapid::catalog`]); false if `name` is
    /// none.
    pub(crate) fn not_run(&mut self, name: &r::Name, kinds: &[Kind]) -> bool {
        let Some(entry) = catalog::find(&name.text, kinds) else {
            return false;
        };
        let d = Diagnostic::error(Code::E0300, entry.message(), name.span)
            .with_help(entry.group.help.to_string())
            .with_note("docs/rapid.md lists what RAPID vworks runs, and under \"Not run\" what it does not");
        self.diags.push(d);
        true
    }

    /// Module-level names first, so routines may be called before they are declared. A
    /// name is declared once in its module, and a task-wide name once in the task; a
    /// `LOCAL` name may repeat in other modules.
    fn collect(&mut self, modules: &[r::RapidModule]) {
        let mut seen: BTreeMap<(usize, String), Span> = BTreeMap::new();
        let mut task_wide: BTreeMap<String, Span> = BTreeMap::new();
        for (mi, m) in modules.iter().enumerate() {
            self.module = mi;
            for it in &m.items {
                let (name, local) = match it {
                    r::Item::Data(d) => (&d.name, d.local),
                    r::Item::Routine(rt) => (&rt.name, rt.local),
                    r::Item::Record(_) => continue,
                };
                let key = name.key();
                self.spelled
                    .entry(key.clone())
                    .or_insert_with(|| name.text.clone());
                let in_module = seen.get(&(mi, key.clone())).map(|s| (*s, "module"));
                let in_task = || (!local).then(|| task_wide.get(&key)).flatten();
                if let Some((prev_span, scope)) =
                    in_module.or_else(|| in_task().map(|s| (*s, "task")))
                {
                    let d = Diagnostic::error(
                        Code::E0012,
                        format!("`{}` is declared twice in this {scope}", name.text),
                        name.span,
                    )
                    .with_related(prev_span, "first declared here")
                    .with_note("RAPID names are case-insensitive; a LOCAL name may repeat in another module");
                    self.diags.push(d);
                    continue;
                }
                seen.insert((mi, key.clone()), name.span);
                if !local {
                    task_wide.insert(key.clone(), name.span);
                }
                if let r::Item::Routine(rt) = it {
                    let sig = self.signature(rt);
                    self.declare(local, key, Sym::Routine(sig));
                }
            }
        }
    }

    /// Declares a module-level name of the current module: task-wide, or `LOCAL`.
    pub(crate) fn declare(&mut self, local: bool, key: String, sym: Sym) {
        if local {
            self.module_scope.insert((self.module, key), sym);
        } else {
            self.scope.insert(key, sym);
        }
    }

    /// The module-level symbol `key` declared by the current module (`LOCAL`) or the task.
    fn declared(&self, local: bool, key: &str) -> Option<&Sym> {
        if local {
            self.module_scope.get(&(self.module, key.to_string()))
        } else {
            self.scope.get(key)
        }
    }

    /// A note for a name the current module does not see but another module declares
    /// `LOCAL`.
    pub(crate) fn local_elsewhere(&self, key: &str) -> Option<String> {
        let (m, _) = self
            .module_scope
            .keys()
            .find(|(m, k)| *m != self.module && k == key)?;
        let module = &self.module_names.get(*m)?.text;
        Some(format!(
            "it is LOCAL to module `{module}`, which alone sees it; drop LOCAL to share it with the task's other modules"
        ))
    }

    /// The WSL name of a module-level name: a `LOCAL` one is prefixed with its module's
    /// name (`moves:init`), so that `LOCAL`s of several modules do not meet.
    fn module_level_name(&self, n: &r::Name, local: bool) -> String {
        let name = wsl_name(n);
        match self.module_names.get(self.module) {
            Some(m) if local => format!("{}:{name}", m.key()),
            _ => name,
        }
    }

    fn signature(&mut self, rt: &r::Routine) -> Sig {
        let mut params = Vec::new();
        let mut by_ref = Vec::new();
        let mut optional = Vec::new();
        let wsl = self.module_level_name(&rt.name, rt.local);
        for p in &rt.params {
            let ty = self.type_of(&p.ty).unwrap_or(Ty::Num);
            if p.optional {
                optional.push(OptParam {
                    key: p.name.key(),
                    spelled: p.name.text.clone(),
                    ty,
                });
            } else {
                params.push(ty);
                by_ref
                    .push((p.mode == r::Mode::Ref).then(|| format!("{wsl}'{}", wsl_name(&p.name))));
            }
        }
        let ret = rt.ret.as_ref().map(|t| self.type_of(t).unwrap_or(Ty::Num));
        Sig {
            kind: rt.kind,
            params,
            by_ref,
            optional,
            ret,
            wsl,
            span: rt.name.span,
        }
    }

    /// The type of a type name, or E0014.
    pub(crate) fn type_of(&mut self, n: &r::Name) -> Option<Ty> {
        if let Some(t) = Ty::from_name(&n.text) {
            return Some(t);
        }
        if let Some(t) = self.record_named(&n.key()) {
            return Some(t);
        }
        if !self.not_run(n, &[Kind::DataType]) {
            // The types a declaration may name anywhere (not MultiMove's).
            let names: Vec<&str> = data::TYPES
                .iter()
                .map(|(n, _)| *n)
                .take_while(|n| *n != "syncident")
                .collect();
            self.error(
                Code::E0014,
                format!("unknown data type `{}`", n.text),
                n.span,
            )
            .help = Some(format!("the types vworks knows are {}", names.join(", ")));
        }
        None
    }

    /// The dimensions of a declaration (none for a scalar): constants of at least 1, with
    /// at most 100000 elements in all.
    fn dims(&mut self, d: &r::DataDecl) -> Result<Vec<u32>, ()> {
        let mut out = Vec::new();
        for n in &d.dims {
            out.push(self.dim_size(n)?);
        }
        if out.iter().map(|&n| u64::from(n)).product::<u64>() > 100_000 {
            self.error(
                Code::E0025,
                "an array holds at most 100000 elements in all",
                d.name.span,
            );
            return Err(());
        }
        Ok(out)
    }

    /// One dimension's size.
    fn dim_size(&mut self, n: &r::Expr) -> Result<u32, ()> {
        match self.const_num(n) {
            Some(x) if (1.0..=100_000.0).contains(&x) && x.fract() == 0.0 => Ok(x as u32),
            Some(x) => {
                self.error(
                    Code::E0025,
                    format!("an array's size must be a whole number from 1 to 100000, not {x}"),
                    n.span,
                );
                Err(())
            }
            None => {
                // (A name declared nowhere is unknown, as anywhere else.)
                match &n.kind {
                    r::ExprKind::Name(name) if self.lookup(&name.key()).is_none() => {
                        self.unknown_name(name);
                    }
                    _ => {
                        self.error(Code::E0080, "an array's size must be a constant", n.span);
                    }
                }
                Err(())
            }
        }
    }

    /// A numeric constant expression's value (literals, `CONST num`s, arithmetic).
    pub(crate) fn const_num(&mut self, e: &r::Expr) -> Option<f64> {
        match &e.kind {
            r::ExprKind::Num(x) => Some(*x),
            r::ExprKind::Unary(r::UnOp::Neg, x) => self.const_num(x).map(|v| -v),
            r::ExprKind::Unary(r::UnOp::Plus, x) => self.const_num(x),
            r::ExprKind::Binary(op, a, bb) => {
                let (a, bb) = (self.const_num(a)?, self.const_num(bb)?);
                let v = match op {
                    r::BinOp::Add => a + bb,
                    r::BinOp::Sub => a - bb,
                    r::BinOp::Mul => a * bb,
                    r::BinOp::Div if bb != 0.0 => a / bb,
                    _ => return None,
                };
                v.is_finite().then_some(v)
            }
            r::ExprKind::Name(n) => match self.lookup(&n.key()) {
                Some(Sym::Data(d)) if d.storage == Storage::Const && d.len.is_none() => d
                    .inline
                    .as_ref()
                    .and_then(|p| p.first())
                    .and_then(b::literal),
                _ => None,
            },
            _ => None,
        }
    }

    /// Looks a name up: locals (innermost first), the task's modules, predefined data.
    pub(crate) fn lookup(&self, key: &str) -> Option<Sym> {
        for s in self.locals.iter().rev() {
            if let Some(d) = s.get(key) {
                return Some(Sym::Data(d.clone()));
            }
        }
        if let Some(s) = self
            .module_scope
            .get(&(self.module, key.to_string()))
            .or_else(|| self.scope.get(key))
        {
            return Some(s.clone());
        }
        predefined(key).map(Sym::Data)
    }

    /// A fresh WSL local name for `want` within the routine.
    pub(crate) fn fresh_local(&mut self, want: &str) -> String {
        let mut name = want.to_string();
        let mut k = 2;
        while self.used.contains(&name) || self.scope.contains_key(&name) {
            name = format!("{want}'{k}");
            k += 1;
        }
        self.used.insert(name.clone());
        name
    }

    /// A hidden temporary's name.
    pub(crate) fn temp(&mut self, what: &str) -> String {
        self.temps += 1;
        let n = format!("{what}#{}", self.temps);
        self.used.insert(n.clone());
        n
    }

    /// The WSL names of the leaves of element `index` (1-based, arrays) of data `d`.
    pub(crate) fn leaf_names(&self, d: &Data, index: Option<u32>) -> Vec<String> {
        let base = match index {
            Some(i) => format!("{}{{{i}}}", d.base),
            None => d.base.clone(),
        };
        self.leaves(d.ty)
            .iter()
            .map(|(suffix, _)| format!("{base}{suffix}"))
            .collect()
    }

    fn module_data(&mut self, d: &r::DataDecl) {
        let Some(ty) = self.type_of(&d.ty) else {
            return;
        };
        let Ok(dims) = self.dims(d) else { return };
        let len = (!dims.is_empty()).then(|| dims.iter().product::<u32>());
        let key = d.name.key();
        if matches!(self.declared(d.local, &key), Some(Sym::Routine(_))) {
            return; // Reported as a duplicate.
        }
        let mut data = Data {
            ty,
            len,
            dims: dims.clone(),
            storage: d.storage,
            base: self.module_level_name(&d.name, d.local),
            span: d.name.span,
            text: None,
            inline: None,
            local: false,
            readonly: d.storage == Storage::Const,
            tasks: Vec::new(),
            optional: false,
        };
        if ty == Ty::Syncident {
            self.syncident(d, &data);
            self.declare(d.local, key, Sym::Data(data));
            return;
        }
        let inits = self.initial_values(d, ty, &dims);
        if ty == Ty::Tasks {
            data.tasks = inits
                .iter()
                .flatten()
                .filter_map(|v| v.text.clone())
                .collect();
        }
        // A CONST string's text is known when compiling (a task list's names, a TPWrite).
        if ty == Ty::Str && d.storage == Storage::Const && len.is_none() {
            data.text = inits
                .as_ref()
                .and_then(|v| v.first())
                .and_then(|v| v.text.clone());
        }
        // A CONST scalar of literal leaves is folded where it is used (array sizes, …).
        if d.storage == Storage::Const
            && len.is_none()
            && let Some(v) = inits.as_ref().and_then(|v| v.first())
            && v.parts.iter().all(|p| b::literal(p).is_some())
            && !v.parts.is_empty()
        {
            data.inline = Some(v.parts.clone());
        }
        // A LOCAL PERS is its module's own: not shared with other tasks.
        let scalar_global = d.storage == Storage::Pers
            && !d.local
            && len.is_none()
            && matches!(ty, Ty::Num | Ty::Bool);
        for (decl, _) in self.leaf_decls(d, &data, inits.as_deref()) {
            self.items.push(match d.storage {
                Storage::Const => w::Item::Const(decl),
                Storage::Pers if scalar_global => w::Item::Global(decl),
                _ => w::Item::Var(decl),
            });
        }
        if len.is_some() && !self.leaves(ty).is_empty() {
            self.array_accessors(&data);
        }
        self.declare(d.local, key, Sym::Data(data));
    }

    /// One WSL declaration per element and leaf of `data` (declared by `d`), with the
    /// initial values `inits` (one per element), and each declaration's name.
    fn leaf_decls(
        &self,
        d: &r::DataDecl,
        data: &Data,
        inits: Option<&[Val]>,
    ) -> Vec<(w::VarDecl, String)> {
        let elements: Vec<Option<u32>> = match data.len {
            None => vec![None],
            Some(n) => (1..=n).map(Some).collect(),
        };
        let mut out = Vec::new();
        for (k, idx) in elements.iter().enumerate() {
            let names = self.leaf_names(data, *idx);
            for (j, (name, (_, wty))) in names.into_iter().zip(self.leaves(data.ty)).enumerate() {
                let init = inits
                    .and_then(|v| v.get(k))
                    .and_then(|v| v.parts.get(j))
                    .cloned();
                let decl = w::VarDecl {
                    name: b::ident(&name, d.name.span),
                    ty: Some(b::type_name(wty, d.ty.span)),
                    init,
                    span: d.span,
                };
                out.push((decl, name));
            }
        }
        out
    }

    /// `VAR syncident s;`: a sync point, met by name (`WaitSyncTask`): nothing to declare.
    fn syncident(&mut self, d: &r::DataDecl, data: &Data) {
        if data.len.is_some() || d.init.is_some() {
            self.unsupported(
                "an array or an initial value of a syncident",
                d.span,
                "declare `VAR syncident name;`",
            );
        }
    }

    /// The declaration's initial value(s), one per element, type-checked.
    fn initial_values(&mut self, d: &r::DataDecl, ty: Ty, dims: &[u32]) -> Option<Vec<Val>> {
        let init = d.init.as_ref()?;
        if dims.is_empty() {
            return self.value(init, ty).map(|v| vec![v]);
        }
        let mut out = Vec::new();
        self.array_values(&d.name.text, init, ty, dims, &mut out)?;
        Some(out)
    }

    /// The values of an array aggregate of dimensions `dims`, row after row: `[…]` of
    /// `dims[0]` values, each an aggregate of the next dimensions.
    pub(crate) fn array_values(
        &mut self,
        name: &str,
        e: &r::Expr,
        ty: Ty,
        dims: &[u32],
        out: &mut Vec<Val>,
    ) -> Option<()> {
        let Some((&n, rest)) = dims.split_first() else {
            out.push(self.value(e, ty)?);
            return Some(());
        };
        let r::ExprKind::Aggregate(items) = &e.kind else {
            self.error(
                Code::E0020,
                format!("an array of {n} needs `[…]` with {n} values"),
                e.span,
            );
            return None;
        };
        if items.len() != n as usize {
            self.error(
                Code::E0013,
                format!(
                    "`{name}` has {n} elements here but {} values are given",
                    items.len()
                ),
                e.span,
            );
            return None;
        }
        for item in items {
            self.array_values(name, item, ty, rest, out)?;
        }
        Some(())
    }

    /// For an array `a` at module level: `a{}` (get element `i`) per leaf, generated.
    fn array_accessors(&mut self, d: &Data) {
        let Some(n) = d.len else { return };
        for (j, (suffix, wty)) in self.leaves(d.ty).iter().enumerate() {
            let span = d.span;
            let fname = format!("{}{{}}{suffix}", d.base);
            let i = b::name("i", span);
            let mut branches = Vec::new();
            for k in 1..=n {
                let names = self.leaf_names(d, Some(k));
                let cond = b::bin(
                    w::BinOp::Eq,
                    i.clone(),
                    b::expr(w::ExprKind::Int(i64::from(k)), span),
                );
                let ret = w::Stmt {
                    kind: w::StmtKind::Return(Some(b::name(&names[j], span))),
                    span,
                };
                branches.push((cond, block(vec![ret], span)));
            }
            let fail = arrays::index_fail(&d.base, n, i.clone(), span);
            let body = vec![
                w::Stmt {
                    kind: w::StmtKind::If {
                        branches,
                        els: None,
                    },
                    span,
                },
                fail,
            ];
            self.items.push(w::Item::Proc(w::ProcDecl {
                is_func: true,
                name: b::ident(&fname, span),
                params: vec![w::Param {
                    name: b::ident("i", span),
                    ty: b::ident("int", span),
                }],
                ret: Some(b::type_name(*wty, span)),
                body: block(body, span),
                handler: None,
                span,
            }));
        }
    }

    fn routine(&mut self, rt: &r::Routine) {
        let Some(Sym::Routine(sig)) = self.declared(rt.local, &rt.name.key()).cloned() else {
            return; // A duplicate, reported.
        };
        if sig.span != rt.name.span {
            return;
        }
        if let Some(h) = rt.other_handler {
            self.unsupported(
                "a `BACKWARD` or `UNDO` handler",
                h,
                "remove the handler: vworks does not run programs backward or undo them",
            );
        }
        self.locals = vec![BTreeMap::new()];
        self.used.clear();
        self.temps = 0;
        self.routine = Some(RoutineCx {
            kind: rt.kind,
            ret: sig.ret,
            has_handler: rt.handler.is_some(),
            in_handler: false,
            labels: None,
            loops: 0,
        });
        let mut params = Vec::new();
        let (mut required, mut optional) = (sig.params.iter(), sig.optional.iter());
        let mut params_seen = 0;
        for p in &rt.params {
            let ty = if p.optional {
                optional.next().map(|o| &o.ty)
            } else {
                required.next()
            };
            let Some(ty) = ty else { continue };
            // By reference: a module variable the caller copies its argument into and
            // back out of (see `refs.rs`).
            let shadow = if p.optional {
                None
            } else {
                sig.by_ref.get(params_seen).cloned().flatten()
            };
            if !p.optional {
                params_seen += 1;
            }
            if p.mode == r::Mode::Ref && p.optional {
                self.unsupported(
                    &format!(
                        "the optional `VAR`/`PERS`/`INOUT` parameter `{}` (by reference)",
                        p.name.text
                    ),
                    p.span,
                    "make it required, or pass the value",
                );
            }
            if p.array {
                self.unsupported(
                    &format!("the array parameter `{}`", p.name.text),
                    p.span,
                    "use the module-level array directly",
                );
            }
            if self.leaves(*ty).is_empty() && !matches!(*ty, Ty::Load | Ty::Switch) {
                self.unsupported(
                    &format!("a parameter of type `{}`", ty.name()),
                    p.span,
                    "pass numbers, bools, positions, joint targets, speeds, zones, tools or work objects",
                );
            }
            if let Some(base) = shadow {
                self.shadow_param(p, *ty, base);
                continue;
            }
            let data = Data {
                ty: *ty,
                len: None,
                dims: Vec::new(),
                storage: Storage::Var,
                base: self.fresh_local(&wsl_name(&p.name)),
                span: p.name.span,
                text: None,
                inline: None,
                local: true,
                readonly: false,
                tasks: Vec::new(),
                optional: p.optional,
            };
            for (name, (_, wty)) in self.leaf_names(&data, None).iter().zip(self.leaves(*ty)) {
                params.push(w::Param {
                    name: b::ident(name, p.name.span),
                    ty: b::type_name(wty, p.ty.span),
                });
            }
            if p.optional {
                params.push(w::Param {
                    name: b::ident(&data.present(), p.name.span),
                    ty: b::ident("bool", p.name.span),
                });
            }
            self.spelled
                .entry(p.name.key())
                .or_insert_with(|| p.name.text.clone());
            if let Some(s) = self.locals.last_mut() {
                s.insert(p.name.key(), data);
            }
        }
        let mut body = Vec::new();
        for d in &rt.locals {
            self.local_data(d, &mut body);
        }
        body.extend(self.routine_body(&rt.body));
        let handler = rt.handler.as_ref().map(|(at, stmts)| {
            if let Some(cx) = self.routine.as_mut() {
                cx.in_handler = true;
            }
            block(self.stmts(stmts), *at)
        });
        let ret = match (rt.kind, sig.ret) {
            (r::RoutineKind::Func, Some(t)) => match self.leaves(t).as_slice() {
                [(_, wty)] => Some(b::type_name(
                    *wty,
                    rt.ret.as_ref().map_or(rt.span, |n| n.span),
                )),
                _ => {
                    self.unsupported(
                        &format!("a FUNC returning `{}`", t.name()),
                        rt.span,
                        "return a num, bool, pos, orient, pose, robtarget or jointtarget",
                    );
                    None
                }
            },
            _ => None,
        };
        let is_func = rt.kind == r::RoutineKind::Func;
        self.items.push(w::Item::Proc(w::ProcDecl {
            is_func: is_func && ret.is_some(),
            name: b::ident(&sig.wsl, rt.name.span),
            params,
            ret,
            body: block(body, rt.span),
            handler,
            span: rt.span,
        }));
        self.locals.clear();
        self.routine = None;
    }

    /// A routine's local data: WSL `var` statements at the top of its body.
    pub(crate) fn local_data(&mut self, d: &r::DataDecl, out: &mut Vec<w::Stmt>) {
        let Some(ty) = self.type_of(&d.ty) else {
            return;
        };
        let Ok(dims) = self.dims(d) else { return };
        let len = (!dims.is_empty()).then(|| dims.iter().product::<u32>());
        if self
            .locals
            .last()
            .is_some_and(|s| s.contains_key(&d.name.key()))
        {
            self.error(
                Code::E0012,
                format!("`{}` is declared twice in this routine", d.name.text),
                d.name.span,
            );
            return;
        }
        let mut data = Data {
            ty,
            len,
            dims: dims.clone(),
            storage: d.storage,
            base: self.fresh_local(&wsl_name(&d.name)),
            span: d.name.span,
            text: None,
            inline: None,
            local: true,
            readonly: d.storage == Storage::Const,
            tasks: Vec::new(),
            optional: false,
        };
        if d.storage == Storage::Pers {
            self.unsupported(
                "`PERS` data inside a routine",
                d.span,
                "declare PERS data at module level",
            );
        }
        let inits = self.initial_values(d, ty, &dims);
        if ty == Ty::Str && d.storage == Storage::Const && len.is_none() {
            data.text = inits
                .as_ref()
                .and_then(|v| v.first())
                .and_then(|v| v.text.clone());
        }
        for (decl, name) in self.leaf_decls(d, &data, inits.as_deref()) {
            self.used.insert(name);
            out.push(w::Stmt {
                kind: w::StmtKind::Var(decl),
                span: d.span,
            });
        }
        self.spelled
            .entry(d.name.key())
            .or_insert_with(|| d.name.text.clone());
        if let Some(s) = self.locals.last_mut() {
            s.insert(d.name.key(), data);
        }
    }
}

/// A WSL block.
pub(crate) fn block(stmts: Vec<w::Stmt>, span: Span) -> w::Block {
    w::Block { stmts, span }
}

/// RAPID's predefined data: speeds, zones, `tool0`, `wobj0`, `load0`.
/// RAPID's `pi`: the system module BASE declares `CONST num pi := 3.1415926;`, seven
/// decimals, not the f64 nearest π (programs that print or compare it see these).
#[allow(clippy::approx_constant)]
const RAPID_PI: f64 = 3.1415926;

fn predefined(key: &str) -> Option<Data> {
    let span = Span::default();
    let mut d = Data {
        ty: Ty::Num,
        len: None,
        dims: Vec::new(),
        storage: Storage::Const,
        base: key.to_string(),
        span,
        text: None,
        inline: None,
        local: false,
        readonly: true,
        tasks: Vec::new(),
        optional: false,
    };
    if let Some((_, v, o)) = data::SPEEDS.iter().find(|(n, _, _)| *n == key) {
        d.ty = Ty::Speed;
        d.inline = Some(vec![
            b::quantity(v * 0.001, vworks_vm::Dim::SPEED, span),
            b::quantity(o.to_radians(), vworks_vm::Dim::ANGSPEED, span),
        ]);
        return Some(d);
    }
    if let Some((_, z, zo, a)) = data::ZONES.iter().find(|(n, ..)| *n == key) {
        d.ty = Ty::Zone;
        d.inline = Some(vec![
            b::quantity(z * 0.001, vworks_vm::Dim::LENGTH, span),
            b::quantity(zo * 0.001, vworks_vm::Dim::LENGTH, span),
            b::quantity(a.to_radians(), vworks_vm::Dim::ANGLE, span),
        ]);
        return Some(d);
    }
    match key {
        "tool0" => {
            d.ty = Ty::Tool;
            d.inline = Some(vec![b::identity(span)]);
        }
        "wobj0" => {
            d.ty = Ty::Wobj;
            d.inline = Some(vec![b::identity(span), b::identity(span)]);
        }
        "load0" => {
            d.ty = Ty::Load;
            d.inline = Some(Vec::new());
        }
        // The predefined nums: pi as RAPID defines it (to 7 decimals), a digital
        // signal's levels, and the longest wait.
        "pi" => d.inline = Some(vec![b::num(RAPID_PI, span)]),
        "high" => d.inline = Some(vec![b::num(1.0, span)]),
        "low" => d.inline = Some(vec![b::num(0.0, span)]),
        "wait_max" => d.inline = Some(vec![b::num(8_388_608.0, span)]),
        // The most recent error's number (in an error handler: the one it handles).
        "errno" => {
            d.inline = Some(vec![b::call(
                "num",
                vec![b::call("errno'", Vec::new(), span)],
                span,
            )]);
        }
        k if data::ERRORS.iter().any(|(n, _)| n.eq_ignore_ascii_case(k)) => {
            let (_, n) = data::ERRORS
                .iter()
                .find(|(n, _)| n.eq_ignore_ascii_case(k))
                .copied()
                .unwrap_or(("", 0));
            d.inline = Some(vec![b::num(f64::from(n), span)]);
        }
        _ => return None,
    }
    Some(d)
}

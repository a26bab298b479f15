//! RAPID's I/O and interrupts, on the engine's globals and `when` handlers.
//!
//! A signal is a level held in one of the cell's globals (an int): `SetDO`, `Set`, `Reset`,
//! `SetGO` and `PulseDO` are `set` events, `WaitDI`/`WaitDO`/`WaitGI`/`WaitGO` are waits on
//! it (released when the signal changes, as on a controller), `DInput`/`DOutput`/`GInput`/
//! `GOutput` and a signal's bare name read it. Which global a signal is comes from the
//! workcell's `[[io]]` (see [`super::super::IoSignal`]).
//!
//! Interrupts: `CONNECT i WITH trap` binds the interrupt variable `i` to the TRAP for the
//! whole task (found before any routine is translated, so the order of the routines does
//! not matter). `ISignalDI`/`ISignalDO`/`ISignalGI`/`ISignalGO` enable a condition handler
//! on the signal reaching the value (a false→true edge, as the controller's interrupt on a
//! change), `ITimer` a periodic or single timer, `IDelete`/`ISleep` disable the trap, and
//! `IWatch` orders it again as the task's one order of it does.

use vworks_vm::Dim;

use super::data::{Ty, build as b};
use super::table::Call;
use super::{Sig, Sym, Tr, Val, block};
use crate::diag::{Code, Diagnostic};
use crate::rapid::SignalKind;
use crate::rapid::syntax::{self as r, Arg};
use crate::syntax::{self as w, Span};

/// The I/O instructions whose first argument (not an option) is a signal's name.
const SIGNAL_INSTRUCTIONS: &[&str] = &[
    "setdo",
    "set",
    "reset",
    "pulsedo",
    "setgo",
    "waitdi",
    "waitdo",
    "waitgi",
    "waitgo",
    "isignaldi",
    "isignaldo",
    "isignalgi",
    "isignalgo",
];

impl Tr<'_> {
    /// Finds every `CONNECT` of the task (with the module it stands in, whose names it
    /// sees), and every order of an interrupt (`ISignalDI …`, `ITimer …`), so that
    /// `IDelete` knows which handlers it disables and `IWatch` how to order it again,
    /// wherever they stand; and the names its I/O instructions give as signals.
    pub(crate) fn collect_connects(&mut self, modules: &[r::RapidModule]) {
        type Found = (
            Vec<(r::Name, r::Name, Span, usize)>,
            Vec<(String, r::Name, Vec<Arg>)>,
            Vec<String>,
            Vec<String>,
        );
        let mut found: Found = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        fn walk(ss: &[r::Stmt], module: usize, found: &mut Found) {
            for s in ss {
                match &s.kind {
                    r::StmtKind::Connect { intno, trap } => {
                        if let r::ExprKind::Name(n) = &intno.kind {
                            found.0.push((n.clone(), trap.clone(), s.span, module));
                        }
                    }
                    r::StmtKind::Call { name, args } => {
                        let k = name.key();
                        // (The signal an I/O instruction names: its first argument that is
                        // not an option.)
                        if SIGNAL_INSTRUCTIONS.contains(&k.as_str())
                            && let Some(Arg::Pos(r::Expr {
                                kind: r::ExprKind::Name(n),
                                ..
                            })) = args.iter().find(|a| matches!(a, Arg::Pos(_)))
                        {
                            found.3.push(n.key());
                        }
                        // (An errnum BookErrNo books: its number is its rank among them.)
                        if k == "bookerrno"
                            && let Some(Arg::Pos(r::Expr {
                                kind: r::ExprKind::Name(n),
                                ..
                            })) = args.first()
                        {
                            found.3.push(format!("bookerrno:{}", n.key()));
                        }
                        if k == "gripload"
                            && let Some(Arg::Pos(r::Expr {
                                kind: r::ExprKind::Name(n),
                                ..
                            })) = args.first()
                            && n.key() != "load0"
                        {
                            found.2.push(n.key());
                        }
                        if k.starts_with("isignal") || k == "itimer" {
                            let last = args.iter().rev().find_map(|a| match a {
                                Arg::Pos(e) => Some(e),
                                Arg::Opt(..) | Arg::Cond(..) => None,
                            });
                            if let Some(r::Expr {
                                kind: r::ExprKind::Name(n),
                                ..
                            }) = last
                            {
                                found.1.push((n.key(), name.clone(), args.clone()));
                            }
                        }
                    }
                    r::StmtKind::If { branches, els } => {
                        for (_, body) in branches {
                            walk(body, module, found);
                        }
                        if let Some(e) = els {
                            walk(e, module, found);
                        }
                    }
                    r::StmtKind::While { body, .. } | r::StmtKind::For { body, .. } => {
                        walk(body, module, found)
                    }
                    r::StmtKind::Test { cases, default, .. } => {
                        for (_, body) in cases {
                            walk(body, module, found);
                        }
                        if let Some(d) = default {
                            walk(d, module, found);
                        }
                    }
                    _ => {}
                }
            }
        }
        for (mi, m) in modules.iter().enumerate() {
            for it in &m.items {
                if let r::Item::Routine(rt) = it {
                    walk(&rt.body, mi, &mut found);
                    if let Some((_, h)) = &rt.handler {
                        walk(h, mi, &mut found);
                    }
                }
            }
        }
        let (connects, orders, mut parts, mut signals) = found;
        parts.sort();
        parts.dedup();
        self.grip_parts = parts;
        signals.sort();
        signals.dedup();
        let (booked, signals): (Vec<String>, Vec<String>) = signals
            .into_iter()
            .partition(|s| s.starts_with("bookerrno:"));
        self.helpers.extend(booked);
        self.named_signals = signals;
        for (intno, trap, span, mi) in connects {
            self.module = mi;
            let sig = match self.lookup(&trap.key()) {
                Some(Sym::Routine(s)) if s.kind == r::RoutineKind::Trap => s.clone(),
                Some(_) => {
                    self.error(
                        Code::E0020,
                        format!("`{}` is not a TRAP routine", trap.text),
                        trap.span,
                    );
                    continue;
                }
                None => {
                    self.error(
                        Code::E0011,
                        format!("unknown TRAP `{}`", trap.text),
                        trap.span,
                    )
                    .help = Some("declare it: `TRAP name … ENDTRAP`".into());
                    continue;
                }
            };
            match self.connects.get(&intno.key()) {
                Some(prev) if prev.wsl != sig.wsl => {
                    let d = Diagnostic::error(
                        Code::E0300,
                        format!(
                            "`{}` is connected to a second TRAP; vworks binds an interrupt to one TRAP for the whole task",
                            intno.text
                        ),
                        span,
                    )
                    .with_help("use one interrupt variable per TRAP");
                    self.diags.push(d);
                }
                _ => {
                    self.connects.insert(intno.key(), sig);
                }
            }
        }
        for (intno, instr, args) in orders {
            let single = args
                .iter()
                .any(|a| matches!(a, Arg::Opt(..) | Arg::Cond(..)));
            self.orders
                .entry(intno.clone())
                .or_default()
                .push((instr, args));
            if let Some(sig) = self.connects.get(&intno) {
                let handler = if single {
                    format!("_{}_single", sig.wsl)
                } else {
                    sig.wsl.clone()
                };
                self.ordered.insert(handler);
            }
        }
    }

    /// The used signals as the cell's globals.
    pub(crate) fn declare_signals(&mut self) {
        let span = Span::default();
        for (g, init) in std::mem::take(&mut self.signals) {
            self.items.push(w::Item::Global(w::VarDecl {
                name: b::ident(&g, span),
                ty: Some(b::ident("int", span)),
                init: Some(b::expr(w::ExprKind::Int(init), span)),
                span,
            }));
        }
    }

    /// The global of signal `n`, which must be of one of `kinds`.
    pub(crate) fn signal(&mut self, n: &r::Name, kinds: &[SignalKind]) -> Option<String> {
        if let Some(Sym::Data(_) | Sym::Routine(_)) = self.lookup(&n.key()) {
            self.error(
                Code::E0020,
                format!("`{}` is data or a routine, not an I/O signal", n.text),
                n.span,
            );
            return None;
        }
        let kind_names = kinds
            .iter()
            .map(|k| k.name())
            .collect::<Vec<_>>()
            .join(" or ");
        let (global, init) = match &self.io {
            None => (n.key(), 0),
            Some(io) => {
                let Some(s) = io.iter().find(|s| s.name.eq_ignore_ascii_case(&n.text)) else {
                    let mut names: Vec<String> = io
                        .iter()
                        .map(|s| format!("{} ({})", s.name, s.kind.name()))
                        .collect();
                    names.sort();
                    let listed = if names.is_empty() {
                        "none".to_string()
                    } else {
                        names.join(", ")
                    };
                    let near = crate::suggest::nearest(&n.text, io.iter().map(|s| s.name.as_str()))
                        .map(|m| format!("did you mean `{m}`? "))
                        .unwrap_or_default();
                    self.error(
                        Code::E0302,
                        format!("`{}` is not an I/O signal of this robot", n.text),
                        n.span,
                    )
                    .help = Some(format!(
                        "{near}declare it in the workcell's [[io]] ({kind_names}); this robot's signals: {listed}"
                    ));
                    return None;
                };
                if !kinds.contains(&s.kind) {
                    self.error(
                        Code::E0020,
                        format!(
                            "`{}` is a {} signal; this needs {kind_names}",
                            n.text,
                            s.kind.name()
                        ),
                        n.span,
                    );
                    return None;
                }
                (s.global.clone(), s.init)
            }
        };
        self.signals.entry(global.clone()).or_insert(init);
        Some(global)
    }

    /// A signal's bare name read as a value (a num), within a workcell.
    pub(crate) fn signal_value(&mut self, n: &r::Name) -> Option<Val> {
        // (Without the workcell's I/O, a name the task's I/O instructions give as a
        // signal: `check` of a lone module reads `IF di1 = 1` as `WaitDI di1, 1` sees it.)
        match self.io.as_ref() {
            Some(io) => {
                io.iter().find(|s| s.name.eq_ignore_ascii_case(&n.text))?;
            }
            None => {
                self.named_signals.binary_search(&n.key()).ok()?;
            }
        }
        let all = [
            SignalKind::Di,
            SignalKind::Do,
            SignalKind::Gi,
            SignalKind::Go,
        ];
        let g = self.signal(n, &all)?;
        Some(Val::one(
            Ty::Num,
            b::call("num", vec![b::name(&g, n.span)], n.span),
        ))
    }

    /// The signal named by an argument.
    fn signal_arg(&mut self, e: &r::Expr, kinds: &[SignalKind]) -> Option<String> {
        match &e.kind {
            r::ExprKind::Name(n) => self.signal(n, kinds),
            _ => {
                self.error(Code::E0020, "expected an I/O signal's name", e.span);
                None
            }
        }
    }

    /// `DInput(s)`, `DOutput(s)`, `GInput(s)`, `GOutput(s)`, `TestDI(s)`: the signal's
    /// value.
    pub(crate) fn io_function(&mut self, c: &Call<'_>) -> Option<Val> {
        let kinds: &[SignalKind] = match c.key {
            "dinput" | "testdi" => &[SignalKind::Di],
            "doutput" => &[SignalKind::Do],
            "ginput" => &[SignalKind::Gi],
            _ => &[SignalKind::Go],
        };
        let (p, span) = (&c.pos, c.span);
        let g = self.signal_arg(p[0], kinds)?;
        let v = b::name(&g, p[0].span);
        if c.key == "testdi" {
            let one = b::expr(w::ExprKind::Int(1), span);
            return Some(Val::one(Ty::Bool, b::bin(w::BinOp::Eq, v, one)));
        }
        Some(Val::one(Ty::Num, b::call("num", vec![v], span)))
    }

    /// `Set s;`, `Reset s;` on a digital output.
    pub(crate) fn set_reset(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        if let Some(g) = self.signal_arg(c.pos[0], &[SignalKind::Do]) {
            let v = i64::from(c.key == "set");
            out.push(assign(&g, b::expr(w::ExprKind::Int(v), c.span), c.span));
        }
    }

    /// `SetDO s, v;`, `SetGO s, v;`.
    pub(crate) fn set_signal(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        let (p, span) = (&c.pos, c.span);
        let kinds: &[SignalKind] = if c.key == "setdo" {
            &[SignalKind::Do]
        } else {
            &[SignalKind::Go]
        };
        if let Some((_, n, _)) = c.opts.iter().find(|(k, _, _)| k == "sdelay") {
            self.unsupported(
                "`\\SDelay`",
                n.span,
                "wait with WaitTime before setting the signal",
            );
            return;
        }
        let Some(g) = self.signal_arg(p[0], kinds) else {
            return;
        };
        if let Some(v) = self.value(p[1], Ty::Num) {
            let v = b::call("int", vec![v.leaf()], p[1].span);
            out.push(assign(&g, v, span));
        }
    }

    /// `PulseDO [\High] [\PLength:=t] s;`
    pub(crate) fn pulse_do(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        let span = c.span;
        let Some(g) = self.signal_arg(c.pos[0], &[SignalKind::Do]) else {
            return;
        };
        let length = match self.opt_value(&c.opts, "plength", "seconds") {
            Err(()) => return,
            Ok(None) => b::quantity(0.2, Dim::TIME, span),
            Ok(Some(e)) => match self.value(e, Ty::Num) {
                Some(v) => b::with_unit(v.leaf(), Dim::TIME),
                None => return,
            },
        };
        // WSL's pulse: 1 now, 0 after PLength by the robot's I/O; the program goes on
        // at once, and the pulse ends even if the program ends first.
        out.push(w::Stmt {
            kind: w::StmtKind::Pulse {
                global: b::ident(&g, span),
                length,
            },
            span,
        });
    }

    /// `WaitDI s, v;`, `WaitDO`, `WaitGI`, `WaitGO`.
    pub(crate) fn wait_signal(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        if let Some(cond) = self.signal_is(c.key, c.pos[0], c.pos[1]) {
            self.timed_wait(&c.name.text, cond, &c.opts, false, c.span, out);
        }
    }

    /// `ISignalDI [\Single] s, v, i;` (and `DO`, `GI`, `GO`).
    pub(crate) fn interrupt_on_signal(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        let p = &c.pos;
        let Some(cond) = self.signal_is(c.key, p[0], p[1]) else {
            return;
        };
        let Some(trap) = self.connected(p[2]) else {
            return;
        };
        let single = !c.opts.is_empty();
        self.enable(w::TriggerExpr::Cond(cond), &trap, single, c.span, out);
    }

    /// `ITimer [\Single] t, i;`
    pub(crate) fn interrupt_timer(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        let p = &c.pos;
        let Some(t) = self.value(p[0], Ty::Num) else {
            return;
        };
        let Some(trap) = self.connected(p[1]) else {
            return;
        };
        let t = b::with_unit(t.leaf(), Dim::TIME);
        let trigger = if c.opts.is_empty() {
            w::TriggerExpr::Every(t)
        } else {
            w::TriggerExpr::After(t)
        };
        self.enable(trigger, &trap, false, c.span, out);
    }

    /// `IDelete i;`, `ISleep i;`
    pub(crate) fn interrupt_off(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        if let Some(trap) = self.connected(c.pos[0]) {
            self.disable_trap(&trap, c.span, out);
        }
    }

    /// `IWatch i;`
    pub(crate) fn interrupt_watch(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        if let Some(trap) = self.connected(c.pos[0])
            && let r::ExprKind::Name(n) = &c.pos[0].kind
        {
            self.watch(n, &trap, c.span, out);
        }
    }

    /// `GripLoad part;` grips the workcell part the loaddata is named after (`grip`);
    /// `GripLoad load0;` releases the part the robot holds. Which part that is, is kept in
    /// the module variable `_held` (0: none; k: the k-th part the task's GripLoads name).
    pub(crate) fn grip_load(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        let (p, span) = (&c.pos, c.span);
        let Some((n, _)) = self.data_arg(p[0], "a loaddata", |d| d.ty == Ty::Load) else {
            return;
        };
        if self.helpers.insert("_held".into()) {
            self.items.push(w::Item::Var(w::VarDecl {
                name: b::ident("_held", Span::default()),
                ty: Some(b::ident("int", Span::default())),
                init: Some(b::expr(w::ExprKind::Int(0), Span::default())),
                span: Span::default(),
            }));
        }
        let int = |k: i64| b::expr(w::ExprKind::Int(k), span);
        let held = || b::name("_held", span);
        let stmt = |kind| w::Stmt { kind, span };
        if n.key() == "load0" {
            let branches = self
                .grip_parts
                .iter()
                .enumerate()
                .map(|(k, part)| {
                    let cond = b::bin(w::BinOp::Eq, held(), int(k as i64 + 1));
                    let rel = stmt(w::StmtKind::Release(b::ident(part, span)));
                    (cond, block(vec![rel], span))
                })
                .collect::<Vec<_>>();
            if !branches.is_empty() {
                out.push(stmt(w::StmtKind::If {
                    branches,
                    els: None,
                }));
            }
            out.push(stmt(b::assign(held(), int(0))));
            return;
        }
        let k = self
            .grip_parts
            .iter()
            .position(|x| *x == n.key())
            .unwrap_or(0);
        out.push(stmt(w::StmtKind::Grip(b::ident(&n.key(), n.span))));
        out.push(stmt(b::assign(held(), int(k as i64 + 1))));
    }

    /// `signal == int(value)` for the wait or interrupt instruction `key`, whose last two
    /// letters are the signal's kind (`WaitDI`, `ISignalGO`).
    fn signal_is(&mut self, key: &str, signal: &r::Expr, value: &r::Expr) -> Option<w::Expr> {
        let kind = SignalKind::from_name(&key[key.len().saturating_sub(2)..])?;
        let g = self.signal_arg(signal, &[kind])?;
        let v = self.value(value, Ty::Num)?;
        Some(b::bin(
            w::BinOp::Eq,
            b::name(&g, signal.span),
            b::call("int", vec![v.leaf()], value.span),
        ))
    }

    /// The TRAP an interrupt variable is connected to.
    fn connected(&mut self, e: &r::Expr) -> Option<Sig> {
        let (n, _) = self.data_arg(e, "an interrupt variable (intnum)", |d| d.ty == Ty::Intnum)?;
        match self.connects.get(&n.key()) {
            Some(s) => Some(s.clone()),
            None => {
                self.error(
                    Code::E0303,
                    format!("the interrupt `{}` is not connected to a TRAP", n.text),
                    n.span,
                )
                .help = Some(format!(
                    "connect it first: `CONNECT {} WITH trap_name;`",
                    n.text
                ));
                None
            }
        }
    }

    /// `disable` of each handler an interrupt's TRAP is ordered with (itself, or its
    /// `\Single` wrapper).
    fn disable_trap(&mut self, trap: &Sig, span: Span, out: &mut Vec<w::Stmt>) {
        for name in [trap.wsl.clone(), format!("_{}_single", trap.wsl)] {
            if self.ordered.contains(&name) {
                out.push(w::Stmt {
                    kind: w::StmtKind::Disable(b::ident(&name, span)),
                    span,
                });
            }
        }
    }

    /// `IWatch i;`: the interrupt ordered again as the task's one order of it (its
    /// `ISignalDI …` or `ITimer …`, translated here), after a `disable`, so that waking
    /// an interrupt that is not asleep leaves one handler, not two.
    fn watch(&mut self, intno: &r::Name, trap: &Sig, span: Span, out: &mut Vec<w::Stmt>) {
        let orders = self.orders.get(&intno.key()).cloned().unwrap_or_default();
        match orders.as_slice() {
            [(instr, args)] => {
                self.disable_trap(trap, span, out);
                self.instruction(&instr.key(), instr, args, span, out);
            }
            [] => {
                self.error(
                    Code::E0303,
                    format!(
                        "`IWatch {}` wakes an interrupt that is never ordered",
                        intno.text
                    ),
                    intno.span,
                )
                .help = Some(format!(
                    "order it first, e.g. `ISignalDI diSignal, 1, {};` or `ITimer 1, {};`",
                    intno.text, intno.text
                ));
            }
            _ => self.unsupported(
                &format!("`IWatch` of `{}`, which is ordered in several places", intno.text),
                intno.span,
                "order each interrupt in one place (IWatch orders it again the same way), or delete it with IDelete and order it again",
            ),
        }
    }

    /// `when trigger do trap();` — with `single`, through a wrapper that disables itself
    /// before running the trap, so it fires once.
    fn enable(
        &mut self,
        trigger: w::TriggerExpr,
        trap: &Sig,
        single: bool,
        span: Span,
        out: &mut Vec<w::Stmt>,
    ) {
        let handler = if single {
            let name = format!("_{}_single", trap.wsl);
            if self.helpers.insert(name.clone()) {
                let body = vec![
                    w::Stmt {
                        kind: w::StmtKind::Disable(b::ident(&name, span)),
                        span,
                    },
                    w::Stmt {
                        kind: w::StmtKind::Call {
                            name: b::ident(&trap.wsl, span),
                            args: Vec::new(),
                        },
                        span,
                    },
                ];
                self.items.push(w::Item::Proc(w::ProcDecl {
                    is_func: false,
                    name: b::ident(&name, span),
                    params: Vec::new(),
                    ret: None,
                    body: block(body, span),
                    handler: None,
                    span,
                }));
            }
            name
        } else {
            trap.wsl.clone()
        };
        out.push(w::Stmt {
            kind: w::StmtKind::When {
                trigger,
                handler: b::ident(&handler, span),
                args: Vec::new(),
            },
            span,
        });
    }
}

/// `g = v;`
fn assign(g: &str, v: w::Expr, span: Span) -> w::Stmt {
    w::Stmt {
        kind: b::assign(b::name(g, span), v),
        span,
    }
}

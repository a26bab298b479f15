//! The parser: tokens to a [`SourceModule`], never panicking, reporting many errors per run.
//!
//! Recursive descent for statements, precedence climbing for expressions. On an error the
//! parser records one diagnostic, marks the node `Error`, and skips to the end of the
//! statement (`;` or the closing `}`, stepping over balanced braces) or, at module level,
//! to the next declaration keyword. Nesting deeper than [`MAX_DEPTH`] is an error, so
//! hostile input cannot overflow the stack.
//!
//! Precedence, loosest first: `or`/`||`; `and`/`&&`; `not`/`!`; comparisons; `+ -`;
//! `* / mod`; unary `-`; postfix call, `.field`, `[index]`.

use crate::diag::{Code, Diagnostic};
use crate::frontend::{Limits, PResult, Parser, Reported};
use crate::lexer::{Kw, Punct, TokKind, Token};
use crate::syntax::*;

/// How deeply blocks and expressions may nest.
pub const MAX_DEPTH: u32 = 128;

/// At most this many parse errors are reported per file.
const MAX_ERRORS: usize = 100;

/// Parses a token stream (from [`crate::lexer::lex`]).
pub fn parse(src: &str, toks: Vec<Token>, diags: &mut Vec<Diagnostic>) -> SourceModule {
    let limits = Limits {
        max_depth: MAX_DEPTH,
        max_errors: MAX_ERRORS,
    };
    Parser::new(src, toks, diags, limits).module()
}

fn describe(t: &TokKind, text: &str) -> String {
    match t {
        TokKind::Ident => format!("`{text}`"),
        TokKind::Kw(k) => format!("keyword `{}`", k.text()),
        TokKind::Int(_) | TokKind::Num(_) | TokKind::Quantity(..) => format!("number `{text}`"),
        TokKind::Str(_) => "a string".into(),
        TokKind::P(p) => format!("`{}`", p.text()),
        TokKind::Eof => "the end of the file".into(),
        TokKind::Error => format!("`{text}`"),
    }
}

/// The options a motion statement takes, by name.
const MOVE_OPTIONS: [&str; 6] = ["speed", "accel", "orient", "duration", "zone", "tool"];

impl Parser<'_, '_, Token> {
    fn kind(&self) -> &TokKind {
        &self.tok().kind
    }

    fn at_p(&self, p: Punct) -> bool {
        self.kind() == &TokKind::P(p)
    }

    fn at_kw(&self, k: Kw) -> bool {
        self.kind() == &TokKind::Kw(k)
    }

    fn at_ident(&self, word: &str) -> bool {
        self.kind() == &TokKind::Ident && self.text(self.span()) == word
    }

    fn eat_p(&mut self, p: Punct) -> bool {
        self.eat_if(|s| s.at_p(p))
    }

    fn eat_kw(&mut self, k: Kw) -> bool {
        self.eat_if(|s| s.at_kw(k))
    }

    /// E0005 for a motion option given a second time (token `t`).
    fn given_twice(&mut self, t: &Token) -> Reported {
        let d = Diagnostic::error(
            Code::E0005,
            format!("`{}` is given twice", self.text(t.span)),
            t.span,
        );
        self.report(d)
    }

    /// `zone Z ori D A` with an operator after D: D is one term.
    fn ori_term(&mut self, distance: Span) -> Reported {
        let t = self.tok().clone();
        let d = Diagnostic::error(
            Code::E0005,
            format!(
                "expected the orientation zone's angle or the next option, found `{}`",
                self.text(t.span)
            ),
            t.span,
        )
        .with_help(format!(
            "the distance after `ori` is one term: put it in parentheses, `ori ({} {} …)`",
            self.text(distance),
            self.text(t.span)
        ));
        self.report(d)
    }

    fn unexpected(&mut self, expected: &str) -> Reported {
        let t = self.tok().clone();
        let found = describe(&t.kind, self.text(t.span));
        let d = Diagnostic::error(
            Code::E0005,
            format!("expected {expected}, found {found}"),
            t.span,
        )
        .with_label(format!("expected {expected}"));
        self.report(d)
    }

    fn expect_p(&mut self, p: Punct, what: &str) -> PResult<Span> {
        if self.at_p(p) {
            return Ok(self.bump().span);
        }
        if p == Punct::Semi {
            // Point just after the previous token: that is where the `;` is missing.
            let at = self.after_prev();
            let t = self.tok().clone();
            let found = describe(&t.kind, self.text(t.span));
            let d = Diagnostic::error(
                Code::E0005,
                format!("expected `;` after {what}, found {found}"),
                at,
            )
            .with_label("add `;` here");
            return Err(self.report(d));
        }
        Err(self.unexpected(&format!("`{}` {what}", p.text())))
    }

    fn ident(&mut self, what: &str) -> PResult<Ident> {
        if self.kind() == &TokKind::Ident {
            let t = self.bump();
            return Ok(Ident {
                name: self.text(t.span).to_string(),
                span: t.span,
            });
        }
        if let TokKind::Kw(k) = self.kind().clone() {
            let t = self.tok().clone();
            let d = Diagnostic::error(
                Code::E0005,
                format!("expected {what}, found keyword `{}`", k.text()),
                t.span,
            )
            .with_label("this word is reserved")
            .with_help(format!("`{}` is a keyword; choose another name", k.text()));
            return Err(self.report(d));
        }
        Err(self.unexpected(what))
    }

    /// One level deeper; an error (and no level) past [`MAX_DEPTH`].
    fn enter(&mut self) -> PResult<()> {
        if !self.deeper() {
            let d = Diagnostic::error(
                Code::E0006,
                format!("nested more than {MAX_DEPTH} levels deep"),
                self.span(),
            )
            .with_note("each operator of a chain like `a + b + c` counts as one level")
            .with_help("split the expression or the blocks into procedures or variables: `var part = a + b; …`");
            return Err(self.report(d));
        }
        Ok(())
    }

    /// Skips to the end of the current statement: past `;`, or before `}` / the end.
    fn sync_stmt(&mut self) {
        let mut depth = 0u32;
        loop {
            match self.kind() {
                TokKind::Eof => return,
                TokKind::P(Punct::LBrace) => depth += 1,
                TokKind::P(Punct::RBrace) => {
                    if depth == 0 {
                        return;
                    }
                    depth -= 1;
                    if depth == 0 {
                        self.bump();
                        // A block ended: a statement like `if … { }` is over.
                        if !self.at_kw(Kw::Else) {
                            return;
                        }
                        continue;
                    }
                }
                TokKind::P(Punct::Semi) if depth == 0 => {
                    self.bump();
                    return;
                }
                _ => {}
            }
            self.bump();
        }
    }

    /// Skips to the next module-level declaration keyword.
    fn sync_item(&mut self) {
        let mut depth = 0u32;
        loop {
            match self.kind() {
                TokKind::Eof => return,
                TokKind::P(Punct::LBrace) => depth += 1,
                TokKind::P(Punct::RBrace) => depth = depth.saturating_sub(1),
                TokKind::Kw(Kw::Proc | Kw::Func | Kw::Global | Kw::Const | Kw::Var | Kw::Param)
                    if depth == 0 =>
                {
                    return;
                }
                _ => {}
            }
            self.bump();
        }
    }

    fn module(&mut self) -> SourceModule {
        let mut items = Vec::new();
        while self.kind() != &TokKind::Eof {
            let start = self.mark();
            match self.item() {
                Ok(i) => items.push(i),
                Err(Reported) => {
                    if self.mark() == start {
                        self.bump();
                    }
                    self.sync_item();
                }
            }
        }
        SourceModule {
            items,
            texts: false,
        }
    }

    fn item(&mut self) -> PResult<Item> {
        match self.kind() {
            TokKind::Kw(Kw::Global) => self.var_decl(Kw::Global).map(Item::Global),
            TokKind::Kw(Kw::Param) => self.var_decl(Kw::Param).map(Item::Param),
            TokKind::Kw(Kw::Const) => self.var_decl(Kw::Const).map(Item::Const),
            TokKind::Kw(Kw::Var) => self.var_decl(Kw::Var).map(Item::Var),
            TokKind::Kw(Kw::Proc | Kw::Func) => self.proc_decl().map(Item::Proc),
            _ => {
                let t = self.tok().clone();
                let found = describe(&t.kind, self.text(t.span));
                let mut d = Diagnostic::error(
                    Code::E0005,
                    format!(
                        "expected a declaration (global, const, param, var, proc or func), found {found}"
                    ),
                    t.span,
                );
                if matches!(t.kind, TokKind::Ident | TokKind::Kw(_)) {
                    d = d.with_help(
                        "statements belong inside a `proc`; the program starts at `proc main()`",
                    );
                }
                Err(self.report(d))
            }
        }
    }

    fn var_decl(&mut self, kw: Kw) -> PResult<VarDecl> {
        let start = self.bump().span;
        let name = self.ident(&format!("a name after `{}`", kw.text()))?;
        let ty = if self.eat_p(Punct::Colon) {
            Some(self.ident("a type name")?)
        } else {
            None
        };
        let init = if self.eat_p(Punct::Assign) {
            Some(self.expr()?)
        } else {
            None
        };
        if ty.is_none() && init.is_none() {
            let d = Diagnostic::error(
                Code::E0005,
                format!("`{}` needs a type or an initial value", name.name),
                name.span,
            )
            .with_help(format!(
                "write `{} {}: int;` or `{} {} = 0;`",
                kw.text(),
                name.name,
                kw.text(),
                name.name
            ));
            return Err(self.report(d));
        }
        self.expect_p(Punct::Semi, "the declaration")?;
        Ok(VarDecl {
            name,
            ty,
            init,
            span: start.to(self.prev_span()),
        })
    }

    fn proc_decl(&mut self) -> PResult<ProcDecl> {
        let kw = self.bump();
        let is_func = kw.kind == TokKind::Kw(Kw::Func);
        let name = self.ident("a procedure name")?;
        self.expect_p(Punct::LParen, "to open the parameter list")?;
        let mut params = Vec::new();
        while !self.at_p(Punct::RParen) {
            let pname = self.ident("a parameter name")?;
            if !self.at_p(Punct::Colon) {
                let d = Diagnostic::error(
                    Code::E0005,
                    format!("parameter `{}` needs a type", pname.name),
                    pname.span,
                )
                .with_help(format!("write `{}: length` (or int, num, bool, angle, time, speed, angspeed, joints, pose)", pname.name));
                return Err(self.report(d));
            }
            self.bump();
            let ty = self.ident("a type name")?;
            params.push(Param { name: pname, ty });
            if !self.eat_p(Punct::Comma) {
                break;
            }
        }
        self.expect_p(Punct::RParen, "to close the parameter list")?;
        let ret = if self.eat_p(Punct::Arrow) {
            Some(self.ident("a return type")?)
        } else {
            None
        };
        let span = kw.span.to(self.prev_span());
        let body = self.block()?;
        Ok(ProcDecl {
            is_func,
            name,
            params,
            ret,
            body,
            handler: None,
            span,
        })
    }

    fn block(&mut self) -> PResult<Block> {
        let open = self.expect_p(Punct::LBrace, "to open a block")?;
        self.enter()?;
        let mut stmts = Vec::new();
        loop {
            if self.at_p(Punct::RBrace) {
                break;
            }
            if self.kind() == &TokKind::Eof {
                let d = Diagnostic::error(Code::E0005, "this block is never closed", open)
                    .with_label("opened here")
                    .with_help("add the missing `}`");
                self.leave();
                return Err(self.report(d));
            }
            let start = self.mark();
            let sspan = self.span();
            match self.stmt() {
                Ok(s) => stmts.push(s),
                Err(Reported) => {
                    if self.mark() == start {
                        self.bump();
                    }
                    self.sync_stmt();
                    stmts.push(Stmt {
                        kind: StmtKind::Error,
                        span: sspan.to(self.prev_span()),
                    });
                }
            }
        }
        self.leave();
        let close = self.bump().span;
        Ok(Block {
            stmts,
            span: open.to(close),
        })
    }

    fn stmt(&mut self) -> PResult<Stmt> {
        let start = self.span();
        let kind = self.stmt_kind()?;
        Ok(Stmt {
            kind,
            span: start.to(self.prev_span()),
        })
    }

    fn end(&mut self, what: &str) -> PResult<()> {
        self.expect_p(Punct::Semi, what).map(|_| ())
    }

    fn stmt_kind(&mut self) -> PResult<StmtKind> {
        let TokKind::Kw(kw) = self.kind().clone() else {
            if self.at_p(Punct::LBrace) {
                return Ok(StmtKind::Block(self.block()?));
            }
            return self.expr_stmt();
        };
        match kw {
            Kw::Var => Ok(StmtKind::Var(self.var_decl(Kw::Var)?)),
            Kw::Const | Kw::Global | Kw::Param | Kw::Proc | Kw::Func => {
                let d = Diagnostic::error(
                    Code::E0005,
                    format!(
                        "`{}` declarations belong at module level, not inside a procedure",
                        kw.text()
                    ),
                    self.span(),
                )
                .with_help(if matches!(kw, Kw::Const) {
                    "move it above the procedure, or use `var` for a local"
                } else {
                    "move it out of the procedure"
                });
                Err(self.report(d))
            }
            Kw::If => self.if_stmt(),
            Kw::While => {
                self.bump();
                let cond = self.expr()?;
                let body = self.block()?;
                Ok(StmtKind::While { cond, body })
            }
            Kw::For => {
                self.bump();
                let var = self.ident("a loop variable")?;
                if !self.eat_kw(Kw::In) {
                    return Err(self.unexpected("`in`"));
                }
                let start = self.expr()?;
                self.expect_p(Punct::DotDot, "between the range's ends (`a..b`)")?;
                let end = self.expr()?;
                let body = self.block()?;
                Ok(StmtKind::For {
                    var,
                    start,
                    end,
                    body,
                })
            }
            Kw::Break => {
                self.bump();
                self.end("`break`")?;
                Ok(StmtKind::Break)
            }
            Kw::Continue => {
                self.bump();
                self.end("`continue`")?;
                Ok(StmtKind::Continue)
            }
            Kw::Return => {
                self.bump();
                let value = if self.at_p(Punct::Semi) {
                    None
                } else {
                    Some(self.expr()?)
                };
                self.end("`return`")?;
                Ok(StmtKind::Return(value))
            }
            Kw::MoveJ | Kw::MoveL | Kw::MoveC => self.move_stmt(kw),
            Kw::Delay => {
                self.bump();
                let e = self.expr()?;
                self.end("the delay")?;
                Ok(StmtKind::Delay(e))
            }
            Kw::WaitUntil => {
                self.bump();
                let cond = self.expr()?;
                let poll = if self.at_ident("poll") {
                    self.bump();
                    Some(self.expr()?)
                } else {
                    None
                };
                let timeout = self.timeout()?;
                self.end("the wait")?;
                Ok(StmtKind::WaitUntil {
                    cond,
                    timeout,
                    poll,
                })
            }
            Kw::WaitSignal => {
                self.bump();
                let name = self.ident("a signal name")?;
                let timeout = self.timeout()?;
                self.end("the wait")?;
                Ok(StmtKind::WaitSignal { name, timeout })
            }
            Kw::Signal => {
                self.bump();
                let robot = self.ident("a robot name (`signal r2.ready;`)")?;
                self.expect_p(Punct::Dot, "between robot and signal (`signal r2.ready;`)")?;
                let name = self.ident("a signal name")?;
                self.end("the signal")?;
                Ok(StmtKind::Signal { robot, name })
            }
            Kw::Remote => {
                self.bump();
                let robot = self.ident("a robot name (`remote r2.weld(1);`)")?;
                self.expect_p(
                    Punct::Dot,
                    "between robot and procedure (`remote r2.weld(1);`)",
                )?;
                let proc = self.ident("a procedure name")?;
                let args = self.args()?;
                self.end("the remote call")?;
                Ok(StmtKind::Remote { robot, proc, args })
            }
            Kw::Parallel => {
                self.bump();
                let b = self.block()?;
                Ok(StmtKind::Parallel(b.stmts))
            }
            Kw::When => self.when_stmt(),
            Kw::Disable => {
                self.bump();
                let name = self.ident("the handler's procedure name")?;
                self.end("`disable`")?;
                Ok(StmtKind::Disable(name))
            }
            Kw::Grip | Kw::Release => {
                self.bump();
                let part = self.ident("a part name")?;
                self.end(&format!("`{}`", kw.text()))?;
                Ok(if kw == Kw::Grip {
                    StmtKind::Grip(part)
                } else {
                    StmtKind::Release(part)
                })
            }
            Kw::Log | Kw::Fail => {
                self.bump();
                let mut args = vec![self.expr()?];
                while self.eat_p(Punct::Comma) {
                    args.push(self.expr()?);
                }
                self.end(&format!("`{}`", kw.text()))?;
                Ok(if kw == Kw::Log {
                    StmtKind::Log(args)
                } else {
                    StmtKind::Fail(args)
                })
            }
            Kw::Stop => {
                self.bump();
                self.end("`stop`")?;
                Ok(StmtKind::Stop)
            }
            Kw::Else => {
                let d = Diagnostic::error(Code::E0005, "`else` without an `if`", self.span())
                    .with_help("an `else` must follow the `}` of an `if` block");
                Err(self.report(d))
            }
            _ => self.expr_stmt(),
        }
    }

    fn timeout(&mut self) -> PResult<Option<Expr>> {
        if self.at_ident("timeout") {
            self.bump();
            Ok(Some(self.expr()?))
        } else {
            Ok(None)
        }
    }

    /// `if`, every `else if` of its chain (a loop: a chain is not nesting), `else`.
    fn if_stmt(&mut self) -> PResult<StmtKind> {
        self.bump();
        let mut branches = Vec::new();
        let cond = self.expr()?;
        let then = self.block()?;
        branches.push((cond, then));
        let mut els = None;
        while self.eat_kw(Kw::Else) {
            if self.eat_kw(Kw::If) {
                let cond = self.expr()?;
                let then = self.block()?;
                branches.push((cond, then));
            } else {
                els = Some(self.block()?);
                break;
            }
        }
        Ok(StmtKind::If { branches, els })
    }

    fn move_stmt(&mut self, kw: Kw) -> PResult<StmtKind> {
        self.bump();
        let kind = match kw {
            Kw::MoveJ => MoveKind::J,
            Kw::MoveL => MoveKind::L,
            _ => MoveKind::C,
        };
        let first = self.expr()?;
        let (via, target) = if kind == MoveKind::C {
            self.expect_p(
                Punct::Comma,
                "between the via point and the target (`move_c via, target`)",
            )?;
            (Some(first), self.expr()?)
        } else {
            (None, first)
        };
        let mut speed = None;
        let mut accel = None;
        let mut zone = None;
        let mut tool = None;
        let mut orient = None;
        let mut duration = None;
        loop {
            if self.at_ident("zone") {
                let t = self.bump();
                let z = if self.at_ident("fine") {
                    self.bump();
                    Zone::Fine
                } else {
                    let radius = self.expr()?;
                    if self.at_ident("ori") {
                        self.bump();
                        // One term (a literal, a name, a call, or parentheses), so that
                        // `ori 15mm -2deg` is a distance and an angle, not a difference.
                        self.enter()?;
                        let ori = self.unary_expr();
                        self.leave();
                        let ori = ori?;
                        let operator = [Punct::Plus, Punct::Star, Punct::Slash]
                            .iter()
                            .any(|p| self.at_p(*p));
                        if operator || self.at_kw(Kw::Mod) {
                            return Err(self.ori_term(ori.span));
                        }
                        // (An angle follows unless the statement or its next option does.)
                        let option = matches!(self.kind(), TokKind::Ident)
                            && MOVE_OPTIONS.iter().any(|o| self.at_ident(o));
                        let angle = if self.at_p(Punct::Semi) || option {
                            None
                        } else {
                            Some(self.expr()?)
                        };
                        Zone::Extended(Box::new(ExtendedZone { radius, ori, angle }))
                    } else {
                        Zone::Radius(radius)
                    }
                };
                if zone.is_some() {
                    return Err(self.given_twice(&t));
                }
                zone = Some(z);
                continue;
            }
            let which = if self.at_ident("speed") {
                &mut speed
            } else if self.at_ident("accel") {
                &mut accel
            } else if self.at_ident("tool") {
                &mut tool
            } else if self.at_ident("orient") {
                &mut orient
            } else if self.at_ident("duration") {
                &mut duration
            } else {
                break;
            };
            let t = self.bump();
            let e = self.expr()?;
            if which.is_some() {
                return Err(self.given_twice(&t));
            }
            *which = Some(e);
        }
        if !self.at_p(Punct::Semi) && matches!(self.kind(), TokKind::Ident) {
            let t = self.tok().clone();
            let d = Diagnostic::error(
                Code::E0005,
                format!("unknown motion option `{}`", self.text(t.span)),
                t.span,
            )
            .with_help("the options are `speed`, `accel`, `orient`, `duration`, `zone` and `tool`");
            return Err(self.report(d));
        }
        self.end(&format!("`{}`", kind.keyword()))?;
        Ok(StmtKind::Move {
            kind,
            via,
            target,
            speed,
            accel,
            orient,
            zone,
            tool,
            duration,
        })
    }

    fn when_stmt(&mut self) -> PResult<StmtKind> {
        self.bump();
        let trigger = if self.eat_kw(Kw::Every) {
            let e = self.expr()?;
            if self.at_ident("cycles") || self.at_ident("cycle") {
                self.bump();
                TriggerExpr::EveryCycles(e)
            } else {
                TriggerExpr::Every(e)
            }
        } else if self.eat_kw(Kw::After) {
            TriggerExpr::After(self.expr()?)
        } else {
            TriggerExpr::Cond(self.expr()?)
        };
        if !self.eat_kw(Kw::Do) {
            return Err(self.unexpected("`do` and the handler call (`when … do handler();`)"));
        }
        let handler = self.ident("the handler procedure")?;
        let args = self.args()?;
        self.end("the `when` statement")?;
        Ok(StmtKind::When {
            trigger,
            handler,
            args,
        })
    }

    fn args(&mut self) -> PResult<Vec<Expr>> {
        self.expect_p(Punct::LParen, "to open the argument list")?;
        let mut args = Vec::new();
        while !self.at_p(Punct::RParen) {
            args.push(self.expr()?);
            if !self.eat_p(Punct::Comma) {
                break;
            }
        }
        self.expect_p(Punct::RParen, "to close the argument list")?;
        Ok(args)
    }

    fn expr_stmt(&mut self) -> PResult<StmtKind> {
        // `pulse g for t;` — `pulse` is special only there, so it stays usable as a name.
        let kind_at = |k: usize| &self.peek(k).kind;
        if self.at_ident("pulse")
            && kind_at(1) == &TokKind::Ident
            && kind_at(2) == &TokKind::Kw(Kw::For)
        {
            self.bump();
            let name = self.bump();
            let global = Ident {
                name: self.text(name.span).to_string(),
                span: name.span,
            };
            self.bump();
            let length = self.expr()?;
            self.end("the pulse")?;
            return Ok(StmtKind::Pulse { global, length });
        }
        // `sync s with r1, r2 [timeout t];` — `sync` and `with` are special only there.
        if self.at_ident("sync")
            && kind_at(1) == &TokKind::Ident
            && kind_at(2) == &TokKind::Ident
            && self.text(self.peek(2).span) == "with"
        {
            self.bump();
            let name = self.ident("a sync point's name")?;
            self.bump();
            let mut tasks = vec![self.ident("a task (`sync s with r1, r2;`)")?];
            while self.eat_p(Punct::Comma) {
                tasks.push(self.ident("a task (`sync s with r1, r2;`)")?);
            }
            let timeout = self.timeout()?;
            self.end("the sync")?;
            return Ok(StmtKind::Sync {
                name,
                tasks,
                timeout,
            });
        }
        let target = self.expr()?;
        let op = match self.kind() {
            TokKind::P(Punct::Assign) => Some(None),
            TokKind::P(Punct::PlusAssign) => Some(Some(BinOp::Add)),
            TokKind::P(Punct::MinusAssign) => Some(Some(BinOp::Sub)),
            TokKind::P(Punct::StarAssign) => Some(Some(BinOp::Mul)),
            TokKind::P(Punct::SlashAssign) => Some(Some(BinOp::Div)),
            _ => None,
        };
        if self.at_p(Punct::Colon) {
            let d = Diagnostic::error(Code::E0005, "WSL assigns with `=`", self.span())
                .with_label("`:=` is RAPID's assignment")
                .with_help("write `x = value;`");
            return Err(self.report(d));
        }
        if let Some(op) = op {
            self.bump();
            let value = self.expr()?;
            self.end("the assignment")?;
            return Ok(StmtKind::Assign { target, op, value });
        }
        if let ExprKind::Call(name, args) = target.kind {
            self.end("the call")?;
            return Ok(StmtKind::Call { name, args });
        }
        if matches!(target.kind, ExprKind::Error) {
            return Err(Reported);
        }
        if self.at_p(Punct::EqEq)
            || self.at_p(Punct::Semi)
            || matches!(target.kind, ExprKind::Binary(BinOp::Eq, ..))
        {
            let d = Diagnostic::error(
                Code::E0005,
                "this expression does nothing on its own",
                target.span,
            )
            .with_help("to assign, write `x = value;`; to call, write `name(args);`");
            return Err(self.report(d));
        }
        Err(self.unexpected("`=` or `;`"))
    }

    // ---- expressions -------------------------------------------------------------------

    /// Parses an expression.
    fn expr(&mut self) -> PResult<Expr> {
        self.enter()?;
        let e = self.or_expr();
        self.leave();
        e
    }

    fn binary(
        &mut self,
        next: fn(&mut Self) -> PResult<Expr>,
        ops: &[(TokKind, BinOp)],
    ) -> PResult<Expr> {
        let mut l = next(self)?;
        // `a + b + c …` is a left-deep tree, one level per operator: the chain counts
        // towards the nesting limit, so that what the compiler walks recursively later
        // (and drops) stays shallow.
        let mut chain = 0;
        let out = loop {
            let Some(op) = ops.iter().find(|(t, _)| t == self.kind()).map(|(_, o)| *o) else {
                break Ok(l);
            };
            self.bump();
            if let Err(e) = self.enter() {
                break Err(e);
            }
            chain += 1;
            let r = match next(self) {
                Ok(r) => r,
                Err(e) => break Err(e),
            };
            let span = l.span.to(r.span);
            l = Expr {
                kind: ExprKind::Binary(op, Box::new(l), Box::new(r)),
                span,
            };
        };
        self.depth -= chain;
        out
    }

    fn or_expr(&mut self) -> PResult<Expr> {
        self.binary(
            Self::and_expr,
            &[
                (TokKind::Kw(Kw::Or), BinOp::Or),
                (TokKind::P(Punct::OrOr), BinOp::Or),
            ],
        )
    }

    fn and_expr(&mut self) -> PResult<Expr> {
        self.binary(
            Self::not_expr,
            &[
                (TokKind::Kw(Kw::And), BinOp::And),
                (TokKind::P(Punct::AndAnd), BinOp::And),
            ],
        )
    }

    fn not_expr(&mut self) -> PResult<Expr> {
        if self.at_kw(Kw::Not) || self.at_p(Punct::Bang) {
            let start = self.bump().span;
            self.enter()?;
            let e = self.not_expr();
            self.leave();
            let e = e?;
            let span = start.to(e.span);
            return Ok(Expr {
                kind: ExprKind::Unary(UnOp::Not, Box::new(e)),
                span,
            });
        }
        self.cmp_expr()
    }

    fn cmp_expr(&mut self) -> PResult<Expr> {
        use Punct::*;
        self.binary(
            Self::add_expr,
            &[
                (TokKind::P(EqEq), BinOp::Eq),
                (TokKind::P(Ne), BinOp::Ne),
                (TokKind::P(Lt), BinOp::Lt),
                (TokKind::P(Le), BinOp::Le),
                (TokKind::P(Gt), BinOp::Gt),
                (TokKind::P(Ge), BinOp::Ge),
            ],
        )
    }

    fn add_expr(&mut self) -> PResult<Expr> {
        self.binary(
            Self::mul_expr,
            &[
                (TokKind::P(Punct::Plus), BinOp::Add),
                (TokKind::P(Punct::Minus), BinOp::Sub),
            ],
        )
    }

    fn mul_expr(&mut self) -> PResult<Expr> {
        self.binary(
            Self::unary_expr,
            &[
                (TokKind::P(Punct::Star), BinOp::Mul),
                (TokKind::P(Punct::Slash), BinOp::Div),
                (TokKind::Kw(Kw::Mod), BinOp::Mod),
            ],
        )
    }

    fn unary_expr(&mut self) -> PResult<Expr> {
        if self.at_p(Punct::Minus) {
            let start = self.bump().span;
            self.enter()?;
            let e = self.unary_expr();
            self.leave();
            let e = e?;
            let span = start.to(e.span);
            return Ok(Expr {
                kind: ExprKind::Unary(UnOp::Neg, Box::new(e)),
                span,
            });
        }
        if self.at_kw(Kw::Not) || self.at_p(Punct::Bang) {
            return self.not_expr();
        }
        self.postfix_expr()
    }

    fn postfix_expr(&mut self) -> PResult<Expr> {
        let mut e = self.primary()?;
        loop {
            if self.at_p(Punct::Dot) {
                self.bump();
                let field = self.ident("a field name (x, y, z, rx, ry or rz)")?;
                let span = e.span.to(field.span);
                e = Expr {
                    kind: ExprKind::Field(Box::new(e), field),
                    span,
                };
            } else if self.at_p(Punct::LBracket) {
                self.bump();
                let i = self.expr()?;
                let close = self.expect_p(Punct::RBracket, "to close the index")?;
                let span = e.span.to(close);
                e = Expr {
                    kind: ExprKind::Index(Box::new(e), Box::new(i)),
                    span,
                };
            } else {
                return Ok(e);
            }
        }
    }

    fn primary(&mut self) -> PResult<Expr> {
        let t = self.tok().clone();
        let kind = match &t.kind {
            TokKind::Int(i) => ExprKind::Int(*i),
            TokKind::Num(x) => ExprKind::Num(*x),
            TokKind::Quantity(x, d) => ExprKind::Quantity(*x, *d),
            TokKind::Str(s) => ExprKind::Str(s.clone()),
            TokKind::Kw(Kw::True) => ExprKind::Bool(true),
            TokKind::Kw(Kw::False) => ExprKind::Bool(false),
            TokKind::Error => {
                self.bump();
                return Ok(Expr {
                    kind: ExprKind::Error,
                    span: t.span,
                });
            }
            TokKind::Ident => {
                self.bump();
                let name = self.text(t.span).to_string();
                if self.at_p(Punct::LParen) {
                    let args = self.args()?;
                    let span = t.span.to(self.prev_span());
                    return Ok(Expr {
                        kind: ExprKind::Call(Ident { name, span: t.span }, args),
                        span,
                    });
                }
                return Ok(Expr {
                    kind: ExprKind::Name(name),
                    span: t.span,
                });
            }
            TokKind::P(Punct::LParen) => {
                self.bump();
                let mut e = self.expr()?;
                let close = self.expect_p(Punct::RParen, "to close the parenthesis")?;
                e.span = t.span.to(close);
                return Ok(e);
            }
            _ => return Err(self.unexpected("an expression")),
        };
        self.bump();
        Ok(Expr { kind, span: t.span })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lexer::lex;

    fn parse_str(s: &str) -> (SourceModule, Vec<Diagnostic>) {
        let mut d = Vec::new();
        let t = lex(s, &mut d);
        let m = parse(s, t, &mut d);
        (m, d)
    }

    #[test]
    fn precedence() {
        let (m, d) = parse_str("proc main() { x = 1 + 2 * 3 < 4 and not b; }");
        assert!(d.is_empty(), "{d:?}");
        let Item::Proc(p) = &m.items[0] else {
            unreachable!()
        };
        let StmtKind::Assign { value, .. } = &p.body.stmts[0].kind else {
            unreachable!()
        };
        let ExprKind::Binary(BinOp::And, l, _) = &value.kind else {
            unreachable!("{value:?}")
        };
        assert!(matches!(l.kind, ExprKind::Binary(BinOp::Lt, ..)));
    }

    #[test]
    fn recovers_and_reports_each_bad_statement() {
        let (_, d) = parse_str("proc main() { x = ; y = 1 +; move_j; }");
        assert_eq!(d.len(), 3, "{d:?}");
    }

    #[test]
    fn deep_nesting_is_an_error_not_a_crash() {
        let src = format!(
            "proc main() {{ x = {}1{}; }}",
            "(".repeat(5000),
            ")".repeat(5000)
        );
        let (_, d) = parse_str(&src);
        assert!(d.iter().any(|d| d.code == Code::E0006));
    }
}

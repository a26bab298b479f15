//! The RAPID parser: tokens to [`syntax`](super::syntax) trees, by recursive descent.
//!
//! Words are compared case-insensitively. After an error the parser skips to the next `;`
//! or to a word that ends a block (`ENDIF`, `ENDPROC`, …) and goes on, so one mistake is
//! reported once. Nesting deeper than [`MAX_DEPTH`] is error E0006, never a stack overflow.
//! Constructs the front-end does not run but that are valid RAPID (`GOTO`, labels,
//! `RAISE`, `RETRY`, `RECORD`, error handlers, …) are parsed far enough to be named in a
//! clear E0300 by the next pass.

use super::lexer::{Tok, Token};
use super::syntax::*;
use crate::diag::{Code, Diagnostic};
use crate::frontend::{Limits, PResult, Parser, Reported};
use crate::syntax::Span;

/// Deepest nesting of statements and expressions.
pub const MAX_DEPTH: u32 = 64;

/// The words that end a statement list.
const BLOCK_END: &[&str] = &[
    "endproc",
    "endfunc",
    "endtrap",
    "error",
    "backward",
    "undo",
    "endif",
    "else",
    "elseif",
    "endwhile",
    "endfor",
    "endtest",
    "case",
    "default",
    "endmodule",
];

/// Reserved words that cannot start an expression or name data.
const RESERVED: &[&str] = &[
    "alias",
    "and",
    "backward",
    "case",
    "connect",
    "const",
    "default",
    "div",
    "do",
    "else",
    "elseif",
    "endfor",
    "endfunc",
    "endif",
    "endmodule",
    "endproc",
    "endrecord",
    "endtest",
    "endtrap",
    "endwhile",
    "error",
    "exit",
    "for",
    "from",
    "func",
    "goto",
    "if",
    "inout",
    "local",
    "mod",
    "module",
    "not",
    "or",
    "pers",
    "proc",
    "raise",
    "record",
    "retry",
    "return",
    "step",
    "test",
    "then",
    "to",
    "trap",
    "trynext",
    "undo",
    "var",
    "while",
    "with",
    "xor",
];

/// Parses a task's text: every `MODULE … ENDMODULE` in it.
pub fn parse(src: &str, toks: Vec<Token>, diags: &mut Vec<Diagnostic>) -> Vec<RapidModule> {
    let limits = Limits {
        max_depth: MAX_DEPTH,
        max_errors: usize::MAX,
    };
    let mut p = Parser::new(src, toks, diags, limits);
    p.header();
    let mut out = Vec::new();
    while !p.at_end() {
        if p.at("module") {
            match p.module() {
                Ok(m) => out.push(m),
                Err(Reported) => p.skip_past_word("endmodule"),
            }
        } else {
            let _ = p.unexpected("`MODULE`");
            p.skip_past_word("endmodule");
        }
    }
    out
}

impl Parser<'_, '_, Token> {
    fn at(&self, word: &str) -> bool {
        self.tok().is(self.src, word)
    }
    fn at_tok(&self, t: &Tok) -> bool {
        &self.tok().tok == t
    }
    fn eat(&mut self, word: &str) -> bool {
        self.eat_if(|p| p.at(word))
    }
    fn eat_tok(&mut self, t: &Tok) -> bool {
        self.eat_if(|p| p.at_tok(t))
    }
    fn at_block_end(&self) -> bool {
        self.at_tok(&Tok::Eof) || BLOCK_END.iter().any(|w| self.at(w))
    }

    fn describe(&self) -> String {
        let t = self.tok();
        match &t.tok {
            Tok::Eof => "the end of the file".to_string(),
            Tok::Str(_) => "a string".to_string(),
            Tok::Num(_) => format!("the number `{}`", self.text(t.span)),
            Tok::Ident => format!("`{}`", self.text(t.span)),
            _ => format!("`{}`", self.text(t.span)),
        }
    }

    fn unexpected(&mut self, expected: &str) -> Reported {
        let d = Diagnostic::error(
            Code::E0005,
            format!("expected {expected}, found {}", self.describe()),
            self.span(),
        )
        .with_label(format!("expected {expected} here"));
        self.report(d)
    }

    fn expect_tok(&mut self, t: Tok, what: &str) -> PResult<Span> {
        if self.at_tok(&t) {
            Ok(self.bump().span)
        } else if t == Tok::Semi {
            // Point just after the previous token: that is where the `;` is missing.
            let d = Diagnostic::error(
                Code::E0005,
                format!("expected `;`, found {}", self.describe()),
                self.after_prev(),
            )
            .with_label("`;` missing here")
            .with_help("every RAPID statement and declaration ends with `;`");
            Err(self.report(d))
        } else {
            Err(self.unexpected(what))
        }
    }

    fn expect(&mut self, word: &str) -> PResult<Span> {
        if self.at(word) {
            Ok(self.bump().span)
        } else {
            Err(self.unexpected(&format!("`{}`", word.to_ascii_uppercase())))
        }
    }

    fn name(&mut self, what: &str) -> PResult<Name> {
        let t = self.tok().clone();
        if t.tok == Tok::Ident {
            let text = self.text(t.span).to_string();
            if RESERVED.contains(&text.to_ascii_lowercase().as_str()) {
                let d = Diagnostic::error(
                    Code::E0005,
                    format!("expected {what}, found the reserved word `{text}`"),
                    t.span,
                )
                .with_help("RAPID's reserved words cannot name data or routines");
                return Err(self.report(d));
            }
            self.bump();
            Ok(Name { text, span: t.span })
        } else {
            Err(self.unexpected(what))
        }
    }

    fn enter(&mut self) -> PResult<()> {
        if !self.deeper() {
            let d = Diagnostic::error(
                Code::E0006,
                format!("nesting deeper than {MAX_DEPTH} levels"),
                self.span(),
            )
            .with_help("move the inner part into a routine of its own");
            // Skip everything: the rest cannot be parsed sensibly at this depth.
            self.diags.push(d);
            self.skip_to_end();
            return Err(Reported);
        }
        Ok(())
    }

    /// Skips to just past `word` (or the end).
    fn skip_past_word(&mut self, word: &str) {
        self.skip_past(|p| p.at(word));
    }

    /// After an error in a statement: to just past the next `;`, or to a block's end word.
    fn sync_stmt(&mut self) {
        loop {
            if self.at_tok(&Tok::Eof) || self.at_block_end() {
                return;
            }
            for w in ["if", "while", "for", "test"] {
                // The start of another statement: resume there.
                if self.at(w) && self.prev().is_some_and(|t| t.tok == Tok::Semi) {
                    return;
                }
            }
            if self.bump().tok == Tok::Semi {
                return;
            }
        }
    }

    /// The `%%% … %%%` header of old `.prg` files.
    fn header(&mut self) {
        let triple = |p: &Self| (0..3).all(|k| p.peek(k).tok == Tok::Percent);
        let past_triple = |p: &mut Self| (0..3).for_each(|_| drop(p.bump()));
        if triple(self) {
            past_triple(self);
            self.skip_until(triple);
            if triple(self) {
                past_triple(self);
            }
        }
    }

    fn module(&mut self) -> PResult<RapidModule> {
        self.expect("module")?;
        let name = self.name("a module name")?;
        if self.eat_tok(&Tok::LParen) {
            // Attributes: SYSMODULE, NOSTEPIN, VIEWONLY, READONLY, NOVIEW.
            while !self.at_tok(&Tok::RParen) && !self.at_tok(&Tok::Eof) {
                self.bump();
            }
            self.expect_tok(Tok::RParen, "`)`")?;
        }
        let mut items = Vec::new();
        loop {
            if self.eat("endmodule") {
                break;
            }
            if self.at_tok(&Tok::Eof) {
                let d = Diagnostic::error(
                    Code::E0005,
                    format!("module `{}` has no `ENDMODULE`", name.text),
                    name.span,
                )
                .with_help("end the module with `ENDMODULE`");
                self.diags.push(d);
                break;
            }
            match self.item() {
                Ok(Some(it)) => items.push(it),
                Ok(None) => {}
                Err(Reported) => self.sync_item(),
            }
        }
        Ok(RapidModule { name, items })
    }

    /// After an error at module level: to the next declaration or routine.
    fn sync_item(&mut self) {
        let starts = [
            "local",
            "task",
            "var",
            "pers",
            "const",
            "proc",
            "func",
            "trap",
            "endmodule",
        ];
        loop {
            if self.at_tok(&Tok::Eof) {
                return;
            }
            let prev_ends = self.prev().is_some_and(|prev| {
                prev.tok == Tok::Semi
                    || ["endproc", "endfunc", "endtrap", "endrecord"]
                        .iter()
                        .any(|w| prev.is(self.src, w))
            });
            if prev_ends && starts.iter().any(|w| self.at(w)) || self.at("endmodule") {
                return;
            }
            self.bump();
        }
    }

    fn item(&mut self) -> PResult<Option<Item>> {
        let start = self.span();
        let local = self.eat("local") | self.eat("task");
        if self.at("var") || self.at("pers") || self.at("const") {
            return Ok(Some(Item::Data(self.data_decl(local, start)?)));
        }
        if self.at("proc") || self.at("func") || self.at("trap") {
            return Ok(Some(Item::Routine(self.routine(local, start)?)));
        }
        if self.eat("record") {
            let name = self.name("the record's name")?;
            let mut fields = Vec::new();
            while !self.at("endrecord") && !self.at_tok(&Tok::Eof) {
                let ty = self.name("a component's type")?;
                let field = self.name("a component's name")?;
                self.expect_tok(Tok::Semi, "`;`")?;
                fields.push((ty, field));
            }
            self.expect("endrecord")?;
            return Ok(Some(Item::Record(RecordDecl {
                local,
                name,
                fields,
                span: start.to(self.prev_span()),
            })));
        }
        if self.at("alias") {
            let d = Diagnostic::error(
                Code::E0300,
                "`ALIAS` declarations are not supported by vworks's RAPID front-end",
                self.span(),
            )
            .with_help("use the data type the alias names");
            self.diags.push(d);
            self.skip_past_semi();
            return Ok(None);
        }
        Err(self.unexpected(
            "a data declaration (`VAR`, `PERS`, `CONST`) or a routine (`PROC`, `FUNC`, `TRAP`)",
        ))
    }

    fn skip_past_semi(&mut self) {
        self.skip_past(|p| p.at_tok(&Tok::Semi));
    }

    fn data_decl(&mut self, local: bool, start: Span) -> PResult<DataDecl> {
        let storage = if self.eat("var") {
            Storage::Var
        } else if self.eat("pers") {
            Storage::Pers
        } else {
            self.expect("const")?;
            Storage::Const
        };
        let ty = self.name("a data type")?;
        let name = self.name("a data name")?;
        let mut dims = Vec::new();
        if self.eat_tok(&Tok::LBrace) {
            loop {
                dims.push(self.expr()?);
                if !self.eat_tok(&Tok::Comma) {
                    break;
                }
            }
            self.expect_tok(Tok::RBrace, "`}`")?;
        }
        let init = if self.eat_tok(&Tok::Assign) {
            Some(self.expr()?)
        } else {
            None
        };
        self.expect_tok(Tok::Semi, "`;`")?;
        Ok(DataDecl {
            local,
            storage,
            ty,
            name,
            dims,
            init,
            span: start.to(self.prev_span()),
        })
    }

    fn routine(&mut self, local: bool, start: Span) -> PResult<Routine> {
        let (kind, end) = if self.eat("proc") {
            (RoutineKind::Proc, "endproc")
        } else if self.eat("func") {
            (RoutineKind::Func, "endfunc")
        } else {
            self.expect("trap")?;
            (RoutineKind::Trap, "endtrap")
        };
        let ret = if kind == RoutineKind::Func {
            Some(self.name("the function's result type")?)
        } else {
            None
        };
        let name = self.name("a routine name")?;
        let mut params = Vec::new();
        if kind != RoutineKind::Trap {
            self.expect_tok(Tok::LParen, "`(`")?;
            if !self.at_tok(&Tok::RParen) {
                loop {
                    params.push(self.param()?);
                    // `\a | \b`: alternatives, all kept as optional parameters.
                    if self.eat_tok(&Tok::Comma) || self.eat_tok(&Tok::Bar) {
                        continue;
                    }
                    if self.at_tok(&Tok::Backslash) {
                        continue;
                    }
                    break;
                }
            }
            self.expect_tok(Tok::RParen, "`)`")?;
        }
        let span = start.to(self.prev_span());
        let mut locals = Vec::new();
        while self.at("var") || self.at("pers") || self.at("const") || self.at("local") {
            let s = self.span();
            let local = self.eat("local");
            match self.data_decl(local, s) {
                Ok(d) => locals.push(d),
                Err(Reported) => self.sync_stmt(),
            }
        }
        let body = self.stmts();
        let mut handler = None;
        let mut other_handler = None;
        while self.at("error") || self.at("backward") || self.at("undo") {
            let error = self.at("error");
            let s = self.bump().span;
            if self.eat_tok(&Tok::LParen) {
                while !self.at_tok(&Tok::RParen) && !self.at_tok(&Tok::Eof) {
                    self.bump();
                }
                self.bump();
            }
            let stmts = self.stmts();
            if error && handler.is_none() {
                handler = Some((s, stmts));
            } else {
                other_handler.get_or_insert(s);
            }
        }
        if !self.eat(end) {
            let d = Diagnostic::error(
                Code::E0005,
                format!(
                    "expected `{}` to end `{}`, found {}",
                    end.to_ascii_uppercase(),
                    name.text,
                    self.describe()
                ),
                self.span(),
            )
            .with_related(name.span, "the routine starts here");
            self.report(d);
            self.skip_past_word(end);
        }
        Ok(Routine {
            local,
            kind,
            ret,
            name,
            params,
            locals,
            body,
            handler,
            other_handler,
            span,
        })
    }

    fn param(&mut self) -> PResult<ParamDecl> {
        let start = self.span();
        let optional = self.eat_tok(&Tok::Backslash);
        let mode = if self.eat("var") || self.eat("pers") || self.eat("inout") {
            Mode::Ref
        } else {
            Mode::In
        };
        let ty = self.name("a parameter type")?;
        let name = self.name("a parameter name")?;
        let mut array = false;
        if self.eat_tok(&Tok::LBrace) {
            array = true;
            while !self.at_tok(&Tok::RBrace) && !self.at_tok(&Tok::Eof) {
                self.bump();
            }
            self.expect_tok(Tok::RBrace, "`}`")?;
        }
        Ok(ParamDecl {
            optional,
            mode,
            ty,
            name,
            array,
            span: start.to(self.prev_span()),
        })
    }

    /// Statements up to a block's end word (not consumed).
    fn stmts(&mut self) -> Vec<Stmt> {
        let mut out = Vec::new();
        while !self.at_block_end() {
            let before = self.mark();
            match self.stmt() {
                Ok(s) => out.push(s),
                Err(Reported) => {
                    self.sync_stmt();
                    if self.mark() == before {
                        self.bump();
                    }
                }
            }
        }
        out
    }

    fn stmt(&mut self) -> PResult<Stmt> {
        self.enter()?;
        let start = self.span();
        let kind = self.stmt_kind();
        self.leave();
        Ok(Stmt {
            kind: kind?,
            span: start.to(self.prev_span()),
        })
    }

    fn stmt_kind(&mut self) -> PResult<StmtKind> {
        if self.eat("if") {
            return self.if_stmt();
        }
        if self.eat("while") {
            let cond = self.expr()?;
            self.expect("do")?;
            let body = self.stmts();
            self.expect("endwhile")?;
            return Ok(StmtKind::While { cond, body });
        }
        if self.eat("for") {
            let var = self.name("the loop variable")?;
            self.expect("from")?;
            let from = self.expr()?;
            self.expect("to")?;
            let to = self.expr()?;
            let step = if self.eat("step") {
                Some(self.expr()?)
            } else {
                None
            };
            self.expect("do")?;
            let body = self.stmts();
            self.expect("endfor")?;
            return Ok(StmtKind::For {
                var,
                from,
                to,
                step,
                body,
            });
        }
        if self.eat("test") {
            let value = self.expr()?;
            let mut cases = Vec::new();
            let mut default = None;
            loop {
                if self.eat("case") {
                    let mut vals = vec![self.expr()?];
                    while self.eat_tok(&Tok::Comma) {
                        vals.push(self.expr()?);
                    }
                    self.expect_tok(Tok::Colon, "`:`")?;
                    cases.push((vals, self.stmts()));
                } else if self.eat("default") {
                    self.expect_tok(Tok::Colon, "`:`")?;
                    default = Some(self.stmts());
                } else {
                    break;
                }
            }
            self.expect("endtest")?;
            return Ok(StmtKind::Test {
                value,
                cases,
                default,
            });
        }
        if self.eat("return") {
            let v = if self.at_tok(&Tok::Semi) {
                None
            } else {
                Some(self.expr()?)
            };
            self.expect_tok(Tok::Semi, "`;`")?;
            return Ok(StmtKind::Return(v));
        }
        if self.eat("exit") {
            self.expect_tok(Tok::Semi, "`;`")?;
            return Ok(StmtKind::Exit);
        }
        if self.eat("connect") {
            let intno = self.expr()?;
            self.expect("with")?;
            let trap = self.name("a trap routine")?;
            self.expect_tok(Tok::Semi, "`;`")?;
            return Ok(StmtKind::Connect { intno, trap });
        }
        if self.eat("raise") {
            let v = if self.at_tok(&Tok::Semi) {
                None
            } else {
                Some(self.expr()?)
            };
            self.expect_tok(Tok::Semi, "`;`")?;
            return Ok(StmtKind::Raise(v));
        }
        if self.eat("retry") {
            self.expect_tok(Tok::Semi, "`;`")?;
            return Ok(StmtKind::Retry);
        }
        if self.eat("trynext") {
            self.expect_tok(Tok::Semi, "`;`")?;
            return Ok(StmtKind::TryNext);
        }
        if self.eat("goto") {
            let label = self.name("a label")?;
            self.expect_tok(Tok::Semi, "`;`")?;
            return Ok(StmtKind::Goto(label));
        }
        if self.at_tok(&Tok::Percent) {
            self.skip_past_semi();
            return Ok(StmtKind::Unsupported("late binding (`%name%`)"));
        }
        // A teach pendant's placeholder: `<SMT>` (a statement not yet written) has no `;`,
        // so only it is skipped (and a `;` after it), never the statements after it.
        if self.at_tok(&Tok::Lt) && self.peek(1).tok == Tok::Ident && self.peek(2).tok == Tok::Gt {
            self.bump();
            self.bump();
            self.bump();
            self.eat_tok(&Tok::Semi);
            return Ok(StmtKind::Unsupported("a placeholder (`<SMT>`)"));
        }
        if self.at_tok(&Tok::Lt) || self.at_tok(&Tok::Question) {
            self.skip_past_semi();
            return Ok(StmtKind::Unsupported("a placeholder (`<SMT>`)"));
        }
        // A label `name:`.
        if self.tok().tok == Tok::Ident && self.peek(1).tok == Tok::Colon {
            let label = self.name("a label")?;
            self.bump();
            return Ok(StmtKind::Label(label));
        }
        let name = self.name("a statement")?;
        if matches!(self.tok().tok, Tok::Assign | Tok::Dot | Tok::LBrace) {
            let target = self.postfix(Expr {
                span: name.span,
                kind: ExprKind::Name(name),
            })?;
            self.expect_tok(Tok::Assign, "`:=`")?;
            let value = self.expr()?;
            self.expect_tok(Tok::Semi, "`;`")?;
            return Ok(StmtKind::Assign { target, value });
        }
        let args = self.args(&Tok::Semi)?;
        self.expect_tok(Tok::Semi, "`;`")?;
        Ok(StmtKind::Call { name, args })
    }

    fn if_stmt(&mut self) -> PResult<StmtKind> {
        let cond = self.expr()?;
        if !self.eat("then") {
            // The compact IF: one statement, no ENDIF.
            let s = self.stmt()?;
            return Ok(StmtKind::If {
                branches: vec![(cond, vec![s])],
                els: None,
            });
        }
        let mut branches = vec![(cond, self.stmts())];
        let mut els = None;
        loop {
            if self.eat("elseif") {
                let c = self.expr()?;
                self.expect("then")?;
                branches.push((c, self.stmts()));
            } else if self.eat("else") {
                els = Some(self.stmts());
            } else {
                break;
            }
        }
        self.expect("endif")?;
        Ok(StmtKind::If { branches, els })
    }

    /// Arguments up to `end` (not consumed): positional ones separated by `,`, optional ones
    /// `\Name` or `\Name:=value` anywhere.
    fn args(&mut self, end: &Tok) -> PResult<Vec<Arg>> {
        let mut out = Vec::new();
        loop {
            if self.at_tok(end) {
                return Ok(out);
            }
            if self.eat_tok(&Tok::Backslash) {
                let n = self.name("an optional argument's name")?;
                if self.eat_tok(&Tok::Question) {
                    let x = self.name("the name of an optional parameter")?;
                    out.push(Arg::Cond(n, x));
                    self.eat_tok(&Tok::Comma);
                    continue;
                }
                let v = if self.eat_tok(&Tok::Assign) {
                    Some(self.expr()?)
                } else {
                    None
                };
                out.push(Arg::Opt(n, v));
                self.eat_tok(&Tok::Comma);
                continue;
            }
            out.push(Arg::Pos(self.expr()?));
            if self.eat_tok(&Tok::Comma) || self.at_tok(&Tok::Backslash) {
                continue;
            }
            if !self.at_tok(end) {
                if *end == Tok::Semi {
                    // Most often the `;` at the end of the line is missing.
                    return Err(self.expect_tok(Tok::Semi, "`;`").err().unwrap_or(Reported));
                }
                return Err(self.unexpected("`,` or `)`"));
            }
        }
    }

    fn expr(&mut self) -> PResult<Expr> {
        self.enter()?;
        let e = self.or_expr();
        self.leave();
        e
    }

    fn bin(&mut self, op: BinOp, l: Expr, r: Expr) -> Expr {
        Expr {
            span: l.span.to(r.span),
            kind: ExprKind::Binary(op, Box::new(l), Box::new(r)),
        }
    }

    fn or_expr(&mut self) -> PResult<Expr> {
        let mut l = self.and_expr()?;
        loop {
            let op = if self.eat("or") {
                BinOp::Or
            } else if self.eat("xor") {
                BinOp::Xor
            } else {
                return Ok(l);
            };
            let r = self.and_expr()?;
            l = self.bin(op, l, r);
        }
    }

    fn and_expr(&mut self) -> PResult<Expr> {
        let mut l = self.not_expr()?;
        while self.eat("and") {
            let r = self.not_expr()?;
            l = self.bin(BinOp::And, l, r);
        }
        Ok(l)
    }

    fn not_expr(&mut self) -> PResult<Expr> {
        if self.at("not") {
            let s = self.bump().span;
            self.enter()?;
            let e = self.not_expr();
            self.leave();
            let e = e?;
            return Ok(Expr {
                span: s.to(e.span),
                kind: ExprKind::Unary(UnOp::Not, Box::new(e)),
            });
        }
        self.cmp_expr()
    }

    fn cmp_expr(&mut self) -> PResult<Expr> {
        let l = self.add_expr()?;
        let op = match self.tok().tok {
            Tok::Eq => BinOp::Eq,
            Tok::Ne => BinOp::Ne,
            Tok::Lt => BinOp::Lt,
            Tok::Le => BinOp::Le,
            Tok::Gt => BinOp::Gt,
            Tok::Ge => BinOp::Ge,
            _ => return Ok(l),
        };
        self.bump();
        let r = self.add_expr()?;
        Ok(self.bin(op, l, r))
    }

    fn add_expr(&mut self) -> PResult<Expr> {
        let mut l = self.mul_expr()?;
        loop {
            let op = match self.tok().tok {
                Tok::Plus => BinOp::Add,
                Tok::Minus => BinOp::Sub,
                _ => return Ok(l),
            };
            self.bump();
            let r = self.mul_expr()?;
            l = self.bin(op, l, r);
        }
    }

    fn mul_expr(&mut self) -> PResult<Expr> {
        let mut l = self.unary()?;
        loop {
            let op = match self.tok().tok {
                Tok::Star => BinOp::Mul,
                Tok::Slash => BinOp::Div,
                _ if self.at("div") => BinOp::IntDiv,
                _ if self.at("mod") => BinOp::Mod,
                _ => return Ok(l),
            };
            self.bump();
            let r = self.unary()?;
            l = self.bin(op, l, r);
        }
    }

    fn unary(&mut self) -> PResult<Expr> {
        let op = match self.tok().tok {
            Tok::Minus => UnOp::Neg,
            Tok::Plus => UnOp::Plus,
            _ => return self.primary_postfix(),
        };
        let s = self.bump().span;
        self.enter()?;
        let e = self.unary();
        self.leave();
        let e = e?;
        Ok(Expr {
            span: s.to(e.span),
            kind: ExprKind::Unary(op, Box::new(e)),
        })
    }

    fn primary_postfix(&mut self) -> PResult<Expr> {
        let p = self.primary()?;
        self.postfix(p)
    }

    fn postfix(&mut self, mut e: Expr) -> PResult<Expr> {
        loop {
            if self.eat_tok(&Tok::Dot) {
                let f = self.name("a component name")?;
                e = Expr {
                    span: e.span.to(f.span),
                    kind: ExprKind::Field(Box::new(e), f),
                };
            } else if self.eat_tok(&Tok::LBrace) {
                let mut idx = vec![self.expr()?];
                while self.eat_tok(&Tok::Comma) {
                    idx.push(self.expr()?);
                }
                let end = self.expect_tok(Tok::RBrace, "`}`")?;
                e = Expr {
                    span: e.span.to(end),
                    kind: ExprKind::Index(Box::new(e), idx),
                };
            } else {
                return Ok(e);
            }
        }
    }

    fn primary(&mut self) -> PResult<Expr> {
        let t = self.tok().clone();
        let kind = match &t.tok {
            Tok::Num(x) => {
                self.bump();
                ExprKind::Num(*x)
            }
            Tok::Str(s) => {
                self.bump();
                ExprKind::Str(s.clone())
            }
            Tok::LParen => {
                self.bump();
                let e = self.expr()?;
                let end = self.expect_tok(Tok::RParen, "`)`")?;
                return Ok(Expr {
                    span: t.span.to(end),
                    kind: e.kind,
                });
            }
            Tok::LBracket => {
                self.bump();
                let mut items = Vec::new();
                if !self.at_tok(&Tok::RBracket) {
                    loop {
                        items.push(self.expr()?);
                        if !self.eat_tok(&Tok::Comma) {
                            break;
                        }
                    }
                }
                let end = self.expect_tok(Tok::RBracket, "`,` or `]`")?;
                return Ok(Expr {
                    span: t.span.to(end),
                    kind: ExprKind::Aggregate(items),
                });
            }
            Tok::Ident if t.is(self.src, "true") => {
                self.bump();
                ExprKind::Bool(true)
            }
            Tok::Ident if t.is(self.src, "false") => {
                self.bump();
                ExprKind::Bool(false)
            }
            Tok::Ident => {
                let n = self.name("a value")?;
                if self.eat_tok(&Tok::LParen) {
                    let args = self.args(&Tok::RParen)?;
                    let end = self.expect_tok(Tok::RParen, "`)`")?;
                    return Ok(Expr {
                        span: n.span.to(end),
                        kind: ExprKind::Call(n, args),
                    });
                }
                ExprKind::Name(n)
            }
            _ => return Err(self.unexpected("a value")),
        };
        Ok(Expr { kind, span: t.span })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_ok(src: &str) -> Vec<RapidModule> {
        let mut d = Vec::new();
        let toks = super::super::lexer::lex(src, &mut d);
        let m = parse(src, toks, &mut d);
        assert!(d.is_empty(), "{d:#?}");
        m
    }

    #[test]
    fn a_module_with_every_statement() {
        let m = parse_ok(
            "MODULE Main(SYSMODULE)\n\
             CONST robtarget p10 := [[500,0,400],[0,0,1,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n\
             PERS num nCount := 0;\n\
             LOCAL VAR num arr{3} := [1,2,3];\n\
             PROC main()\n\
               VAR num i;\n\
               MoveJ p10, v1000, z50, tool0;\n\
               MoveL Offs(p10, 0, 0, 100), v100 \\V:=50, fine, tool0 \\WObj:=wobj0;\n\
               IF nCount > 2 AND NOT TRUE THEN nCount := 0; ELSEIF nCount = 1 THEN Incr nCount; ELSE Decr nCount; ENDIF\n\
               IF nCount < 0 nCount := 0;\n\
               FOR i FROM 1 TO 3 STEP 1 DO arr{i} := arr{i} * 2; ENDFOR\n\
               WHILE nCount < 10 DO nCount := nCount + 1 MOD 3; ENDWHILE\n\
               TEST nCount CASE 1, 2: TPWrite \"one or two\"; DEFAULT: Stop; ENDTEST\n\
               WaitUntil nCount = 0 \\MaxTime:=5 \\TimeFlag:=flag;\n\
               p10.trans.x := -5;\n\
               RETURN;\n\
             ENDPROC\n\
             FUNC num Twice(num x) RETURN 2 * x; ENDFUNC\n\
             TRAP tr CONNECT i WITH tr; ENDTRAP\n\
             ENDMODULE\n",
        );
        assert_eq!(m.len(), 1);
        assert_eq!(m[0].items.len(), 6);
        let Item::Routine(r) = &m[0].items[3] else {
            panic!("main is a routine")
        };
        assert_eq!(r.locals.len(), 1);
        assert_eq!(r.body.len(), 10);
    }

    #[test]
    fn errors_are_reported_once_and_parsing_goes_on() {
        let src =
            "MODULE m\nPROC main()\n  MoveL p10 v100;\n  x := ;\n  Stop;\nENDPROC\nENDMODULE\n";
        let mut d = Vec::new();
        let toks = super::super::lexer::lex(src, &mut d);
        let m = parse(src, toks, &mut d);
        assert_eq!(d.len(), 2, "{d:#?}");
        let Item::Routine(r) = &m[0].items[0] else {
            panic!("main is a routine")
        };
        assert_eq!(r.body.len(), 1, "Stop is still parsed");
    }

    #[test]
    fn deep_nesting_is_an_error_not_a_crash() {
        let src = format!(
            "MODULE m\nPROC main()\n x := {}1;\nENDPROC\nENDMODULE",
            "-".repeat(10_000)
        );
        let mut d = Vec::new();
        let toks = super::super::lexer::lex(&src, &mut d);
        let _ = parse(&src, toks, &mut d);
        assert!(d.iter().any(|d| d.code == Code::E0006));
    }
}

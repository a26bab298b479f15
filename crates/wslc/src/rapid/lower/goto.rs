//! `GOTO` and labels. A routine with labels at its top level is translated as a loop over
//! the stretches between them: `GOTO l;` notes where to go on (`l`'s stretch) and starts
//! the loop again, which runs that stretch and every one after it:
//!
//! ```text
//! var goto#1: int = 0;
//! while true {
//!     if goto#1 <= 0 { …statements before the first label… }
//!     if goto#1 <= 1 { …statements after `l1:`… }
//!     break;
//! }
//! ```
//!
//! So a `GOTO` may jump back (a loop) or forward (a skip) from any depth of `IF` and
//! `TEST`; a label inside an `IF` or a loop, or a `GOTO` inside a `WHILE` or `FOR` (whose
//! loop the jump would have to leave), is E0300.

use super::data::build as b;
use super::{Tr, block};
use crate::diag::Code;
use crate::rapid::syntax as r;
use crate::syntax as w;

impl Tr<'_> {
    /// The routine's body, as stretches between its top-level labels if it has any.
    pub(crate) fn routine_body(&mut self, body: &[r::Stmt]) -> Vec<w::Stmt> {
        let labels: Vec<&r::Name> = body
            .iter()
            .filter_map(|s| match &s.kind {
                r::StmtKind::Label(n) => Some(n),
                _ => None,
            })
            .collect();
        if labels.is_empty() {
            return self.stmts(body);
        }
        let mut keys: Vec<String> = Vec::new();
        for n in &labels {
            if keys.contains(&n.key()) {
                self.error(
                    Code::E0012,
                    format!("the label `{}` is declared twice", n.text),
                    n.span,
                );
            }
            keys.push(n.key());
        }
        let var = self.temp("goto");
        if let Some(cx) = self.routine.as_mut() {
            cx.labels = Some((keys, var.clone()));
        }
        let span = body.first().map_or_else(Default::default, |s| s.span);
        let mut stretches: Vec<Vec<r::Stmt>> = vec![Vec::new()];
        for s in body {
            match &s.kind {
                r::StmtKind::Label(_) => stretches.push(Vec::new()),
                _ => {
                    if let Some(last) = stretches.last_mut() {
                        last.push(s.clone());
                    }
                }
            }
        }
        let int = |k: i64| b::expr(w::ExprKind::Int(k), span);
        let mut inner = Vec::new();
        for (k, stretch) in stretches.iter().enumerate() {
            let stmts = self.stmts(stretch);
            let cond = b::bin(w::BinOp::Le, b::name(&var, span), int(k as i64));
            inner.push(w::Stmt {
                kind: w::StmtKind::If {
                    branches: vec![(cond, block(stmts, span))],
                    els: None,
                },
                span,
            });
        }
        inner.push(w::Stmt {
            kind: w::StmtKind::Break,
            span,
        });
        if let Some(cx) = self.routine.as_mut() {
            cx.labels = None;
        }
        vec![
            w::Stmt {
                kind: w::StmtKind::Var(w::VarDecl {
                    name: b::ident(&var, span),
                    ty: Some(b::ident("int", span)),
                    init: Some(int(0)),
                    span,
                }),
                span,
            },
            w::Stmt {
                kind: w::StmtKind::While {
                    cond: b::expr(w::ExprKind::Bool(true), span),
                    body: block(inner, span),
                },
                span,
            },
        ]
    }

    /// `GOTO l;`: go on from label `l`'s stretch.
    pub(crate) fn goto(&mut self, label: &r::Name) -> Option<Vec<w::StmtKind>> {
        let cx = self.routine.as_ref()?;
        let in_loop = cx.loops > 0;
        let Some((labels, var)) = cx.labels.clone() else {
            self.error(
                Code::E0010,
                format!("unknown label `{}`: this routine has none", label.text),
                label.span,
            )
            .help = Some("a GOTO goes to a label of its own routine (`name:`)".into());
            return None;
        };
        if in_loop {
            self.unsupported(
                "a GOTO inside a WHILE or FOR",
                label.span,
                "leave the loop first (end it by its condition), then GOTO",
            );
            return None;
        }
        let Some(k) = labels.iter().position(|l| *l == label.key()) else {
            self.error(
                Code::E0010,
                format!("unknown label `{}`", label.text),
                label.span,
            )
            .help = Some(format!("this routine's labels: {}", labels.join(", ")));
            return None;
        };
        let span = label.span;
        Some(vec![
            b::assign(
                b::name(&var, span),
                b::expr(w::ExprKind::Int(k as i64 + 1), span),
            ),
            w::StmtKind::Continue,
        ])
    }

    /// A label inside an `IF`, `TEST` or loop (only a routine's top level has them).
    pub(crate) fn misplaced_label(&mut self, label: &r::Name) {
        self.unsupported(
            &format!("the label `{}` inside a compound statement", label.text),
            label.span,
            "put labels at the routine's top level (not inside IF, TEST, WHILE or FOR)",
        );
    }

    /// Entering (`+1`) or leaving (`-1`) a RAPID loop.
    pub(crate) fn in_loop(&mut self, by: i32) {
        if let Some(cx) = self.routine.as_mut() {
            cx.loops = cx.loops.saturating_add_signed(by);
        }
    }
}

//! Parameters by reference (`VAR`, `PERS`, `INOUT`): each is a module variable of its
//! routine (`pick'p`, one per leaf); a call copies its argument in before and back out
//! after, so the routine's writes reach the caller's data when it returns. **Choice:** a
//! routine that calls itself shares the variable, and a write the routine makes to the
//! argument's own data directly is overwritten by the copy back (RAPID passes the data
//! itself); and when the routine fails and a caller's error handler takes the error, the
//! copy back is skipped (a RETRY copies in again), so the routine's writes before the
//! error are lost where RAPID would keep them. None of these is common in cell programs.

use super::data::{Ty, build as b};
use super::{Data, Sig, Tr};
use crate::diag::Code;
use crate::rapid::syntax::{self as r, Arg, Storage};
use crate::syntax as w;

impl Tr<'_> {
    /// A by-reference parameter `p` of type `ty`: its module variable `base`, declared,
    /// and seen in the routine under the parameter's name.
    pub(crate) fn shadow_param(&mut self, p: &r::ParamDecl, ty: Ty, base: String) {
        let data = Data {
            ty,
            len: None,
            dims: Vec::new(),
            storage: Storage::Var,
            base,
            span: p.name.span,
            text: None,
            inline: None,
            local: false,
            readonly: false,
            tasks: Vec::new(),
            optional: false,
        };
        for (name, (_, wty)) in self
            .leaf_names(&data, None)
            .into_iter()
            .zip(self.leaves(ty))
        {
            self.items.push(w::Item::Var(w::VarDecl {
                name: b::ident(&name, p.name.span),
                ty: Some(b::type_name(wty, p.ty.span)),
                init: Some(b::zero(wty, p.name.span)),
                span: p.span,
            }));
        }
        self.spelled
            .entry(p.name.key())
            .or_insert_with(|| p.name.text.clone());
        if let Some(s) = self.locals.last_mut() {
            s.insert(p.name.key(), data);
        }
    }

    /// The copies around a call of `sig` with `args`: each by-reference argument into its
    /// parameter's variable before, and back after. `None` after a diagnostic (an
    /// argument that is not data the caller may write).
    pub(crate) fn ref_copies(
        &mut self,
        sig: &Sig,
        args: &[Arg],
    ) -> Option<(Vec<w::StmtKind>, Vec<w::StmtKind>)> {
        let pos: Vec<&r::Expr> = args
            .iter()
            .filter_map(|a| match a {
                Arg::Pos(e) => Some(e),
                _ => None,
            })
            .collect();
        let (mut copy_in, mut copy_out) = (Vec::new(), Vec::new());
        for ((e, ty), by_ref) in pos.into_iter().zip(&sig.params).zip(&sig.by_ref) {
            let Some(base) = by_ref else { continue };
            let (d, idx) = self.place(e)?;
            if d.ty != *ty {
                self.error(
                    Code::E0020,
                    format!(
                        "this parameter takes {} by reference, not {}",
                        super::expr::article(*ty),
                        super::expr::article(d.ty)
                    ),
                    e.span,
                );
                return None;
            }
            let shadow = Data {
                base: base.clone(),
                len: None,
                dims: Vec::new(),
                ..d.clone()
            };
            let theirs = self.leaf_names(&d, idx);
            let ours = self.leaf_names(&shadow, None);
            for (t, o) in theirs.iter().zip(&ours) {
                copy_in.push(b::assign(b::name(o, e.span), b::name(t, e.span)));
                copy_out.push(b::assign(b::name(t, e.span), b::name(o, e.span)));
            }
        }
        Some((copy_in, copy_out))
    }
}

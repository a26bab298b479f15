//! Quantities written as text outside a program — `"250mm"` in a workcell, `--until 10s`
//! on the command line — read with the lexer's own units, so that a unit means the same
//! everywhere WSL text appears.

use vworks_vm::Dim;

use crate::lexer::{Punct, TokKind, lex};

/// A quantity read from text.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Quantity {
    /// A plain number (`0.25`, `-3`): SI by convention.
    Number(f64),
    /// A number with a unit, in SI (`250mm` → 0.25 of [`Dim::LENGTH`]).
    WithUnit(f64, Dim),
}

impl Quantity {
    /// The value in SI if it has dimension `dim` (a plain number has every dimension);
    /// otherwise the dimension it has.
    pub fn si(self, dim: Dim) -> Result<f64, Dim> {
        match self {
            Quantity::Number(x) => Ok(x),
            Quantity::WithUnit(x, d) if d == dim => Ok(x),
            Quantity::WithUnit(_, d) => Err(d),
        }
    }
}

/// Reads one quantity, optionally signed: `250mm`, `-90deg`, `4ms`, `0.25`. `None` if
/// the text is anything else (two numbers, an unknown unit, a name).
pub fn parse_quantity(text: &str) -> Option<Quantity> {
    let mut diags = Vec::new();
    let toks = lex(text.trim(), &mut diags);
    if !diags.is_empty() {
        return None;
    }
    let kinds: Vec<&TokKind> = toks
        .iter()
        .map(|t| &t.kind)
        .filter(|k| **k != TokKind::Eof)
        .collect();
    let (sign, rest) = match kinds.as_slice() {
        [TokKind::P(Punct::Minus), rest @ ..] => (-1.0, rest),
        rest => (1.0, rest),
    };
    match rest {
        [TokKind::Quantity(x, d)] => Some(Quantity::WithUnit(sign * x, *d)),
        [TokKind::Int(i)] => Some(Quantity::Number(sign * *i as f64)),
        [TokKind::Num(x)] => Some(Quantity::Number(sign * x)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantities_read_as_in_wsl() {
        assert_eq!(
            parse_quantity(" 250mm "),
            Some(Quantity::WithUnit(0.25, Dim::LENGTH))
        );
        assert_eq!(
            parse_quantity("-90deg").map(|q| q.si(Dim::ANGLE)),
            Some(Ok(-std::f64::consts::FRAC_PI_2))
        );
        assert_eq!(
            parse_quantity("4ms").map(|q| q.si(Dim::LENGTH)),
            Some(Err(Dim::TIME))
        );
        assert_eq!(parse_quantity("3"), Some(Quantity::Number(3.0)));
        assert_eq!(parse_quantity("-0.5"), Some(Quantity::Number(-0.5)));
        for bad in ["", "mm", "1 2", "1mm 2mm", "x", "1furlong", "--1"] {
            assert_eq!(parse_quantity(bad), None, "{bad}");
        }
    }
}

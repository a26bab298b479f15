//! The lexer: source text to tokens, never failing.
//!
//! A quantity literal is a number immediately followed by a unit (`250mm/s`, `50%`): the
//! lexer converts it to SI and its dimension. `mm/s` is one unit only when `/s` (or `/s2`, `/s3`)
//! follows the base unit with no space; `10mm / s` divides by a variable `s`. Bad input
//! (an unknown character, an unknown unit, an unterminated string) becomes an
//! [`TokKind::Error`] token plus a diagnostic, and lexing goes on.

use vworks_vm::Dim;

use crate::diag::{Code, Diagnostic};
use crate::syntax::Span;

/// What a token is.
#[derive(Clone, Debug, PartialEq)]
pub enum TokKind {
    /// An identifier (its text is the span's text).
    Ident,
    /// A reserved word.
    Kw(Kw),
    /// An integer literal without unit.
    Int(i64),
    /// A real literal without unit.
    Num(f64),
    /// A literal with a unit, converted to SI.
    Quantity(f64, Dim),
    /// A string literal, escapes resolved.
    Str(String),
    /// Punctuation or operator.
    P(Punct),
    /// End of input.
    Eof,
    /// Something unreadable (already reported).
    Error,
}

/// Reserved words.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum Kw {
    Global,
    Param,
    Const,
    Var,
    Proc,
    Func,
    Return,
    If,
    Else,
    While,
    For,
    In,
    Break,
    Continue,
    MoveJ,
    MoveL,
    MoveC,
    Delay,
    WaitUntil,
    WaitSignal,
    Signal,
    Parallel,
    Remote,
    When,
    Every,
    After,
    Do,
    Disable,
    Grip,
    Release,
    Log,
    Stop,
    Fail,
    True,
    False,
    And,
    Or,
    Not,
    Mod,
}

/// Every reserved word with its spelling.
pub const KEYWORDS: &[(&str, Kw)] = &[
    ("global", Kw::Global),
    ("param", Kw::Param),
    ("const", Kw::Const),
    ("var", Kw::Var),
    ("proc", Kw::Proc),
    ("func", Kw::Func),
    ("return", Kw::Return),
    ("if", Kw::If),
    ("else", Kw::Else),
    ("while", Kw::While),
    ("for", Kw::For),
    ("in", Kw::In),
    ("break", Kw::Break),
    ("continue", Kw::Continue),
    ("move_j", Kw::MoveJ),
    ("move_l", Kw::MoveL),
    ("move_c", Kw::MoveC),
    ("delay", Kw::Delay),
    ("wait_until", Kw::WaitUntil),
    ("wait_signal", Kw::WaitSignal),
    ("signal", Kw::Signal),
    ("parallel", Kw::Parallel),
    ("remote", Kw::Remote),
    ("when", Kw::When),
    ("every", Kw::Every),
    ("after", Kw::After),
    ("do", Kw::Do),
    ("disable", Kw::Disable),
    ("grip", Kw::Grip),
    ("release", Kw::Release),
    ("log", Kw::Log),
    ("stop", Kw::Stop),
    ("fail", Kw::Fail),
    ("true", Kw::True),
    ("false", Kw::False),
    ("and", Kw::And),
    ("or", Kw::Or),
    ("not", Kw::Not),
    ("mod", Kw::Mod),
];

impl Kw {
    /// The keyword as written.
    pub fn text(self) -> &'static str {
        KEYWORDS
            .iter()
            .find(|(_, k)| *k == self)
            .map_or("?", |(s, _)| s)
    }
}

/// Punctuation and operators.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum Punct {
    LParen,
    RParen,
    LBrace,
    RBrace,
    LBracket,
    RBracket,
    Comma,
    Semi,
    Colon,
    Dot,
    DotDot,
    Arrow,
    Plus,
    Minus,
    Star,
    Slash,
    Assign,
    PlusAssign,
    MinusAssign,
    StarAssign,
    SlashAssign,
    EqEq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
    AndAnd,
    OrOr,
    Bang,
}

impl Punct {
    /// The punctuation as written.
    pub fn text(self) -> &'static str {
        use Punct::*;
        match self {
            LParen => "(",
            RParen => ")",
            LBrace => "{",
            RBrace => "}",
            LBracket => "[",
            RBracket => "]",
            Comma => ",",
            Semi => ";",
            Colon => ":",
            Dot => ".",
            DotDot => "..",
            Arrow => "->",
            Plus => "+",
            Minus => "-",
            Star => "*",
            Slash => "/",
            Assign => "=",
            PlusAssign => "+=",
            MinusAssign => "-=",
            StarAssign => "*=",
            SlashAssign => "/=",
            EqEq => "==",
            Ne => "!=",
            Lt => "<",
            Le => "<=",
            Gt => ">",
            Ge => ">=",
            AndAnd => "&&",
            OrOr => "||",
            Bang => "!",
        }
    }
}

/// A token and where it is.
#[derive(Clone, Debug, PartialEq)]
pub struct Token {
    /// What it is.
    pub kind: TokKind,
    /// Where it is.
    pub span: Span,
}

impl crate::frontend::Lexeme for Token {
    fn span_mut(&mut self) -> &mut Span {
        &mut self.span
    }
    fn span(&self) -> Span {
        self.span
    }
    fn is_eof(&self) -> bool {
        self.kind == TokKind::Eof
    }
    fn is_error(&self) -> bool {
        self.kind == TokKind::Error
    }
    fn eof(at: Span) -> Self {
        Token {
            kind: TokKind::Eof,
            span: at,
        }
    }
}

/// The units a literal may carry: spelling, SI factor, dimension.
pub const UNITS: &[(&str, f64, Dim)] = &[
    ("mm", 1e-3, Dim::LENGTH),
    ("m", 1.0, Dim::LENGTH),
    ("deg", std::f64::consts::PI / 180.0, Dim::ANGLE),
    ("rad", 1.0, Dim::ANGLE),
    ("ms", 1e-3, Dim::TIME),
    ("s", 1.0, Dim::TIME),
];

const UNIT_HELP: &str = "units are mm, m, deg, rad, ms, s and %, and the compound units mm/s, m/s, deg/s, rad/s, mm/s2, m/s2, deg/s2, rad/s2, mm/s3, m/s3, deg/s3, rad/s3";

/// Splits `src` into tokens (ending with [`TokKind::Eof`]); problems go to `diags`.
pub fn lex(src: &str, diags: &mut Vec<Diagnostic>) -> Vec<Token> {
    let mut lx = Lexer {
        src,
        b: src.as_bytes(),
        // A UTF-8 byte-order mark (as some Windows editors write) is not code.
        i: if src.starts_with('\u{feff}') { 3 } else { 0 },
        toks: Vec::with_capacity(src.len() / 3 + 1),
        diags,
    };
    lx.run();
    lx.toks
}

struct Lexer<'a, 'd> {
    src: &'a str,
    b: &'a [u8],
    i: usize,
    toks: Vec<Token>,
    diags: &'d mut Vec<Diagnostic>,
}

fn is_ident_start(c: u8) -> bool {
    c.is_ascii_alphabetic() || c == b'_'
}

fn is_ident_char(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_'
}

impl Lexer<'_, '_> {
    fn peek(&self, k: usize) -> u8 {
        self.b.get(self.i + k).copied().unwrap_or(0)
    }

    fn push(&mut self, kind: TokKind, start: usize) {
        self.toks.push(Token {
            kind,
            span: Span::new(start, self.i),
        });
    }

    fn error(&mut self, code: Code, start: usize, end: usize, msg: String, help: Option<&str>) {
        let mut d = Diagnostic::error(code, msg, Span::new(start, end));
        if let Some(h) = help {
            d = d.with_help(h);
        }
        self.diags.push(d);
    }

    fn run(&mut self) {
        while self.i < self.b.len() {
            let c = self.b[self.i];
            let start = self.i;
            if c.is_ascii_whitespace() {
                self.i += 1;
            } else if c == b'/' && self.peek(1) == b'/' {
                while self.i < self.b.len() && self.b[self.i] != b'\n' {
                    self.i += 1;
                }
            } else if c == b'/' && self.peek(1) == b'*' {
                self.block_comment();
            } else if is_ident_start(c) {
                while self.i < self.b.len() && is_ident_char(self.b[self.i]) {
                    self.i += 1;
                }
                let text = &self.src[start..self.i];
                let kind = KEYWORDS
                    .iter()
                    .find(|(k, _)| *k == text)
                    .map_or(TokKind::Ident, |(_, k)| TokKind::Kw(*k));
                self.push(kind, start);
            } else if c.is_ascii_digit() {
                self.number();
            } else if c == b'"' {
                self.string();
            } else {
                self.punct(c, start);
            }
        }
        let end = self.b.len();
        self.toks.push(Token {
            kind: TokKind::Eof,
            span: Span::new(end, end),
        });
    }

    fn block_comment(&mut self) {
        let start = self.i;
        self.i += 2;
        let mut depth = 1;
        while self.i < self.b.len() {
            if self.b[self.i] == b'*' && self.peek(1) == b'/' {
                depth -= 1;
                self.i += 2;
                if depth == 0 {
                    return;
                }
            } else if self.b[self.i] == b'/' && self.peek(1) == b'*' {
                depth += 1;
                self.i += 2;
            } else {
                self.i += 1;
            }
        }
        self.error(
            Code::E0002,
            start,
            start + 2,
            "this block comment is never closed".into(),
            Some("close it with */"),
        );
    }

    fn string(&mut self) {
        let start = self.i;
        self.i += 1;
        let mut text = String::new();
        loop {
            let Some(ch) = self.src[self.i..].chars().next() else {
                self.error(
                    Code::E0002,
                    start,
                    start + 1,
                    "this string is never closed".into(),
                    Some("end it with \" on the same line"),
                );
                self.push(TokKind::Error, start);
                return;
            };
            match ch {
                '"' => {
                    self.i += 1;
                    break;
                }
                '\n' => {
                    self.error(
                        Code::E0002,
                        start,
                        self.i,
                        "this string is never closed".into(),
                        Some("end it with \" on the same line"),
                    );
                    self.push(TokKind::Error, start);
                    return;
                }
                '\\' => {
                    let esc = self.src[self.i + 1..].chars().next();
                    let out = match esc {
                        Some('n') => Some('\n'),
                        Some('t') => Some('\t'),
                        Some('"') => Some('"'),
                        Some('\\') => Some('\\'),
                        _ => None,
                    };
                    match out {
                        Some(o) => {
                            text.push(o);
                            self.i += 2;
                        }
                        None => {
                            let len = 1 + esc.map_or(0, char::len_utf8);
                            self.error(
                                Code::E0001,
                                self.i,
                                self.i + len,
                                "unknown escape in a string".into(),
                                Some("the escapes are \\n, \\t, \\\" and \\\\"),
                            );
                            self.i += len;
                        }
                    }
                }
                c => {
                    text.push(c);
                    self.i += c.len_utf8();
                }
            }
        }
        self.push(TokKind::Str(text), start);
    }

    fn number(&mut self) {
        let start = self.i;
        while self.peek(0).is_ascii_digit() {
            self.i += 1;
        }
        let mut real = false;
        if self.peek(0) == b'.' && self.peek(1).is_ascii_digit() {
            real = true;
            self.i += 1;
            while self.peek(0).is_ascii_digit() {
                self.i += 1;
            }
        }
        let e = self.peek(0);
        if (e == b'e' || e == b'E')
            && (self.peek(1).is_ascii_digit()
                || (matches!(self.peek(1), b'+' | b'-') && self.peek(2).is_ascii_digit()))
        {
            real = true;
            self.i += 2;
            while self.peek(0).is_ascii_digit() {
                self.i += 1;
            }
        }
        let digits = &self.src[start..self.i];
        let value: f64 = digits.parse().unwrap_or(f64::INFINITY);
        // A unit?
        let c = self.peek(0);
        if c == b'%' {
            self.i += 1;
            self.push(TokKind::Quantity(value * 0.01, Dim::PLAIN), start);
            return;
        }
        if is_ident_start(c) {
            let ustart = self.i;
            while is_ident_char(self.peek(0)) {
                self.i += 1;
            }
            let unit = &self.src[ustart..self.i];
            let Some(&(_, factor, dim)) = UNITS.iter().find(|(u, _, _)| *u == unit) else {
                self.error(
                    Code::E0003,
                    ustart,
                    self.i,
                    format!("unknown unit `{unit}`"),
                    Some(UNIT_HELP),
                );
                self.push(TokKind::Error, start);
                return;
            };
            let mut si = value * factor;
            let mut dim = dim;
            // `/s`, `/s2` or `/s3` glued to a base unit of length or angle.
            if self.peek(0) == b'/' && self.peek(1) == b's' && dim != Dim::TIME {
                let power = match self.peek(2) {
                    b'2' | b'3' if !is_ident_char(self.peek(3)) => (self.peek(2) - b'0') as i8,
                    c if !is_ident_char(c) => 1,
                    _ => 0,
                };
                if power > 0 {
                    self.i += if power > 1 { 3 } else { 2 };
                    dim.time = -power;
                    si = value * factor;
                }
            }
            self.push_finite(TokKind::Quantity(si, dim), si, start);
            return;
        }
        if real {
            self.push_finite(TokKind::Num(value), value, start);
        } else {
            match digits.parse::<i64>() {
                Ok(v) => self.push(TokKind::Int(v), start),
                Err(_) => {
                    self.error(
                        Code::E0004,
                        start,
                        self.i,
                        "this integer does not fit in 64 bits".into(),
                        Some("integers range from -9223372036854775808 to 9223372036854775807; write a real number (with a decimal point) for larger values"),
                    );
                    self.push(TokKind::Error, start);
                }
            }
        }
    }

    /// Pushes a number token, or an error if `value` overflowed to infinity.
    fn push_finite(&mut self, kind: TokKind, value: f64, start: usize) {
        if value.is_finite() {
            self.push(kind, start);
        } else {
            self.error(
                Code::E0004,
                start,
                self.i,
                "this number is too large".into(),
                Some("numbers must stay below about 1.8e308 in magnitude"),
            );
            self.push(TokKind::Error, start);
        }
    }

    fn punct(&mut self, c: u8, start: usize) {
        use Punct::*;
        let two = [c, self.peek(1)];
        let p2 = match &two {
            b".." => Some(DotDot),
            b"->" => Some(Arrow),
            b"+=" => Some(PlusAssign),
            b"-=" => Some(MinusAssign),
            b"*=" => Some(StarAssign),
            b"/=" => Some(SlashAssign),
            b"==" => Some(EqEq),
            b"!=" => Some(Ne),
            b"<=" => Some(Le),
            b">=" => Some(Ge),
            b"&&" => Some(AndAnd),
            b"||" => Some(OrOr),
            _ => None,
        };
        if let Some(p) = p2 {
            self.i += 2;
            self.push(TokKind::P(p), start);
            return;
        }
        let p1 = match c {
            b'(' => Some(LParen),
            b')' => Some(RParen),
            b'{' => Some(LBrace),
            b'}' => Some(RBrace),
            b'[' => Some(LBracket),
            b']' => Some(RBracket),
            b',' => Some(Comma),
            b';' => Some(Semi),
            b':' => Some(Colon),
            b'.' => Some(Dot),
            b'+' => Some(Plus),
            b'-' => Some(Minus),
            b'*' => Some(Star),
            b'/' => Some(Slash),
            b'=' => Some(Assign),
            b'<' => Some(Lt),
            b'>' => Some(Gt),
            b'!' => Some(Bang),
            _ => None,
        };
        if let Some(p) = p1 {
            self.i += 1;
            self.push(TokKind::P(p), start);
            return;
        }
        let ch = self.src[self.i..].chars().next().unwrap_or('\u{fffd}');
        self.i += ch.len_utf8().max(1);
        let help = match ch {
            '%' => Some("`%` is a unit: write it right after a number, as in 50%"),
            '\'' => Some("strings use double quotes: \"text\""),
            '…' => Some("`…` is a placeholder in examples; write the statements"),
            _ => None,
        };
        self.error(
            Code::E0001,
            start,
            self.i,
            format!("unexpected character `{ch}`"),
            help,
        );
        self.push(TokKind::Error, start);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(s: &str) -> Vec<TokKind> {
        let mut d = Vec::new();
        let t = lex(s, &mut d);
        assert!(d.is_empty(), "{d:?}");
        t.into_iter().map(|t| t.kind).collect()
    }

    #[test]
    fn quantities_are_si_with_dimensions() {
        let k = kinds("250mm/s 90deg 2s 50% 200mm / 2s 1.5m/s2");
        assert_eq!(k[0], TokKind::Quantity(0.25, Dim::SPEED));
        assert!(
            matches!(k[1], TokKind::Quantity(x, Dim::ANGLE) if (x - std::f64::consts::FRAC_PI_2).abs() < 1e-15)
        );
        assert_eq!(k[2], TokKind::Quantity(2.0, Dim::TIME));
        assert_eq!(k[3], TokKind::Quantity(0.5, Dim::PLAIN));
        assert_eq!(k[4], TokKind::Quantity(0.2, Dim::LENGTH));
        assert_eq!(k[5], TokKind::P(Punct::Slash));
        assert_eq!(k[7], TokKind::Quantity(1.5, Dim::ACCEL));
    }

    #[test]
    fn ranges_are_not_decimals() {
        let k = kinds("0..n");
        assert_eq!(k[0], TokKind::Int(0));
        assert_eq!(k[1], TokKind::P(Punct::DotDot));
    }

    #[test]
    fn unknown_units_are_reported() {
        let mut d = Vec::new();
        lex("delay 2x;", &mut d);
        assert_eq!(d.len(), 1);
        assert_eq!(d[0].code, Code::E0003);
    }
}

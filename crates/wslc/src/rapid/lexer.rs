//! The RAPID lexer: text to tokens, never failing.
//!
//! RAPID is case-insensitive: identifiers keep their spelling (for messages) and the
//! parser compares words with [`Token::is`]. Comments run from `!` to the end of the line.
//! Numbers are plain decimals with an optional exponent (`9E9`, `1.5e-3`); RAPID numbers
//! have no units, the front-end gives them (mm, degrees, seconds) by where they are used.
//! Strings are `"…"` with `""` or `\"` for a quote and `\\` for a backslash. Bad input
//! (an unknown character, an unterminated string) becomes an [`Tok::Error`] token and a
//! diagnostic, and lexing goes on.

use crate::diag::{Code, Diagnostic};
use crate::syntax::Span;

/// What a token is.
#[derive(Clone, Debug, PartialEq)]
pub enum Tok {
    /// An identifier or a reserved word (compared case-insensitively by the parser).
    Ident,
    /// A number.
    Num(f64),
    /// A string literal, escapes resolved.
    Str(String),
    /// `:=`
    Assign,
    /// `,`
    Comma,
    /// `;`
    Semi,
    /// `:`
    Colon,
    /// `(`
    LParen,
    /// `)`
    RParen,
    /// `[`
    LBracket,
    /// `]`
    RBracket,
    /// `{`
    LBrace,
    /// `}`
    RBrace,
    /// `\`: an optional argument or parameter follows.
    Backslash,
    /// `.`
    Dot,
    /// `+`
    Plus,
    /// `-`
    Minus,
    /// `*`
    Star,
    /// `/`
    Slash,
    /// `=`
    Eq,
    /// `<>`
    Ne,
    /// `<`
    Lt,
    /// `<=`
    Le,
    /// `>`
    Gt,
    /// `>=`
    Ge,
    /// `%`: late binding (`%name%`), not supported but recognised for a clear message.
    Percent,
    /// `|`: alternative optional parameters.
    Bar,
    /// `<` placeholders of the teach pendant (`<SMT>`) end up as `Lt` … `Gt`; `?` too.
    Question,
    /// End of input.
    Eof,
    /// Something unreadable (already reported).
    Error,
}

/// A token and where it is.
#[derive(Clone, Debug, PartialEq)]
pub struct Token {
    /// What it is.
    pub tok: Tok,
    /// Where.
    pub span: Span,
}

impl Token {
    /// True if this is the identifier or reserved word `word`, in any case.
    pub fn is(&self, src: &str, word: &str) -> bool {
        self.tok == Tok::Ident && src[self.span.range()].eq_ignore_ascii_case(word)
    }
}

impl crate::frontend::Lexeme for Token {
    fn span_mut(&mut self) -> &mut Span {
        &mut self.span
    }
    fn span(&self) -> Span {
        self.span
    }
    fn is_eof(&self) -> bool {
        self.tok == Tok::Eof
    }
    fn is_error(&self) -> bool {
        self.tok == Tok::Error
    }
    fn eof(at: Span) -> Self {
        Token {
            tok: Tok::Eof,
            span: at,
        }
    }
}

/// Turns a RAPID source into tokens, ending with [`Tok::Eof`]. Problems are added to
/// `diags`.
pub fn lex(src: &str, diags: &mut Vec<Diagnostic>) -> Vec<Token> {
    let bytes = src.as_bytes();
    let mut toks = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        let start = i;
        if c.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        if c == b'!' {
            while i < bytes.len() && bytes[i] != b'\n' {
                i += 1;
            }
            continue;
        }
        let tok = if c.is_ascii_alphabetic() || c == b'_' {
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            Tok::Ident
        } else if c.is_ascii_digit()
            || (c == b'.' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit))
        {
            i = number_end(bytes, i);
            let text = &src[start..i];
            match text.parse::<f64>() {
                Ok(x) if x.is_finite() => Tok::Num(x),
                _ => {
                    diags.push(
                        Diagnostic::error(
                            Code::E0004,
                            format!("`{text}` is not a number RAPID can hold"),
                            Span::new(start, i),
                        )
                        .with_help("RAPID numbers are decimal, at most about 3.4E38"),
                    );
                    Tok::Error
                }
            }
        } else if c == b'"' {
            let (tok, end) = string(src, start, diags);
            i = end;
            tok
        } else {
            let two = bytes.get(i + 1).copied();
            let (t, n) = match (c, two) {
                (b':', Some(b'=')) => (Tok::Assign, 2),
                (b'<', Some(b'>')) => (Tok::Ne, 2),
                (b'<', Some(b'=')) => (Tok::Le, 2),
                (b'>', Some(b'=')) => (Tok::Ge, 2),
                (b',', _) => (Tok::Comma, 1),
                (b';', _) => (Tok::Semi, 1),
                (b':', _) => (Tok::Colon, 1),
                (b'(', _) => (Tok::LParen, 1),
                (b')', _) => (Tok::RParen, 1),
                (b'[', _) => (Tok::LBracket, 1),
                (b']', _) => (Tok::RBracket, 1),
                (b'{', _) => (Tok::LBrace, 1),
                (b'}', _) => (Tok::RBrace, 1),
                (b'\\', _) => (Tok::Backslash, 1),
                (b'.', _) => (Tok::Dot, 1),
                (b'+', _) => (Tok::Plus, 1),
                (b'-', _) => (Tok::Minus, 1),
                (b'*', _) => (Tok::Star, 1),
                (b'/', _) => (Tok::Slash, 1),
                (b'=', _) => (Tok::Eq, 1),
                (b'<', _) => (Tok::Lt, 1),
                (b'>', _) => (Tok::Gt, 1),
                (b'%', _) => (Tok::Percent, 1),
                (b'|', _) => (Tok::Bar, 1),
                (b'?', _) => (Tok::Question, 1),
                _ => {
                    let ch = src[i..].chars().next().unwrap_or('\u{fffd}');
                    let n = ch.len_utf8();
                    diags.push(Diagnostic::error(
                        Code::E0001,
                        format!(
                            "unexpected character `{}` in a RAPID module",
                            ch.escape_debug()
                        ),
                        Span::new(i, i + n),
                    ));
                    (Tok::Error, n)
                }
            };
            i += n;
            t
        };
        toks.push(Token {
            tok,
            span: Span::new(start, i),
        });
    }
    toks.push(Token {
        tok: Tok::Eof,
        span: Span::new(bytes.len(), bytes.len()),
    });
    toks
}

fn number_end(b: &[u8], mut i: usize) -> usize {
    while i < b.len() && b[i].is_ascii_digit() {
        i += 1;
    }
    if i < b.len() && b[i] == b'.' {
        i += 1;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        let mut j = i + 1;
        if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
            j += 1;
        }
        if j < b.len() && b[j].is_ascii_digit() {
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
            i = j;
        }
    }
    i
}

fn string(src: &str, start: usize, diags: &mut Vec<Diagnostic>) -> (Tok, usize) {
    let mut out = String::new();
    let mut chars = src[start + 1..].char_indices().peekable();
    while let Some((k, ch)) = chars.next() {
        let at = start + 1 + k;
        match ch {
            '"' => {
                if let Some(&(_, '"')) = chars.peek() {
                    chars.next();
                    out.push('"');
                } else {
                    return (Tok::Str(out), at + 1);
                }
            }
            '\\' => match chars.peek() {
                Some(&(_, '\\')) => {
                    chars.next();
                    out.push('\\');
                }
                Some(&(_, '"')) => {
                    chars.next();
                    out.push('"');
                }
                _ => out.push('\\'),
            },
            '\n' => break,
            c => out.push(c),
        }
    }
    let end = src[start..].find('\n').map_or(src.len(), |n| start + n);
    diags.push(
        Diagnostic::error(
            Code::E0002,
            "this string has no closing `\"` on its line",
            Span::new(start, end),
        )
        .with_help("end the string with `\"` before the end of the line"),
    );
    (Tok::Error, end)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(src: &str) -> Vec<Tok> {
        let mut d = Vec::new();
        let t = lex(src, &mut d);
        assert!(d.is_empty(), "{d:?}");
        t.into_iter().map(|t| t.tok).collect()
    }

    #[test]
    fn tokens_of_a_motion() {
        use Tok::*;
        assert_eq!(
            kinds("MoveL Offs(p10,0,0,-5E1), v100\\V:=50, z10; ! c"),
            vec![
                Ident,
                Ident,
                LParen,
                Ident,
                Comma,
                Num(0.0),
                Comma,
                Num(0.0),
                Comma,
                Minus,
                Num(50.0),
                RParen,
                Comma,
                Ident,
                Backslash,
                Ident,
                Assign,
                Num(50.0),
                Comma,
                Ident,
                Semi,
                Eof
            ]
        );
    }

    #[test]
    fn strings_and_bad_input() {
        assert_eq!(kinds(r#""a""b\\c""#)[0], Tok::Str("a\"b\\c".into()));
        let mut d = Vec::new();
        let t = lex("x := \"open\n$ 1E999;", &mut d);
        assert_eq!(d.len(), 3, "{d:?}");
        assert_eq!(t.last().map(|t| &t.tok), Some(&Tok::Eof));
    }
}

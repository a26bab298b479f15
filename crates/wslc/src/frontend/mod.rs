//! The front-end kit every language's parser is built from: what WSL's and RAPID's
//! parsers share, so that a next language (KUKA KRL) is a token type, a parser and a
//! translation table, not a third copy of the machinery.
//!
//! - [`Span`] (of [`crate::syntax`]): a byte range of a program's joined text (every token
//!   and node has one);
//! - [`program::ProgramText`]: a program's files joined into one text, each lexed and
//!   parsed on its own ([`program::ProgramText::parse_each`]), positions and diagnostics
//!   mapped back to their file;
//! - [`Lexeme`]: what the kit needs of a language's tokens (span, end of file, a token
//!   the lexer already reported);
//! - [`Parser`]: the token cursor (`tok`, `peek`, `bump`, `eat_if`, the previous token's
//!   end where a missing `;` goes), error reporting with a cap per file and no second
//!   error on a token the lexer reported, recovery (`skip_until`, `skip_to_end`), and
//!   the nesting limit (`deeper`/`leave`). A language's parser is an `impl` block on
//!   `Parser<'_, '_, ItsToken>` with its grammar, its words and its messages.

pub(crate) mod program;

use crate::diag::Diagnostic;
pub(crate) use crate::syntax::Span;

/// What the kit needs of a language's token.
pub(crate) trait Lexeme: Clone {
    /// Where it is.
    fn span_mut(&mut self) -> &mut Span;
    /// Where it is.
    fn span(&self) -> Span;
    /// The end of the file (a lexer ends every file with one).
    fn is_eof(&self) -> bool;
    /// Text the lexer could not read and has reported already.
    fn is_error(&self) -> bool;
    /// An end-of-file token at `at`.
    fn eof(at: Span) -> Self;
}

/// A parse failure that has been reported; the caller recovers.
#[derive(Debug)]
pub(crate) struct Reported;

/// A parse step's result.
pub(crate) type PResult<T> = Result<T, Reported>;

/// A language's limits on one file's parse.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Limits {
    /// How deeply blocks and expressions may nest (past it: E0006, never a stack
    /// overflow).
    pub(crate) max_depth: u32,
    /// At most this many errors are reported per file (`usize::MAX`: all).
    pub(crate) max_errors: usize,
}

/// The state of one file's parse: the tokens and the cursor in them, the diagnostics,
/// the nesting depth. Never indexes out of the tokens: the last is always the end of the
/// file, and the cursor never moves past it.
pub(crate) struct Parser<'s, 'd, T> {
    /// The program's joined text (token spans index it).
    pub(crate) src: &'s str,
    toks: Vec<T>,
    pos: usize,
    /// Where errors go.
    pub(crate) diags: &'d mut Vec<Diagnostic>,
    /// How deeply the parse is nested now.
    pub(crate) depth: u32,
    /// Errors reported so far (past `limits.max_errors`, counted but not kept).
    errors: usize,
    /// The language's limits.
    pub(crate) limits: Limits,
}

impl<'s, 'd, T: Lexeme> Parser<'s, 'd, T> {
    /// A parse of `toks` (a lexer's output for one file of `src`; an end-of-file token is
    /// added if it lacks one).
    pub(crate) fn new(
        src: &'s str,
        mut toks: Vec<T>,
        diags: &'d mut Vec<Diagnostic>,
        limits: Limits,
    ) -> Self {
        if !toks.last().is_some_and(T::is_eof) {
            let end = toks.last().map_or(Span::default(), |t| {
                let e = t.span().end as usize;
                Span::new(e, e)
            });
            toks.push(T::eof(end));
        }
        Parser {
            src,
            toks,
            pos: 0,
            diags,
            depth: 0,
            errors: 0,
            limits,
        }
    }

    /// The token at the cursor.
    pub(crate) fn tok(&self) -> &T {
        &self.toks[self.pos.min(self.toks.len() - 1)]
    }

    /// The token `n` after the cursor (the end of the file past it).
    pub(crate) fn peek(&self, n: usize) -> &T {
        &self.toks[self.pos.saturating_add(n).min(self.toks.len() - 1)]
    }

    /// The token before the cursor, if any.
    pub(crate) fn prev(&self) -> Option<&T> {
        self.pos.checked_sub(1).and_then(|i| self.toks.get(i))
    }

    /// Where the cursor is, as a count of tokens consumed (to tell whether a step moved).
    pub(crate) fn mark(&self) -> usize {
        self.pos
    }

    /// The span of the token at the cursor.
    pub(crate) fn span(&self) -> Span {
        self.tok().span()
    }

    /// The span of the token before the cursor (empty at the start).
    pub(crate) fn prev_span(&self) -> Span {
        self.prev().map_or(Span::default(), T::span)
    }

    /// The empty span just after the previous token: where a missing `;` goes.
    pub(crate) fn after_prev(&self) -> Span {
        let end = self.prev_span().end as usize;
        Span::new(end, end)
    }

    /// The source text of `s` (empty if it is not in the text).
    pub(crate) fn text(&self, s: Span) -> &'s str {
        self.src.get(s.range()).unwrap_or("")
    }

    /// At the end of the file.
    pub(crate) fn at_end(&self) -> bool {
        self.tok().is_eof()
    }

    /// The token at the cursor, moving past it (never past the end of the file).
    pub(crate) fn bump(&mut self) -> T {
        let t = self.tok().clone();
        if !t.is_eof() {
            self.pos += 1;
        }
        t
    }

    /// Moves past the token at the cursor if `at` holds for it.
    pub(crate) fn eat_if(&mut self, at: impl Fn(&Self) -> bool) -> bool {
        let yes = at(self);
        if yes {
            self.bump();
        }
        yes
    }

    /// Recovery: moves to the first token (from the cursor's) where `stop` holds, or to
    /// the end of the file.
    pub(crate) fn skip_until(&mut self, stop: impl Fn(&Self) -> bool) {
        while !self.at_end() && !stop(self) {
            self.bump();
        }
    }

    /// Recovery: to just past the first token where `stop` holds (or to the end).
    pub(crate) fn skip_past(&mut self, stop: impl Fn(&Self) -> bool) {
        self.skip_until(stop);
        self.bump();
    }

    /// Recovery from what cannot be parsed at all: the rest of the file is skipped.
    pub(crate) fn skip_to_end(&mut self) {
        self.pos = self.toks.len() - 1;
    }

    /// Adds an error (unless the file has had `max_errors` already, or the cursor is on a
    /// token the lexer reported: one mistake, one error) and returns that it was reported.
    pub(crate) fn report(&mut self, d: Diagnostic) -> Reported {
        if self.errors < self.limits.max_errors && !self.tok().is_error() {
            self.diags.push(d);
        }
        self.errors += 1;
        Reported
    }

    /// One level deeper, if the language's nesting limit allows it (else nothing changes
    /// and the language's parser reports E0006 in its words). Every `true` is matched by
    /// a [`Parser::leave`].
    pub(crate) fn deeper(&mut self) -> bool {
        if self.depth >= self.limits.max_depth {
            return false;
        }
        self.depth += 1;
        true
    }

    /// One level back out.
    pub(crate) fn leave(&mut self) {
        self.depth = self.depth.saturating_sub(1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Clone, Debug, PartialEq)]
    struct T(char, Span);

    impl Lexeme for T {
        fn span_mut(&mut self) -> &mut Span {
            &mut self.1
        }
        fn span(&self) -> Span {
            self.1
        }
        fn is_eof(&self) -> bool {
            self.0 == '$'
        }
        fn is_error(&self) -> bool {
            self.0 == '?'
        }
        fn eof(at: Span) -> Self {
            T('$', at)
        }
    }

    fn toks(s: &str) -> Vec<T> {
        s.char_indices()
            .map(|(i, c)| T(c, Span::new(i, i + 1)))
            .collect()
    }

    const LIMITS: Limits = Limits {
        max_depth: 2,
        max_errors: 2,
    };

    #[test]
    fn the_cursor_stops_at_the_end_of_the_file() {
        let mut diags = Vec::new();
        // No end-of-file token: one is added after the last.
        let mut p = Parser::new("ab;c", toks("ab;c"), &mut diags, LIMITS);
        assert_eq!(p.peek(10).span(), Span::new(4, 4));
        assert!(p.eat_if(|p| p.text(p.span()) == "a"));
        assert!(!p.eat_if(|p| p.text(p.span()) == "a"));
        assert_eq!(p.after_prev(), Span::new(1, 1));
        p.skip_past(|p| p.tok().0 == ';');
        assert_eq!(p.tok().0, 'c');
        p.skip_until(|_| false);
        assert!(p.at_end());
        assert!(p.bump().is_eof() && p.at_end());
        let empty = Parser::new("", Vec::<T>::new(), &mut diags, LIMITS);
        assert!(empty.at_end() && empty.prev().is_none());
    }

    #[test]
    fn errors_are_capped_and_not_repeated_on_a_lexer_error() {
        let mut diags = Vec::new();
        let mut p = Parser::new("x?", toks("x?$"), &mut diags, LIMITS);
        let e = || Diagnostic::error(crate::Code::E0005, "e", Span::default());
        let _ = p.report(e());
        p.bump();
        // On the lexer's error: counted, not kept.
        let _ = p.report(e());
        p.bump();
        // Past the cap.
        let _ = p.report(e());
        assert_eq!(diags.len(), 1);
    }

    #[test]
    fn nesting_stops_at_the_limit() {
        let mut diags = Vec::new();
        let mut p = Parser::new("", toks("$"), &mut diags, LIMITS);
        assert!(p.deeper() && p.deeper());
        assert!(!p.deeper());
        assert_eq!(p.depth, 2);
        p.leave();
        assert!(p.deeper());
    }
}

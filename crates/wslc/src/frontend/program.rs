//! A program's source text: one file, or several (a RAPID task's modules, a WSL program
//! with its library files), joined one after another.
//!
//! The front-ends lex and parse each file on its own (an unterminated comment or block
//! never runs into the next file) and give every span as a byte offset into the joined
//! text, so one syntax tree covers all the files. [`ProgramText`] turns such an offset
//! back into a file and a `line:col` in it: for the module's positions
//! ([`vworks_vm::SrcPos`]'s `file` is the file's index) and for diagnostics, whose spans
//! it rebases onto their file's own text for rendering.

use vworks_vm::bytecode::SrcPos;

use super::{Lexeme, Span};
use crate::diag::{Diagnostic, LineIndex};

/// One file of a program.
struct File {
    path: String,
    /// Byte offset of its text in the joined text.
    start: usize,
    /// Length of its text.
    len: usize,
    index: LineIndex,
}

/// The joined text of a program's files, with each file's place in it.
pub(crate) struct ProgramText {
    text: String,
    files: Vec<File>,
}

impl ProgramText {
    /// Joins `files` ((path, text) in order), each after a newline that belongs to none,
    /// so the end of one file (where its end-of-file token is) is not the start of the
    /// next.
    pub(crate) fn new(files: &[(&str, &str)]) -> ProgramText {
        let mut text = String::new();
        let mut out = Vec::with_capacity(files.len());
        for (i, (path, src)) in files.iter().enumerate() {
            if i > 0 {
                text.push('\n');
            }
            out.push(File {
                path: (*path).to_string(),
                start: text.len(),
                len: src.len(),
                index: LineIndex::new(src),
            });
            text.push_str(src);
        }
        ProgramText { text, files: out }
    }

    /// The joined text (spans index it).
    pub(crate) fn text(&self) -> &str {
        &self.text
    }

    /// The files' paths, in order.
    pub(crate) fn paths(&self) -> Vec<String> {
        self.files.iter().map(|f| f.path.clone()).collect()
    }

    /// Each file as (its index, the offset of its text, its text).
    pub(crate) fn files(&self) -> impl Iterator<Item = (usize, usize, &str)> {
        self.files
            .iter()
            .enumerate()
            .map(|(i, f)| (i, f.start, &self.text[f.start..f.start + f.len]))
    }

    /// Each file lexed with its front-end's `lex` and parsed on its own with `parse`
    /// (which gets the joined text and the file's tokens), as (the offset of the file's
    /// text, what `parse` made of it), in file order.
    pub(crate) fn parse_each<T: Lexeme, R>(
        &self,
        diags: &mut Vec<Diagnostic>,
        lex: impl Fn(&str, &mut Vec<Diagnostic>) -> Vec<T>,
        mut parse: impl FnMut(&str, Vec<T>, &mut Vec<Diagnostic>) -> R,
    ) -> Vec<(usize, R)> {
        let mut out = Vec::with_capacity(self.files.len());
        for (_, start, text) in self.files() {
            let toks = ProgramText::lex(start, text, diags, &lex);
            out.push((start, parse(self.text(), toks, diags)));
        }
        out
    }

    /// Lexes a file's `text` (at byte `start` of the joined text) with its front-end's
    /// `lex`, moving the spans of its tokens and of the diagnostics it adds onto the
    /// joined text.
    fn lex<T: Lexeme>(
        start: usize,
        text: &str,
        diags: &mut Vec<Diagnostic>,
        lex: impl Fn(&str, &mut Vec<Diagnostic>) -> Vec<T>,
    ) -> Vec<T> {
        let first_new = diags.len();
        let mut toks = lex(text, diags);
        for t in &mut toks {
            let s = t.span_mut();
            *s = s.shifted(start);
        }
        for d in &mut diags[first_new..] {
            let places = std::iter::once(&mut d.at).chain(d.related.iter_mut().map(|n| &mut n.at));
            for s in places.filter_map(|loc| loc.span.as_mut()) {
                *s = s.shifted(start);
            }
        }
        toks
    }

    /// The index of the file that holds byte `offset` of the joined text (the last file
    /// for an offset past the end; the first for a program without files).
    fn file_at(&self, offset: usize) -> usize {
        self.files
            .partition_point(|f| f.start <= offset)
            .saturating_sub(1)
    }

    /// The position of byte `offset` of the joined text.
    pub(crate) fn pos(&self, offset: usize) -> SrcPos {
        let i = self.file_at(offset);
        let Some(f) = self.files.get(i) else {
            return SrcPos::default();
        };
        let (line, col) = f.index.line_col(offset.saturating_sub(f.start));
        SrcPos {
            file: i as u32,
            line,
            col,
        }
    }

    /// The order of `path` among the files (for sorting diagnostics; files not of this
    /// program after them).
    pub(crate) fn order_of(&self, path: &str) -> usize {
        self.files
            .iter()
            .position(|f| f.path == path)
            .unwrap_or(self.files.len())
    }

    /// Fills in a diagnostic's places that have a span but no file: the file the span
    /// starts in, the span rebased onto that file's text, and its line and column.
    pub(crate) fn resolve(&self, d: &mut Diagnostic) {
        let places = std::iter::once(&mut d.at).chain(d.related.iter_mut().map(|n| &mut n.at));
        for loc in places {
            if !loc.file.is_empty() {
                continue;
            }
            let start = loc.span.map_or(0, |s| s.start as usize);
            let Some(f) = self.files.get(self.file_at(start)) else {
                continue;
            };
            loc.file = f.path.clone();
            if let Some(span) = loc.span {
                let local = |o: u32| (o as usize).saturating_sub(f.start).min(f.len);
                let (s, e) = (local(span.start), local(span.end));
                loc.span = Some(Span::new(s, e.max(s)));
                if loc.line == 0 {
                    let (l, c) = f.index.line_col(s);
                    loc.line = l;
                    loc.col = c;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_map_to_their_file_line_and_column() {
        let p = ProgramText::new(&[("a.mod", "ab\ncd"), ("b.mod", "x\ny\n")]);
        assert_eq!(p.text(), "ab\ncd\nx\ny\n");
        let at = |o| {
            let s = p.pos(o);
            (s.file, s.line, s.col)
        };
        assert_eq!(at(0), (0, 1, 1));
        assert_eq!(at(4), (0, 2, 2));
        // The end of a.mod (its end-of-file token) is still a.mod.
        assert_eq!(at(5), (0, 2, 3));
        assert_eq!(at(6), (1, 1, 1));
        assert_eq!(at(8), (1, 2, 1));
        let files: Vec<_> = p.files().map(|(i, s, t)| (i, s, t.to_string())).collect();
        assert_eq!(files[1], (1, 6, "x\ny\n".to_string()));
    }

    #[test]
    fn a_diagnostic_is_rebased_onto_its_file() {
        let p = ProgramText::new(&[("a.mod", "ab\ncd"), ("b.mod", "x\nyy\n")]);
        let mut d = Diagnostic::error(crate::Code::E0300, "m", Span::new(8, 10));
        p.resolve(&mut d);
        assert_eq!(d.at.file, "b.mod");
        assert_eq!(d.at.span, Some(Span::new(2, 4)));
        assert_eq!((d.at.line, d.at.col), (2, 1));
    }
}

//! Diagnostics: stable codes, positions and rendering.
//!
//! A [`Diagnostic`] names its file, a byte span (or, for link-time problems found in
//! bytecode, a line and column), a stable [`Code`], a message, and optionally a help line,
//! notes and secondary labels. [`render`] prints them like rustc does — `file:line:col`,
//! the source line and a caret under the span — through `codespan-reporting`; without the
//! source text it falls back to `--> file:line:col`.

use std::fmt;

use codespan_reporting::diagnostic as cs;
use codespan_reporting::files::SimpleFiles;
use codespan_reporting::term;

use crate::syntax::Span;

macro_rules! codes {
    ($($code:ident = $title:literal,)*) => {
        /// A stable diagnostic code. `E…` are errors, `W…` warnings. Codes never change
        /// meaning; `docs/language.md` lists them all.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[allow(missing_docs)]
        pub enum Code { $($code,)* }

        impl Code {
            /// Every code in order.
            pub const ALL: &'static [Code] = &[$(Code::$code,)*];

            /// The code as printed, e.g. `E0021`.
            pub fn as_str(self) -> &'static str {
                match self { $(Code::$code => stringify!($code),)* }
            }

            /// A one-line title of what the code means.
            pub fn title(self) -> &'static str {
                match self { $(Code::$code => $title,)* }
            }
        }
    };
}

codes! {
    E0001 = "unexpected character",
    E0002 = "unterminated string or comment",
    E0003 = "unknown unit",
    E0004 = "number out of range",
    E0005 = "syntax error",
    E0006 = "nesting too deep",
    E0010 = "unknown name",
    E0011 = "unknown procedure or function",
    E0012 = "duplicate declaration",
    E0013 = "wrong number of arguments",
    E0014 = "unknown type",
    E0020 = "type mismatch",
    E0021 = "unit mismatch",
    E0022 = "operator or field not applicable",
    E0023 = "not assignable",
    E0024 = "condition is not a bool",
    E0025 = "value out of range",
    E0026 = "division by zero or overflow in a constant",
    E0030 = "`break` or `continue` outside a loop",
    E0031 = "return value mismatch",
    E0032 = "function may end without a value",
    E0033 = "procedure used as a value",
    E0034 = "text outside `log` and `fail`",
    E0040 = "condition can never change",
    E0041 = "clock or robot state in a condition",
    E0042 = "module variable in a condition",
    E0050 = "`when` handler takes time",
    E0051 = "handler is not a procedure",
    E0060 = "`remote` outside `parallel`",
    E0061 = "more than one local branch in `parallel`",
    E0062 = "statement not allowed directly in `parallel`",
    E0063 = "`return`, `break` or `continue` leaves a `parallel` block",
    E0070 = "not allowed in a function",
    E0080 = "initializer is not constant",
    E0081 = "global of a non-scalar type",
    E0082 = "parameter of a non-scalar type",
    E0083 = "parameter without a default value",
    E0100 = "global disagrees across modules",
    E0101 = "unknown robot",
    E0102 = "remote procedure missing",
    E0103 = "remote arguments do not match",
    E0104 = "unknown part",
    E0105 = "joint count does not match the robot",
    E0106 = "entry procedure missing",
    E0107 = "sync point's task list does not match the cell",
    E0300 = "RAPID construct not supported",
    E0301 = "RAPID optional argument not accepted",
    E0302 = "unknown I/O signal",
    E0303 = "interrupt not connected or not ordered",
    E0304 = "error recovery outside an error handler",
    E0900 = "internal compiler error",
    W0001 = "local shadows a global",
    W0002 = "`disable` of a handler never enabled",
    W0003 = "signal never awaited",
    W0004 = "unreachable code",
}

impl fmt::Display for Code {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl Code {
    /// Errors stop compilation or linking; warnings do not.
    pub fn severity(self) -> Severity {
        if self.as_str().starts_with('W') {
            Severity::Warning
        } else {
            Severity::Error
        }
    }
}

impl Code {
    /// The step of making a program that gives this code: linking the cell's modules
    /// (`E01xx`, `W0003`) or compiling one program (every other code).
    pub fn stage(self) -> Stage {
        match self {
            Code::E0100
            | Code::E0101
            | Code::E0102
            | Code::E0103
            | Code::E0104
            | Code::E0105
            | Code::E0106
            | Code::E0107
            | Code::W0003 => Stage::Link,
            _ => Stage::Compile,
        }
    }
}

/// The step of making a program that found a problem: callers tell a program that does
/// not compile from programs that do not fit together by this, never by the code's text.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Stage {
    /// Compiling one program: its text read, parsed, checked and turned into bytecode.
    Compile,
    /// Linking a cell's modules: globals, remote calls, signals, parts, joints, entries.
    Link,
}

/// Error or warning.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Severity {
    /// Something that must be fixed.
    Error,
    /// Something that is probably a mistake.
    Warning,
}

/// Where a diagnostic points.
#[derive(Clone, Debug, PartialEq)]
pub struct Location {
    /// The file, as given to the compiler. Empty until the compiler fills it in.
    pub file: String,
    /// Byte span in the file, if known.
    pub span: Option<Span>,
    /// 1-based line (0 until resolved).
    pub line: u32,
    /// 1-based column in characters (0 until resolved).
    pub col: u32,
}

/// A secondary label: another place that explains the problem.
#[derive(Clone, Debug, PartialEq)]
pub struct Note {
    /// Where.
    pub at: Location,
    /// What is there.
    pub message: String,
}

/// A problem found in a program.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    /// Stable code.
    pub code: Code,
    /// What is wrong, in a sentence.
    pub message: String,
    /// Where.
    pub at: Location,
    /// A label under the primary span.
    pub label: String,
    /// Other places.
    pub related: Vec<Note>,
    /// What to do about it.
    pub help: Option<String>,
    /// Further facts.
    pub notes: Vec<String>,
}

impl Diagnostic {
    /// A diagnostic at a span of the file being compiled.
    pub fn error(code: Code, message: impl Into<String>, span: Span) -> Diagnostic {
        Diagnostic {
            code,
            message: message.into(),
            at: Location {
                file: String::new(),
                span: Some(span),
                line: 0,
                col: 0,
            },
            label: String::new(),
            related: Vec::new(),
            help: None,
            notes: Vec::new(),
        }
    }

    /// A diagnostic at a line and column of a file (link-time problems).
    pub fn at_pos(
        code: Code,
        message: impl Into<String>,
        file: &str,
        line: u32,
        col: u32,
    ) -> Diagnostic {
        let mut d = Diagnostic::error(code, message, Span::default());
        d.at = Location {
            file: file.to_string(),
            span: None,
            line,
            col,
        };
        d
    }

    /// Compile or link, from the code.
    pub fn stage(&self) -> Stage {
        self.code.stage()
    }

    /// Error or warning, from the code.
    pub fn severity(&self) -> Severity {
        self.code.severity()
    }

    /// True for errors.
    pub fn is_error(&self) -> bool {
        self.severity() == Severity::Error
    }

    /// Adds a help line.
    pub fn with_help(mut self, help: impl Into<String>) -> Diagnostic {
        self.help = Some(help.into());
        self
    }

    /// Adds a label under the primary span.
    pub fn with_label(mut self, label: impl Into<String>) -> Diagnostic {
        self.label = label.into();
        self
    }

    /// Adds a note.
    pub fn with_note(mut self, note: impl Into<String>) -> Diagnostic {
        self.notes.push(note.into());
        self
    }

    /// Adds a secondary label in the same file.
    pub fn with_related(mut self, span: Span, message: impl Into<String>) -> Diagnostic {
        self.related.push(Note {
            at: Location {
                file: String::new(),
                span: Some(span),
                line: 0,
                col: 0,
            },
            message: message.into(),
        });
        self
    }

    /// Adds a secondary label at a line and column of any file.
    pub fn with_related_pos(
        mut self,
        file: &str,
        line: u32,
        col: u32,
        message: impl Into<String>,
    ) -> Diagnostic {
        self.related.push(Note {
            at: Location {
                file: file.to_string(),
                span: None,
                line,
                col,
            },
            message: message.into(),
        });
        self
    }

    /// `file:line:col: error[E0021]: message` — one line, for logs and tests.
    pub fn short(&self) -> String {
        let sev = match self.severity() {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        format!(
            "{}:{}:{}: {sev}[{}]: {}",
            self.at.file, self.at.line, self.at.col, self.code, self.message
        )
    }
}

/// Line starts of a source text, for byte offset ↔ line/column.
#[derive(Clone, Debug)]
pub struct LineIndex {
    starts: Vec<usize>,
    text: String,
}

impl LineIndex {
    /// Indexes `text`.
    pub fn new(text: &str) -> LineIndex {
        let mut starts = vec![0];
        starts.extend(
            text.bytes()
                .enumerate()
                .filter(|(_, b)| *b == b'\n')
                .map(|(i, _)| i + 1),
        );
        LineIndex {
            starts,
            text: text.to_string(),
        }
    }

    /// 1-based line and character column of a byte offset.
    pub fn line_col(&self, offset: usize) -> (u32, u32) {
        let offset = offset.min(self.text.len());
        let line = match self.starts.binary_search(&offset) {
            Ok(i) => i,
            Err(i) => i - 1,
        };
        let start = self.starts[line];
        let col = self
            .text
            .get(start..offset)
            .map_or(offset - start, |s| s.chars().count());
        (line as u32 + 1, col as u32 + 1)
    }

    /// The byte offset of a 1-based line and column, if inside the text.
    pub fn offset(&self, line: u32, col: u32) -> Option<usize> {
        let start = *self.starts.get(line.checked_sub(1)? as usize)?;
        let rest = &self.text[start..];
        let skip = col.checked_sub(1)? as usize;
        let mut it = rest.char_indices();
        match it.nth(skip) {
            Some((i, _)) => Some(start + i),
            None if rest.chars().count() == skip => Some(start + rest.len()),
            None => None,
        }
    }

    /// A span covering the word (identifier or literal) at a byte offset, else one char.
    pub fn word_at(&self, offset: usize) -> Span {
        let rest = self.text.get(offset..).unwrap_or("");
        let len = rest
            .char_indices()
            .find(|(_, c)| !(c.is_ascii_alphanumeric() || *c == '_' || *c == '.'))
            .map_or(rest.len(), |(i, _)| i);
        let len = if len == 0 {
            rest.chars().next().map_or(0, char::len_utf8)
        } else {
            len
        };
        Span::new(offset, offset + len)
    }
}

/// Source texts by file name, for rendering diagnostics with their source lines.
#[derive(Debug, Default)]
pub struct Sources {
    files: Vec<(String, String)>,
}

impl Sources {
    /// No sources.
    pub fn new() -> Sources {
        Sources::default()
    }
    /// Adds (or replaces) a file's text.
    pub fn add(&mut self, file: &str, text: &str) {
        self.files.retain(|(f, _)| f != file);
        self.files.push((file.to_string(), text.to_string()));
    }
    fn get(&self, file: &str) -> Option<&str> {
        self.files
            .iter()
            .find(|(f, _)| f == file)
            .map(|(_, t)| t.as_str())
    }
}

/// Renders diagnostics as text, each followed by a blank line. `color` adds ANSI colours.
pub fn render(diags: &[Diagnostic], sources: &Sources, color: bool) -> String {
    let mut files = SimpleFiles::new();
    let mut ids: Vec<(String, usize, LineIndex)> = Vec::new();
    let mut id_of =
        |file: &str, files: &mut SimpleFiles<String, String>| -> Option<(usize, LineIndex)> {
            if let Some((_, id, ix)) = ids.iter().find(|(f, _, _)| f == file) {
                return Some((*id, ix.clone()));
            }
            let text = sources.get(file)?;
            let id = files.add(file.to_string(), text.to_string());
            let ix = LineIndex::new(text);
            ids.push((file.to_string(), id, ix.clone()));
            Some((id, ix))
        };
    let config = term::Config {
        chars: term::Chars::ascii(),
        ..term::Config::default()
    };
    let mut out = String::new();
    for d in diags {
        let span_of = |loc: &Location, ix: &LineIndex| -> Option<std::ops::Range<usize>> {
            match loc.span {
                Some(s) => Some(s.range()),
                None => ix.offset(loc.line, loc.col).map(|o| ix.word_at(o).range()),
            }
        };
        let primary =
            id_of(&d.at.file, &mut files).and_then(|(id, ix)| Some((id, span_of(&d.at, &ix)?)));
        let Some((id, range)) = primary else {
            out.push_str(&render_plain(d));
            continue;
        };
        let sev = match d.severity() {
            Severity::Error => cs::Diagnostic::error(),
            Severity::Warning => cs::Diagnostic::warning(),
        };
        let mut labels = vec![cs::Label::primary(id, range).with_message(d.label.clone())];
        let mut notes = Vec::new();
        for n in &d.related {
            match id_of(&n.at.file, &mut files)
                .and_then(|(id, ix)| Some((id, span_of(&n.at, &ix)?)))
            {
                Some((nid, r)) => {
                    labels.push(cs::Label::secondary(nid, r).with_message(n.message.clone()))
                }
                None => notes.push(format!(
                    "{} ({}:{}:{})",
                    n.message, n.at.file, n.at.line, n.at.col
                )),
            }
        }
        if let Some(h) = &d.help {
            notes.push(format!("help: {h}"));
        }
        notes.extend(d.notes.iter().map(|n| format!("note: {n}")));
        let diag = sev
            .with_code(d.code.as_str())
            .with_message(d.message.clone())
            .with_labels(labels)
            .with_notes(notes);
        let rendered = if color {
            let mut buf = term::termcolor::Buffer::ansi();
            term::emit_to_write_style(&mut buf, &config, &files, &diag)
                .ok()
                .map(|_| String::from_utf8_lossy(buf.as_slice()).into_owned())
        } else {
            term::emit_into_string(&config, &files, &diag).ok()
        };
        match rendered {
            Some(s) => out.push_str(&s),
            None => out.push_str(&render_plain(d)),
        }
    }
    out
}

fn render_plain(d: &Diagnostic) -> String {
    let sev = match d.severity() {
        Severity::Error => "error",
        Severity::Warning => "warning",
    };
    let mut s = format!(
        "{sev}[{}]: {}\n  --> {}:{}:{}\n",
        d.code, d.message, d.at.file, d.at.line, d.at.col
    );
    for n in &d.related {
        s.push_str(&format!(
            "  --> {}:{}:{}: {}\n",
            n.at.file, n.at.line, n.at.col, n.message
        ));
    }
    if let Some(h) = &d.help {
        s.push_str(&format!("  = help: {h}\n"));
    }
    for n in &d.notes {
        s.push_str(&format!("  = note: {n}\n"));
    }
    s.push('\n');
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_col_round_trips() {
        let ix = LineIndex::new("ab\ncdé\nf");
        assert_eq!(ix.line_col(0), (1, 1));
        assert_eq!(ix.line_col(4), (2, 2));
        assert_eq!(ix.line_col(8), (3, 1));
        assert_eq!(ix.offset(2, 2), Some(4));
        assert_eq!(ix.offset(3, 1), Some(8));
        assert_eq!(ix.offset(9, 1), None);
    }

    #[test]
    fn codes_are_unique_and_titled() {
        let mut seen = std::collections::BTreeSet::new();
        for c in Code::ALL {
            assert!(seen.insert(c.as_str()));
            assert!(!c.title().is_empty());
        }
    }
}

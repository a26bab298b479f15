//! Text from files (names in a workcell, a URDF or a log) as a terminal may print it:
//! control characters escaped, so an escape sequence in a name cannot drive the terminal.

use std::borrow::Cow;

/// `text` with each control character (C0, DEL, C1) escaped as Rust's `{:?}` escapes it —
/// `\u{1b}`, `\n`, `\t` — as log texts are shown (quoted with `{:?}`); everything else as it
/// is. Borrowed when there is nothing to escape.
pub fn escape_controls(text: &str) -> Cow<'_, str> {
    if !text.chars().any(char::is_control) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if c.is_control() {
            out.extend(c.escape_debug());
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// [`escape_controls`] of a line already made: the line itself when there is nothing to
/// escape.
pub fn escape_controls_owned(line: String) -> String {
    match escape_controls(&line) {
        Cow::Borrowed(_) => line,
        Cow::Owned(escaped) => escaped,
    }
}

/// A number for a message with `decimals` places, as `{:.N}` writes it while it is of a
/// size people write (below 10⁶ in magnitude); a larger one in scientific notation
/// (`1.000e297`, not 298 digits), and an infinity as `inf`.
pub fn number(x: f64, decimals: usize) -> String {
    if !x.is_finite() || x.abs() < 1e6 {
        format!("{x:.decimals$}")
    } else {
        format!("{x:.3e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_are_escaped_as_debug_escapes_them() {
        assert!(matches!(
            escape_controls("r1 Zelle ü \"x\" \\"),
            Cow::Borrowed(_)
        ));
        let name = "r\u{1b}[31m1\u{7}\t\n\u{7f}\u{9b}";
        assert_eq!(
            escape_controls(name),
            "r\\u{1b}[31m1\\u{7}\\t\\n\\u{7f}\\u{9b}"
        );
        // What `{:?}` shows of the same text, quotes aside.
        assert_eq!(
            format!("{name:?}"),
            format!("\"{}\"", escape_controls(name))
        );
        assert_eq!(
            escape_controls_owned(name.to_string()),
            escape_controls(name)
        );
    }

    #[test]
    fn huge_numbers_are_written_in_scientific_notation() {
        assert_eq!(number(0.12345, 4), "0.1235");
        assert_eq!(number(-999_999.0, 1), "-999999.0");
        assert_eq!(number(1e297, 4), "1.000e297");
        assert_eq!(number(f64::INFINITY, 4), "inf");
    }
}

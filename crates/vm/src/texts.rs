//! Texts at run time: RAPID's `string` values (WSL writes text only in `log` and `fail`).
//!
//! A text is one slot holding a *handle* ([`crate::Type::Text`]): 0 is the empty text,
//! `k + 1` the module's string `k`, and the handles after those the texts this robot's run
//! made (`+`, `StrPart`, `NumToStr`, …), kept in [`Texts`] for the run. Made texts are
//! interned, so a loop that builds the same text again makes no new one, and handles are
//! given in the order the texts were first made: the same program makes the same handles.
//! A text holds at most [`MAX_CHARS`] characters, as RAPID's `string` does; positions count
//! characters from 1, as RAPID's do (a Latin-1 source file's byte is one character).
//!
//! The functions below are the text instructions' meaning, kept out of the dispatch loop.

use std::collections::BTreeMap;
use std::sync::Arc;

use crate::bytecode::Module;

/// The most characters a text holds: RAPID's `string` holds 80 (a longer one is the error
/// ERR_STRTOOLNG on the controller).
pub const MAX_CHARS: usize = 80;

/// The most texts one run may make (each kept once, shared by the list and the index: a
/// few MiB at most): a loop that makes a new text every round would otherwise grow
/// without bound.
pub const MAX_MADE: usize = 1 << 16;

/// RAPID's error numbers (vworks's own; the RAPID front-end names them) of the text
/// errors a handler may take: a text too long, a position outside one.
pub const ERR_STRTOOLNG: i64 = 1005;
/// See [`ERR_STRTOOLNG`].
pub const ERR_OUTOFBND: i64 = 1006;

/// A text instruction's error: RAPID's number if a handler may take it, and the message.
pub type TextError = (Option<i64>, String);

/// The texts a robot's run made, and their handles.
#[derive(Clone, Debug, Default)]
pub struct Texts {
    made: Vec<Arc<str>>,
    index: BTreeMap<Arc<str>, u64>,
}

impl Texts {
    /// The text of handle `h`, or `None` for a handle no text has (a corrupt module).
    pub fn get<'a>(&'a self, m: &'a Module, h: u64) -> Option<&'a str> {
        let n = m.strings.len() as u64;
        match h {
            0 => Some(""),
            // (A module's string longer than any text is no text: a forged handle.)
            h if h <= n => m
                .strings
                .get(h as usize - 1)
                .map(String::as_str)
                .filter(|s| s.len() <= 4 * MAX_CHARS),
            h => self.made.get((h - n - 1) as usize).map(|s| &**s),
        }
    }

    /// The handle of `s`, made if it is new: an error if it is longer than
    /// [`MAX_CHARS`] characters or the run has made [`MAX_MADE`] texts.
    pub fn make(&mut self, m: &Module, s: String) -> Result<u64, TextError> {
        if s.is_empty() {
            return Ok(0);
        }
        let chars = s.chars().count();
        if chars > MAX_CHARS {
            return Err((
                Some(ERR_STRTOOLNG),
                format!(
                    "a text of {chars} characters (ERR_STRTOOLNG): a string holds at most {MAX_CHARS}"
                ),
            ));
        }
        if let Some(&h) = self.index.get(s.as_str()) {
            return Ok(h);
        }
        if self.made.len() >= MAX_MADE {
            return Err((
                None,
                format!(
                    "the run made more than {MAX_MADE} different texts; build fewer distinct texts in the loop"
                ),
            ));
        }
        let h = m.strings.len() as u64 + 1 + self.made.len() as u64;
        let s: Arc<str> = s.into();
        self.made.push(s.clone());
        self.index.insert(s, h);
        Ok(h)
    }
}

/// A 1-based character position from a num, or an error naming `what`.
fn position(x: f64, what: &str) -> Result<usize, TextError> {
    if x.fract() != 0.0 || !(1.0..=1e9).contains(&x) {
        return Err(out_of_bounds(format!(
            "{what} must be a whole number from 1 (ERR_OUTOFBND), not {x}"
        )));
    }
    Ok(x as usize)
}

fn out_of_bounds(message: String) -> TextError {
    (Some(ERR_OUTOFBND), message)
}

/// `StrPart(s, start, len)`: `len` characters from position `start`.
pub fn part(s: &str, start: f64, len: f64) -> Result<String, TextError> {
    let start = position(start, "the start of StrPart")?;
    if len.fract() != 0.0 || !(0.0..=1e9).contains(&len) {
        return Err(out_of_bounds(format!(
            "the length of StrPart must be a whole number from 0 (ERR_OUTOFBND), not {len}"
        )));
    }
    let n = s.chars().count();
    let len = len as usize;
    if start + len > n + 1 {
        return Err(out_of_bounds(format!(
            "StrPart from character {start} for {len} runs past the text's {n} characters (ERR_OUTOFBND)"
        )));
    }
    Ok(s.chars().skip(start - 1).take(len).collect())
}

/// `StrFind(s, start, set [\NotInSet])`: the position of the first character from `start`
/// on that is in `set` (not in it, with `not_in`), or the length + 1 if none is.
pub fn find(s: &str, start: f64, set: &str, not_in: bool) -> Result<f64, TextError> {
    let start = start_in(s, start, "StrFind")?;
    let n = s.chars().count();
    let at = s
        .chars()
        .enumerate()
        .skip(start - 1)
        .find(|(_, c)| set.contains(*c) != not_in)
        .map_or(n + 1, |(k, _)| k + 1);
    Ok(at as f64)
}

/// `StrMatch(s, start, pattern)`: the position of `pattern` from `start` on, or the
/// length + 1 if it is not there.
pub fn find_text(s: &str, start: f64, pattern: &str) -> Result<f64, TextError> {
    let start = start_in(s, start, "StrMatch")?;
    let chars: Vec<char> = s.chars().collect();
    let pat: Vec<char> = pattern.chars().collect();
    let n = chars.len();
    let at = (start - 1..=n.saturating_sub(pat.len()))
        .find(|&k| k + pat.len() <= n && chars[k..k + pat.len()] == pat[..])
        .map_or(n + 1, |k| k + 1);
    Ok(at as f64)
}

/// `StrMemb(s, pos, set)`: whether the character at `pos` is in `set`.
pub fn member(s: &str, pos: f64, set: &str) -> Result<bool, TextError> {
    let pos = position(pos, "the position of StrMemb")?;
    let n = s.chars().count();
    match s.chars().nth(pos - 1) {
        Some(c) => Ok(set.contains(c)),
        None => Err(out_of_bounds(format!(
            "StrMemb at character {pos} of a text of {n} (ERR_OUTOFBND)"
        ))),
    }
}

/// `StrMap(s, from, to)`: each character of `s` found in `from` replaced by the character
/// at the same place in `to`.
pub fn map(s: &str, from: &str, to: &str) -> String {
    let from: Vec<char> = from.chars().collect();
    let to: Vec<char> = to.chars().collect();
    s.chars()
        .map(|c| match from.iter().position(|f| *f == c) {
            Some(k) => to.get(k).copied().unwrap_or(c),
            None => c,
        })
        .collect()
}

/// The start of a search: from 1 to the length + 1 (an empty rest finds nothing).
fn start_in(s: &str, start: f64, what: &str) -> Result<usize, TextError> {
    let k = position(start, &format!("the start of {what}"))?;
    let n = s.chars().count();
    if k > n + 1 {
        return Err(out_of_bounds(format!(
            "{what} from character {k} of a text of {n} (ERR_OUTOFBND)"
        )));
    }
    Ok(k)
}

/// `NumToStr(x, dec)`: `x` rounded to `dec` decimals (a whole number, 0 to 15), half away
/// from zero, without a sign on a value that rounds to zero.
pub fn num_to_str(x: f64, dec: f64) -> Result<String, TextError> {
    if dec.fract() != 0.0 || !(0.0..=15.0).contains(&dec) {
        return Err((
            None,
            format!("NumToStr's decimals must be a whole number from 0 to 15, not {dec}"),
        ));
    }
    if !x.is_finite() {
        return Err((None, format!("NumToStr of {x}")));
    }
    // Half away from zero on the decimals kept (2.25 to one decimal is 2.3).
    let k = 10f64.powi(dec as i32);
    let s = format!("{:.*}", dec as usize, (x * k).round() / k);
    Ok(match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => s,
    })
}

/// `ValToStr(x)` of a num: at most 6 significant digits (RAPID's num is a 32-bit float),
/// no trailing zeros, no exponent below a million.
pub fn num_value(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return if x.is_finite() {
            "0".into()
        } else {
            x.to_string()
        };
    }
    let magnitude = x.abs().log10().floor() as i32;
    let decimals = (5 - magnitude).clamp(0, 15) as usize;
    let s = format!("{:.*}", decimals, x);
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" { "0".into() } else { s }
}

/// `StrToVal(s, x)` of a num: the number `s` writes (RAPID's literal: digits, a point, an
/// exponent, a sign; spaces around it), or `None`.
pub fn parse_num(s: &str) -> Option<f64> {
    let t = s.trim();
    let ok = !t.is_empty()
        && t.chars()
            .all(|c| c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | 'E'));
    if !ok {
        return None;
    }
    t.parse::<f64>().ok().filter(|x| x.is_finite())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn parts_finds_and_maps_count_characters_from_one() {
        assert_eq!(part("Robotics", 1.0, 5.0).unwrap(), "Robot");
        assert_eq!(part("Robotics", 6.0, 3.0).unwrap(), "ics");
        assert_eq!(part("abc", 4.0, 0.0).unwrap(), "");
        assert!(part("abc", 3.0, 2.0).is_err());
        assert!(part("abc", 0.0, 1.0).is_err());
        assert_eq!(find("Robotics", 1.0, "aeiou", false).unwrap(), 2.0);
        assert_eq!(find("Robotics", 1.0, "Robt", true).unwrap(), 6.0);
        assert_eq!(find("abc", 1.0, "xyz", false).unwrap(), 4.0);
        assert_eq!(find_text("Robotics", 1.0, "bot").unwrap(), 3.0);
        assert_eq!(find_text("Robotics", 4.0, "bot").unwrap(), 9.0);
        assert_eq!(find_text("ab", 1.0, "abc").unwrap(), 3.0);
        assert!(member("Robotics", 2.0, "aeiou").unwrap());
        assert!(!member("Robotics", 1.0, "aeiou").unwrap());
        assert_eq!(map("Robotics", "aeiou", "AEIOU"), "RObOtIcs");
        // Latin-1 text: one character, one position.
        assert_eq!(part("café", 4.0, 1.0).unwrap(), "é");
    }

    #[test]
    fn numbers_print_as_rapid_prints_them_and_parse_back() {
        assert_eq!(num_to_str(0.38521, 3.0).unwrap(), "0.385");
        assert_eq!(num_to_str(1.0, 0.0).unwrap(), "1");
        assert_eq!(num_to_str(-0.0001, 2.0).unwrap(), "0.00");
        assert_eq!(num_to_str(2.5, 1.0).unwrap(), "2.5");
        assert_eq!(num_to_str(2.25, 1.0).unwrap(), "2.3");
        assert_eq!(num_to_str(-2.25, 1.0).unwrap(), "-2.3");
        assert!(num_to_str(1.0, 1.5).is_err());
        assert_eq!(num_value(1.5), "1.5");
        assert_eq!(num_value(std::f64::consts::PI), "3.14159");
        assert_eq!(num_value(-20.0), "-20");
        assert_eq!(num_value(123456.0), "123456");
        assert_eq!(num_value(0.0), "0");
        assert_eq!(parse_num(" 3.5 "), Some(3.5));
        assert_eq!(parse_num("-1e3"), Some(-1000.0));
        assert_eq!(parse_num("12a"), None);
        assert_eq!(parse_num(""), None);
    }

    #[test]
    fn texts_are_interned_and_bounded() {
        let m = Module {
            strings: vec!["a".into(), "b".into()],
            ..Module::default()
        };
        let mut t = Texts::default();
        assert_eq!(t.get(&m, 0), Some(""));
        assert_eq!(t.get(&m, 1), Some("a"));
        assert_eq!(t.get(&m, 2), Some("b"));
        assert_eq!(t.get(&m, 3), None);
        let h = t.make(&m, "ab".into()).unwrap();
        assert_eq!(h, 3);
        assert_eq!(t.make(&m, "ab".into()).unwrap(), 3);
        assert_eq!(t.make(&m, String::new()).unwrap(), 0);
        assert_eq!(t.get(&m, h), Some("ab"));
        assert!(t.make(&m, "x".repeat(81)).is_err());
        assert!(t.make(&m, "x".repeat(80)).is_ok());
    }
}

//! What the commands print: stdout that ends quietly when the reader is gone ([`out!`]),
//! counts and times as people read them.

/// `println!` that ends the process quietly when stdout is gone (`vworks log events … | head`)
/// instead of panicking.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if writeln!(std::io::stdout(), $($arg)*).is_err() {
            std::process::exit(141); // as a shell reports SIGPIPE
        }
    }};
}
pub(crate) use out;

pub(crate) fn plural(n: usize, word: &str) -> String {
    format!("{n} {word}{}", if n == 1 { "" } else { "s" })
}

pub(crate) fn secs(ns: i64) -> String {
    format!("{:.3} s", ns as f64 / 1e9)
}

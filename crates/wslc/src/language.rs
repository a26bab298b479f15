//! The languages vworks compiles, and which one a file is written in: the one place that
//! maps a file's extension (or a language's name, as Python and the CLI take it) to a
//! front-end. [`crate::compile_program`] dispatches on it; the cell loader, the CLI and
//! Python call these and decide nothing themselves.

/// The language of a program file, from its extension: RAPID for `.mod`, `.modx`, `.sys`,
/// `.sysx` and `.prg`, WSL for anything else.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Language {
    /// WSL, vworks's own language.
    Wsl,
    /// ABB RAPID.
    Rapid,
}

/// Every language, in the order messages list them.
const ALL: [Language; 2] = [Language::Wsl, Language::Rapid];

impl Language {
    /// The file extensions of its source files (without the dot; matched in any case).
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            Language::Wsl => &["wsl"],
            Language::Rapid => crate::rapid::EXTENSIONS,
        }
    }

    /// The language a source file is written in, by its extension; `None` for a file of
    /// none of them (`.wslb`, `.toml`, no extension).
    pub fn of_source_file(path: &str) -> Option<Language> {
        let ext = std::path::Path::new(path).extension()?.to_str()?;
        ALL.into_iter()
            .find(|l| l.extensions().iter().any(|x| x.eq_ignore_ascii_case(ext)))
    }

    /// The language of a file by its extension: WSL unless it is a RAPID module's.
    pub fn of_path(path: &str) -> Language {
        Language::of_source_file(path).unwrap_or(Language::Wsl)
    }

    /// The language of a program of several files: the first file's, which every other
    /// must share; else the index of the first file in another language and a message
    /// naming both. (WSL for no files.)
    pub fn of_files(paths: &[&str]) -> Result<Language, (usize, String)> {
        let Some(first) = paths.first() else {
            return Ok(Language::Wsl);
        };
        let language = Language::of_path(first);
        match paths.iter().position(|p| Language::of_path(p) != language) {
            None => Ok(language),
            Some(k) => Err((
                k,
                format!(
                    "`{}` is {} but `{first}` is {}: one program's files are all in one language",
                    paths[k],
                    Language::of_path(paths[k]).name(),
                    language.name()
                ),
            )),
        }
    }

    /// The language called `name` (`wsl` or `rapid`, any case), as the CLI and Python
    /// take it; else a message listing the names.
    pub fn from_name(name: &str) -> Result<Language, String> {
        ALL.into_iter()
            .find(|l| l.name().eq_ignore_ascii_case(name))
            .ok_or_else(|| {
                let name = name.to_ascii_lowercase();
                format!("unknown language {name:?}: use \"wsl\" or \"rapid\"")
            })
    }

    /// Its name as messages give it: `WSL` or `RAPID`.
    pub fn name(self) -> &'static str {
        match self {
            Language::Wsl => "WSL",
            Language::Rapid => "RAPID",
        }
    }

    /// A file name for a program given without one (`x.wsl`, `x.mod`).
    pub fn default_path(self) -> &'static str {
        match self {
            Language::Wsl => "x.wsl",
            Language::Rapid => "x.mod",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_is_in_the_language_of_its_extension() {
        assert_eq!(Language::of_source_file("a/b.WSL"), Some(Language::Wsl));
        for ext in ["mod", "MODX", "sys", "sysx", "Prg"] {
            let path = format!("r1.{ext}");
            assert_eq!(
                Language::of_source_file(&path),
                Some(Language::Rapid),
                "{path}"
            );
        }
        assert_eq!(Language::of_source_file("r1.wslb"), None);
        assert_eq!(Language::of_source_file("cell.toml"), None);
        assert_eq!(Language::of_source_file("Makefile"), None);
        assert_eq!(Language::of_path("cell.toml"), Language::Wsl);
        for l in ALL {
            assert_eq!(Language::of_path(l.default_path()), l);
            assert_eq!(Language::from_name(&l.name().to_lowercase()), Ok(l));
        }
        assert!(Language::from_name("krl").is_err());
    }

    #[test]
    fn a_program_is_in_one_language() {
        assert_eq!(Language::of_files(&[]), Ok(Language::Wsl));
        assert_eq!(Language::of_files(&["a.mod", "b.sys"]), Ok(Language::Rapid));
        let (k, why) = Language::of_files(&["a.mod", "b.wsl"])
            .err()
            .unwrap_or_default();
        assert_eq!(k, 1);
        assert!(why.contains("`b.wsl` is WSL but `a.mod` is RAPID"), "{why}");
    }
}

//! [`CellError`]: why a workcell could not be loaded, naming the file, the key (or line)
//! and what to do.

use vworks_wslc::{Diagnostic, Stage};

/// Why a workcell could not be loaded.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CellError {
    /// A file could not be read.
    #[error("cannot read `{file}`: {reason}")]
    Read {
        /// The file.
        file: String,
        /// Why.
        reason: String,
    },
    /// The workcell file is wrong at a key.
    #[error("{file}: {key}: {message}")]
    Invalid {
        /// The workcell file.
        file: String,
        /// Where in it, e.g. `robot[0].default_speed`.
        key: String,
        /// What is wrong and what to do.
        message: String,
    },
    /// A robot model failed to load.
    #[error("{file}: robot `{robot}`: {source}")]
    Model {
        /// The workcell file.
        file: String,
        /// The robot.
        robot: String,
        /// The model error (it names the URDF file and element).
        source: Box<vworks_model::ModelError>,
    },
    /// Programs did not compile or link: every diagnostic, rendered with its source.
    #[error("{rendered}")]
    Program {
        /// Whether a program did not compile, or the cell's programs did not link.
        stage: Stage,
        /// The diagnostics.
        diagnostics: Vec<Diagnostic>,
        /// The same, rendered with source lines.
        rendered: String,
    },
}

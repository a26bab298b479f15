//! Errors of model loading: each names the file, the URDF element, what is wrong and what
//! to do.

/// Why a robot model could not be loaded.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// The file could not be read.
    #[error(
        "cannot read `{file}`: {reason}; check the path (relative paths are relative to the workcell file)"
    )]
    Read {
        /// The file.
        file: String,
        /// The operating system's reason.
        reason: String,
    },
    /// The file is not well-formed URDF XML.
    #[error(
        "`{file}` is not a valid URDF: {reason}; a URDF is XML with one <robot> element holding <link> and <joint> elements"
    )]
    Parse {
        /// The file.
        file: String,
        /// What the XML reader said.
        reason: String,
    },
    /// The URDF is well-formed but describes something vworks cannot use.
    #[error("{file}: {element}: {message}; {help}")]
    Invalid {
        /// The file.
        file: String,
        /// The element, e.g. "joint `joint_3`".
        element: String,
        /// What is wrong.
        message: String,
        /// What to do.
        help: String,
    },
    /// A mesh could not be found or read.
    #[error("{file}: {element}: mesh `{mesh}`: {message}")]
    Mesh {
        /// The URDF file.
        file: String,
        /// The element, e.g. "link `link_2` collision 1".
        element: String,
        /// The mesh file name as written.
        mesh: String,
        /// What is wrong and what to do.
        message: String,
    },
    /// No built-in model has that name.
    #[error("there is no built-in model `{name}`; the built-in models are {known}")]
    UnknownModel {
        /// The name asked for.
        name: String,
        /// The names there are.
        known: String,
    },
}

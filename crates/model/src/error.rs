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
        /// What is wrong, as a kind a program can match (the message says it in words).
        problem: UrdfProblem,
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

/// What is wrong with a well-formed URDF that vworks cannot use ([`ModelError::Invalid`]):
/// the kind, for programs and tests to match; the error's message says it in words.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[non_exhaustive]
pub enum UrdfProblem {
    /// Elements nest deeper than [`crate::urdf::MAX_NESTING`].
    TooDeep,
    /// A joint type vworks does not simulate (`floating`, `planar`, `spherical`).
    UnsupportedJointType,
    /// A joint type URDF does not have.
    UnknownJointType,
    /// A joint without a `type`.
    MissingJointType,
    /// Two links of one name.
    DuplicateLink,
    /// A robot without links.
    NoLinks,
    /// A joint's parent or child link does not exist.
    MissingLink,
    /// A link with two parent joints.
    TwoParents,
    /// A number that is not finite (an `<origin>`).
    NotFinite,
    /// A moving joint's axis of zero length (or not finite).
    ZeroAxis,
    /// More than one link without a parent.
    SeveralRoots,
    /// Joints that close a loop.
    Cycle,
    /// The tool link asked for is not a link of the robot.
    UnknownToolLink,
    /// The tree branches, no `tool0`, and no tool link named.
    AmbiguousToolLink,
    /// Joint limits that are not a finite range (`lower > upper`, not finite).
    BadJointRange,
    /// A moving joint's velocity limit that is not positive and finite.
    BadVelocityLimit,
    /// An acceleration, deceleration or jerk limit that is not positive and finite.
    BadDynamicLimit,
    /// A shape's size that is not positive and finite.
    BadSize,
    /// A mesh with no volume, so no convex hull.
    DegenerateMesh,
    /// More than 12 axes on the chain to the tool.
    TooManyAxes,
    /// A `<mimic>` joint on the chain to the tool.
    MimicOnToolChain,
}

//! Robot models for vworks: what the VM moves and the SE checks for collisions.
//!
//! - [`urdf`]: URDF import (urdf-rs) with the checks a robot description needs — one root,
//!   no cycles, finite origins, non-zero axes, usable limits, meshes that exist — each
//!   failure a [`ModelError`] naming the file and the element.
//! - [`model`]: links, joints, axes, limits, collision shapes (parry3d, built once at
//!   load: meshes become convex hulls) and forward kinematics (f64, no allocation).
//! - [`ik`]: analytic IK for spherical-wrist 6-axis arms (all solutions, nearest chosen)
//!   and damped-least-squares IK for any chain.
//! - [`builtin`]: `irb120`, `kr6r900`, `lrmate200id`, `ur5`, `turntable`, `track`.
//! - [`mesh`]: STL (binary, ASCII) and OBJ vertices.
//! - [`files`]: where URDFs and meshes are read from (the disk, or memory).
//! - [`output`]: where every file vworks writes goes through: never over an input, through
//!   a temporary file renamed at the end.
//! - [`math`]: the small rigid-transform algebra all of it uses.
//! - [`timing`]: the time-optimal timing of a path within axis and path limits (TOPP-RA).
//! - [`text`]: names from files as a terminal may print them (control characters escaped).
//!
//! Joint values are radians for revolute axes and metres for prismatic ones. A joint
//! whose URDF gives no acceleration limit accelerates to full speed in
//! [`model::DEFAULT_ACCEL_TIME`] (0.3 s); the built-in arms carry their own
//! (docs/models.md), and a model may limit its TCP ([`model::TcpLimits`]).

pub mod builtin;
pub mod error;
pub mod files;
pub mod ik;
pub mod math;
pub mod mesh;
pub mod model;
pub mod output;
pub mod text;
pub mod timing;
pub mod urdf;

pub use error::{ModelError, UrdfProblem};
pub use ik::IkError;
pub use math::Iso;
pub use model::{JointKind, RobotModel};

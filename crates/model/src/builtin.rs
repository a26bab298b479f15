//! The built-in models, written for vworks from published kinematic data, with link
//! geometry as enveloping capsules, boxes and cylinders (no vendor meshes). They are URDF
//! files (`crates/model/models/`) loaded by the same loader as user models, so the
//! Pinocchio oracle tests read exactly what vworks reads.

use crate::error::ModelError;
use crate::model::RobotModel;
use crate::urdf::{LoadOptions, load_str};

/// Name and URDF text of every built-in model.
pub const MODELS: &[(&str, &str)] = &[
    ("irb120", include_str!("../models/irb120.urdf")),
    ("kr6r900", include_str!("../models/kr6r900.urdf")),
    ("lrmate200id", include_str!("../models/lrmate200id.urdf")),
    ("ur5", include_str!("../models/ur5.urdf")),
    ("turntable", include_str!("../models/turntable.urdf")),
    ("track", include_str!("../models/track.urdf")),
];

/// The names of the built-in models.
pub fn names() -> Vec<&'static str> {
    MODELS.iter().map(|(n, _)| *n).collect()
}

/// Loads a built-in model by name.
pub fn load(name: &str) -> Result<RobotModel, ModelError> {
    let Some((_, text)) = MODELS.iter().find(|(n, _)| *n == name) else {
        return Err(ModelError::UnknownModel {
            name: name.to_string(),
            known: names().join(", "),
        });
    };
    load_str(
        text,
        &format!("builtin:{name}"),
        None,
        &LoadOptions::default(),
    )
}

//! The workcell file as TOML writes it: serde's view of every section, unknown keys
//! refused.

use std::collections::BTreeMap;

use serde::Deserialize;

#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub(crate) struct PoseFile {
    pub(crate) xyz: Option<Vec<toml::Value>>,
    pub(crate) rpy: Option<Vec<toml::Value>>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub(crate) struct RobotFile {
    pub(crate) name: String,
    pub(crate) model: Option<String>,
    pub(crate) urdf: Option<String>,
    pub(crate) tool_link: Option<String>,
    #[serde(default)]
    pub(crate) package_path: Vec<String>,
    pub(crate) base: Option<PoseFile>,
    pub(crate) tool: Option<PoseFile>,
    /// One file, or a list of files (a RAPID task's modules).
    pub(crate) program: Option<toml::Value>,
    pub(crate) entry: Option<String>,
    pub(crate) task: Option<String>,
    pub(crate) serve_only: Option<bool>,
    pub(crate) default_speed: Option<toml::Value>,
    pub(crate) default_zone: Option<toml::Value>,
    pub(crate) grip_distance: Option<toml::Value>,
    pub(crate) jerk: Option<toml::Value>,
    pub(crate) tcp_speed: Option<toml::Value>,
    pub(crate) tcp_acceleration: Option<toml::Value>,
    pub(crate) home: Option<Vec<toml::Value>>,
    /// Values of its program's `param`s (`[robot.params]`).
    #[serde(default)]
    pub(crate) params: BTreeMap<String, toml::Value>,
    /// Allowed pairs may follow any table (TOML puts a key after `[[robot]]` into it).
    #[serde(default)]
    pub(crate) allow_collision: Vec<Vec<String>>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub(crate) struct BodyFile {
    pub(crate) name: String,
    #[serde(rename = "box")]
    pub(crate) box_: Option<Vec<toml::Value>>,
    pub(crate) cylinder: Option<Vec<toml::Value>>,
    pub(crate) sphere: Option<toml::Value>,
    pub(crate) mesh: Option<String>,
    pub(crate) scale: Option<f64>,
    pub(crate) pose: Option<PoseFile>,
    #[serde(default)]
    pub(crate) allow_collision: Vec<Vec<String>>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub(crate) struct CellFile {
    pub(crate) name: Option<String>,
    pub(crate) cycle: Option<toml::Value>,
    pub(crate) clearance: Option<toml::Value>,
    pub(crate) grip_distance: Option<toml::Value>,
    pub(crate) on_collision: Option<String>,
    #[serde(default)]
    pub(crate) robot: Vec<RobotFile>,
    #[serde(default)]
    pub(crate) device: Vec<BodyFile>,
    #[serde(default)]
    pub(crate) part: Vec<BodyFile>,
    #[serde(default)]
    pub(crate) allow_collision: Vec<Vec<String>>,
    /// Values of the programs' `param`s (`[params]`), for every program that declares them.
    #[serde(default)]
    pub(crate) params: BTreeMap<String, toml::Value>,
    /// The I/O wiring (`[[io]]`).
    #[serde(default)]
    pub(crate) io: Vec<IoFile>,
}

/// One `[[io]]` table.
#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub(crate) struct IoFile {
    pub(crate) name: String,
    pub(crate) kind: String,
    pub(crate) robot: String,
    #[serde(default)]
    pub(crate) inputs: Vec<IoInputFile>,
    pub(crate) value: Option<i64>,
}

/// An input a wire drives.
#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub(crate) struct IoInputFile {
    pub(crate) robot: String,
    pub(crate) name: String,
}

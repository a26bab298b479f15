//! A loaded workcell: [`Cell`], its [`Robot`]s and [`Body`]s, ready to simulate.

use std::path::PathBuf;
use std::sync::Arc;

use parry3d::shape::SharedShape;
use vworks_model::RobotModel;
use vworks_model::math::Iso;
use vworks_model::model::Geometry;
use vworks_vm::Module;
use vworks_wslc::link::Linked;
use vworks_wslc::{Diagnostic, Sources};

#[derive(Debug, Clone)]
pub struct Robot {
    /// Its name.
    pub name: String,
    /// Its model.
    pub model: Arc<RobotModel>,
    /// Base frame in the cell.
    pub base: Iso,
    /// TCP in the tool-link frame.
    pub tool: Iso,
    /// Its compiled program.
    pub module: Arc<Module>,
    /// The program file (the first, for a program of several files: the module's
    /// `files` lists them all, and positions name their own).
    pub program: String,
    /// Entry procedure (`None`: serve-only).
    pub entry: Option<u32>,
    /// Speed of `move_l`/`move_c` without `speed` (m/s).
    pub default_speed: f64,
    /// Zone radius of motions without `zone` (m; `None`: `fine`).
    pub default_zone: Option<f64>,
    /// How far a part may be from this robot's gripper (its TCP, or a collision body of
    /// its tool link) for `grip` to take it (m): its own `grip_distance`, else the cell's.
    pub grip_distance: f64,
    /// Joints at the start.
    pub home: Vec<f64>,
    /// The task it runs, as sync points' task lists name it (`task`; default: its name).
    pub task: String,
    /// A RAPID robot's wired I/O signals as (cell global, the name its program gives the
    /// signal), sorted: messages name what the program wrote (`diFromR2`), not the wire's
    /// global (`dotor1`). Empty for WSL robots, whose programs name the globals.
    pub signal_names: Vec<(String, String)>,
}

/// A static or movable body: a device or a part.
#[derive(Debug, Clone)]
pub struct Body {
    /// Its name.
    pub name: String,
    /// What it is.
    pub geometry: Geometry,
    /// Its parry shape.
    pub shape: SharedShape,
    /// Shape pose in the body frame (cylinders turned onto z).
    pub local: Iso,
    /// Body pose in the cell.
    pub pose: Iso,
}

/// A loaded workcell.
#[derive(Debug, Clone)]
pub struct Cell {
    /// Its name.
    pub name: String,
    /// The workcell file.
    pub file: PathBuf,
    /// Cycle period (ns).
    pub cycle_ns: i64,
    /// Near-miss distance (m).
    pub clearance: f64,
    /// The cell's `grip_distance` (m; [`DEFAULT_GRIP_DISTANCE`] unless the file sets
    /// it): each robot's [`Robot::grip_distance`] unless the robot sets its own.
    pub grip_distance: f64,
    /// Stop at the first collision.
    pub stop_on_collision: bool,
    /// Robots, in file order.
    pub robots: Vec<Robot>,
    /// Static bodies.
    pub devices: Vec<Body>,
    /// Movable bodies.
    pub parts: Vec<Body>,
    /// Pairs allowed to touch: body names (`r1.link_6`, `r1` for all its links, `part1`).
    pub allowed: Vec<(String, String)>,
    /// The linked programs.
    pub linked: Linked,
    /// The workcell file and every program: (path, text).
    pub sources: Vec<(String, String)>,
    /// Every other file the run read: each URDF and each mesh, (path, bytes), in load order.
    pub files: Vec<(String, Vec<u8>)>,
    /// The programs' compile warnings (in robot order, each program once) and the link
    /// warnings: `vworks run` prints them as `vworks check` does, and every run's result
    /// lists them (`vworks_log::result::RunResult::warnings`).
    pub warnings: Vec<Diagnostic>,
    /// The values a [`Loader`](crate::Loader) changed from the workcell file: (path, value as TOML), in
    /// order (empty for the file as written).
    pub overrides: Vec<(String, String)>,
}

impl Cell {
    /// The compile and link warnings, rendered with their source lines as `vworks check`
    /// prints them (empty if there are none).
    pub fn render_warnings(&self, color: bool) -> String {
        if self.warnings.is_empty() {
            return String::new();
        }
        let mut sources = Sources::new();
        for (path, text) in &self.sources {
            sources.add(path, text);
        }
        vworks_wslc::render(&self.warnings, &sources, color)
    }
}

/// Link names match ignoring `_` and case: `link6` names `link_6`.
pub fn same_link(a: &str, b: &str) -> bool {
    let norm = |s: &str| {
        s.chars()
            .filter(|c| *c != '_')
            .flat_map(char::to_lowercase)
            .collect::<String>()
    };
    a == b || norm(a) == norm(b)
}

/// How far a part may be from a robot's gripper for `grip` to take it when the workcell
/// does not say (m): 5 mm, a gripper closing on a part that its fingers nearly touch.
pub const DEFAULT_GRIP_DISTANCE: f64 = 0.005;

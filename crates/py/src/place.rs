//! Where in the programs something happened, for Python: the motion each robot in a
//! collision or near miss was making (`RobotMotion`) and the lines the programs logged
//! (`LogLine`). Mirrors `vworks_log::place`.

use pyo3::prelude::*;

/// A robot whose body (a link, or a part it holds) is in a collision or near miss, and the
/// motion statement it was making then — or, standing, the last one it made.
#[pyclass(frozen, module = "vworks", get_all, name = "RobotMotion")]
#[derive(Clone)]
pub(crate) struct PyRobotMotion {
    /// The robot's name.
    robot: String,
    /// Whether it was moving at that instant.
    moving: bool,
    /// The motion statement's program file (None: the robot has not moved yet).
    file: Option<String>,
    /// Its line (0 if none).
    line: u32,
    /// Its column (0 if none).
    col: u32,
    /// The statement's text as written (`move_l above speed 250mm/s;`).
    statement: String,
}

#[pymethods]
impl PyRobotMotion {
    fn __repr__(&self) -> String {
        format!("<RobotMotion {}>", self.describe())
    }

    /// For people: `r1 moving: r1.wsl:7:9 move_l above speed 250mm/s;`.
    fn describe(&self) -> String {
        self.inner().describe()
    }
}

impl PyRobotMotion {
    fn inner(&self) -> vworks_log::place::RobotMotion {
        vworks_log::place::RobotMotion {
            robot: self.robot.clone(),
            moving: self.moving,
            file: self.file.clone(),
            line: self.line,
            col: self.col,
            statement: self.statement.clone(),
        }
    }
}

/// The Python objects of a list of motions.
pub(crate) fn motions(list: &[vworks_log::place::RobotMotion]) -> Vec<PyRobotMotion> {
    list.iter()
        .map(|m| PyRobotMotion {
            robot: m.robot.clone(),
            moving: m.moving,
            file: m.file.clone(),
            line: m.line,
            col: m.col,
            statement: m.statement.clone(),
        })
        .collect()
}

/// A line a robot's program logged (`log "…";`, RAPID's `TPWrite`).
#[pyclass(frozen, module = "vworks", get_all, name = "LogLine")]
#[derive(Clone)]
pub(crate) struct PyLogLine {
    /// When (s).
    time: f64,
    /// When (ns).
    time_ns: i64,
    /// The robot whose program logged it.
    robot: String,
    /// The text.
    text: String,
    /// The `log` statement's file, if known.
    file: Option<String>,
    /// Its line (0 if unknown).
    line: u32,
    /// Its column (0 if unknown).
    col: u32,
}

#[pymethods]
impl PyLogLine {
    fn __repr__(&self) -> String {
        format!(
            "<LogLine {:.3} s {}: {:?}>",
            self.time, self.robot, self.text
        )
    }
}

/// The Python object of a logged line.
pub(crate) fn log_line(l: &vworks_log::place::LogLine) -> PyLogLine {
    PyLogLine {
        time: l.time_ns as f64 / 1e9,
        time_ns: l.time_ns,
        robot: l.robot.clone(),
        text: l.text.clone(),
        file: l.file.clone(),
        line: l.line,
        col: l.col,
    }
}

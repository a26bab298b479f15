//! Variants of a workcell by dotted paths (`Loader`), and `param`s set by the workcell.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};
use std::sync::Arc;

use vworks_cell::{Disk, Loader, MemoryFiles, Override};
use vworks_vm::ConstValue;

fn workcell(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../../workcells/{name}/cell.toml"))
}

#[test]
fn overrides_change_the_values_they_name_and_nothing_else() {
    let loader = Loader::new(&workcell("handoff"), &Disk).unwrap();
    let base = loader.base();
    let v = loader
        .load(&[
            Override::new("robot.r2.base.xyz.0", "650mm"),
            Override::new("cycle", "2ms"),
            Override::new("robot.r1.default_speed", 0.4),
        ])
        .unwrap();
    assert!((v.robots[1].base.t[0] - 0.65).abs() < 1e-12);
    assert_eq!(v.robots[1].base.t[1], base.robots[1].base.t[1]);
    assert_eq!(v.cycle_ns, 2_000_000);
    assert_eq!(v.robots[0].default_speed, 0.4);
    assert_eq!(base.cycle_ns, 4_000_000);
    assert_eq!(
        v.overrides,
        vec![
            ("robot.r2.base.xyz.0".to_string(), "\"650mm\"".to_string()),
            ("cycle".to_string(), "\"2ms\"".to_string()),
            ("robot.r1.default_speed".to_string(), "0.4".to_string()),
        ]
    );
    // Each program compiled once, each model loaded once, for every variant.
    assert!(Arc::ptr_eq(&v.robots[0].module, &base.robots[0].module));
    assert!(Arc::ptr_eq(&v.robots[1].model, &base.robots[1].model));
    // A later override of the same path wins.
    let w = loader
        .load(&[Override::new("cycle", "2ms"), Override::new("cycle", "8ms")])
        .unwrap();
    assert_eq!(w.cycle_ns, 8_000_000);
}

#[test]
fn grip_distances_are_variables_cell_wide_and_per_robot() {
    // handoff sets no grip_distance: 5 mm for both robots; the cell's value applies to
    // every robot, and a robot's own wins over it.
    let loader = Loader::new(&workcell("handoff"), &Disk).unwrap();
    for p in [
        "grip_distance",
        "robot.r1.grip_distance",
        "robot.r2.grip_distance",
    ] {
        assert!(loader.variables().iter().any(|v| v == p), "{p}");
    }
    let base = loader.base();
    assert_eq!(base.grip_distance, vworks_cell::DEFAULT_GRIP_DISTANCE);
    assert_eq!(base.robots[1].grip_distance, 0.005);
    let v = loader
        .load(&[
            Override::new("grip_distance", "20mm"),
            Override::new("robot.r2.grip_distance", "1mm"),
        ])
        .unwrap();
    assert!((v.robots[0].grip_distance - 0.02).abs() < 1e-12);
    assert!((v.robots[1].grip_distance - 0.001).abs() < 1e-12);
}

#[test]
fn absent_poses_are_variables_too() {
    // crash's robot `left` has no `base`, and the table has no `rpy`.
    let loader = Loader::new(&workcell("crash"), &Disk).unwrap();
    for p in [
        "robot.left.base.xyz.1",
        "robot.left.base.rpy.2",
        "device.table.pose.rpy.2",
        "device.table.pose.xyz.2",
        "robot.right.tool.xyz.2",
        "clearance",
    ] {
        assert!(loader.variables().iter().any(|v| v == p), "{p}");
    }
    let v = loader
        .load(&[
            Override::new("robot.left.base.xyz.1", -0.1),
            Override::new("device.table.pose.rpy.2", "90deg"),
        ])
        .unwrap();
    assert!((v.robots[0].base.t[1] + 0.1).abs() < 1e-12);
    assert_eq!(v.robots[0].base.t[0], 0.0);
    assert!(
        (v.devices[0].pose.r[0][1] + 1.0).abs() < 1e-12,
        "{:?}",
        v.devices[0].pose
    );
}

#[test]
fn a_wrong_path_lists_the_nearest_and_a_wrong_value_names_its_path() {
    let loader = Loader::new(&workcell("handoff"), &Disk).unwrap();
    let e = loader
        .load(&[Override::new("robot.r3.base.xyz.0", 0.5)])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("robot.r3.base.xyz.0: not a value of this workcell"),
        "{e}"
    );
    assert!(
        e.contains("robot.r1.base.xyz.0") && e.contains("robot.r2.base.xyz.0"),
        "{e}"
    );
    // Names and file paths are not variables.
    assert!(loader.check("robot.r1.program").is_err());
    assert!(loader.check("robot.r1.model").is_err());
    let e = loader
        .load(&[Override::new("robot.r2.base.xyz.0", "12 apples")])
        .unwrap_err()
        .to_string();
    assert!(e.contains("robot[1] `r2`.base.xyz"), "{e}");
}

#[test]
fn params_are_variables_and_take_their_values() {
    let mut files = MemoryFiles::default();
    files.insert(
        Path::new("c/cell.toml"),
        b"name = \"p\"\n[params]\npause = \"2s\"\n[[robot]]\nname = \"a\"\nmodel = \"turntable\"\nprogram = \"t.wsl\"\n[[robot]]\nname = \"b\"\nmodel = \"turntable\"\nprogram = \"t.wsl\"\nbase = { xyz = [2, 0, 0] }\n".to_vec(),
    );
    files.insert(
        Path::new("c/t.wsl"),
        b"param pause = 1s;\nparam laps = 2;\nproc main() { for k in 1..laps { delay pause; } }\n"
            .to_vec(),
    );
    let loader = Loader::new(Path::new("c/cell.toml"), &files).unwrap();
    for p in [
        "params.pause",
        "params.laps",
        "robot.a.params.laps",
        "robot.b.params.pause",
    ] {
        assert!(loader.variables().iter().any(|v| v == p), "{p}");
    }
    let init = |c: &vworks_cell::Cell, r: usize, name: &str| {
        let m = &c.robots[r].module;
        m.vars
            .iter()
            .find(|v| m.str(v.name) == name)
            .unwrap()
            .init
            .clone()
    };
    // The file's [params] apply to both robots; the module is shared while they agree.
    let base = loader.base();
    assert_eq!(init(base, 0, "pause"), ConstValue::Num(2.0));
    assert!(Arc::ptr_eq(&base.robots[0].module, &base.robots[1].module));
    let v = loader
        .load(&[
            Override::new("robot.b.params.laps", 5),
            Override::new("params.pause", "250ms"),
        ])
        .unwrap();
    assert_eq!(init(&v, 0, "laps"), ConstValue::Int(2));
    assert_eq!(init(&v, 1, "laps"), ConstValue::Int(5));
    assert_eq!(init(&v, 1, "pause"), ConstValue::Num(0.25));
    let e = loader
        .load(&[Override::new("params.laps", 2.5)])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("params.laps") && e.contains("a whole number"),
        "{e}"
    );
}

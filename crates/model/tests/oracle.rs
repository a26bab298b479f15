//! Forward kinematics equals Pinocchio's, link by link, to 1e-9 m.
//!
//! `test_data/reference/*.json` is written by `scripts/pin_reference.py` from Pinocchio (the
//! `pin` wheel) loading the same URDFs: the six built-in models and three third-party
//! URDFs from the `pybullet` wheel's pybullet_data (kuka_iiwa, franka_panda, xarm6). CI
//! re-runs the script with `--check`. The third-party URDFs are read from pybullet_data
//! itself: set PYBULLET_DATA, or have a `python3` that imports pybullet_data. Without
//! them this test fails; it does not skip.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::path::PathBuf;
use std::process::Command;

use vworks_model::urdf::{LoadOptions, load_file};
use vworks_model::{RobotModel, builtin};

fn pybullet_data() -> PathBuf {
    if let Some(p) = std::env::var_os("PYBULLET_DATA") {
        return PathBuf::from(p);
    }
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    for py in [root.join(".venv/bin/python"), PathBuf::from("python3")] {
        let out = Command::new(&py)
            .args([
                "-c",
                "import pybullet_data; print(pybullet_data.getDataPath())",
            ])
            .output();
        if let Ok(o) = out
            && o.status.success()
        {
            return PathBuf::from(String::from_utf8_lossy(&o.stdout).trim());
        }
    }
    panic!(
        "pybullet_data not found: `pip install pybullet` (the README's test command does) or set PYBULLET_DATA"
    );
}

fn load(reference: &serde_json::Value) -> RobotModel {
    let name = reference["model"].as_str().unwrap();
    let tool = reference["tool"].as_str().map(str::to_string);
    match reference["where"].as_str().unwrap() {
        "builtin" => builtin::load(name).unwrap_or_else(|e| panic!("{e}")),
        _ => {
            let path = pybullet_data().join(reference["urdf"].as_str().unwrap());
            let opts = LoadOptions {
                tool_link: tool.filter(|_| name == "franka_panda"),
                package_paths: vec![],
            };
            load_file(&path, &opts).unwrap_or_else(|e| panic!("{e}"))
        }
    }
}

#[test]
fn fk_of_every_link_equals_pinocchio() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("test_data/reference");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    assert_eq!(
        files.len(),
        9,
        "six built-in models and three pybullet_data URDFs"
    );
    let mut compared = 0usize;
    let mut worst: f64 = 0.0;
    for f in files {
        let r: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&f).unwrap()).unwrap();
        let m = load(&r);
        let name = r["model"].as_str().unwrap();
        let axes: Vec<&str> = r["axes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|a| a.as_str().unwrap())
            .collect();
        let mine: Vec<&str> = (0..m.dof()).map(|i| m.axis(i).name.as_str()).collect();
        assert_eq!(mine, axes, "{name}: axes");
        assert_eq!(
            m.links[m.tool_link].name,
            r["tool"].as_str().unwrap(),
            "{name}: tool link"
        );
        let samples = r["samples"].as_array().unwrap();
        assert!(samples.len() >= 100);
        let mut frames = m.frames_buffer();
        for s in samples {
            let q: Vec<f64> = s["q"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            m.fk_into(&q, &mut frames);
            let links = s["links"].as_object().unwrap();
            assert_eq!(links.len(), m.links.len(), "{name}: link count");
            for (lname, pose) in links {
                let li = m
                    .link_index(lname)
                    .unwrap_or_else(|| panic!("{name}: no link {lname}"));
                let want: Vec<f64> = pose
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|v| v.as_f64().unwrap())
                    .collect();
                let got = frames[li];
                let mut err: f64 = 0.0;
                for k in 0..3 {
                    err = err.max((got.t[k] - want[k]).abs());
                    for c in 0..3 {
                        err = err.max((got.r[k][c] - want[3 + 3 * k + c]).abs());
                    }
                }
                assert!(
                    err < 1e-9,
                    "{name} link {lname} q {q:?}: differs by {err:e}"
                );
                worst = worst.max(err);
                compared += 1;
            }
        }
    }
    eprintln!("compared {compared} link frames with Pinocchio; largest difference {worst:e}");
}

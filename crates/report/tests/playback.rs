//! The report's playback data from real logs: what moves is sampled at 30 frames per
//! simulated second and at every collision's start, each sample the latest `/tf`
//! transform at or before its time; what does not move keeps its first pose. A robot's
//! link is one angle per sample, a held part its whole pose.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::path::PathBuf;
use std::sync::Arc;

use vworks_log::mcaplog::{McapLog, ReadOptions, read_log_with};
use vworks_log::trace::Kind;
use vworks_report::playback::{FRAMES_PER_SECOND, Joint, Playback};
use vworks_se::Simulation;

fn log_of(cell: &str) -> vworks_log::mcaplog::LogContents {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    log_of_cell(cell, &root.join(format!("workcells/{cell}/cell.toml")))
}

fn log_of_cell(cell: &str, file: &std::path::Path) -> vworks_log::mcaplog::LogContents {
    let c = Arc::new(vworks_cell::load(file).unwrap());
    let path = std::env::temp_dir().join(format!(
        "vworks-playback-{cell}-{}.mcap",
        std::process::id()
    ));
    let log = McapLog::create(&path, &Arc::new(vworks_se::describe(&c)), 1).unwrap();
    Simulation::new(Arc::clone(&c)).with_log(log).run(None);
    let contents = read_log_with(&path, ReadOptions { poses: true }).unwrap();
    let _ = std::fs::remove_file(&path);
    contents
}

#[test]
fn links_are_sampled_and_the_rest_keeps_its_pose() {
    let log = log_of("crash");
    let p = Playback::from_log(&log).unwrap();
    let step = 1_000_000_000 / FRAMES_PER_SECOND;
    // Every 1/30 s, the collision's start, and the end.
    let collision = log
        .events
        .iter()
        .find(|e| e.kind == Kind::CollisionStart)
        .unwrap()
        .time_ns as u64;
    assert!(p.times_ns.contains(&collision) && !collision.is_multiple_of(step));
    assert!(p.times_ns.windows(2).all(|w| w[0] < w[1]));
    // The robots' links move, each about its joint's axis (one angle per sample); the
    // world, the robots' bases, their TCPs and the devices do not.
    let name = |i: u32| p.frames[i as usize].as_str();
    assert!(
        p.tracks
            .iter()
            .all(|t| name(t.frame).contains(".link_") && matches!(t.joint, Joint::Revolute { .. })),
        "{:?}",
        p.tracks
    );
    assert!(p.tracks.len() >= 6);
    assert_eq!(p.stride(), p.tracks.len());
    assert_eq!(p.values.len(), p.times_ns.len() * p.stride());
    // The frame tree as /tf gives it: each link under the one before it.
    let index = |n: &str| p.frames.iter().position(|f| f == n).unwrap() as u32;
    assert_eq!(
        p.parents[index("left.link_2") as usize],
        Some(index("left.link_1"))
    );
    // Each sample is the latest transform at or before its time.
    // (To f32 precision: the angle is encoded as f32.)
    for (k, &t) in p.times_ns.iter().enumerate().step_by(7) {
        for m in p.tracks.iter().map(|t| t.frame) {
            let latest = log
                .transforms
                .iter()
                .take_while(|(at, _)| *at <= t)
                .flat_map(|(_, ts)| ts.iter())
                .filter(|tr| tr.child == m)
                .last()
                .unwrap();
            let want = [
                latest.translation[0],
                latest.translation[1],
                latest.translation[2],
                latest.rotation[0],
                latest.rotation[1],
                latest.rotation[2],
                latest.rotation[3],
            ];
            assert!(
                close(&p.pose(k, m).unwrap(), &want),
                "{} at {t}: {:?} vs {want:?}",
                name(m),
                p.pose(k, m)
            );
        }
    }
}

/// Poses equal to 1e-6 (a rotation and its negative quaternion are the same).
fn close(a: &[f64; 7], b: &[f64; 7]) -> bool {
    let same = |sign: f64| (3..7).all(|i| (a[i] - sign * b[i]).abs() < 1e-6);
    (0..3).all(|i| (a[i] - b[i]).abs() < 1e-6) && (same(1.0) || same(-1.0))
}

/// Every track of `cell`'s playback gives back, at every sample, the latest logged
/// transform of its frame; returns the tracks by kind (revolute, prismatic, free).
fn every_sample_is_the_logged_pose(
    cell: &str,
    log: &vworks_log::mcaplog::LogContents,
) -> [usize; 3] {
    let p = Playback::from_log(log).unwrap();
    let mut latest: Vec<Option<[f64; 7]>> = vec![None; p.frames.len()];
    let mut next = 0;
    for (k, &t) in p.times_ns.iter().enumerate() {
        while let Some((at, ts)) = log.transforms.get(next)
            && *at <= t
        {
            for tr in ts {
                let (q, r) = (tr.translation, tr.rotation);
                latest[tr.child as usize] = Some([q[0], q[1], q[2], r[0], r[1], r[2], r[3]]);
            }
            next += 1;
        }
        // (`world` is no frame's child.) Frames that do not move keep their first pose.
        for (f, want) in latest.iter().enumerate() {
            let Some(want) = want else { continue };
            let got = p.pose(k, f as u32).unwrap();
            assert!(
                close(&got, want),
                "{cell} {} at {t}: {got:?} vs {want:?}",
                p.frames[f]
            );
        }
    }
    let mut kinds = [0; 3];
    for t in &p.tracks {
        kinds[match t.joint {
            Joint::Revolute { .. } => 0,
            Joint::Prismatic { .. } => 1,
            Joint::Free => 2,
        }] += 1;
    }
    kinds
}

#[test]
fn joints_are_one_number_and_held_parts_a_pose() {
    // track: a turntable and an arm; handoff: a part carried from r1 to r2, which moves
    // freely in the world; a linear track (prismatic) written here.
    let track = every_sample_is_the_logged_pose("track", &log_of("track"));
    assert!(track[0] >= 7 && track[1] == 0 && track[2] == 0, "{track:?}");
    let handoff = every_sample_is_the_logged_pose("handoff", &log_of("handoff"));
    assert!(handoff[0] >= 12 && handoff[2] >= 1, "{handoff:?}");
    let dir = std::env::temp_dir().join(format!("vworks-playback-rail-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("cell.toml"),
        "name = \"rail\"\n[[robot]]\nname = \"rail\"\nmodel = \"track\"\nprogram = \"rail.wsl\"\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("rail.wsl"),
        "proc main() { move_j joints(2m); move_j joints(0.5m); }\n",
    )
    .unwrap();
    let rail =
        every_sample_is_the_logged_pose("rail", &log_of_cell("rail", &dir.join("cell.toml")));
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(rail, [0, 1, 0]);
}

#[test]
fn a_log_without_tf_has_no_playback() {
    let mut log = log_of("deadlock");
    assert!(Playback::from_log(&log).is_some());
    log.transforms.clear();
    log.frames.clear();
    assert!(Playback::from_log(&log).is_none());
}

#[test]
fn the_page_carries_the_view_and_loads_nothing() {
    let log = log_of("crash");
    let (report, page) = vworks_report::page(&log, "crash.mcap");
    assert_eq!(report.collisions.len(), 1);
    // One data block, three.js inlined, the page's script after the tables it links to.
    assert_eq!(page.matches("id=\"vworks-playback\"").count(), 1);
    assert!(page.contains("var THREE="));
    assert!(page.find("id=\"events\"") < page.rfind("window.vworksView"));
    // Nothing from elsewhere: no script or stylesheet by URL, no external URL at all in
    // the markup (three.js's own code is checked by loading the page in Chromium).
    assert!(!page.contains("<script src") && !page.contains("<link"));
    let data = vworks_report::viewer::data(&log).unwrap();
    let bodies = data["bodies"].as_array().unwrap();
    // Two irb120s (their capsules drawn as capsules) and the table.
    assert!(
        bodies
            .iter()
            .any(|b| b["frame"] == "table" && b["label"] == "table")
    );
    let kinds: Vec<&str> = bodies
        .iter()
        .flat_map(|b| b["shapes"].as_array().unwrap())
        .map(|s| s["kind"].as_str().unwrap())
        .collect();
    assert!(
        kinds.contains(&"capsule") && kinds.contains(&"box"),
        "{kinds:?}"
    );
    // The colliding links turn red at the collision's start (from /scene).
    let colours = data["colours"].as_array().unwrap();
    assert!(
        colours
            .iter()
            .any(|c| c[1] == "left.link_6" && c[2].as_f64() == Some(0.9))
    );
    assert_eq!(data["tcps"], serde_json::json!(["left:tcp", "right:tcp"]));
    // The same log gives the same bytes.
    assert_eq!(vworks_report::page(&log, "crash.mcap").1, page);
}

#[test]
fn a_log_without_scene_has_a_note_instead_of_the_view() {
    let mut log = log_of("crash");
    log.scene.clear();
    let (_, page) = vworks_report::page(&log, "old.mcap");
    assert!(page.contains("No 3D view: this log has no /scene"));
    assert!(!page.contains("var THREE=") && !page.contains("id=\"vworks-playback\""));
    // The timeline stays (it moves the Gantt chart's cursor).
    assert!(page.contains("id=\"timeline\"") && page.contains("id=\"gantt-cursor\""));
}

#[test]
fn coarse_meshes_keep_the_shape_with_fewer_triangles() {
    // A sphere's 40 × 20 triangle mesh (unit radius).
    let (mut vertices, mut indices) = (Vec::new(), Vec::new());
    let (n, m) = (40u32, 20u32);
    for i in 0..=m {
        for j in 0..n {
            let (th, ph) = (
                std::f32::consts::PI * i as f32 / m as f32,
                2.0 * std::f32::consts::PI * j as f32 / n as f32,
            );
            vertices.extend([th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()]);
        }
    }
    for i in 0..m {
        for j in 0..n {
            let (a, b) = (i * n + j, i * n + (j + 1) % n);
            let (c, d) = (a + n, b + n);
            indices.extend([a, c, b, b, c, d]);
        }
    }
    let (cv, ci) = vworks_report::viewer::coarse(&vertices, &indices, 8.0);
    assert!(
        ci.len() * 3 < indices.len(),
        "{} of {}",
        ci.len() / 3,
        indices.len() / 3
    );
    assert!(ci.len() >= 3 * 40 && ci.iter().all(|&i| (i as usize) < cv.len() / 3));
    // Every coarse vertex is a mean of nearby vertices of the sphere: within a cell of it.
    for v in cv.chunks_exact(3) {
        let r = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        assert!((0.85..=1.0 + 1e-6).contains(&r), "{r}");
    }
}

//! The report's playback data from real logs: what moves is sampled at 30 frames per
//! simulated second and at every collision's start, each sample the latest `/tf`
//! transform at or before its time; what does not move keeps its first pose.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::path::PathBuf;
use std::sync::Arc;

use vworks_report::playback::{FRAMES_PER_SECOND, Playback};
use vworks_se::engine::Simulation;
use vworks_se::mcaplog::{McapLog, ReadOptions, read_log_with};
use vworks_se::trace::Kind;

fn log_of(cell: &str) -> vworks_se::mcaplog::LogContents {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let c = Arc::new(vworks_cell::load(&root.join(format!("workcells/{cell}/cell.toml"))).unwrap());
    let path = std::env::temp_dir().join(format!(
        "vworks-playback-{cell}-{}.mcap",
        std::process::id()
    ));
    let log = McapLog::create(&path, &c, 1).unwrap();
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
    assert_eq!(p.poses.len(), p.times_ns.len() * p.moving.len() * 7);
    // The robots' links move; the world, the robots' bases and the devices do not.
    let name = |i: u32| p.frames[i as usize].as_str();
    assert!(
        p.moving.iter().all(|&m| name(m).contains(".link_")),
        "{:?}",
        p.moving.iter().map(|&m| name(m)).collect::<Vec<_>>()
    );
    assert!(p.moving.len() >= 6);
    // The frame tree as /tf gives it: each link under the one before it.
    let index = |n: &str| p.frames.iter().position(|f| f == n).unwrap() as u32;
    assert_eq!(
        p.parents[index("left.link_2") as usize],
        Some(index("left.link_1"))
    );
    // Each sample is the latest transform at or before its time.
    for (k, &t) in p.times_ns.iter().enumerate().step_by(7) {
        for &m in &p.moving {
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
            ]
            .map(|x| x as f32);
            assert_eq!(p.pose(k, m).unwrap(), want, "{} at {t}", name(m));
        }
    }
}

#[test]
fn a_log_without_tf_has_no_playback() {
    let mut log = log_of("deadlock");
    assert!(Playback::from_log(&log).is_some());
    log.transforms.clear();
    log.frames.clear();
    assert!(Playback::from_log(&log).is_none());
}

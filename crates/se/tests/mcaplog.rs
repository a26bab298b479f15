//! MCAP logs read back with the `mcap` crate's reader: valid and complete after every
//! outcome, per-topic counts equal the run's own, events equal the trace, thinning works.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use foxglove::messages::FrameTransforms;
use prost::Message as _;
use vworks_cell::{Cell, load};
use vworks_log::mcaplog::{
    Encoding, LogOptions, McapLog, ReadOptions, read_log_bytes, read_log_bytes_with,
};
use vworks_log::result::{Outcome, RunResult};
use vworks_log::trace::Kind;
use vworks_model::math::Iso;
use vworks_se::CellNames;
use vworks_se::Simulation;

/// `vworks.CycleState` as the log's descriptor defines it (the descriptor itself is checked
/// in the unit tests and, independently, by the Python tests).
#[derive(Clone, PartialEq, prost::Message)]
struct CycleState {
    #[prost(uint64, tag = "1")]
    time_ns: u64,
    #[prost(uint64, tag = "2")]
    cycle: u64,
    #[prost(message, repeated, tag = "3")]
    robots: Vec<RobotState>,
}

#[derive(Clone, PartialEq, prost::Message)]
struct RobotState {
    #[prost(string, tag = "1")]
    name: String,
    #[prost(double, repeated, tag = "2")]
    joints: Vec<f64>,
    #[prost(message, optional, tag = "3")]
    tcp: Option<foxglove::messages::Pose>,
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn run_logged(
    cell: &Arc<Cell>,
    every: u64,
    until: Option<i64>,
    name: &str,
) -> (RunResult, Vec<u8>) {
    let path = std::env::temp_dir().join(format!("vworks-log-{name}-{}.mcap", std::process::id()));
    let log = McapLog::create(&path, &Arc::new(vworks_se::describe(cell)), every).unwrap();
    let r = Simulation::new(Arc::clone(cell)).with_log(log).run(until);
    assert!(r.log_error.is_none(), "{:?}", r.log_error);
    let bytes = std::fs::read(&path).unwrap();
    let _ = std::fs::remove_file(&path);
    (r, bytes)
}

/// Reads every message (checking chunk CRCs) and the summary; returns per-topic counts
/// and the event lines.
fn read_back(bytes: &[u8]) -> (BTreeMap<String, u64>, Vec<String>) {
    let summary = mcap::Summary::read(bytes)
        .unwrap()
        .expect("a finished file has a summary");
    assert_eq!(summary.channels.len(), 5);
    // Every channel counts, even one with no messages.
    let mut counts: BTreeMap<String, u64> = summary
        .channels
        .values()
        .map(|c| (c.topic.clone(), 0))
        .collect();
    let mut events = Vec::new();
    for m in mcap::MessageStream::new(bytes).unwrap() {
        let m = m.unwrap();
        *counts.entry(m.channel.topic.clone()).or_default() += 1;
        let schema = m.channel.schema.as_ref().unwrap();
        if m.channel.message_encoding == "protobuf" {
            // The schema is a FileDescriptorSet naming the message; the message decodes.
            assert_eq!(schema.encoding, "protobuf");
            let set = prost_types::FileDescriptorSet::decode(&schema.data[..])
                .unwrap_or_else(|e| panic!("schema {} does not parse: {e}", schema.name));
            assert!(
                set.file
                    .iter()
                    .any(|f| f.message_type.iter().any(|d| Some(format!(
                        "{}.{}",
                        f.package(),
                        d.name()
                    )) == Some(schema.name.clone()))),
                "{} is not in its descriptor set",
                schema.name
            );
            match m.channel.topic.as_str() {
                "/tf" => assert!(
                    !FrameTransforms::decode(&m.data[..])
                        .unwrap()
                        .transforms
                        .is_empty()
                ),
                "/state" => assert!(!CycleState::decode(&m.data[..]).unwrap().robots.is_empty()),
                other => panic!("{other} is not a protobuf topic"),
            }
            continue;
        }
        assert_eq!(schema.encoding, "jsonschema");
        let _: serde_json::Value = serde_json::from_slice(&schema.data)
            .unwrap_or_else(|e| panic!("schema {} is not JSON: {e}", schema.name));
        let v: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
        if m.channel.topic == "/events" {
            let pos = match v["file"].as_str() {
                Some(f) => format!(
                    "{}:{}:{}",
                    Path::new(f).file_name().unwrap().to_string_lossy(),
                    v["line"],
                    v["col"]
                ),
                None => "-".into(),
            };
            let details = v["details"]
                .as_str()
                .filter(|d| !d.is_empty())
                .unwrap_or("-");
            events.push(format!(
                "{} {} {} {details} {pos}",
                v["time_ns"],
                v["robot"].as_str().unwrap_or("-"),
                v["kind"].as_str().unwrap()
            ));
        }
    }
    (counts, events)
}

fn check(cell: &Arc<Cell>, r: &RunResult, bytes: &[u8]) {
    let (counts, events) = read_back(bytes);
    let own: BTreeMap<String, u64> = r
        .log_counts
        .iter()
        .map(|(k, v)| (k.to_string(), *v))
        .collect();
    assert_eq!(counts, own, "per-topic counts");
    let trace: Vec<String> = r.trace.iter().map(|e| e.line(&CellNames(cell))).collect();
    assert_eq!(events, trace, "the log's events are the trace");
}

#[test]
fn logs_are_complete_after_every_outcome() {
    for (name, want) in [
        ("monitor", Outcome::Completed),
        ("crash", Outcome::Collision),
        ("deadlock", Outcome::Deadlock),
    ] {
        let cell = Arc::new(load(&root().join("workcells").join(name).join("cell.toml")).unwrap());
        let (r, bytes) = run_logged(&cell, 1, None, name);
        assert_eq!(r.outcome, want);
        check(&cell, &r, &bytes);
        // Every processed boundary has a state and a transform message.
        let (counts, _) = read_back(&bytes);
        assert_eq!(counts["/state"], r.cycles, "{name}");
        assert_eq!(counts["/tf"], r.cycles, "{name}");
    }
    // --until.
    let cell = Arc::new(load(&root().join("workcells/handoff/cell.toml")).unwrap());
    let (r, bytes) = run_logged(&cell, 1, Some(5_000_000_000), "until");
    assert_eq!(r.outcome, Outcome::Until);
    check(&cell, &r, &bytes);
}

#[test]
fn a_runtime_error_leaves_a_valid_log() {
    let dir = std::env::temp_dir().join(format!("vworks-log-err-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("cell.toml"),
        "[[robot]]\nname = \"r1\"\nmodel = \"irb120\"\nprogram = \"r1.wsl\"\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("r1.wsl"),
        "proc main() {\n    delay 0.1s;\n    fail \"gripper empty\";\n}\n",
    )
    .unwrap();
    let cell = Arc::new(load(&dir.join("cell.toml")).unwrap());
    let (r, bytes) = run_logged(&cell, 1, None, "error");
    assert_eq!(r.outcome, Outcome::Error);
    check(&cell, &r, &bytes);
    let (counts, events) = read_back(&bytes);
    assert!(
        events.last().unwrap().contains("error \"gripper empty\""),
        "{events:?}"
    );
    assert_eq!(counts["/log"], 1);
}

#[test]
fn thinning_keeps_every_event_and_every_nth_state() {
    let cell = Arc::new(load(&root().join("workcells/monitor/cell.toml")).unwrap());
    let (r, bytes) = run_logged(&cell, 10, None, "thin");
    check(&cell, &r, &bytes);
    let (counts, _) = read_back(&bytes);
    assert_eq!(counts["/state"], r.cycles.div_ceil(10));
    assert_eq!(counts["/events"], r.trace.len() as u64);
}

#[test]
fn the_cell_and_its_programs_are_attached() {
    let cell = Arc::new(load(&root().join("workcells/handoff/cell.toml")).unwrap());
    let (r, bytes) = run_logged(&cell, 100, Some(1_000_000_000), "attach");
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let names: Vec<String> = summary
        .attachment_indexes
        .iter()
        .map(|a| {
            Path::new(&a.name)
                .file_name()
                .unwrap()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    assert_eq!(names, ["cell.toml", "r1.wsl", "r2.wsl"]);
    let meta = &summary.metadata_indexes;
    let names: Vec<&str> = meta.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["vworks", "vworks_result"]);
    // The run's result closes the log: outcome, end time, each robot's ending, as the
    // run itself gave them.
    let log = read_log_bytes("attach.mcap", &bytes).unwrap();
    assert_eq!(log.metadata["log_version"], "3");
    assert_eq!(log.result["outcome"], "until");
    assert_eq!(log.result["end_time_ns"], "1000000000");
    let ended: Vec<String> = r
        .robots
        .iter()
        .map(|s| format!("{}={}", s.name, s.ended.name()))
        .collect();
    assert_eq!(log.result["ended"], ended.join(","));
    assert_eq!(log.result["ended"], "r1=running,r2=waiting");
}

#[test]
fn urdfs_and_meshes_are_attached_and_meshes_drawn_as_triangles() {
    let dir = std::env::temp_dir().join(format!("vworks-log-urdf-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    let stl = "solid t\n\
        facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\nvertex 0 0.1 0\nendloop\nendfacet\n\
        facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0.1 0\nvertex 0 0 0.1\nendloop\nendfacet\n\
        facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0 0.1\nvertex 0.1 0 0\nendloop\nendfacet\n\
        facet normal 0 0 0\nouter loop\nvertex 0.1 0 0\nvertex 0 0.1 0\nvertex 0 0 0.1\nendloop\nendfacet\n\
        endsolid t\n";
    std::fs::write(dir.join("meshes/tip.stl"), stl).unwrap();
    let urdf = r#"<robot name="arm">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="tip"><collision><geometry><mesh filename="meshes/tip.stl"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="tip"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" velocity="2" effort="1"/></joint>
</robot>
"#;
    std::fs::write(dir.join("arm.urdf"), urdf).unwrap();
    std::fs::write(
        dir.join("cell.toml"),
        "[[robot]]\nname = \"r1\"\nurdf = \"arm.urdf\"\nprogram = \"r1.wsl\"\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("r1.wsl"),
        "proc main() {\n    move_j joints(30deg);\n}\n",
    )
    .unwrap();
    let cell = Arc::new(load(&dir.join("cell.toml")).unwrap());
    let (r, bytes) = run_logged(&cell, 1, None, "urdf");
    assert_eq!(r.outcome, Outcome::Completed);
    check(&cell, &r, &bytes);
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let mut attached = BTreeMap::new();
    for index in &summary.attachment_indexes {
        let a = mcap::read::attachment(&bytes, index).unwrap();
        let name = Path::new(&a.name)
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        attached.insert(name, (a.media_type.clone(), a.data.into_owned()));
    }
    let names: Vec<&String> = attached.keys().collect();
    assert_eq!(names, ["arm.urdf", "cell.toml", "r1.wsl", "tip.stl"]);
    assert_eq!(attached["arm.urdf"].0, "application/xml");
    assert_eq!(attached["arm.urdf"].1, urdf.as_bytes());
    assert_eq!(attached["tip.stl"].0, "model/stl");
    assert_eq!(attached["tip.stl"].1, stl.as_bytes());
    // The first scene message draws the mesh's hull: a tetrahedron, 4 triangles.
    let scene = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(Result::unwrap)
        .find(|m| m.channel.topic == "/scene")
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&scene.data).unwrap();
    let tip = v["entities"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["frame_id"] == "r1.tip")
        .unwrap();
    let points = tip["triangles"][0]["points"].as_array().unwrap();
    assert_eq!(points.len(), 12, "{tip}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every `/tf` transform of a log, as (time, parent, child, translation, rotation),
/// whichever encoding it was written in.
type Transform = (u64, String, String, [f64; 3], [f64; 4]);

fn transforms(bytes: &[u8]) -> Vec<Transform> {
    let mut out = Vec::new();
    for m in mcap::MessageStream::new(bytes).unwrap() {
        let m = m.unwrap();
        if m.channel.topic != "/tf" {
            continue;
        }
        if m.channel.message_encoding == "protobuf" {
            for t in FrameTransforms::decode(&m.data[..]).unwrap().transforms {
                let (p, q) = (t.translation.unwrap(), t.rotation.unwrap());
                let stamp = t.timestamp.unwrap();
                let time = u64::from(stamp.sec()) * 1_000_000_000 + u64::from(stamp.nsec());
                assert_eq!(time, m.log_time);
                out.push((
                    m.log_time,
                    t.parent_frame_id,
                    t.child_frame_id,
                    [p.x, p.y, p.z],
                    [q.x, q.y, q.z, q.w],
                ));
            }
        } else {
            let v: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
            for t in v["transforms"].as_array().unwrap() {
                let f = |x: &serde_json::Value| x.as_f64().unwrap();
                let (p, q) = (&t["translation"], &t["rotation"]);
                out.push((
                    m.log_time,
                    t["parent_frame_id"].as_str().unwrap().to_string(),
                    t["child_frame_id"].as_str().unwrap().to_string(),
                    [f(&p["x"]), f(&p["y"]), f(&p["z"])],
                    [f(&q["x"]), f(&q["y"]), f(&q["z"]), f(&q["w"])],
                ));
            }
        }
    }
    out
}

/// Every `/state` of a log: time → per robot (name, joints, TCP position, TCP rotation).
type States = BTreeMap<u64, Vec<(String, Vec<f64>, [f64; 3], [f64; 4])>>;

fn states(bytes: &[u8]) -> States {
    let mut out = BTreeMap::new();
    for m in mcap::MessageStream::new(bytes).unwrap() {
        let m = m.unwrap();
        if m.channel.topic != "/state" {
            continue;
        }
        let robots = if m.channel.message_encoding == "protobuf" {
            let s = CycleState::decode(&m.data[..]).unwrap();
            assert_eq!(s.time_ns, m.log_time);
            s.robots
                .into_iter()
                .map(|r| {
                    let tcp = r.tcp.unwrap_or_default();
                    let (p, q) = (
                        tcp.position.unwrap_or_default(),
                        tcp.orientation.unwrap_or_default(),
                    );
                    (r.name, r.joints, [p.x, p.y, p.z], [q.x, q.y, q.z, q.w])
                })
                .collect()
        } else {
            let v: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
            assert_eq!(v["time_ns"].as_u64(), Some(m.log_time));
            let f = |x: &serde_json::Value| x.as_f64().unwrap();
            v["robots"]
                .as_array()
                .unwrap()
                .iter()
                .map(|r| {
                    let (p, q) = (&r["tcp"]["position"], &r["tcp"]["orientation"]);
                    (
                        r["name"].as_str().unwrap().to_string(),
                        r["joints"].as_array().unwrap().iter().map(f).collect(),
                        [f(&p["x"]), f(&p["y"]), f(&p["z"])],
                        [f(&q["x"]), f(&q["y"]), f(&q["z"]), f(&q["w"])],
                    )
                })
                .collect()
        };
        out.insert(m.log_time, robots);
    }
    out
}

/// The rigid transform of a translation and a unit quaternion (x, y, z, w).
fn iso(t: [f64; 3], q: [f64; 4]) -> Iso {
    let [x, y, z, w] = q;
    Iso {
        r: [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - z * w),
                2.0 * (x * z + y * w),
            ],
            [
                2.0 * (x * y + z * w),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - x * w),
            ],
            [
                2.0 * (x * z - y * w),
                2.0 * (y * z + x * w),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ],
        t,
    }
}

#[test]
fn protobuf_and_json_logs_carry_the_same_states_and_poses() {
    let cell = Arc::new(load(&root().join("workcells/track/cell.toml")).unwrap());
    let mut logs = Vec::new();
    for (encoding, name) in [(Encoding::Protobuf, "pb"), (Encoding::Json, "json")] {
        let path =
            std::env::temp_dir().join(format!("vworks-log-{name}-{}.mcap", std::process::id()));
        let log = McapLog::create_with(
            &path,
            &Arc::new(vworks_se::describe(&cell)),
            LogOptions::new(1, encoding),
        )
        .unwrap();
        let r = Simulation::new(Arc::clone(&cell)).with_log(log).run(None);
        let bytes = std::fs::read(&path).unwrap();
        let _ = std::fs::remove_file(&path);
        check(&cell, &r, &bytes);
        // vworks's own reader (for playback) decodes /tf as the foxglove crate does, and
        // reads every /scene message.
        let read = read_log_bytes_with("t.mcap", &bytes, ReadOptions { poses: true }).unwrap();
        let ours: Vec<Transform> = read
            .transforms
            .iter()
            .flat_map(|(t, ts)| {
                let names = &read.frames;
                ts.iter().map(move |f| {
                    (
                        *t,
                        names[f.parent as usize].clone(),
                        names[f.child as usize].clone(),
                        f.translation,
                        f.rotation,
                    )
                })
            })
            .collect();
        assert_eq!(ours, transforms(&bytes), "{name}");
        assert_eq!(read.scene.len() as u64, read.counts["/scene"]);
        assert!(
            read.scene[0].1["entities"]
                .as_array()
                .is_some_and(|e| !e.is_empty())
        );
        // Without the option, only counted.
        let plain = read_log_bytes("t.mcap", &bytes).unwrap();
        assert!(plain.transforms.is_empty() && plain.scene.is_empty() && plain.frames.is_empty());
        logs.push((transforms(&bytes), states(&bytes)));
    }
    // The JSON writer prints shortest round-trip decimals; serde_json's default parser may
    // land one ulp away, so values agree to 1e-15 and times and names exactly.
    let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-15);
    let ((tf_pb, state_pb), (tf_json, state_json)) = (&logs[0], &logs[1]);
    assert!(tf_pb.len() > 1000, "{}", tf_pb.len());
    assert_eq!(tf_pb.len(), tf_json.len());
    for (pb, json) in tf_pb.iter().zip(tf_json) {
        assert_eq!((pb.0, &pb.1, &pb.2), (json.0, &json.1, &json.2));
        assert!(
            close(&pb.3, &json.3) && close(&pb.4, &json.4),
            "{pb:?} vs {json:?}"
        );
    }
    assert!(state_pb.len() > 1000, "{}", state_pb.len());
    assert_eq!(
        state_pb.keys().collect::<Vec<_>>(),
        state_json.keys().collect::<Vec<_>>()
    );
    for (pb, json) in state_pb.values().zip(state_json.values()) {
        for (a, b) in pb.iter().zip(json) {
            assert_eq!((&a.0, a.1.len()), (&b.0, b.1.len()));
            assert!(
                close(&a.1, &b.1) && close(&a.2, &b.2) && close(&a.3, &b.3),
                "{a:?} vs {b:?}"
            );
        }
    }
    // Between keyframes only changed frames are sent; at t = 0 every frame is, each once
    // (a robot's links and its TCP).
    let frames = cell
        .robots
        .iter()
        .map(|r| r.model.links.len() + 1)
        .sum::<usize>()
        + cell.devices.len()
        + cell.parts.len();
    assert_eq!(tf_pb.iter().filter(|t| t.0 == 0).count(), frames);
}

/// The latest `/tf` transforms replayed: each frame's parent and pose in it.
type Latest = BTreeMap<String, (String, Iso)>;

/// Frame `frame`'s pose in `world`: its chain of latest transforms.
fn in_world(latest: &Latest, frame: &str) -> Iso {
    let mut pose = Iso::IDENTITY;
    let mut at = frame.to_string();
    while at != "world" {
        let (parent, local) = &latest[&at];
        pose = local.mul(&pose);
        at = parent.clone();
    }
    pose
}

/// True if every rotation and translation entry of `a` and `b` is within 1e-9.
fn close(a: &Iso, b: &Iso) -> bool {
    a.t.iter()
        .chain(a.r.iter().flatten())
        .zip(b.t.iter().chain(b.r.iter().flatten()))
        .all(|(x, y)| (x - y).abs() < 1e-9)
}

#[test]
fn frame_transforms_are_the_forward_kinematics_of_the_logged_joints() {
    // /tf is a tree (world → each robot's root link → its links by joint; devices and parts
    // under world). Replaying it, every link's pose in the world (its chain of latest
    // transforms) equals base × FK(the joints /state logged at that time), and /state's
    // TCP equals base × FK × tool and the pose of the `robot:tcp` frame.
    for name in ["track", "handoff"] {
        let cell = Arc::new(load(&root().join(format!("workcells/{name}/cell.toml"))).unwrap());
        let (r, bytes) = run_logged(&cell, 1, Some(20_000_000_000), &format!("fk-{name}"));
        assert!(r.log_error.is_none());
        let states = states(&bytes);
        let mut latest = Latest::new();
        let all = transforms(&bytes);
        let mut checked = 0;
        for (i, (t, parent, child, p, q)) in all.iter().enumerate() {
            latest.insert(child.clone(), (parent.clone(), iso(*p, *q)));
            // Check once the whole message at `t` has been applied.
            if all.get(i + 1).is_some_and(|next| next.0 == *t) {
                continue;
            }
            for (r, robot) in cell.robots.iter().enumerate() {
                let (_, q, tcp_p, tcp_q) = &states[t][r];
                let fk = robot.model.fk(q);
                for (l, link) in robot.model.links.iter().enumerate() {
                    let got = in_world(&latest, &format!("{}.{}", robot.name, link.name));
                    let want = robot.base.mul(&fk[l]);
                    assert!(
                        close(&want, &got),
                        "{name} {}.{} at {t}",
                        robot.name,
                        link.name
                    );
                    checked += 1;
                }
                let tcp = robot.base.mul(&fk[robot.model.tool_link]).mul(&robot.tool);
                let logged = iso(*tcp_p, *tcp_q);
                let framed = in_world(&latest, &vworks_log::mcaplog::tcp_frame(&robot.name));
                for got in [logged, framed] {
                    assert!(close(&tcp, &got), "{name} {} TCP at {t}", robot.name);
                }
            }
        }
        assert!(checked > 1000, "{checked}");
    }
}

#[cfg(target_os = "linux")]
#[test]
fn a_log_that_cannot_be_written_is_reported_and_the_run_goes_on() {
    // /dev/full accepts the open and fails every write with ENOSPC: the writer thread
    // stops, the run finishes as it would without a log and says why the log is missing.
    let cell = Arc::new(load(&root().join("workcells/handoff/cell.toml")).unwrap());
    let plain = Simulation::new(Arc::clone(&cell)).run(None);
    let log = McapLog::create(
        Path::new("/dev/full"),
        &Arc::new(vworks_se::describe(&cell)),
        1,
    )
    .unwrap();
    let r = Simulation::new(Arc::clone(&cell)).with_log(log).run(None);
    let err = r.log_error.clone().expect("the log error is reported");
    assert!(
        err.contains("`/dev/full`") && err.contains("No space left on device"),
        "{err}"
    );
    assert_eq!(
        (r.outcome, r.end_time_ns),
        (plain.outcome, plain.end_time_ns)
    );
    let lines = |x: &RunResult| {
        x.trace
            .iter()
            .map(|e| e.line(&CellNames(&cell)))
            .collect::<Vec<_>>()
    };
    assert_eq!(lines(&r), lines(&plain));
    assert!(r.log_counts.is_empty());
    // A file that cannot be created is an error at once, naming it.
    let missing = root().join("no such dir").join("run.mcap");
    let err = McapLog::create(&missing, &Arc::new(vworks_se::describe(&cell)), 1)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("no such dir") && err.contains("No such file"),
        "{err}"
    );
}

#[test]
fn chunks_are_compressed_at_the_documented_zstd_level() {
    // The level reaches zstd through the mcap crate's u32 parameter; check it took effect:
    // a full chunk compresses to about what zstd gives at ZSTD_LEVEL, and clearly not to
    // what it gives at level 1.
    let cell = Arc::new(load(&root().join("workcells/handoff/cell.toml")).unwrap());
    let (_, bytes) = run_logged(&cell, 1, Some(20_000_000_000), "level");
    let mut checked = 0;
    for record in mcap::read::LinearReader::new(&bytes).unwrap() {
        let mcap::records::Record::Chunk { header, data } = record.unwrap() else {
            continue;
        };
        assert_eq!(header.compression, "zstd");
        if header.uncompressed_size < 1 << 20 {
            continue; // the last, partial chunk
        }
        let raw = zstd::decode_all(&data[..]).unwrap();
        assert_eq!(raw.len() as u64, header.uncompressed_size);
        let at = |level: i32| zstd::bulk::compress(&raw, level).unwrap().len() as f64;
        let (ours, documented, level1) = (
            data.len() as f64,
            at(vworks_log::mcaplog::ZSTD_LEVEL),
            at(1),
        );
        assert!(
            (ours / documented - 1.0).abs() < 0.03,
            "{ours} vs {documented}"
        );
        assert!(ours > level1 * 1.04, "{ours} vs level 1: {level1}");
        checked += 1;
    }
    assert!(checked >= 2, "{checked} full chunks");
}

#[test]
fn bodies_turn_red_while_they_touch() {
    // The crash cell, but the run goes on through the collision and the arms pull back.
    let dir = std::env::temp_dir().join(format!("vworks-log-red-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let toml = std::fs::read_to_string(root().join("workcells/crash/cell.toml")).unwrap();
    std::fs::write(
        dir.join("cell.toml"),
        toml.replace("on_collision = \"stop\"", "on_collision = \"continue\""),
    )
    .unwrap();
    let program = "proc main() {\n    move_j joints(0deg, 60deg, -30deg, 0deg, 30deg, 0deg) speed 50%;\n    move_j joints(0deg, -30deg, 30deg, 0deg, 60deg, 0deg) speed 50%;\n}\n";
    for name in ["left.wsl", "right.wsl"] {
        std::fs::write(dir.join(name), program).unwrap();
    }
    let cell = Arc::new(load(&dir.join("cell.toml")).unwrap());
    let (r, bytes) = run_logged(&cell, 1, None, "red");
    check(&cell, &r, &bytes);
    let changes: Vec<(i64, bool, String, String)> = r
        .trace
        .iter()
        .filter(|e| matches!(e.kind, Kind::CollisionStart | Kind::CollisionEnd))
        .map(|e| {
            let details = e.details(&CellNames(&cell));
            let mut n = details.split(' ');
            let (a, b) = (n.next().unwrap(), n.next().unwrap());
            (
                e.time,
                e.kind == Kind::CollisionStart,
                a.to_string(),
                b.to_string(),
            )
        })
        .collect();
    assert!(
        changes.iter().any(|c| c.1) && changes.iter().any(|c| !c.1),
        "{changes:?}"
    );
    let scenes: Vec<(u64, serde_json::Value)> = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(Result::unwrap)
        .filter(|m| m.channel.topic == "/scene")
        .map(|m| (m.log_time, serde_json::from_slice(&m.data).unwrap()))
        .collect();
    assert_eq!(scenes.len(), 1 + changes.len());
    let colour = |e: &serde_json::Value| {
        let prims = ["cubes", "spheres", "cylinders", "triangles"];
        let c = prims
            .iter()
            .find_map(|p| e[p].as_array().and_then(|a| a.first()))
            .unwrap();
        (
            c["color"]["r"].as_f64().unwrap(),
            c["color"]["g"].as_f64().unwrap(),
        )
    };
    // At t = 0 every body in its kind's colour: robot links amber (their frame is
    // `robot.link`), devices slate grey.
    let own = |frame: &str| {
        if frame.contains('.') {
            (0.95, 0.68)
        } else {
            (0.55, 0.6)
        }
    };
    let all = scenes[0].1["entities"].as_array().unwrap();
    assert!(all.len() > 10);
    for e in all {
        assert_eq!(colour(e), own(e["frame_id"].as_str().unwrap()), "{e}");
    }
    // Then, per change, exactly the two bodies' entities, red from start to end.
    for ((t, on, a, b), (log_time, scene)) in changes.iter().zip(&scenes[1..]) {
        assert_eq!(*log_time, *t as u64);
        let entities = scene["entities"].as_array().unwrap();
        assert!(!entities.is_empty());
        for e in entities {
            let frame = e["frame_id"].as_str().unwrap();
            assert!(
                frame == a || frame == b,
                "{frame} in the update for {a} {b}"
            );
            assert_eq!(colour(e), if *on { (0.9, 0.1) } else { own(frame) });
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_same_run_writes_the_same_bytes() {
    let cell = Arc::new(load(&root().join("workcells/handoff/cell.toml")).unwrap());
    let (_, first) = run_logged(&cell, 1, None, "same-1");
    let (_, second) = run_logged(&cell, 1, None, "same-2");
    assert!(first.len() > 1_000_000);
    assert!(first == second, "two runs of one cell wrote different logs");
}

/// Found by the `log` fuzz target: a damaged chunk header claiming 2^56 bytes
/// uncompressed made the mcap crate allocate them (an abort). The reader stops before
/// that chunk and says the file is damaged there.
#[test]
fn a_chunk_claiming_an_absurd_size_is_damage_not_an_abort() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/log-chunk-claims-2-56-bytes.mcap");
    let bytes = std::fs::read(&path).unwrap();
    match read_log_bytes("damaged.mcap", &bytes) {
        Ok(contents) => {
            let (_, why) = contents.damage.expect("reported as damaged");
            assert!(why.contains("claims") || !why.is_empty(), "{why}");
        }
        Err(e) => assert!(e.to_string().contains("damaged.mcap"), "{e}"),
    }
}

/// Found by the `log` fuzz target: a damaged metadata record whose map claims 3.5 GB made
/// the mcap crate reserve them. Fields longer than their record are damage.
#[test]
fn a_field_longer_than_its_record_is_damage_not_a_huge_allocation() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/log-metadata-map-claims-3-5-gb.mcap");
    let bytes = std::fs::read(&path).unwrap();
    match read_log_bytes("damaged.mcap", &bytes) {
        Ok(contents) => assert!(contents.damage.is_some()),
        Err(e) => assert!(e.to_string().contains("damaged.mcap"), "{e}"),
    }
}

/// Found by the `log` fuzz target: a record inside an uncompressed chunk claimed more
/// bytes than the chunk has, and the mcap crate's reader underflowed its count (a panic
/// with overflow checks, a misread without). Such a chunk is damage; the reader stops
/// before it and names its byte offset.
#[test]
fn a_record_longer_than_its_chunk_is_damage() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/log-record-longer-than-its-chunk.mcap");
    let bytes = std::fs::read(&path).unwrap();
    let contents = read_log_bytes("damaged.mcap", &bytes).unwrap();
    let (read, why) = contents.damage.expect("reported as damaged");
    assert_eq!(read, 0);
    assert!(
        why.contains("the chunk at byte 41 holds a record longer than the chunk"),
        "{why}"
    );
}

#[test]
fn the_logged_tcp_is_the_tool_the_robot_moves_with() {
    // A RAPID robot moves with tGun (its TCP 100 mm along the flange's z), then with
    // tool0. /state's TCP and the `r1:tcp` frame are base × FK × the tool of the motion
    // under way (tGun from the first motion's start until the second's, then tool0), not
    // the workcell's.
    let dir = std::env::temp_dir().join(format!("vworks-log-tools-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("cell.toml"),
        "name = \"tools\"\n[[robot]]\nname = \"r1\"\nmodel = \"irb120\"\nprogram = \"r1.mod\"\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("r1.mod"),
        "MODULE R1
  PERS tooldata tGun := [TRUE, [[0, 0, 100], [1, 0, 0, 0]], [1, [0, 0, 1], [1, 0, 0, 0], 0, 0, 0]];
  CONST jointtarget j1 := [[0, 0, 0, 0, 90, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST jointtarget j2 := [[30, 0, 0, 0, 90, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  PROC main()
    MoveAbsJ j1, v1000, fine, tGun;
    MoveAbsJ j2, v1000, fine, tool0;
  ENDPROC
ENDMODULE
",
    )
    .unwrap();
    let cell = Arc::new(load(&dir.join("cell.toml")).unwrap());
    let (r, bytes) = run_logged(&cell, 1, None, "tools");
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(r.outcome, Outcome::Completed);
    let starts: Vec<u64> = r
        .trace
        .iter()
        .filter(|e| e.kind == Kind::MotionStart)
        .map(|e| e.time as u64)
        .collect();
    assert_eq!(starts.len(), 2);
    let gun = Iso {
        r: Iso::IDENTITY.r,
        t: [0.0, 0.0, 0.1],
    };
    let robot = &cell.robots[0];
    let states = states(&bytes);
    let mut latest = Latest::new();
    let all = transforms(&bytes);
    let (mut with_gun, mut with_tool0) = (0, 0);
    for (i, (t, parent, child, p, q)) in all.iter().enumerate() {
        latest.insert(child.clone(), (parent.clone(), iso(*p, *q)));
        if all.get(i + 1).is_some_and(|next| next.0 == *t) {
            continue;
        }
        // At the boundary at 0 s the first motion has not started (a boundary comes before
        // the events at its time): the workcell's tool.
        let tool = if *t <= starts[0] {
            robot.tool
        } else if *t < starts[1] {
            with_gun += 1;
            gun
        } else {
            with_tool0 += 1;
            Iso::IDENTITY
        };
        let (_, q, tcp_p, tcp_q) = &states[t][0];
        let want = robot
            .base
            .mul(&robot.model.fk(q)[robot.model.tool_link])
            .mul(&tool);
        let framed = in_world(&latest, &vworks_log::mcaplog::tcp_frame(&robot.name));
        for got in [iso(*tcp_p, *tcp_q), framed] {
            assert!(close(&want, &got), "TCP at {t}: {want:?} != {got:?}");
        }
    }
    assert!(with_gun > 10 && with_tool0 > 10, "{with_gun} {with_tool0}");
}

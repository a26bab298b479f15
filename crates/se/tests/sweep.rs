//! Contacts between cycle boundaries: a body that passes through another between two
//! boundaries is found, at its first-contact time, by the sweep (conservative
//! advancement) — checked against an analytic contact time and against a per-cycle check
//! with a 40× finer cycle.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::path::PathBuf;
use std::sync::Arc;

use vworks_cell::load;
use vworks_log::issue::IssueKind;
use vworks_log::result::{Outcome, RunResult};
use vworks_log::trace::Kind;
use vworks_se::CellNames;
use vworks_se::Simulation;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn write_cell(name: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("vworks-sweep-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (f, text) in files {
        std::fs::write(dir.join(f), text).unwrap();
    }
    dir.join("cell.toml")
}

fn run(path: &std::path::Path) -> RunResult {
    run_with(path, true)
}

fn run_with(path: &std::path::Path, sweep: bool) -> RunResult {
    let cell = Arc::new(load(path).unwrap_or_else(|e| panic!("{e}")));
    let r = Simulation::new(cell).with_sweep(sweep).run(None);
    let times: Vec<i64> = r.trace.iter().map(|e| e.time).collect();
    assert!(times.is_sorted(), "the trace is in time order");
    r
}

/// A 1 cm blade on a linear axis (3 m/s, full speed in 0.3 s) and a 2 mm plate.
const SLIDER: &str = r#"<?xml version="1.0"?>
<robot name="slider">
  <link name="base_link"/>
  <link name="blade">
    <collision><geometry><box size="0.01 0.5 0.5"/></geometry></collision>
  </link>
  <joint name="slide" type="prismatic">
    <parent link="base_link"/>
    <child link="blade"/>
    <origin xyz="0 0 0.5" rpy="0 0 0"/>
    <axis xyz="1 0 0"/>
    <limit lower="0" upper="2" velocity="3" effort="0"/>
  </joint>
</robot>
"#;

#[test]
fn a_blade_passing_through_a_thin_plate_between_boundaries_is_found() {
    let cell = r#"
name = "plate"
cycle = "12ms"
clearance = "1mm"
on_collision = "continue"
[[robot]]
name = "s"
urdf = "slider.urdf"
program = "s.wsl"
[[device]]
name = "plate"
box = ["2mm", "500mm", "500mm"]
pose = { xyz = ["610mm", "0mm", "500mm"] }
"#;
    let prog = "proc main() {\n    move_j joints(1500mm) speed 100%;\n}\n";
    let path = write_cell(
        "plate",
        &[
            ("cell.toml", cell),
            ("slider.urdf", SLIDER),
            ("s.wsl", prog),
        ],
    );
    let r = run(&path);
    // The motion: 10 m/s² to 3 m/s (0.3 s, 0.45 m), then 3 m/s. The blade's front face
    // (q + 5 mm) meets the plate's back face (609 mm) at q = 0.604 m: 0.3 s + 0.154 m /
    // 3 m/s. Its back face leaves the plate's front (611 mm) at q = 0.616 m, 4 ms later:
    // between the boundaries at 348 ms (q = 0.594) and 360 ms (q = 0.630) the blade is
    // through, so a check at boundaries alone never sees it touch.
    let analytic = 0.3 + 0.154 / 3.0;
    let q = |t: f64| 0.45 + 3.0 * (t - 0.3);
    assert!(q(0.348) + 0.005 < 0.609 && q(0.360) - 0.005 > 0.611);
    let (c,) = match &r.collisions[..] {
        [c] => (c,),
        other => panic!("{other:?}"),
    };
    assert_eq!((c.a.as_str(), c.b.as_str()), ("s.blade", "plate"));
    let t = c.time_ns as f64 / 1e9;
    assert!(t > 0.348 && t < 0.360);
    // First contact to within 0.1 ms, as the issue asks; in fact within 2 µs (one minimum
    // step late at most, and early only by parry's f32 precision).
    assert!((analytic - t).abs() < 1e-4, "{t} vs {analytic}");
    assert!((analytic - t).abs() < 2e-6, "{t} vs {analytic}");
    // With boundary checks only, the run sees nothing.
    assert!(run_with(&path, false).collisions.is_empty());
    // It starts touching and, by the next boundary, has passed.
    let kinds: Vec<(i64, &str)> = r
        .trace
        .iter()
        .filter(|e| matches!(e.kind, Kind::CollisionStart | Kind::CollisionEnd))
        .map(|e| (e.time, e.kind.name()))
        .collect();
    assert_eq!(
        kinds,
        [
            (c.time_ns, "collision_start"),
            (360_000_000, "collision_end")
        ]
    );
    assert_eq!(r.outcome, Outcome::Completed);
}

#[test]
fn the_sweep_agrees_with_a_40x_finer_cycle() {
    // The crash cell: its arms meet between two 4 ms boundaries. With a 0.1 ms cycle (the
    // shortest a workcell allows) the per-cycle check finds the first boundary in contact;
    // the sweep with 4 ms must agree with it to within 0.1 ms.
    let dir = root().join("workcells/crash");
    let toml = std::fs::read_to_string(dir.join("cell.toml")).unwrap();
    let left = std::fs::read_to_string(dir.join("left.wsl")).unwrap();
    let right = std::fs::read_to_string(dir.join("right.wsl")).unwrap();
    let coarse = run(&write_cell(
        "coarse",
        &[
            ("cell.toml", &toml),
            ("left.wsl", &left),
            ("right.wsl", &right),
        ],
    ));
    let fine_toml = toml.replace("cycle = \"4ms\"", "cycle = \"0.1ms\"");
    assert_ne!(fine_toml, toml);
    let fine = run_with(
        &write_cell(
            "fine",
            &[
                ("cell.toml", &fine_toml),
                ("left.wsl", &left),
                ("right.wsl", &right),
            ],
        ),
        false, // boundaries only: the oracle
    );
    assert_eq!(
        (coarse.outcome, fine.outcome),
        (Outcome::Collision, Outcome::Collision)
    );
    let (t, t_fine) = (coarse.collisions[0].time_ns, fine.collisions[0].time_ns);
    // The true first contact lies in (t_fine − 0.1 ms, t_fine]; the sweep must be within
    // 0.1 ms of it. (The arms' flanges, two cylinders, first touch at 370.0857 ms: the
    // sweep with 4 ms and with 0.1 ms cycles agree to 0.1 µs; boundaries alone see it at
    // 370.1 ms.)
    assert!(
        t > t_fine - 200_000 && t <= t_fine + 1_000,
        "sweep {t} ns, 0.1 ms cycles {t_fine} ns"
    );
    // Both runs report the same pair.
    let pair = |r: &RunResult| (r.collisions[0].a.clone(), r.collisions[0].b.clone());
    assert_eq!(pair(&coarse), pair(&fine));
}

#[test]
fn every_first_contact_of_grazing_arms_agrees_with_a_40x_finer_cycle() {
    // Found by the adaptive-checking property test: two arms whose links graze nearly
    // parallel. parry's f32 capsule query read the overlapping links as 1 µm apart, then as
    // not in contact at all, so the sweep missed left.link_3/right.link_4's first contact
    // (then at 1606.2 ms) until the 1608 ms boundary; its f32 GJK also put a capsule 1.9 mm from a
    // cylinder in contact. Every pair's first contact must be within 0.1 ms of a
    // boundary-only run with 0.1 ms cycles.
    let toml = std::fs::read_to_string(root().join("workcells/crash/cell.toml"))
        .unwrap()
        .replace("on_collision = \"stop\"", "on_collision = \"continue\"");
    let program = |targets: [[i32; 6]; 2]| {
        let mut p = String::from("proc main() {\n");
        for t in targets {
            let j: Vec<String> = t.iter().map(|d| format!("{d}deg")).collect();
            p += &format!("    move_j joints({}) speed 22%;\n", j.join(", "));
        }
        p + "}\n"
    };
    let left = program([[8, 59, -51, 0, 0, 0], [0, 20, -2, 0, 0, 0]]);
    let right = program([[-2, 53, -26, -37, 13, -31], [-2, 41, -39, -39, 2, -2]]);
    let first_contacts = |cycle: &str, sweep: bool| {
        let toml = toml.replace("cycle = \"4ms\"", &format!("cycle = \"{cycle}\""));
        let path = write_cell(
            &format!("graze-{sweep}"),
            &[
                ("cell.toml", &toml),
                ("left.wsl", &left),
                ("right.wsl", &right),
            ],
        );
        let mut first = std::collections::BTreeMap::new();
        for c in run_with(&path, sweep).collisions {
            first.entry((c.a, c.b)).or_insert(c.time_ns);
        }
        first
    };
    let (coarse, fine) = (first_contacts("4ms", true), first_contacts("0.1ms", false));
    assert!(fine.len() >= 10, "{fine:?}");
    for (pair, t_fine) in &fine {
        let t = coarse[pair];
        // The true first contact lies in (t_fine − 0.1 ms, t_fine].
        assert!(
            t > t_fine - 100_000 - 1_000 && t <= t_fine + 1_000,
            "{pair:?}: sweep {t} ns, 0.1 ms cycles {t_fine} ns"
        );
    }
    let graze = ("left.link_3".to_string(), "right.link_4".to_string());
    // (1562.2 ms in a run with the IRB 120's dynamics; 1606.2 ms, the time the property
    // test found, with the 0.3 s ramps the model had then: the joint paths are the same,
    // the timing along them is not.)
    assert!(
        (1_562_100_000..=1_562_400_000).contains(&coarse[&graze]),
        "{:?}",
        coarse[&graze]
    );
}

#[test]
fn adaptive_checking_finds_what_the_exhaustive_check_finds() {
    // Every example cell, and the crash cell going on through its collision: skipping the
    // queries that speed bounds prove unneeded changes no event, only the query count.
    let mut cells: Vec<PathBuf> = [
        "handoff",
        "weldline",
        "monitor",
        "crash",
        "deadlock",
        "track",
        "palletize",
    ]
    .iter()
    .map(|n| root().join("workcells").join(n).join("cell.toml"))
    .collect();
    let dir = root().join("workcells/crash");
    let toml = std::fs::read_to_string(dir.join("cell.toml"))
        .unwrap()
        .replace("on_collision = \"stop\"", "on_collision = \"continue\"");
    let back = "proc main() {\n    move_j joints(0deg, 60deg, -30deg, 0deg, 30deg, 0deg) speed 50%;\n    move_j joints(0deg, -30deg, 30deg, 0deg, 60deg, 0deg) speed 50%;\n}\n";
    cells.push(write_cell(
        "through",
        &[
            ("cell.toml", &toml),
            ("left.wsl", back),
            ("right.wsl", back),
        ],
    ));
    for path in &cells {
        let cell = Arc::new(load(path).unwrap());
        let run = |adaptive: bool| {
            Simulation::new(Arc::clone(&cell))
                .with_adaptive(adaptive)
                .run(None)
        };
        let (fast, all) = (run(true), run(false));
        let lines = |r: &RunResult| {
            r.trace
                .iter()
                .map(|e| e.line(&CellNames(&cell)))
                .collect::<Vec<_>>()
        };
        assert_eq!(lines(&fast), lines(&all), "{}", path.display());
        assert_eq!(fast.collisions, all.collisions);
        assert!(fast.queries <= all.queries, "{}", path.display());
        eprintln!(
            "{}: {} queries adaptive, {} exhaustive ({} cycles)",
            cell.name, fast.queries, all.queries, all.cycles
        );
    }
}

use proptest::prelude::Strategy as _;

/// The collider's horizon (skipping boundaries no pair can come near before it) changes
/// nothing the run reports: four arms working over one shared table, as it is, with the
/// table raised into their way (they touch it) and with a clearance that makes near misses,
/// give the trace the exhaustive check gives, with fewer queries.
#[test]
fn the_horizon_skips_only_what_cannot_matter() {
    let dir = root().join("bench/cells/shared4");
    let toml = std::fs::read_to_string(dir.join("cell.toml")).unwrap();
    let side = std::fs::read_to_string(dir.join("side.wsl")).unwrap();
    let variants = [
        ("as-is", toml.clone()),
        (
            "raised",
            toml.replace(
                "box = [\"500mm\", \"500mm\", \"220mm\"]",
                "box = [\"500mm\", \"500mm\", \"500mm\"]",
            )
            .replace(
                "clearance = \"5mm\"",
                "clearance = \"5mm\"\non_collision = \"continue\"",
            ),
        ),
        (
            "near",
            toml.replace("clearance = \"5mm\"", "clearance = \"90mm\""),
        ),
    ];
    for (name, text) in variants {
        assert!(name == "as-is" || text != toml, "{name}");
        let path = write_cell(
            &format!("horizon-{name}"),
            &[("cell.toml", &text), ("side.wsl", &side)],
        );
        let cell = Arc::new(load(&path).unwrap());
        let run = |adaptive: bool| {
            Simulation::new(Arc::clone(&cell))
                .with_adaptive(adaptive)
                .run(Some(12_000_000_000))
        };
        let (fast, all) = (run(true), run(false));
        let lines = |r: &RunResult| {
            r.trace
                .iter()
                .map(|e| e.line(&CellNames(&cell)))
                .collect::<Vec<_>>()
        };
        assert_eq!(lines(&fast), lines(&all), "{name}");
        assert_eq!(fast.cycles, all.cycles, "{name}");
        assert!(
            fast.queries < all.queries,
            "{name}: {} against {}",
            fast.queries,
            all.queries
        );
        let collisions = fast.collisions.len();
        let near = fast
            .warnings
            .iter()
            .filter(|w| w.kind == IssueKind::NearMiss)
            .count();
        match name {
            "raised" => assert!(collisions > 0, "{name}"),
            "near" => assert!(near > 0, "{name}"),
            _ => assert_eq!((collisions, near), (0, 0)),
        }
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 16, ..Default::default() })]

    /// Two arms facing each other move through random joint targets (meeting or not):
    /// adaptive checking reports exactly the contacts and near misses the exhaustive
    /// check reports.
    #[test]
    fn adaptive_equals_exhaustive_on_random_motions(
        // Around the crash cell's meeting pose (0, 60, -30, 0, 30, 0) deg: some meet,
        // some pass close, some stay apart.
        targets in proptest::collection::vec(
            (-25i32..25, 20i32..75, -60i32..0, -40i32..40, 0i32..60, -40i32..40)
                .prop_map(|(a, b, c, d, e, f)| vec![a, b, c, d, e, f]),
            4,
        ),
        speed in 20i32..100,
    ) {
        let dir = root().join("workcells/crash");
        let toml = std::fs::read_to_string(dir.join("cell.toml"))
            .unwrap()
            .replace("on_collision = \"stop\"", "on_collision = \"continue\"");
        let program = |pair: &[Vec<i32>]| {
            let mut p = String::from("proc main() {\n");
            for t in pair {
                let j: Vec<String> = t.iter().map(|d| format!("{d}deg")).collect();
                p += &format!("    move_j joints({}) speed {speed}%;\n", j.join(", "));
            }
            p + "}\n"
        };
        let path = write_cell(
            "random",
            &[
                ("cell.toml", &toml),
                ("left.wsl", &program(&targets[..2])),
                ("right.wsl", &program(&targets[2..])),
            ],
        );
        let cell = Arc::new(load(&path).unwrap());
        let run = |adaptive: bool| Simulation::new(Arc::clone(&cell)).with_adaptive(adaptive).run(None);
        let (fast, all) = (run(true), run(false));
        let lines = |r: &RunResult| r.trace.iter().map(|e| e.line(&CellNames(&cell))).collect::<Vec<_>>();
        proptest::prop_assert_eq!(lines(&fast), lines(&all));
        // One bounded query per pair and checked boundary, adaptive or not: adaptive
        // checking makes no more queries than checking every boundary. (It used to add an
        // unbounded distance query behind each promise: (-6, 55, -54, 0, 0, 0),
        // (0, 20, -2, 0, 0, 0) against (-7, 61, -56, 26, 46, 13), (3, 53, -11, -35, 27, 21)
        // at 98 % made 19,092 queries against 19,051; this test found it.)
        proptest::prop_assert!(
            fast.queries <= all.queries,
            "adaptive {} against exhaustive {} queries",
            fast.queries,
            all.queries
        );
    }
}

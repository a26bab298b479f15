//! Orientation zones (RAPID's `pzone_ori` and `zone_ori`; WSL's `zone r ori d a`), from
//! docs/engine.md ("Zones", "Orientation zones") and docs/language.md: on an IRB 120, two
//! 100 mm lines at 500 mm/s through a point `b` where the tool has turned 30° about the
//! vertical (the first turns it from 0° to 30°, the second back to 0°), every expected
//! number computed by hand from the docs.
//!
//! - The first line's `motion_end` comes where its TCP enters the orientation zone: `d`
//!   before `b` (the TCP cruises at 500 mm/s there, so to 1 nm).
//! - Over the orientation zone the tool turns with progressions of its own: the first
//!   line's fraction runs out from `1 − d/L` as `1 − (d/L)(1 − u)²` and the second's runs in
//!   as `(d/L)·u²` (u from 0 to 1 across the zone), so the tool's angle about the vertical
//!   is `30°·(o₁ − o₂) = 30°·(1 − d/L + 2(d/L)u − 2(d/L)u²)`: largest at u = ½,
//!   `30°·(1 − d/2L)` — 25.5° for d = 30 mm, 28.5° for the TCP zone alone (10 mm).
//! - After the zone the tool is where the second line alone would have it at that place,
//!   `30°·(1 − x/L)` x past `b` (the reference: as if `b` were a stop point).
//! - On the straight stretches of the zone, at the TCP's constant speed v, the angle's
//!   second derivative is `−30°·4(d/L)·(v/2d)²`: −2,500°/s² for d = 30 mm.
//! - `zone_ori` bounds the zone's share of each line to `zone_ori/30°`: 6° gives
//!   20 mm (largest angle 27°); 1.5° (RAPID's z10) gives 5 mm, less than the TCP zone, so
//!   the orientation turns within the TCP zone as without an orientation zone, and the
//!   run is the same to the nanosecond.
//! - Every axis within its speed and acceleration at 1 kHz, joints and their speeds
//!   continuous at every event.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::sync::Arc;

use proptest::prelude::*;

use vworks_model::builtin;
use vworks_model::math::{Iso, norm, sub};
use vworks_vm::machine::{Event, EventKind, Next, Vm, VmConfig};

/// The program: `a` → `b` (turning 30°) → `c` (turning back) at 500 mm/s, with `zone` at
/// `b`.
fn program(zone: &str) -> String {
    format!(
        "const a = pose(400mm, -150mm, 250mm, 180deg, 0deg, 0deg);
const b = pose(400mm, -50mm, 250mm, 180deg, 0deg, 30deg);
const c = pose(400mm, 50mm, 250mm, 180deg, 0deg, 0deg);
proc main() {{
    move_j a;
    move_l b speed 500mm/s {zone};
    move_l c speed 500mm/s zone fine;
}}
"
    )
}

const B: [f64; 3] = [0.4, -0.05, 0.25];
const STEP: i64 = 100_000; // 0.1 ms

/// A run: its events, and the TCP and joints every 0.1 ms (sampled as the SE does: a time
/// with every event at or before it performed), with joints and their speeds checked
/// continuous at every event.
struct Run {
    events: Vec<Event>,
    samples: Vec<(i64, Iso, [f64; 12])>,
}

/// [`run_any`], with no warning (no corner failure: every corner flies).
fn run(src: &str) -> Run {
    let (r, warnings) = run_any(src);
    assert!(warnings.is_empty(), "{warnings:?}");
    r
}

/// The run of `src`, and its warnings.
fn run_any(src: &str) -> (Run, Vec<vworks_vm::machine::Warning>) {
    let out = vworks_wslc::compile("t.wsl", src).unwrap_or_else(|e| panic!("{e}\n{src}"));
    let m = Arc::new(out.module);
    let entry = m.proc_index("main").unwrap();
    let model = Arc::new(builtin::load("irb120").unwrap());
    let cfg = VmConfig {
        start_joints: vec![0.0, -0.5, 0.5, 0.0, 1.0, 0.0],
        ..VmConfig::default()
    };
    let mut v = Vm::new(m, model, cfg, Some(entry));
    let (mut events, mut samples, mut tick) = (Vec::new(), Vec::new(), 0i64);
    let h = 1_000;
    while let Next::Event(e) = v.next_event() {
        while tick < e.time {
            samples.push((tick, v.tcp_at(tick), v.joints_at(tick)));
            tick += STEP;
        }
        let t = e.time;
        let (q0, qa) = (v.joints_at(t - h), v.joints_at(t));
        v.perform();
        let (qb, q1) = (v.joints_at(t), v.joints_at(t + h));
        for i in 0..6 {
            assert!((qa[i] - qb[i]).abs() < 1e-9, "axis {i} jumps at {t}");
            let (vl, vr) = ((qa[i] - q0[i]) / 1e-6, (q1[i] - qb[i]) / 1e-6);
            assert!(
                (vl - vr).abs() < 0.05,
                "axis {i} speed jumps at {t}: {vl} → {vr}"
            );
        }
        assert!(!matches!(e.kind, EventKind::Error { .. }), "{:?}", e.kind);
        events.push(e);
    }
    (Run { events, samples }, v.take_warnings())
}

/// The tool's angle about the vertical (degrees): the poses are `Rz(θ)·Rx(180°)`.
fn angle(p: &Iso) -> f64 {
    p.r[1][0].atan2(p.r[0][0]).to_degrees()
}

fn motion_ends(r: &Run) -> Vec<i64> {
    r.events
        .iter()
        .filter(|e| matches!(e.kind, EventKind::MotionEnd { .. }))
        .map(|e| e.time)
        .collect()
}

/// How far from `b` the TCP is at the first line's motion_end (its first sample after it:
/// less than 0.1 ms, 50 µm at 500 mm/s).
fn from_b_at_motion_end(r: &Run) -> f64 {
    let end = motion_ends(r)[1];
    norm(sub(r.samples.iter().find(|s| s.0 >= end).unwrap().1.t, B))
}

/// The sampled TCP at `t` (a multiple of `STEP`).
fn at(r: &Run, t: i64) -> &(i64, Iso, [f64; 12]) {
    let k = (t / STEP) as usize;
    assert_eq!(r.samples[k].0, t);
    &r.samples[k]
}

/// The largest angle over the corner (samples from the first line's motion_end on).
fn largest_angle(r: &Run) -> f64 {
    let from = motion_ends(r)[1];
    r.samples
        .iter()
        .filter(|s| s.0 >= from)
        .map(|s| angle(&s.1))
        .fold(f64::MIN, f64::max)
}

/// Every axis within its speed and acceleration at 1 kHz (1e-9 of the limit, 1e-8 rad/s²
/// for rounding), as the zones property tests check.
fn within_limits(r: &Run) {
    if let Err(e) = limits_kept(r) {
        panic!("{e}");
    }
}

/// [`within_limits`], or where an axis is not.
fn limits_kept(r: &Run) -> Result<(), String> {
    let model = builtin::load("irb120").unwrap();
    let ms: Vec<_> = r.samples.iter().step_by(10).collect();
    for w in ms.windows(3) {
        for i in 0..6 {
            let axis = model.axis(i);
            let speed = (w[2].2[i] - w[1].2[i]).abs() / 1e-3;
            if speed > axis.max_velocity * (1.0 + 1e-9) {
                return Err(format!("axis {i} after {}: {speed} rad/s", w[1].0));
            }
            let acc = (w[2].2[i] - 2.0 * w[1].2[i] + w[0].2[i]).abs() / 1e-6;
            if acc > axis.max_accel * (1.0 + 1e-9) + 1e-8 {
                return Err(format!("axis {i} at {}: {acc} rad/s²", w[1].0));
            }
        }
    }
    Ok(())
}

#[test]
fn the_tool_turns_over_the_orientation_zone_and_leaves_it_as_from_a_stop_point() {
    let r = run(&program("zone 10mm ori 30mm"));
    within_limits(&r);
    let ends = motion_ends(&r);
    // The motion_end where the TCP enters the orientation zone: 30 mm before b.
    let end = ends[1];
    let d = from_b_at_motion_end(&r);
    // (At 500 mm/s, the first sample is less than 0.1 ms, 50 µm, after it.)
    assert!(d <= 0.030 && d > 0.030 - 5.1e-5, "{d}");
    // Largest angle 30°·(1 − 30/200) = 25.5° (sampled every 0.1 ms at 500 mm/s: u within
    // 0.0004 of ½, 30°·2·0.3·0.0004² ≈ 3e-6° below it).
    let top = largest_angle(&r);
    assert!((top - 25.5).abs() < 1e-4, "{top}");
    // After the zone, the second line's own orientation at its place.
    let past: Vec<_> = r
        .samples
        .iter()
        .filter(|s| s.0 > end && s.0 < ends[2])
        .map(|s| (s.1.t[1] - B[1], angle(&s.1)))
        .filter(|(x, _)| *x > 0.030 + 1e-9)
        .collect();
    assert!(past.len() > 1000, "{}", past.len());
    for (x, a) in past {
        let want = 30.0 * (1.0 - x / 0.1);
        assert!((a - want).abs() < 1e-6, "{x}: {a}° against {want}°");
    }
    // The angle's acceleration on the stretch before the curve (30 to 10 mm before b, at
    // 500 mm/s: the 40 ms after the motion_end), −2,500°/s², by second differences over
    // 1 ms.
    let t0 = (end / STEP + 1) * STEP;
    for k in 0..35 {
        let t = t0 + k * 1_000_000 + 1_000_000;
        let (a0, a1, a2) = (
            angle(&at(&r, t - 1_000_000).1),
            angle(&at(&r, t).1),
            angle(&at(&r, t + 1_000_000).1),
        );
        let acc = (a2 - 2.0 * a1 + a0) / 1e-6;
        assert!((acc + 2500.0).abs() < 1.0, "{t}: {acc}°/s²");
    }
}

#[test]
fn without_an_orientation_zone_the_tool_turns_within_the_tcp_zone() {
    let r = run(&program("zone 10mm"));
    within_limits(&r);
    let top = largest_angle(&r);
    // 30°·(1 − 10/200).
    assert!((top - 28.5).abs() < 1e-3, "{top}");
    // The motion_end no later than where the TCP enters the zone (here a look-ahead point
    // before it, where braking for the sharpest corner would have to begin).
    let d = from_b_at_motion_end(&r);
    assert!(d >= 0.010 - 5.1e-5, "{d}");
}

#[test]
fn zone_ori_narrows_the_orientation_zone_to_the_angle_it_allows() {
    // 6° of the 30° each line turns: 20 mm of their 100 mm.
    let r = run(&program("zone 10mm ori 30mm 6deg"));
    within_limits(&r);
    let top = largest_angle(&r);
    assert!((top - 27.0).abs() < 1e-4, "{top}");
    let d = from_b_at_motion_end(&r);
    assert!(d <= 0.020 && d > 0.020 - 5.1e-5, "{d}");
    // 10° allows 33 mm: the 30 mm zone, as without an angle.
    let wide = run(&program("zone 10mm ori 30mm 10deg"));
    let plain = run(&program("zone 10mm ori 30mm"));
    assert_eq!(wide.events, plain.events);
    // RAPID's z10 (15 mm, 1.5°): 5 mm, less than the TCP zone: the same run as `zone 10mm`.
    let z10 = run(&program("zone 10mm ori 15mm 1.5deg"));
    let tcp_only = run(&program("zone 10mm"));
    assert_eq!(z10.events, tcp_only.events);
}

/// A program of lines through `points` (mm from (400, 0, 300) mm, and the tool's angle
/// about the vertical in degrees) at `speeds` (mm/s), each with a zone (mm; 0: fine) and
/// an orientation zone (its radius as a multiple of the zone, and an angle in degrees).
fn turning_lines(
    points: &[(i32, i32, i32, i32)],
    speeds: &[u32],
    zones: &[(u32, u32, u32)],
) -> String {
    let mut s =
        String::from("proc main() {\n    move_j pose(400mm, 0mm, 300mm, 180deg, 0deg, 0deg);\n");
    for ((x, y, z, a), (v, (r, k, deg))) in points.iter().zip(speeds.iter().zip(zones)) {
        let zone = match (r, k) {
            (0, _) => "zone fine".to_string(),
            (r, 1) => format!("zone {r}mm"),
            (r, k) => format!("zone {r}mm ori {}mm {deg}deg", r * k),
        };
        s += &format!(
            "    move_l pose({}mm, {y}mm, {}mm, 180deg, 0deg, {a}deg) speed {v}mm/s {zone};\n",
            400 + x,
            300 + z
        );
    }
    s + "}\n"
}

/// `src` with every zone `fine`.
fn fine(src: &str) -> String {
    src.lines()
        .map(|l| match l.find(" zone ") {
            Some(k) => format!("{};\n", &l[..k]),
            None => format!("{l}\n"),
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    /// Random lines turning the tool, with orientation zones: every axis within its limits
    /// at 1 kHz, joints and their speeds continuous at every event (`run_any`), never
    /// slower than the same program with `fine` points, and no corner failure that the
    /// TCP zones alone would not have.
    #[test]
    fn orientation_zones_keep_every_limit_and_cost_no_more_than_stops(
        pts in prop::collection::vec((-100i32..100, -100i32..100, -80i32..80, -45i32..45), 2..6),
        speeds in prop::collection::vec(100u32..800, 6),
        zones in prop::collection::vec((prop_oneof![Just(0u32), 1u32..40], 1u32..4, 1u32..30), 6),
    ) {
        let src = turning_lines(&pts, &speeds, &zones);
        let (r, warnings) = run_any(&src);
        // No corner lost to an orientation zone: a turn that no timing keeps turns within
        // the curve, as without one (the same program with the TCP zones alone has as
        // many corner failures, or more).
        let plain: String = src
            .lines()
            .map(|l| match l.find(" ori ") {
                Some(k) => format!("{};\n", &l[..k]),
                None => format!("{l}\n"),
            })
            .collect();
        let (_, plain_warnings) = run_any(&plain);
        prop_assert!(
            warnings.len() <= plain_warnings.len(),
            "{warnings:?} against {plain_warnings:?}\n{src}"
        );
        prop_assert!(r.events.iter().all(|e| !matches!(e.kind, EventKind::Error { .. })), "{src}");
        if let Err(e) = limits_kept(&r) {
            prop_assert!(false, "{e}\n{src}");
        }
        let (stops, _) = run_any(&fine(&src));
        let (end, end_stops) = (r.events.last().unwrap().time, stops.events.last().unwrap().time);
        prop_assert!(end <= end_stops, "zoned {end} > fine {end_stops}\n{src}");
    }
}

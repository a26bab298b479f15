//! Property tests of zones (fly-by points), from `docs/engine.md` ("Zones"): random
//! programs of zoned `move_l`/`move_j` on an IRB 120 (with and without jerk limits), run
//! by one VM and sampled at 1 kHz as the simulation engine samples it.
//!
//! - A Cartesian corner stays within its zone: from the `motion_end` of a zoned point
//!   until the next motion's `motion_end`, the TCP is within the zone radius of the point
//!   (plus 1e-9 m) or on the next motion's straight line; and at every sample while the
//!   robot finishes a zoned motion (`Vm::zoned_point`), within the zone (1e-9 m; joint-space
//!   corners, checked by the VM at 32 instants, 0.1 mm).
//! - No program, joint-space, Cartesian or mixed, exceeds an axis's speed or
//!   acceleration (first and second differences at 1 kHz, means of the speed and the
//!   acceleration: within 1e-9 of the limit, and 1e-8 rad/s² for rounding), though its
//!   Cartesian paths and corners are checked at samples: between them, where a speed or
//!   an acceleration turns, at the peak of the curve through the samples around; a corner
//!   that cannot keep them stops.
//! - Position and velocity are continuous at every event: the joints and their one-sided
//!   finite-difference velocities agree before and after the event is performed.
//! - A zoned program is never slower than the same program with `fine` points, and a
//!   Cartesian one never faster than its straight segments' lower bound
//!   `Σ (Lₖ − zₖ₋₁ − zₖ)⁺ / vₖ` (outside the zones only one motion moves the TCP).

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

mod common;

use common::HOME;
use proptest::prelude::*;
use vworks_model::builtin;
use vworks_model::math::{norm, sub};
use vworks_vm::machine::{Event, EventKind, Next, Vm, WarningKind};

const MS: i64 = 1_000_000;
/// Joint-space corners keep the TCP in the zone at the 32 instants the VM checks (the
/// TCP is not a linear function of the joints, so no closed-form bound): between them it
/// may stray by a little. At 1 kHz on these random programs the worst was 0.1 µm inside
/// its zone; the bound allowed is 0.1 mm.
const JOINT_CORNER_TOLERANCE: f64 = 1e-4;

fn vm(src: &str, jerk: Option<f64>) -> Vm {
    common::irb120_vm(src, jerk)
}

/// What a run gives: its events, and at every millisecond (and every event, on both
/// sides) the joints and the TCP position.
struct Run {
    events: Vec<Event>,
    samples: Vec<(i64, [f64; 12], [f64; 3])>,
    end: i64,
    /// The largest distance from a zoned point while the robot finishes it after the next
    /// motion has started (in its corner), less that point's zone radius: ≤ 0 when every
    /// corner stays in its zone.
    zone_excess: f64,
}

/// Runs `v` alone, sampling it as the SE does: a time is sampled with every event at or
/// before it performed. At each event, continuity of position and velocity is checked.
fn run(v: &mut Vm, vel_tol: f64) -> Run {
    let h = 1_000; // 1 µs
    let mut events = Vec::new();
    let mut samples = Vec::new();
    let mut tick = 0i64;
    let mut zone = 0.0;
    let mut zone_excess = f64::NEG_INFINITY;
    // The corner begins as the next motion starts (a look-ahead `motion_end` may come
    // before the TCP reaches the zone).
    let mut corner_from = 0i64;
    let mut sample = |v: &Vm, t: i64, zone: f64, corner_from: i64| {
        let tcp = v.tcp_at(t).t;
        if let Some((end, p)) = v.zoned_point()
            && t < end
            && t >= corner_from
        {
            zone_excess = zone_excess.max(norm(sub(tcp, p)) - zone);
        }
        (t, v.joints_at(t), tcp)
    };
    while let Next::Event(e) = v.next_event() {
        while tick < e.time {
            samples.push(sample(v, tick, zone, corner_from));
            tick += MS;
        }
        match e.kind {
            EventKind::MotionStart { .. } => corner_from = e.time,
            EventKind::MotionEnd { .. } => corner_from = i64::MAX,
            _ => {}
        }
        if let EventKind::MotionEnd {
            zone_m: Some(z), ..
        } = e.kind
        {
            zone = z;
        }
        let t = e.time;
        let (q0, qa) = (v.joints_at(t - h), v.joints_at(t));
        v.perform();
        let (qb, q1) = (v.joints_at(t), v.joints_at(t + h));
        for i in 0..6 {
            assert!(
                (qa[i] - qb[i]).abs() < 1e-9,
                "axis {i} jumps at {t} ({:?}): {} → {}",
                e.kind,
                qa[i],
                qb[i]
            );
            let (vl, vr) = ((qa[i] - q0[i]) / 1e-6, (q1[i] - qb[i]) / 1e-6);
            assert!(
                (vl - vr).abs() <= vel_tol,
                "axis {i} speed jumps at {t} ({:?}): {vl} → {vr}",
                e.kind
            );
        }
        events.push(e);
    }
    let end = events.last().map_or(0, |e| e.time);
    while tick <= end {
        samples.push(sample(v, tick, zone, corner_from));
        tick += MS;
    }
    Run {
        events,
        samples,
        end,
        zone_excess,
    }
}

/// Each motion_start of a run: its time and the radius it blends out of a zone within.
fn motion_starts(r: &Run) -> Vec<(i64, Option<f64>)> {
    r.events
        .iter()
        .filter_map(|e| match e.kind {
            EventKind::MotionStart { blend_m, .. } => Some((e.time, blend_m)),
            _ => None,
        })
        .collect()
}

fn zone_text(z: u32) -> String {
    if z == 0 {
        "zone fine".into()
    } else {
        format!("zone {z}mm")
    }
}

/// A program of straight moves through `points` (offsets from the start pose, mm) at
/// `speeds` (mm/s) with `zones` (mm, 0: fine).
fn line_program(points: &[(i32, i32, i32)], speeds: &[u32], zones: &[u32]) -> String {
    let mut s = format!("proc main() {{\n    move_j {HOME};\n    var p = current_pose();\n");
    for ((x, y, z), (v, zone)) in points.iter().zip(speeds.iter().zip(zones)) {
        s += &format!(
            "    move_l offset(p, {x}mm, {y}mm, {z}mm) speed {v}mm/s {};\n",
            zone_text(*zone)
        );
    }
    s + "}\n"
}

fn joint_program(targets: &[[i32; 6]], speeds: &[u32], zones: &[u32]) -> String {
    let mut s = format!("proc main() {{\n    move_j {HOME};\n");
    for (t, (v, zone)) in targets.iter().zip(speeds.iter().zip(zones)) {
        let home = [0, -30, 30, 0, 60, 0];
        let q: Vec<String> = t
            .iter()
            .zip(home)
            .map(|(d, h)| format!("{}deg", h + d))
            .collect();
        s += &format!(
            "    move_j joints({}) speed {v}% {};\n",
            q.join(", "),
            zone_text(*zone)
        );
    }
    s + "}\n"
}

fn fine(src: &str) -> String {
    let mut out = String::new();
    for line in src.lines() {
        let l = match line.find(" zone ") {
            Some(k) => format!("{};", &line[..k]),
            None => line.to_string(),
        };
        out += &l;
        out.push('\n');
    }
    out
}

/// Runs `src` as written and with every zone `fine`: the zoned run has no error and ends
/// no later than the fine one. Returns the zoned run.
fn zoned_and_fine(src: &str, jerk: Option<f64>, vel_tol: f64) -> Result<Run, TestCaseError> {
    let r = run(&mut vm(src, jerk), vel_tol);
    prop_assert!(
        r.events
            .iter()
            .all(|e| !matches!(e.kind, EventKind::Error { .. })),
        "{src}"
    );
    let rf = run(&mut vm(&fine(src), jerk), vel_tol);
    prop_assert!(r.end <= rf.end, "zoned {} > fine {}\n{src}", r.end, rf.end);
    Ok(r)
}

/// The TCP at every `motion_end` of `src` with every zone `fine`: home, then its points.
fn fine_points(src: &str, jerk: Option<f64>) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    let mut f = vm(&fine(src), jerk);
    while let Next::Event(e) = f.next_event() {
        f.perform();
        if matches!(e.kind, EventKind::MotionEnd { .. }) {
            out.push(f.tcp_at(e.time).t);
        }
    }
    out
}

/// Every axis of the IRB 120 within its speed and acceleration at 1 kHz (first and
/// second differences: means of the speed and acceleration), to 1e-9 of the limit and
/// 1e-8 rad/s² for rounding in a second difference. The paths and corners that are
/// checked at samples are checked between them too (docs/engine.md, "Limits").
fn within_limits(r: &Run, src: &str) -> Result<(), TestCaseError> {
    let model = builtin::load("irb120").unwrap();
    for w in r.samples.windows(3) {
        let (t, q0, q1, q2) = (w[1].0, w[0].1, w[1].1, w[2].1);
        for i in 0..6 {
            let axis = model.axis(i);
            let speed = (q2[i] - q1[i]).abs() / 1e-3;
            prop_assert!(
                speed <= axis.max_velocity * (1.0 + 1e-9),
                "axis {i} after {t}: {} × its speed limit\n{src}",
                speed / axis.max_velocity
            );
            let acc = (q2[i] - 2.0 * q1[i] + q0[i]).abs() / 1e-6;
            prop_assert!(
                acc <= axis.max_accel * (1.0 + 1e-9) + 1e-8,
                "axis {i} at {t}: {} × its acceleration limit\n{src}",
                acc / axis.max_accel
            );
        }
    }
    Ok(())
}

fn points() -> impl Strategy<Value = Vec<(i32, i32, i32)>> {
    prop::collection::vec((-120i32..120, -120i32..120, -100i32..100), 2..6)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn cartesian_corners_stay_in_their_zones_and_cost_no_more_than_stops(
        pts in points(),
        speeds in prop::collection::vec(100u32..800, 6),
        zones in prop::collection::vec(prop_oneof![Just(0u32), 1u32..60], 6),
        jerk in prop_oneof![Just(None), Just(Some(0.05)), Just(Some(0.15))],
    ) {
        let src = line_program(&pts, &speeds, &zones);
        let r = zoned_and_fine(&src, jerk, 50.0)?;
        prop_assert!(r.zone_excess <= 1e-9, "{} m outside a zone\n{src}", r.zone_excess);
        // Every axis within its speed and acceleration: a first difference at 1 kHz is
        // the mean speed over the millisecond, a second difference a weighted mean of the
        // acceleration over two, so neither exceeds a limit the motion keeps (within
        // 1e-9 of it, and 1e-8 rad/s² of rounding in a second difference).
        within_limits(&r, &src)?;
        // The points (TCP positions at each motion_end of the fine run), then the zones.
        let ends = fine_points(&src, jerk);
        // ends[0] is home; ends[k + 1] is point k.
        let starts: Vec<usize> = r.events.iter().enumerate()
            .filter(|(_, e)| matches!(e.kind, EventKind::MotionStart { .. })).map(|(i, _)| i).collect();
        let motion_ends: Vec<i64> = r.events.iter()
            .filter(|e| matches!(e.kind, EventKind::MotionEnd { .. })).map(|e| e.time).collect();
        prop_assert_eq!(starts.len(), pts.len() + 1);
        for k in 0..pts.len().saturating_sub(1) {
            let EventKind::MotionEnd { zone_m: Some(zone), .. } = r.events.iter()
                .filter(|e| matches!(e.kind, EventKind::MotionEnd { .. })).nth(k + 1).unwrap().kind.clone()
            else { continue };
            let (before, p, next) = (ends[k], ends[k + 1], ends[k + 2]);
            // From the next motion's start (the corner's): between a look-ahead
            // `motion_end` and it the TCP is still on its own line, outside the zone; a
            // motion that takes over through a timed corner starts there too.
            let (from, to) = (r.events[starts[k + 2]].time, motion_ends[k + 2]);
            // The distance from the TCP to the segment p → q.
            let off_segment = |tcp: [f64; 3], p: [f64; 3], q: [f64; 3]| {
                let u = sub(q, p);
                let l2 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
                let w = sub(tcp, p);
                let s = ((w[0] * u[0] + w[1] * u[1] + w[2] * u[2]) / l2).clamp(0.0, 1.0);
                norm(sub(w, [u[0] * s, u[1] * s, u[2] * s]))
            };
            for (t, _, tcp) in r.samples.iter().filter(|(t, ..)| *t >= from && *t <= to) {
                let d = norm(sub(*tcp, p));
                // Or on the next line, or still on its own.
                let off = off_segment(*tcp, p, next).min(off_segment(*tcp, before, p));
                prop_assert!(d <= zone + 1e-9 || off <= 1e-7,
                    "at {t}: {d} m from point {k} (zone {zone}), {off} m off both lines\n{src}");
            }
        }
        // Lower bound: outside the zones, one motion at a time at most at its speed.
        let mut bound = 0.0;
        let mut prev = ends[0];
        for k in 0..pts.len() {
            let p = ends[k + 1];
            let z_in = if k > 0 { zones[k - 1] as f64 / 1000.0 } else { 0.0 };
            let z_out = zones[k] as f64 / 1000.0;
            bound += (norm(sub(p, prev)) - z_in - z_out).max(0.0) / (speeds[k] as f64 / 1000.0);
            prev = p;
        }
        let first_move = r.events.iter().find(|e| matches!(e.kind, EventKind::MotionEnd { .. })).unwrap().time;
        prop_assert!((r.end - first_move) as f64 / 1e9 >= bound - 1e-9, "{} < {bound}\n{src}", r.end);
    }

    #[test]
    fn joint_corners_keep_every_axis_within_its_speed_and_acceleration(
        targets in prop::collection::vec(prop::array::uniform6(-40i32..40), 2..6),
        speeds in prop::collection::vec(20u32..=100, 6),
        zones in prop::collection::vec(prop_oneof![Just(0u32), 1u32..120], 6),
        jerk in prop_oneof![Just(None), Just(Some(0.05)), Just(Some(0.15))],
    ) {
        let src = joint_program(&targets, &speeds, &zones);
        let model = builtin::load("irb120").unwrap();
        // Velocity continuity: over 2 µs the speed changes by at most 2 µs × the limit.
        let amax = (0..6).map(|i| model.axis(i).max_accel).fold(0.0, f64::max);
        let r = zoned_and_fine(&src, jerk, 2e-6 * amax * 1.01 + 1e-9)?;
        prop_assert!(r.zone_excess <= JOINT_CORNER_TOLERANCE, "{} m outside a zone\n{src}", r.zone_excess);
        within_limits(&r, &src)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Lines at a low `accel` (trapezoids where the axes allow them, so corners fly with
    /// ramps and look-ahead, else timed as one path): every corner in its zone, the TCP
    /// never faster than the fastest programmed speed nor — outside corners superposed as
    /// planned — accelerating harder than `accel` (second differences at 1 kHz, a mean of
    /// the acceleration), never slower than stopping.
    #[test]
    fn cartesian_corners_with_look_ahead_keep_the_tcp_acceleration(
        pts in points(),
        speeds in prop::collection::vec(50u32..300, 6),
        zones in prop::collection::vec(prop_oneof![Just(0u32), 1u32..60], 6),
        accel in 1u32..3,
    ) {
        let src = line_program(&pts, &speeds, &zones)
            .replace("mm/s zone", &format!("mm/s accel {accel}m/s2 zone"));
        let r = zoned_and_fine(&src, None, 50.0)?;
        prop_assert!(r.zone_excess <= 1e-9, "{} m outside a zone\n{src}", r.zone_excess);
        let vmax = speeds.iter().take(pts.len()).copied().max().unwrap() as f64 / 1000.0;
        let amax = f64::from(accel);
        let dt = 1e-3;
        // (After the first move_j, which the samples' TCP follows at its own limits.)
        let first_move = r.events.iter().find(|e| matches!(e.kind, EventKind::MotionEnd { .. })).unwrap().time;
        // A corner superposed as planned (the TCP's acceleration adds up there) is left
        // out: one with ramps blends within min(zone, L₂/2) or a power-of-two fraction of
        // it; one timed as one path starts as the motion before ends (its motion_end).
        let ends = fine_points(&src, None);
        let mut superposed = Vec::new();
        let (mut zone, mut k, mut ended) = (0.0, 0usize, 0i64);
        for (i, e) in r.events.iter().enumerate() {
            match e.kind {
                EventKind::MotionEnd { zone_m, .. } => {
                    zone = zone_m.unwrap_or(0.0);
                    k += 1;
                    ended = e.time;
                }
                EventKind::MotionStart { blend_m: Some(b), .. } if b > 0.0 => {
                    let l2 = norm(sub(ends[k], ends[k - 1]));
                    let r0 = zone.min(0.5 * l2);
                    let ramps = (0..4).any(|j| (b - r0 / f64::from(1u32 << j)).abs() <= 1e-12 * r0);
                    let timed = e.time == ended;
                    if !ramps && !timed {
                        let to = r.events[i..].iter().find(|e| matches!(e.kind, EventKind::MotionEnd { .. })).unwrap().time;
                        superposed.push((e.time - MS, to + MS));
                    }
                }
                _ => {}
            }
        }
        let in_ramps = |t: i64| !superposed.iter().any(|&(a, b)| t >= a && t <= b);
        for w in r.samples.windows(3).filter(|w| w[0].0 >= first_move && in_ramps(w[1].0)) {
            let (t, p0, p1, p2) = (w[1].0, w[0].2, w[1].2, w[2].2);
            let speed = norm(sub(p2, p1)) / dt;
            prop_assert!(speed <= vmax * (1.0 + 1e-9), "TCP at {t}: {speed} m/s > {vmax}\n{src}");
            let acc = norm([p2[0] - 2.0 * p1[0] + p0[0], p2[1] - 2.0 * p1[1] + p0[1], p2[2] - 2.0 * p1[2] + p0[2]]) / (dt * dt);
            prop_assert!(acc <= amax * (1.0 + 1e-6) + 1e-6, "TCP at {t}: {acc} m/s² > {amax}\n{src}");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    /// Mixed corners (`move_j` → `move_l` and back) blend in joint space: continuous
    /// joints and speeds at every event, every axis within its limits, and never slower
    /// than stopping.
    #[test]
    fn mixed_corners_are_continuous_and_cost_no_more_than_stops(
        pts in points(),
        zones in prop::collection::vec(prop_oneof![Just(0u32), 1u32..60], 6),
        jerk in prop_oneof![Just(None), Just(Some(0.1))],
    ) {
        let mut src = format!("proc main() {{\n    move_j {HOME};\n    var p = current_pose();\n");
        for (k, ((x, y, z), zone)) in pts.iter().zip(&zones).enumerate() {
            let cmd = if k % 2 == 0 { "move_j" } else { "move_l" };
            src += &format!("    {cmd} offset(p, {x}mm, {y}mm, {z}mm) {};\n", zone_text(*zone));
        }
        src += "}\n";
        let r = zoned_and_fine(&src, jerk, 50.0)?;
        prop_assert!(r.zone_excess <= JOINT_CORNER_TOLERANCE, "{} m outside a zone\n{src}", r.zone_excess);
        within_limits(&r, &src)?;
    }
}

#[test]
fn a_delay_after_a_zoned_point_waits_for_the_robot_with_one_warning() {
    let src = format!(
        "proc main() {{\n    move_j {HOME};\n    var p = current_pose();\n    var k = 0;\n    while k < 2 {{\n        move_l offset(p, 100mm, 0mm, 0mm) zone 10mm;\n        delay 0.1s;\n        move_l p zone fine;\n        k += 1;\n    }}\n}}\n"
    );
    let mut v = vm(&src, None);
    let r = run(&mut v, 50.0);
    let warnings = v.take_warnings();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert_eq!(warnings[0].kind, WarningKind::StopPoint);
    assert!(
        warnings[0].message.contains(
            "`delay` makes the zoned point of the motion at line 6 of t.wsl a stop point"
        )
    );
    // The delay starts when the robot reaches the point: the moves take as long as fine.
    let mut f = vm(&fine(&src), None);
    let rf = run(&mut f, 50.0);
    assert_eq!(r.end, rf.end);
    let delays: Vec<i64> = r
        .events
        .iter()
        .filter(|e| matches!(e.kind, EventKind::Delay { .. }))
        .map(|e| e.time)
        .collect();
    let fine_delays: Vec<i64> = rf
        .events
        .iter()
        .filter(|e| matches!(e.kind, EventKind::Delay { .. }))
        .map(|e| e.time)
        .collect();
    assert_eq!(delays, fine_delays);
}

/// A Cartesian motion with another tool than the zoned one before it does not blend
/// (docs/language.md, `tool`): it starts at the point, from its own TCP there — the flange
/// at the point with the new tool, 100 mm below the old TCP — without a jump (`run`
/// checks the joints at every event), and ends at its target with that tool. (It used to
/// start its path from the old tool's TCP: its axes jumped by 0.29 rad.)
#[test]
fn a_motion_with_another_tool_after_a_zoned_point_starts_there_with_its_own_tcp() {
    let src = "proc main() {\n    move_j pose(400mm, 0mm, 300mm, 180deg, 0deg, 0deg);\n    move_l pose(400mm, 100mm, 300mm, 180deg, 0deg, 0deg) speed 200mm/s zone 10mm;\n    move_l pose(450mm, 100mm, 300mm, 180deg, 0deg, 0deg) speed 200mm/s tool pose(0mm, 0mm, 100mm, 0deg, 0deg, 0deg);\n}\n";
    let mut v = vm(src, None);
    let r = run(&mut v, 50.0);
    let starts = motion_starts(&r);
    assert_eq!(starts[2].1, None, "{:?}", r.events);
    let at = |t: i64| r.samples.iter().find(|s| s.0 >= t).unwrap().2;
    // The new TCP at the start: the point, 100 mm down the flange's z (pointing down); the
    // first sample, less than 1 ms after it, within what 28 m/s² moves it in 1 ms.
    let start = at(starts[2].0);
    assert!(norm(sub(start, [0.4, 0.1, 0.2])) < 1.4e-5, "{start:?}");
    assert!(norm(sub(v.tcp_at(r.end).t, [0.45, 0.1, 0.3])) < 1e-9);
}

/// A 12-gon of 31 mm sides (radius 60 mm) at 1000 mm/s, where the IRB 120's axes time
/// the lines: every corner is timed as one path, taking the robot over at the motion_end
/// of the line before — whose motion_end is where its own corner ends, rounded down to
/// the nanosecond, a few nanometres short of it: the next takes over at once, or the
/// nanosecond the robot passes it (it used to be refused there and superposed, starting up
/// to 32 ms later: 10 mm zones took 1.069 s, 2 % more than 5 mm ones). A larger zone is
/// then faster: 3 to 13 mm, each shorter than the last.
#[test]
fn a_chain_of_timed_corners_takes_over_at_each_motion_end() {
    let polygon = |zone: u32| {
        let mut s = String::from(
            "proc main() {\n    move_j pose(460mm, 0mm, 300mm, 180deg, 0deg, 0deg);\n",
        );
        for k in 1..=12 {
            let a = k as f64 * std::f64::consts::TAU / 12.0;
            let z = if k == 12 {
                "fine".to_string()
            } else {
                format!("{zone}mm")
            };
            s += &format!(
                "    move_l pose({:.3}mm, {:.3}mm, 300mm, 180deg, 0deg, 0deg) speed 1000mm/s zone {z};\n",
                400.0 + 60.0 * a.cos(),
                60.0 * a.sin()
            );
        }
        s + "}\n"
    };
    let mut last = i64::MAX;
    for zone in 3..=13 {
        let mut v = vm(&polygon(zone), None);
        let r = run(&mut v, 50.0);
        assert!(v.take_warnings().is_empty());
        let mut end = None;
        for e in &r.events {
            match e.kind {
                EventKind::MotionEnd { .. } => end = Some(e.time),
                // (At once, or the few nanoseconds later its corner ends.)
                EventKind::MotionStart {
                    blend_m: Some(_), ..
                } => {
                    let late = e.time - end.unwrap();
                    assert!((0..1_000).contains(&late), "zone {zone}: {late} ns late");
                }
                _ => {}
            }
        }
        assert!(r.end < last, "zone {zone} mm: {} after {last}", r.end);
        last = r.end;
    }
}

/// A line whose axis 1 would pass its speed limit at the programmed speed (close to axis
/// 1 at 2 m/s), on an IRB 120 whose axes ramp their accelerations up in 20 ms: no S-curve
/// at 2 m/s fits, and the line is timed within every axis's speed, acceleration and jerk
/// (docs/engine.md, "Jerk limits"), with a `slowdown` warning. It is faster than the
/// S-curve at the best lower speed, which took 0.215 s (measured before the jerk-limited
/// timing), and every axis's jerk, by third differences of its joint every millisecond,
/// stays within 1 % of its limit.
#[test]
fn a_jerk_limited_line_that_binds_an_axis_speed_is_timed_within_every_axis_jerk() {
    let ramp = 0.02;
    let src = "proc main() {
        move_j pose(300mm, -80mm, 400mm, 180deg, 0deg, 0deg);
        move_l pose(300mm, 80mm, 400mm, 180deg, 0deg, 0deg) speed 2000mm/s;
    }";
    let model = builtin::load("irb120").unwrap();
    let jerks: Vec<f64> = (0..6)
        .map(|k| model.joints[model.axes[k]].max_accel / ramp)
        .collect();
    let mut v = vm(src, Some(ramp));
    let mut window = None;
    let mut start = 0;
    let mut joints = Vec::new();
    let mut tick = 0i64;
    while let Next::Event(e) = v.next_event() {
        match e.kind {
            EventKind::MotionStart {
                command: "move_l", ..
            } => start = e.time,
            EventKind::MotionEnd { .. } if start > 0 && window.is_none() => {
                window = Some((start, e.time));
            }
            EventKind::Error { .. } => panic!("{e:?}"),
            _ => {}
        }
        while tick < e.time {
            joints.push(v.joints_at(tick));
            tick += 1_000_000;
        }
        v.perform();
    }
    let (t0, t1) = window.expect("the move_l ran");
    let seconds = (t1 - t0) as f64 * 1e-9;
    assert!(seconds < 0.215, "{seconds} s");
    for w in joints.windows(4) {
        for (i, j) in jerks.iter().enumerate() {
            let d3 = (w[3][i] - 3.0 * w[2][i] + 3.0 * w[1][i] - w[0][i]) / 1e-9;
            assert!(d3.abs() <= j * 1.01, "axis {i}: jerk {d3} of {j}");
        }
    }
    let w = v.take_warnings();
    assert!(
        w.iter()
            .any(|w| w.kind == WarningKind::Slowdown && w.pos.line == 3),
        "{w:?}"
    );
}

/// The program of the IRB 120's picking cycle corner at its own limits (docs/models.md):
/// 25 mm up from `a`, then `dy` mm across at the model's TCP speed, with `zone`.
fn pick_corner(dy: i32, zone: &str) -> String {
    format!(
        "const a = pose(400mm, -150mm, 200mm, 180deg, 0deg, 0deg);\nproc main() {{\n    move_j a;\n    move_l offset(a, 0mm, 0mm, 25mm) speed 6200mm/s {zone};\n    move_l offset(a, 0mm, {dy}mm, 25mm) speed 6200mm/s zone fine;\n}}\n"
    )
}

/// Corners timed as one path (docs/engine.md, "Zones"): the up move of the IRB 120's
/// picking cycle is timed within its axes' limits, so the move across takes the robot over
/// at its motion_end — the same instant — and runs through a parabola inside the zone
/// (12.5 mm: half the up move). Sampled every 0.5 ms: the TCP within the zone around the
/// point until it is on the second line, its acceleration within the model's 28 m/s², the
/// axes within their limits (1e-6, the samples' rounding); faster than stopping. Flying
/// straight on (a point halfway along one line) costs what the one line does, to the
/// timing's steps (0.5 %).
#[test]
fn a_corner_timed_as_one_path_takes_over_and_keeps_every_limit() {
    let model = builtin::load("irb120").unwrap();
    let src = pick_corner(300, "zone 25mm");
    let mut v = vm(&src, None);
    let r = run(&mut v, 50.0);
    let ends: Vec<i64> = r
        .events
        .iter()
        .filter(|e| matches!(e.kind, EventKind::MotionEnd { .. }))
        .map(|e| e.time)
        .collect();
    let starts = motion_starts(&r);
    assert_eq!(starts[2].0, ends[1], "{:?}", r.events);
    assert!(
        starts[2].1.is_some_and(|b| (b - 0.0125).abs() < 1e-12),
        "{:?}",
        starts[2]
    );
    // Finer samples through the corner: every 0.5 ms from the take-over to the end.
    let (from, to) = (ends[1], ends[2]);
    let h = 500_000;
    let samples: Vec<_> = (0..=(to - from) / h)
        .map(|k| {
            let t = from + k * h;
            (t, v.joints_at(t), v.tcp_at(t).t)
        })
        .collect();
    let corner = [400e-3, -150e-3, 225e-3];
    for (t, _, p) in &samples {
        let d = norm(sub(*p, corner));
        let on_second = (p[0] - 0.4).abs() < 1e-7 && (p[2] - 0.225).abs() < 1e-7;
        let on_first = (p[0] - 0.4).abs() < 1e-7 && (p[1] + 0.15).abs() < 1e-7;
        assert!(
            d <= 0.0125 + 1e-9 || on_first || on_second,
            "at {t}: {d} m from the point"
        );
    }
    let dt = h as f64 / 1e9;
    for w in samples.windows(3) {
        let (t, p0, p1, p2) = (w[1].0, w[0].2, w[1].2, w[2].2);
        let acc = norm([
            p2[0] - 2.0 * p1[0] + p0[0],
            p2[1] - 2.0 * p1[1] + p0[1],
            p2[2] - 2.0 * p1[2] + p0[2],
        ]) / (dt * dt);
        assert!(acc <= 28.0 * (1.0 + 1e-6), "TCP at {t}: {acc} m/s²");
        for i in 0..6 {
            let j = model.axis(i);
            let speed = (w[2].1[i] - w[1].1[i]).abs() / dt;
            let a = (w[2].1[i] - 2.0 * w[1].1[i] + w[0].1[i]).abs() / (dt * dt);
            assert!(
                speed <= j.max_velocity * (1.0 + 1e-6),
                "axis {i} at {t}: {speed}"
            );
            assert!(a <= j.max_accel * (1.0 + 1e-6), "axis {i} at {t}: {a}");
        }
    }
    let stop = run(&mut vm(&pick_corner(300, "zone fine"), None), 50.0);
    assert!(r.end < stop.end, "{} against stopping {}", r.end, stop.end);
    // Straight on: up 25 mm and on up 25 mm, against one 50 mm line.
    let straight = |zone: &str| {
        format!(
            "const a = pose(400mm, -150mm, 200mm, 180deg, 0deg, 0deg);\nproc main() {{\n    move_j a;\n    move_l offset(a, 0mm, 0mm, 25mm) speed 6200mm/s {zone};\n    move_l offset(a, 0mm, 0mm, 50mm) speed 6200mm/s zone fine;\n}}\n"
        )
    };
    let one = "const a = pose(400mm, -150mm, 200mm, 180deg, 0deg, 0deg);\nproc main() {\n    move_j a;\n    move_l offset(a, 0mm, 0mm, 50mm) speed 6200mm/s zone fine;\n}\n";
    let (flown, line) = (
        run(&mut vm(&straight("zone 25mm"), None), 50.0).end,
        run(&mut vm(one, None), 50.0).end,
    );
    let ratio = flown as f64 / line as f64;
    assert!((0.995..1.005).contains(&ratio), "{flown} against {line}");
}

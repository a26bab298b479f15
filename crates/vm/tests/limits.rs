//! Every motion keeps every axis within its limits, and the joints never jump (docs/engine.md,
//! "Timing"): random `move_l`, `move_c` and `move_j` of the four built-in arms, each sampled
//! at 1 kHz through `Vm::joints_at` as the engine samples it. Axis speeds are first
//! differences of the samples and accelerations second differences, averages over 1 or
//! 2 ms: within 1e-9 of the limit (and 1e-8 rad/s² for rounding in a second difference),
//! as issue 30 asks. (Before the UR5's numeric IK took its last steps to the pose's
//! rounding, its joints were 1e-10 rad off by an amount that drifts along a path: 1e-4
//! rad/s² at 1 kHz, 9e-6 of its 10 rad/s², in 5 of 600 random motions.)
//!
//! A motion the VM refuses (a point out of reach, a singularity on the way, a self-made
//! joint limit) is no case: the property is about the motions that run.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::sync::Arc;

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use vworks_model::{RobotModel, builtin};
use vworks_vm::machine::{EventKind, Next, Vm, VmConfig};

/// Start joints (degrees) away from singularities, per model (the middle of
/// `bench/fidelity.py`'s ranges): the elbow bent, the wrist bent.
fn start(model: &str) -> [f64; 6] {
    match model {
        "ur5" => [0.0, -80.0, 80.0, -90.0, -90.0, 0.0],
        "kr6r900" => [0.0, -85.0, 100.0, 0.0, 60.0, 0.0],
        "lrmate200id" => [0.0, 15.0, -15.0, 0.0, 60.0, 0.0],
        _ => [0.0, 20.0, 30.0, 0.0, 60.0, 0.0],
    }
}

/// The motion statements of a case: `kind` 0 a line, 1 an arc, 2 a joint move.
fn program(
    model: &str,
    jitter: [f64; 6],
    offset: [f64; 3],
    side: f64,
    kind: u8,
    speed: f64,
) -> String {
    let s = start(model);
    let q: Vec<String> = s
        .iter()
        .zip(jitter)
        .map(|(a, d)| format!("{:.3}deg", a + d))
        .collect();
    let [dx, dy, dz] = offset;
    let motion = match kind {
        0 => format!("move_l offset(p, {dx:.1}mm, {dy:.1}mm, {dz:.1}mm) speed {speed}mm/s;"),
        1 => {
            // The via point: the chord's middle pushed sideways (perpendicular in xy).
            let (mx, my, mz) = (dx / 2.0, dy / 2.0, dz / 2.0);
            let n = (dx * dx + dy * dy).sqrt().max(1e-9);
            let (vx, vy) = (mx - side * dy / n * 60.0, my + side * dx / n * 60.0);
            format!(
                "move_c offset(p, {vx:.1}mm, {vy:.1}mm, {mz:.1}mm), offset(p, {dx:.1}mm, {dy:.1}mm, {dz:.1}mm) speed {speed}mm/s;"
            )
        }
        _ => format!("move_j offset(p, {dx:.1}mm, {dy:.1}mm, {dz:.1}mm) speed 100%;"),
    };
    format!(
        "proc main() {{\n    move_j joints({});\n    var p = current_pose();\n    {motion}\n}}\n",
        q.join(", ")
    )
}

/// Runs the program, sampling every motion at 1 kHz; returns the samples of each motion,
/// or `None` if the VM refused a motion (an error event).
fn motions(vm: &mut Vm) -> Option<Vec<Vec<[f64; 12]>>> {
    let mut out = Vec::new();
    let mut start = None;
    for _ in 0..1000 {
        match vm.next_event() {
            Next::Event(e) => {
                match &e.kind {
                    EventKind::Error { .. } => return None,
                    EventKind::MotionStart { .. } => start = Some(e.time),
                    EventKind::MotionEnd { .. } => {
                        let t0 = start.take()?;
                        let samples = (0..)
                            .map(|k| t0 + k * 1_000_000)
                            .take_while(|t| *t <= e.time)
                            .chain([e.time])
                            .map(|t| vm.joints_at(t))
                            .collect();
                        out.push(samples);
                    }
                    _ => {}
                }
                vm.perform();
            }
            _ => break,
        }
    }
    Some(out)
}

/// Checks a motion's 1 kHz samples against the axis limits: the largest ratio of an
/// axis's speed, and of its acceleration, to its limit.
fn peaks(model: &RobotModel, samples: &[[f64; 12]]) -> (f64, f64) {
    let h = 1e-3;
    let (mut v, mut a) = (0.0f64, 0.0f64);
    // The last sample is the motion's end, less than 1 ms after the one before it: left
    // out of the differences (uneven spacing).
    let even = &samples[..samples.len().saturating_sub(1)];
    for i in 0..model.dof() {
        let j = model.axis(i);
        for w in even.windows(2) {
            v = v.max((w[1][i] - w[0][i]).abs() / h / j.max_velocity);
        }
        for w in even.windows(3) {
            let acc = (w[2][i] - 2.0 * w[1][i] + w[0][i]) / (h * h);
            // (Less the rounding of a second difference of joints of about 1: 1e-8 rad/s².)
            a = a.max((acc.abs() - 1e-8).max(0.0) / j.max_accel);
        }
    }
    (v, a)
}

/// Runs one case; false if the VM refused its motion (then it is no case).
fn check(
    model_name: &str,
    jitter: [f64; 6],
    offset: [f64; 3],
    side: f64,
    kind: u8,
    speed: f64,
) -> bool {
    let src = program(model_name, jitter, offset, side, kind, speed);
    let out = vworks_wslc::compile("t.wsl", &src).unwrap_or_else(|e| panic!("{e}\n{src}"));
    let m = Arc::new(out.module);
    let entry = m.proc_index("main").unwrap();
    let model = Arc::new(builtin::load(model_name).unwrap());
    let mut vm = Vm::new(m, Arc::clone(&model), VmConfig::default(), Some(entry));
    let Some(motions) = motions(&mut vm) else {
        return false;
    };
    for samples in &motions {
        let (v, a) = peaks(&model, samples);
        assert!(
            v <= 1.0 + 1e-9,
            "{model_name}: axis speed {v} of its limit\n{src}"
        );
        assert!(
            a <= 1.0 + 1e-9,
            "{model_name}: axis acceleration {a} of its limit\n{src}"
        );
    }
    true
}

fn jitter() -> impl Strategy<Value = [f64; 6]> {
    prop::array::uniform6(-15.0f64..15.0)
}

fn offset() -> impl Strategy<Value = [f64; 3]> {
    prop::array::uniform3(-250.0f64..250.0)
}

/// The TCP speeds the motions are programmed at (mm/s).
fn tcp_speed() -> impl Strategy<Value = f64> {
    prop::sample::select(vec![100.0, 500.0, 1000.0, 2000.0, 4000.0])
}

proptest! {
    // 40 motions that run per arm; at most 40 refused on the way (out of reach, a
    // singularity), so that the property is never checked on too few.
    // A fixed seed: the same cases in every run (the trace of a failure is reproducible).
    #![proptest_config(ProptestConfig {
        cases: 40,
        max_global_rejects: 40,
        rng_seed: RngSeed::Fixed(30),
        ..ProptestConfig::default()
    })]

    #[test]
    fn irb120_motions_keep_every_axis_within_its_limits(
        j in jitter(), o in offset(), side in -1.0f64..1.0, kind in 0u8..3,
        speed in tcp_speed(),
    ) {
        prop_assume!(check("irb120", j, o, side, kind, speed));
    }

    #[test]
    fn kr6r900_motions_keep_every_axis_within_its_limits(
        j in jitter(), o in offset(), side in -1.0f64..1.0, kind in 0u8..3,
        speed in tcp_speed(),
    ) {
        prop_assume!(check("kr6r900", j, o, side, kind, speed));
    }

    #[test]
    fn lrmate200id_motions_keep_every_axis_within_its_limits(
        j in jitter(), o in offset(), side in -1.0f64..1.0, kind in 0u8..3,
        speed in tcp_speed(),
    ) {
        prop_assume!(check("lrmate200id", j, o, side, kind, speed));
    }

    #[test]
    fn ur5_motions_keep_every_axis_within_its_limits(
        j in jitter(), o in offset(), side in -1.0f64..1.0, kind in 0u8..3,
        speed in tcp_speed(),
    ) {
        prop_assume!(check("ur5", j, o, side, kind, speed));
    }
}

/// The worst case the random ones found: an arc at 100 mm/s passing near the irb120's axis
/// 1 (the TCP near the base's axis), where axis 1 turns at its full speed.
#[test]
fn an_arc_near_a_singularity_keeps_its_axes_within_their_limits() {
    assert!(check(
        "irb120",
        // (joints -11.902°, -21.344°, 20°, 0°, 60°, 0°)
        [-11.902, -41.344, -10.0, 0.0, 0.0, 0.0],
        [-201.6, 25.8, 0.0],
        -0.9,
        1,
        100.0
    ));
}

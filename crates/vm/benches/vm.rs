//! Interpreter dispatch (target ≥ 100 M simple instructions/s on an int loop) and motion
//! sampling (the robot's joints at a time inside a move_l, target ≤ 5 µs per sample), and
//! planning a `move_l` with and without jerk limits.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // benches fail by panicking

use std::hint::black_box;
use std::sync::Arc;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use vworks_model::{RobotModel, builtin};
use vworks_vm::machine::{EventKind, Next, Vm, VmConfig};

const LOOPS: i64 = 1_000_000;

fn vm(src: &str, robot: &str) -> Vm {
    let m = Arc::new(vworks_wslc::compile("b.wsl", src).unwrap().module);
    let entry = m.proc_index("main");
    let cfg = VmConfig {
        budget: u64::MAX,
        ..VmConfig::default()
    };
    Vm::new(m, Arc::new(builtin::load(robot).unwrap()), cfg, entry)
}

fn dispatch(c: &mut Criterion) {
    // Per iteration: LoadLocal, PushInt, CmpI, JumpIfFalse, LoadLocal, LoadLocal, AddI,
    // StoreLocal, LoadLocal, PushInt, AddI, StoreLocal, Jump = 13 instructions.
    let src = format!(
        "proc main() {{ var i = 0; var s = 0; while i < {LOOPS} {{ s = s + i; i = i + 1; }} delay 1s; }}"
    );
    let mut g = c.benchmark_group("interpreter");
    g.throughput(Throughput::Elements(13 * LOOPS as u64));
    g.sample_size(20);
    g.bench_function("int_loop", |b| {
        b.iter_batched(
            || vm(&src, "irb120"),
            |mut v| {
                let Next::Event(e) = v.next_event() else {
                    panic!()
                };
                assert!(matches!(e.kind, EventKind::Delay { .. }));
                black_box(e)
            },
            criterion::BatchSize::LargeInput,
        )
    });
    g.finish();
}

fn sampling(c: &mut Criterion) {
    let src = "
        const start = joints(0deg, 10deg, 20deg, 0deg, 60deg, 0deg);
        proc main() {
            move_j start;
            var p = current_pose();
            move_l offset(p, 100mm, -150mm, -80mm) speed 200mm/s;
        }";
    let mut v = vm(src, "irb120");
    // Into the move_l.
    let (mut t0, mut dur) = (0, 0);
    while let Next::Event(e) = v.next_event() {
        v.perform();
        if let EventKind::MotionStart {
            command: "move_l",
            duration_ns,
            ..
        } = e.kind
        {
            (t0, dur) = (e.time, duration_ns);
            break;
        }
    }
    assert!(dur > 0);
    let mut k = 0i64;
    c.bench_function("motion/joints_at_inside_move_l", |b| {
        b.iter(|| {
            k = (k + 7_919_000) % dur;
            black_box(v.joints_at(t0 + k))
        })
    });
}

/// Sampling a robot inside a corner (two motions superposed, IK of the blended pose)
/// against the same straight line: two 100 mm lines at 90°, 500 mm/s, `zone 10mm`, whose
/// corner overlaps them for 92 ms (docs/engine.md, "Zones").
fn corner_sampling(c: &mut Criterion) {
    let src = "
        const start = joints(0deg, -30deg, 30deg, 0deg, 60deg, 0deg);
        proc main() {
            move_j start;
            var p = current_pose();
            move_l offset(p, 100mm, 0mm, 0mm) speed 500mm/s zone 10mm;
            move_l offset(p, 100mm, 100mm, 0mm) speed 500mm/s;
        }";
    let mut g = c.benchmark_group("motion");
    for (name, corner) in [
        ("joints_at_line_straight", false),
        ("joints_at_line_corner", true),
    ] {
        let mut v = vm(src, "irb120");
        let mut starts = 0;
        let mut t0 = 0;
        while let Next::Event(e) = v.next_event() {
            v.perform();
            if let EventKind::MotionStart {
                command: "move_l", ..
            } = e.kind
            {
                starts += 1;
                t0 = e.time;
                // The first line from its start, or the second from its start in the corner.
                if starts == if corner { 2 } else { 1 } {
                    break;
                }
            }
        }
        let window = 90_000_000; // within the 92 ms overlap
        let mut k = 0i64;
        g.bench_function(name, |b| {
            b.iter(|| {
                k = (k + 7_919_000) % window;
                black_box(v.joints_at(t0 + k))
            })
        });
    }
    g.finish();
}

/// An IRB 120, with `ramp`, its axes' jerk limits ramping each acceleration up in `ramp` s.
fn irb120_ramping(ramp: Option<f64>) -> Arc<RobotModel> {
    let mut model = builtin::load("irb120").unwrap();
    if let Some(ramp) = ramp {
        for k in 0..model.dof() {
            let j = model.axes[k];
            model.joints[j].max_jerk = Some(model.joints[j].max_accel / ramp);
        }
    }
    Arc::new(model)
}

/// Planning one `move_l` (sampling its path, checking and timing it): 300 mm past axis 1 of
/// an IRB 120 at 2 m/s, an axis's speed binding; without jerk limits (TOPP-RA), and with
/// axes ramping their accelerations in 20 ms (the jerk-limited timing's linear programs).
fn planning(c: &mut Criterion) {
    let src = "
        proc main() {
            move_j pose(300mm, -150mm, 400mm, 180deg, 0deg, 0deg);
            move_l pose(300mm, 150mm, 400mm, 180deg, 0deg, 0deg) speed 2000mm/s;
        }";
    let m = Arc::new(vworks_wslc::compile("b.wsl", src).unwrap().module);
    let entry = m.proc_index("main");
    let mut g = c.benchmark_group("plan");
    g.sample_size(10);
    for (name, ramp) in [("move_l", None), ("move_l_jerk_limited", Some(0.02))] {
        let model = irb120_ramping(ramp);
        g.bench_function(name, |b| {
            b.iter(|| {
                // (A new VM each time: its memo would remember the path.)
                let mut v = Vm::new(m.clone(), model.clone(), VmConfig::default(), entry);
                loop {
                    match v.next_event() {
                        Next::Event(e) => {
                            let line = matches!(
                                e.kind,
                                EventKind::MotionStart {
                                    command: "move_l",
                                    ..
                                }
                            );
                            v.perform();
                            if line {
                                break;
                            }
                        }
                        _ => panic!("no move_l"),
                    }
                }
                black_box(v.joints_at(0))
            })
        });
    }
    g.finish();
}

/// Planning two `move_l` with a right-angle corner between them timed as one path: 200 mm
/// and 200 mm at 1 m/s, `zone 10mm`, on an IRB 120 without jerk limits (TOPP-RA from the
/// robot's speed) and with its axes ramping in 20 ms (the jerk programs from the robot's
/// speed and acceleration): both lines and the corner, to the second line's start.
fn corner_planning(c: &mut Criterion) {
    let src = "
        proc main() {
            move_j pose(300mm, -100mm, 400mm, 180deg, 0deg, 0deg);
            move_l pose(300mm, 100mm, 400mm, 180deg, 0deg, 0deg) speed 1000mm/s zone 10mm;
            move_l pose(500mm, 100mm, 400mm, 180deg, 0deg, 0deg) speed 1000mm/s;
        }";
    let m = Arc::new(vworks_wslc::compile("b.wsl", src).unwrap().module);
    let entry = m.proc_index("main");
    let mut g = c.benchmark_group("plan");
    g.sample_size(10);
    for (name, ramp) in [("corner", None), ("corner_jerk_limited", Some(0.02))] {
        let model = irb120_ramping(ramp);
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut v = Vm::new(m.clone(), model.clone(), VmConfig::default(), entry);
                let mut lines = 0;
                loop {
                    match v.next_event() {
                        Next::Event(e) => {
                            if let EventKind::MotionStart {
                                command: "move_l",
                                blend_m,
                                ..
                            } = e.kind
                            {
                                lines += 1;
                                // (The corner must be the timed one measured.)
                                if lines == 2 {
                                    assert_eq!(blend_m, Some(0.01));
                                    break;
                                }
                            }
                            v.perform();
                        }
                        _ => panic!("no second move_l"),
                    }
                }
                black_box(v.joints_at(0))
            })
        });
    }
    g.finish();
}

criterion_group!(
    benches,
    dispatch,
    sampling,
    corner_sampling,
    planning,
    corner_planning
);
criterion_main!(benches);

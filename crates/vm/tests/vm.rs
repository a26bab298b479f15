//! One VM driven by a small harness that plays the simulation engine: it takes the VM's
//! next event, records it, performs it, and answers sets, waits and signals itself.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::sync::Arc;

use vworks_model::builtin;
use vworks_vm::machine::{Event, EventKind, Next, Vm, VmConfig};

fn vm(src: &str, robot: &str, cfg: VmConfig) -> Vm {
    let out = vworks_wslc::compile("t.wsl", src).unwrap_or_else(|e| panic!("{e}"));
    let m = Arc::new(out.module);
    let entry = m.proc_index("main").unwrap();
    Vm::new(m, Arc::new(builtin::load(robot).unwrap()), cfg, entry)
}

/// Runs the VM alone until it ends or blocks; sets are applied to its own globals.
fn run(vm: &mut Vm) -> Vec<Event> {
    let mut events = Vec::new();
    for _ in 0..10_000 {
        match vm.next_event() {
            Next::Event(e) => {
                events.push(e.clone());
                vm.perform();
                if let EventKind::Set { .. } = e.kind {
                    // A lone VM: its own set may release its own wait.
                    vm.check_wait(e.time);
                }
            }
            Next::Blocked | Next::Done => break,
        }
    }
    events
}

fn kinds(ev: &[Event]) -> Vec<&'static str> {
    ev.iter().map(|e| e.kind.name()).collect()
}

#[test]
fn one_axis_move_j_takes_the_closed_form_trapezoid_time() {
    // Turntable: 90°/s, full speed in 0.3 s. 90° takes d/v + v/a = 1 s + 0.3 s.
    let mut v = vm(
        "proc main() { move_j joints(90deg); }",
        "turntable",
        VmConfig::default(),
    );
    let ev = run(&mut v);
    assert_eq!(kinds(&ev), ["motion_start", "motion_end", "end"]);
    let EventKind::MotionStart { duration_ns, .. } = ev[0].kind else {
        panic!()
    };
    let (d, vmax) = (90f64.to_radians(), 90f64.to_radians());
    let a = vmax / 0.3;
    let exact = (d / vmax + vmax / a) * 1e9;
    assert!(
        (duration_ns as f64 - exact).abs() <= 1.0,
        "{duration_ns} vs {exact}"
    );
    assert_eq!(ev[1].time, duration_ns);
    assert!((v.joints_at(ev[1].time)[0] - d).abs() < 1e-12);
    // At 50 %: twice the cruise time, the same ramp shape scaled: d/(v/2) + (v/2)/a.
    let mut v = vm(
        "proc main() { move_j joints(90deg) speed 50%; }",
        "turntable",
        VmConfig::default(),
    );
    let ev = run(&mut v);
    let EventKind::MotionStart { duration_ns, .. } = ev[0].kind else {
        panic!()
    };
    let exact = (d / (vmax / 2.0) + (vmax / 2.0) / a) * 1e9;
    assert!(
        (duration_ns as f64 - exact).abs() <= 1.0,
        "{duration_ns} vs {exact}"
    );
}

#[test]
fn move_l_stays_on_its_line_and_ends_on_the_target() {
    let src = "
        const start = joints(0deg, 10deg, 20deg, 0deg, 60deg, 0deg);
        proc main() {
            move_j start;
            var p = current_pose();
            move_l offset(p, 100mm, -150mm, -80mm) speed 200mm/s;
        }";
    let mut v = vm(src, "irb120", VmConfig::default());
    let model = builtin::load("irb120").unwrap();
    let mut events = Vec::new();
    let mut line_to = [0.0; 3];
    let mut worst: f64 = 0.0;
    while let Next::Event(e) = v.next_event() {
        let move_l = match e.kind {
            EventKind::MotionStart {
                command: "move_l",
                duration_ns,
            } => Some(duration_ns),
            _ => None,
        };
        let line_from = v.tcp_at(e.time).t;
        v.perform();
        if let Some(duration_ns) = move_l {
            line_to = v.tcp_at(e.time + duration_ns).t;
            // Every millisecond of the motion: FK of the sampled joints lies on the line.
            let d = [
                line_to[0] - line_from[0],
                line_to[1] - line_from[1],
                line_to[2] - line_from[2],
            ];
            let len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let mut t = e.time;
            while t <= e.time + duration_ns {
                let q = v.joints_at(t);
                let p = model.flange(&q[..6]).t;
                let w = [
                    p[0] - line_from[0],
                    p[1] - line_from[1],
                    p[2] - line_from[2],
                ];
                let s = (w[0] * d[0] + w[1] * d[1] + w[2] * d[2]) / len2;
                let off = [w[0] - s * d[0], w[1] - s * d[1], w[2] - s * d[2]];
                worst = worst.max((off[0] * off[0] + off[1] * off[1] + off[2] * off[2]).sqrt());
                t += 1_000_000;
            }
        }
        events.push(e);
    }
    assert_eq!(
        kinds(&events),
        [
            "motion_start",
            "motion_end",
            "motion_start",
            "motion_end",
            "end"
        ]
    );
    assert!(worst < 1e-6, "the TCP left the line by {worst} m");
    // The pose at motion_end is the target, to 1e-9.
    let end = model.flange(&v.joints_at(events[3].time)[..6]);
    let err = ((end.t[0] - line_to[0]).powi(2)
        + (end.t[1] - line_to[1]).powi(2)
        + (end.t[2] - line_to[2]).powi(2))
    .sqrt();
    assert!(err < 1e-9, "end pose off by {err}");
    // 0.2 m/s over |(0.1, -0.15, -0.08)| = 0.197 m, plus the 0.3 s ramp.
    let len = (0.1f64 * 0.1 + 0.15 * 0.15 + 0.08 * 0.08).sqrt();
    let EventKind::MotionStart { duration_ns, .. } = events[2].kind else {
        panic!()
    };
    assert!(
        ((duration_ns as f64) / 1e9 - (len / 0.2 + 0.3)).abs() < 1e-9,
        "{duration_ns}"
    );
}

#[test]
fn an_endless_loop_is_an_error_at_its_line() {
    let src = "proc main() {\n    var n = 0;\n    while true {\n        n = n + 1;\n    }\n}\n";
    let mut v = vm(
        src,
        "irb120",
        VmConfig {
            budget: 100_000,
            ..VmConfig::default()
        },
    );
    let ev = run(&mut v);
    let last = ev.last().unwrap();
    let EventKind::Error { message } = &last.kind else {
        panic!("{ev:?}")
    };
    assert!(message.contains("endless zero-time loop"), "{message}");
    assert!(
        (3..=4).contains(&last.pos.line),
        "at line {}",
        last.pos.line
    );
}

#[test]
fn deep_recursion_is_an_error_at_the_call() {
    let src = "proc down(n: int) {\n    down(n + 1);\n}\nproc main() { down(0); }\n";
    let mut v = vm(src, "irb120", VmConfig::default());
    let ev = run(&mut v);
    let last = ev.last().unwrap();
    let EventKind::Error { message } = &last.kind else {
        panic!("{ev:?}")
    };
    assert!(message.contains("nested more than 256"), "{message}");
    assert_eq!(last.pos.line, 2);
}

#[test]
fn statements_produce_their_events() {
    let src = r#"
        global parts = 0;
        var count = 0;
        proc main() {
            log "start ", 250mm/s, " ", 90deg;
            parts = parts + 2;
            wait_until parts >= 2;
            delay 0.5s;
            wait_until parts >= 10 timeout 1s;
            if timed_out() { log "timed out at ", now(); }
            grip part1;
            release part1;
            signal r2.ready;
            count += 1;
            if count == 1 { stop; }
            log "never";
        }"#;
    let mut v = vm(src, "irb120", VmConfig::default());
    let ev = run(&mut v);
    assert_eq!(
        kinds(&ev),
        [
            "log",
            "set",
            "wait_until",
            "wait_end",
            "delay",
            "delay_end",
            "wait_until",
            "wait_end",
            "log",
            "grip",
            "release",
            "signal",
            "end"
        ]
    );
    let EventKind::Log { text } = &ev[0].kind else {
        panic!()
    };
    assert_eq!(text, "start 250mm/s 90deg");
    assert_eq!(ev[7].time, 1_500_000_000);
    let EventKind::Log { text } = &ev[8].kind else {
        panic!()
    };
    assert_eq!(text, "timed out at 1.5s");
}

#[test]
fn a_wait_for_a_signal_blocks_until_it_arrives() {
    let mut v = vm(
        "proc main() { wait_signal go; log \"went\"; }",
        "irb120",
        VmConfig::default(),
    );
    let ev = run(&mut v);
    assert_eq!(kinds(&ev), ["wait_until"]);
    assert_eq!(v.next_event(), Next::Blocked);
    assert!(v.deliver_signal("go", 7_000));
    let ev = run(&mut v);
    assert_eq!(kinds(&ev), ["wait_end", "log", "end"]);
    assert_eq!(ev[0].time, 7_000);
}

//! One VM driven by a small harness that plays the simulation engine: it takes the VM's
//! next event, records it, performs it, and answers sets, waits and signals itself.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::sync::Arc;

use vworks_model::builtin;
use vworks_vm::machine::{Event, EventKind, Next, Vm, VmConfig, WarningKind};

fn vm(src: &str, robot: &str, cfg: VmConfig) -> Vm {
    let out = vworks_wslc::compile("t.wsl", src).unwrap_or_else(|e| panic!("{e}"));
    let m = Arc::new(out.module);
    let entry = m.proc_index("main").unwrap();
    Vm::new(m, Arc::new(builtin::load(robot).unwrap()), cfg, Some(entry))
}

/// Runs the VM alone until it ends or blocks; sets are applied to its own globals.
fn run(vm: &mut Vm) -> Vec<Event> {
    let mut events = Vec::new();
    for _ in 0..100_000 {
        match vm.next_event() {
            Next::Event(e) => {
                events.push(e.clone());
                vm.perform();
                if let EventKind::Set { .. } = e.kind {
                    // A lone VM: its own set may release its own wait or fire its handlers.
                    vm.check_wait(e.time);
                    vm.check_when(e.time);
                }
            }
            Next::Blocked | Next::Done | Next::Idle => break,
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
            move_l offset(p, 100mm, -150mm, -80mm) speed 200mm/s accel 1m/s2;
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
                ..
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
    // 0.2 m/s over |(0.1, -0.15, -0.08)| = 0.197 m, plus the ramp to 0.2 m/s at 1 m/s²
    // (0.2 s; no axis comes near its limits at that).
    let len = (0.1f64 * 0.1 + 0.15 * 0.15 + 0.08 * 0.08).sqrt();
    let EventKind::MotionStart { duration_ns, .. } = events[2].kind else {
        panic!()
    };
    assert!(
        ((duration_ns as f64) / 1e9 - (len / 0.2 + 0.2)).abs() < 1e-9,
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

fn logs(ev: &[Event]) -> Vec<(i64, String)> {
    ev.iter()
        .filter_map(|e| match &e.kind {
            EventKind::Log { text } => Some((e.time, text.clone())),
            _ => None,
        })
        .collect()
}

#[test]
fn handlers_fire_by_cycles_by_time_once_and_on_edges() {
    let src = r#"
        global parts = 0;
        var ticks = 0;
        proc tick() { ticks += 1; }
        proc sample() { log "sample ", now(); }
        proc alarm() { log "alarm ", now(); }
        proc report(n: int) { log "report ", n; }
        proc main() {
            when every 10 cycles do tick();
            when every 100ms do sample();
            when after 250ms do alarm();
            when parts >= 2 do report(parts);
            delay 0.3s;
            parts = 1;
            parts = 2;
            parts = 3;
            disable tick;
            log "ticks ", ticks;
        }"#;
    let mut v = vm(src, "irb120", VmConfig::default());
    let ev = run(&mut v);
    let ms = 1_000_000;
    assert_eq!(
        logs(&ev),
        [
            (100 * ms, "sample 0.1s".to_string()),
            (200 * ms, "sample 0.2s".to_string()),
            (250 * ms, "alarm 0.25s".to_string()),
            (300 * ms, "sample 0.3s".to_string()),
            (300 * ms, "report 2".to_string()),
            (300 * ms, "ticks 7".to_string()),
        ]
    );
    // Every 10 cycles of 4 ms: 40, 80, …, 280 ms; every fire has its end.
    let fires = ev
        .iter()
        .filter(|e| matches!(e.kind, EventKind::WhenFire { .. }))
        .count();
    let ends = ev
        .iter()
        .filter(|e| matches!(e.kind, EventKind::WhenEnd { .. }))
        .count();
    assert_eq!(fires, 7 + 3 + 1 + 1);
    assert_eq!(ends, fires);
    assert_eq!(
        ev.iter().filter(|e| e.kind.name() == "enable_when").count(),
        4
    );
}

#[test]
fn a_handler_runs_while_the_motion_goes_on() {
    let src = r#"
        proc mark() { log "mark ", now(); }
        proc main() {
            when after 0.5s do mark();
            move_j joints(90deg);
            log "arrived ", now();
        }"#;
    let mut v = vm(src, "turntable", VmConfig::default());
    let ev = run(&mut v);
    assert_eq!(
        logs(&ev),
        [
            (500_000_000, "mark 0.5s".into()),
            (1_300_000_000, "arrived 1.3s".into())
        ]
    );
    assert_eq!(
        kinds(&ev),
        [
            "enable_when",
            "motion_start",
            "when_fire",
            "log",
            "when_end",
            "motion_end",
            "log",
            "end"
        ]
    );
}

#[test]
fn a_handler_that_takes_time_is_a_runtime_error() {
    // The compiler rejects this; bytecode from elsewhere is caught by the VM.
    let out = vworks_wslc::compile(
        "t.wsl",
        "proc h() { log \"x\"; log \"y\"; }\nproc main() { when every 1 cycles do h(); delay 1s; }",
    )
    .unwrap();
    let mut m = out.module;
    let h = m.proc_index("h").unwrap() as usize;
    let at = m.procs[h].code_start as usize;
    m.code[at] = vworks_vm::Instr::PushNum(1.0);
    m.code[at + 1] = vworks_vm::Instr::Delay;
    m.verify().unwrap();
    let entry = m.proc_index("main");
    let mut v = Vm::new(
        Arc::new(m),
        Arc::new(builtin::load("irb120").unwrap()),
        VmConfig::default(),
        entry,
    );
    let ev = run(&mut v);
    let EventKind::Error { message } = &ev.last().unwrap().kind else {
        panic!("{ev:?}")
    };
    assert!(message.contains("zero time"), "{message}");
}

/// Plays the SE for several VMs: earliest event first (ties by robot order), routing
/// sets, signals and remote requests.
fn run_cell(vms: &mut [Vm], names: &[&str]) -> Vec<(usize, Event)> {
    let mut serving: Vec<std::collections::VecDeque<(usize, u64)>> =
        vec![Default::default(); vms.len()];
    let mut out = Vec::new();
    for _ in 0..100_000 {
        let mut best: Option<(i64, usize)> = None;
        for (i, v) in vms.iter_mut().enumerate() {
            if let Next::Event(e) = v.next_event()
                && best.is_none_or(|(t, _)| e.time < t)
            {
                best = Some((e.time, i));
            }
        }
        let Some((_, i)) = best else { break };
        let Next::Event(e) = vms[i].next_event() else {
            unreachable!()
        };
        vms[i].perform();
        match &e.kind {
            EventKind::RemoteCall { site, req, args } => {
                let m = vms[i].module();
                let (robot, proc) = (
                    m.str(m.remotes[*site as usize].robot).to_string(),
                    m.str(m.remotes[*site as usize].proc).to_string(),
                );
                let t = names.iter().position(|n| *n == robot).unwrap();
                let p = vms[t].module().proc_index(&proc).unwrap();
                vms[t].request_remote(p, args.clone(), e.time);
                serving[t].push_back((i, *req));
            }
            EventKind::RemoteEnd { .. } => {
                let (caller, req) = serving[i].pop_front().unwrap();
                vms[caller].remote_done(req, e.time);
            }
            EventKind::Set { global, value, .. } => {
                let m = vms[i].module();
                let name = m.str(m.globals[*global as usize].name).to_string();
                for v in vms.iter_mut() {
                    if let Some(g) = v.module().global_index(&name) {
                        v.set_global(g, *value);
                        v.check_wait(e.time);
                        v.check_when(e.time);
                    }
                }
            }
            EventKind::Signal { site } => {
                let m = vms[i].module();
                let s = &m.signals_sent[*site as usize];
                let (robot, name) = (m.str(s.robot).to_string(), m.str(s.name).to_string());
                let t = names.iter().position(|n| *n == robot).unwrap();
                vms[t].deliver_signal(&name, e.time);
            }
            _ => {}
        }
        out.push((i, e));
    }
    out
}

#[test]
fn parallel_waits_for_remote_work_served_when_the_robot_is_idle() {
    let r1 = r#"
        proc main() {
            parallel {
                remote r2.weld(2, 100mm);
                { delay 0.5s; }
            }
            log "joined at ", now();
            signal r2.done;
        }"#;
    let r2 = r#"
        proc main() { delay 0.2s; log "r2 main done"; }
        proc weld(n: int, len: length) { delay len / 100mm/s; log "welded ", n, " at ", now(); }
        proc never() { wait_signal done; }"#;
    let mut vms = vec![
        vm(
            r1,
            "irb120",
            VmConfig {
                robot: 0,
                ..VmConfig::default()
            },
        ),
        vm(
            r2,
            "irb120",
            VmConfig {
                robot: 1,
                ..VmConfig::default()
            },
        ),
    ];
    let ev = run_cell(&mut vms, &["r1", "r2"]);
    assert!(
        ev.iter().all(|(i, e)| e.robot as usize == *i),
        "every event names its robot"
    );
    let logs: Vec<(usize, String)> = ev
        .iter()
        .filter_map(|(i, e)| match &e.kind {
            EventKind::Log { text } => Some((*i, text.clone())),
            _ => None,
        })
        .collect();
    assert_eq!(
        logs,
        [
            (1, "r2 main done".into()),
            (1, "welded 2 at 1.2s".into()),
            (0, "joined at 1.2s".into())
        ]
    );
    let trace: Vec<(usize, &str)> = ev.iter().map(|(i, e)| (*i, e.kind.name())).collect();
    assert!(
        trace.contains(&(0, "remote_call"))
            && trace.contains(&(1, "remote_start"))
            && trace.contains(&(1, "remote_end"))
            && trace.contains(&(0, "join"))
    );
}

#[test]
fn move_c_follows_its_arc_to_the_target() {
    let src = "
        const start = joints(0deg, 10deg, 20deg, 0deg, 60deg, 0deg);
        proc main() {
            move_j start;
            var p = current_pose();
            move_c offset(p, 50mm, 50mm, 0mm), offset(p, 100mm, 0mm, 0mm) speed 100mm/s;
        }";
    let mut v = vm(src, "irb120", VmConfig::default());
    let model = builtin::load("irb120").unwrap();
    let mut start = [0.0; 3];
    let mut ev = Vec::new();
    while let Next::Event(e) = v.next_event() {
        if let EventKind::MotionStart {
            command: "move_c", ..
        } = e.kind
        {
            start = v.tcp_at(e.time).t;
        }
        ev.push(e);
        v.perform();
    }
    assert_eq!(
        kinds(&ev),
        [
            "motion_start",
            "motion_end",
            "motion_start",
            "motion_end",
            "end"
        ]
    );
    // Radius 50 mm around (start.x + 50, start.y): every sample at that distance.
    let (t0, t1) = (ev[2].time, ev[3].time);
    let center = [start[0] + 0.05, start[1], start[2]];
    let mut t = t0;
    while t <= t1 {
        let p = model.flange(&v.joints_at(t)[..6]).t;
        let r =
            ((p[0] - center[0]).powi(2) + (p[1] - center[1]).powi(2) + (p[2] - center[2]).powi(2))
                .sqrt();
        assert!(
            (r - 0.05).abs() < 1e-6,
            "off the arc by {} at {t}",
            r - 0.05
        );
        t += 2_000_000;
    }
    let end = model.flange(&v.joints_at(t1)[..6]).t;
    assert!(((end[0] - start[0] - 0.1).powi(2) + (end[1] - start[1]).powi(2)).sqrt() < 1e-9);
}

#[test]
fn limits_reach_and_speed_are_checked() {
    // Axis 3 of the IRB 120 stops at +70°.
    let mut v = vm(
        "proc main() { move_j joints(0deg, 0deg, 100deg, 0deg, 0deg, 0deg); }",
        "irb120",
        VmConfig::default(),
    );
    let ev = run(&mut v);
    let EventKind::Error { message } = &ev[0].kind else {
        panic!("{ev:?}")
    };
    assert!(
        message.contains("joint limit exceeded: axis 3"),
        "{message}"
    );
    // Three metres away.
    let mut v = vm(
        "proc main() { move_l pose(3000mm, 0mm, 300mm, 180deg, 0deg, 0deg); }",
        "irb120",
        VmConfig::default(),
    );
    let ev = run(&mut v);
    let EventKind::Error { message } = &ev[0].kind else {
        panic!("{ev:?}")
    };
    assert!(
        message.contains("unreachable pose") && message.contains("out of reach"),
        "{message}"
    );
    // Passing close to axis 1 at 2 m/s would spin axis 1 beyond 250°/s: slowed, with a warning.
    let src = "proc main() {
        move_j pose(300mm, -80mm, 400mm, 180deg, 0deg, 0deg);
        move_l pose(300mm, 80mm, 400mm, 180deg, 0deg, 0deg) speed 2000mm/s;
    }";
    let mut v = vm(src, "irb120", VmConfig::default());
    let ev = run(&mut v);
    assert_eq!(
        kinds(&ev),
        [
            "motion_start",
            "motion_end",
            "motion_start",
            "motion_end",
            "end"
        ]
    );
    let w = v.take_warnings();
    assert!(
        w.iter().any(|w| w
            .message
            .contains("slows the TCP below its programmed speed")
            && w.pos.line == 3
            && w.kind == WarningKind::Slowdown),
        "{w:?}"
    );
    // The same line back and forth three times: one warning for each statement, at its
    // first execution (a loop repeats it every round).
    let src = "proc main() {
        var i = 0;
        while i < 3 {
            move_j pose(300mm, -80mm, 400mm, 180deg, 0deg, 0deg);
            move_l pose(300mm, 80mm, 400mm, 180deg, 0deg, 0deg) speed 2000mm/s;
            i = i + 1;
        }
    }";
    let mut v = vm(src, "irb120", VmConfig::default());
    let ev = run(&mut v);
    assert_eq!(ev.len(), 13, "{ev:?}");
    let w = v.take_warnings();
    let slowed: Vec<_> = w
        .iter()
        .filter(|w| w.kind == WarningKind::Slowdown)
        .collect();
    assert_eq!(slowed.len(), 1, "{w:?}");
    assert_eq!(slowed[0].pos.line, 5);
    assert_eq!(slowed[0].time, ev[2].time, "{w:?}");
    // Where only the axes' accelerations bind (the IRB 120 cannot give this line its TCP's
    // 28 m/s² at the start), the motion accelerates as fast as the axes let it, slower
    // than 28 m/s² would, and that is its dynamics, not a slowdown: no warning.
    let src = "proc main() {
        move_j pose(450mm, -200mm, 140mm, 180deg, 0deg, 0deg);
        move_l pose(450mm, -200mm, 40mm, 180deg, 0deg, 0deg) speed 100mm/s;
    }";
    let mut v = vm(src, "irb120", VmConfig::default());
    let ev = run(&mut v);
    let EventKind::MotionStart { duration_ns, .. } = ev[2].kind else {
        panic!("{ev:?}")
    };
    // 100 mm at 100 mm/s: longer than at 28 m/s² (1 + 0.1/28 s), and by little.
    let secs = duration_ns as f64 / 1e9;
    assert!(secs > 1.0 + 0.1 / 28.0 && secs < 1.01, "{secs}");
    let w = v.take_warnings();
    assert!(w.is_empty(), "{w:?}");
}

/// Replaces the identifiers a, b, x, y, q, l, p by their constant twins (a_c, …).
fn rename_vars(e: &str) -> String {
    let mut out = String::new();
    let mut word = String::new();
    // A field name after `.` is not a variable.
    let flush = |word: &mut String, out: &mut String| {
        if !out.ends_with('.') && ["a", "b", "x", "y", "q", "l", "p"].contains(&word.as_str()) {
            word.push_str("_c");
        }
        out.push_str(word);
        word.clear();
    };
    for ch in e.chars() {
        if ch.is_ascii_alphanumeric() || ch == '_' {
            word.push(ch);
        } else {
            flush(&mut word, &mut out);
            out.push(ch);
        }
    }
    flush(&mut word, &mut out);
    out
}

/// The interpreter agrees with the compiler's constant folder: each expression is logged
/// once folded at compile time (from constants) and once computed at run time (from
/// module variables, which the compiler cannot fold).
#[test]
fn runtime_arithmetic_equals_constant_folding() {
    let exprs = [
        "a + b * 3 - 7",
        "a / b",
        "a mod b",
        "-a mod b",
        "abs(-a) + min(a, b) * max(a, b)",
        "x * y / 4.5 - x",
        "sqrt(x * x + y * y)",
        "atan2(y, x)",
        "sin(q) + cos(q)",
        "int(x * 10.7)",
        "num(a) * 0.5",
        "x > y and not (a == b) or false",
        "offset(p, 10mm, -5mm, 1mm).z",
        "tool_offset(p, 10mm, 20mm, 30mm).x",
        "tool_offset(p, 10mm, 20mm, 30mm).y",
        "joints(q, q * 2, 0deg)[1]",
        "l * 2 + 3mm",
        "l / 2s",
    ];
    let mut src = String::from(
        "const a_c = 17;\nconst b_c = 5;\nconst x_c = 2.5;\nconst y_c = -1.25;\nconst q_c = 30deg;\nconst l_c = 120mm;\nconst p_c = pose(400mm, -100mm, 300mm, 180deg, 10deg, 30deg);\n",
    );
    src.push_str("var a = a_c;\nvar b = b_c;\nvar x = x_c;\nvar y = y_c;\nvar q = q_c;\nvar l = l_c;\nvar p = p_c;\n");
    for (i, e) in exprs.iter().enumerate() {
        let folded = rename_vars(e);
        src.push_str(&format!("const k{i} = {folded};\n"));
    }
    src.push_str("proc main() {\n");
    for (i, e) in exprs.iter().enumerate() {
        src.push_str(&format!("    log k{i}, \" \", {e};\n"));
    }
    src.push_str("}\n");
    let out = vworks_wslc::compile("fold.wsl", &src);
    let out = out.unwrap_or_else(|e| panic!("{e}\n{src}"));
    let m = Arc::new(out.module);
    let entry = m.proc_index("main");
    let mut v = Vm::new(
        m,
        Arc::new(builtin::load("irb120").unwrap()),
        VmConfig::default(),
        entry,
    );
    let ev = run(&mut v);
    let l = logs(&ev);
    assert_eq!(l.len(), exprs.len(), "{ev:?}");
    for ((_, text), e) in l.iter().zip(exprs) {
        let (folded, computed) = text.split_once(' ').unwrap();
        assert_eq!(folded, computed, "{e}");
    }
}

#[test]
fn runtime_errors_name_their_line() {
    let cases = [
        ("var z = 0;\n    var n = 10 / z;", "division by zero", 3),
        (
            "var j = current_joints();\n    var k = 9;\n    var v = j[k];",
            "joint index 9 is out of range",
            4,
        ),
        (
            "var x = -1.0;\n    var r = sqrt(x);",
            "square root of a negative",
            3,
        ),
        ("fail \"gripper empty: \", 3;", "gripper empty: 3", 2),
    ];
    for (body, msg, line) in cases {
        let src = format!("proc main() {{\n    {body}\n}}\n");
        let mut v = vm(&src, "irb120", VmConfig::default());
        let ev = run(&mut v);
        let last = ev.last().unwrap();
        let EventKind::Error { message } = &last.kind else {
            panic!("{src}: {ev:?}")
        };
        assert!(message.contains(msg), "{src}: {message}");
        assert_eq!(last.pos.line, line, "{src}");
    }
}

#[test]
fn control_flow_calls_and_components_run_as_written() {
    let src = r#"
        var primes = 0;
        func fact(n: int) -> int { if n <= 1 { return 1; } return n * fact(n - 1); }
        func is_prime(n: int) -> bool {
            if n < 2 { return false; }
            var d = 2;
            while d * d <= n {
                if n mod d == 0 { return false; }
                d += 1;
            }
            return true;
        }
        proc count(limit: int) {
            for i in 0..limit {
                if not is_prime(i) { continue; }
                if i > 50 { break; }
                primes += 1;
            }
        }
        proc main() {
            count(1000);
            var p = pose(1mm, 2mm, 3mm, 0deg, 0deg, 0deg);
            p.z = p.z * 10;
            p.rz += 45deg;
            var j = joints(0deg, 10deg, 20deg, 30deg, 40deg, 50deg);
            j[5] = j[5] - 50deg;
            j[0] += 1deg;
            log primes, " ", fact(10), " ", p.z, " ", p.rz, " ", j[0], " ", j[5], " ", j;
        }"#;
    let mut v = vm(src, "irb120", VmConfig::default());
    let ev = run(&mut v);
    assert_eq!(
        logs(&ev),
        [(
            0,
            "15 3628800 30mm 45deg 1deg 0deg joints(1deg, 10deg, 20deg, 30deg, 40deg, 0deg)"
                .to_string()
        )]
    );
}

#[test]
fn signal_timeouts_and_the_cycle_count() {
    let src = r#"
        proc main() {
            wait_signal go timeout 0.25s;
            log timed_out(), " ", now(), " ", cycle();
            delay 1s;
            wait_signal go timeout 2s;
            log timed_out(), " ", now(), " ", cycle();
        }"#;
    let mut v = vm(
        src,
        "irb120",
        VmConfig {
            cycle_ns: 4_000_000,
            ..VmConfig::default()
        },
    );
    let mut ev = Vec::new();
    while let Next::Event(e) = v.next_event() {
        v.perform();
        let is_delay = matches!(e.kind, EventKind::Delay { .. });
        ev.push(e);
        if is_delay {
            // A signal sent during the delay is counted, then consumed at once by the wait.
            assert!(!v.deliver_signal("go", 500_000_000));
        }
    }
    assert_eq!(
        logs(&ev),
        [
            (250_000_000, "true 0.25s 62".to_string()),
            (1_250_000_000, "false 1.25s 312".to_string())
        ]
    );
}

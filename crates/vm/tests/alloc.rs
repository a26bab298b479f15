//! Motions allocate nothing: planning (`move_j` to a pose, `move_l` to joints and poses,
//! `move_c`), zones and corners, and sampling the robot, once the VM is built. Counted
//! by a global allocator that counts (`stats_alloc`).

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::alloc::System;
use std::sync::Arc;

use stats_alloc::{INSTRUMENTED_SYSTEM, Region, StatsAlloc};
use vworks_model::builtin;
use vworks_vm::machine::{EventKind, Next, Vm, VmConfig};

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

/// Performs `n` events of `vm` (it must not end or block before), sampling the robot at
/// each; returns how many were motion starts.
fn perform(vm: &mut Vm, n: usize) -> usize {
    let mut starts = 0;
    for _ in 0..n {
        let Next::Event(e) = vm.next_event() else {
            panic!("the program ended or blocked: {:?}", vm.take_warnings());
        };
        if let EventKind::Error { message } = &e.kind {
            panic!("{message}");
        }
        if let EventKind::MotionStart { .. } = e.kind {
            starts += 1;
        }
        // Every way of sampling the robot, as the engine does each cycle.
        std::hint::black_box((
            vm.joints_at(e.time),
            vm.tcp_at(e.time),
            vm.axis_rate_bounds(),
            vm.moving_at(e.time),
        ));
        vm.perform();
    }
    starts
}

/// The counts are process-wide: one test, so that no other test allocates meanwhile.
#[test]
fn planning_and_running_motions_allocates_nothing() {
    let src = "
        const home = joints(0deg, -30deg, 30deg, 0deg, 60deg, 0deg);
        const side = joints(20deg, -20deg, 35deg, 10deg, 50deg, 5deg);
        proc main() {
            move_j home;
            var p = current_pose();
            while true {
                move_j offset(p, 0mm, 40mm, 0mm) speed 50%;
                move_l side speed 200mm/s zone 10mm;
                move_l offset(p, 60mm, 0mm, 0mm) speed 150mm/s zone 5mm;
                move_c offset(p, 45mm, 45mm, 0mm), offset(p, 0mm, 60mm, 0mm) speed 100mm/s;
                move_l p duration 0.5s;
                move_j home zone 20mm;
            }
        }";
    let out = vworks_wslc::compile("t.wsl", src).unwrap_or_else(|e| panic!("{e}"));
    let m = Arc::new(out.module);
    let entry = m.proc_index("main").unwrap();
    let model = Arc::new(builtin::load("irb120").unwrap());
    let mut vm = Vm::new(m, model, VmConfig::default(), Some(entry));
    // Warm up: the first rounds (the thread's scratch sized, every path sampled once).
    perform(&mut vm, 200);
    let warnings = vm.take_warnings();
    let region = Region::new(GLOBAL);
    let starts = perform(&mut vm, 2_000);
    let change = region.change();
    assert!(starts > 500, "{starts} motions");
    assert_eq!(
        change.allocations + change.reallocations,
        0,
        "{starts} motions: {change:?} (warnings in the warm-up: {warnings:?})"
    );
}

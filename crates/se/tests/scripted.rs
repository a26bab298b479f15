//! The collider driven by scripted robots (its `RobotPoses` trait, no VM): the crash
//! cell's two arms, moved along a straight line in joint space from their home into each
//! other's space, touch; the boundary checks and the sweep between boundaries agree on
//! when; standing still, they never touch.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // tests fail by panicking

use std::path::Path;

use vworks_model::math::Iso;
use vworks_se::{Collider, CollisionEvent, RobotPoses, SWEEP_MIN_STEP_NS};
use vworks_vm::MAX_AXES;

/// A robot moving its joints from `from` to `to` at constant speed over `[start, end]`
/// (ns), standing still before and after.
struct Scripted {
    from: [f64; MAX_AXES],
    to: [f64; MAX_AXES],
    start: i64,
    end: i64,
}

impl Scripted {
    fn degrees(from: [f64; 6], to: [f64; 6], start: i64, end: i64) -> Scripted {
        let mut s = Scripted {
            from: [0.0; MAX_AXES],
            to: [0.0; MAX_AXES],
            start,
            end,
        };
        for k in 0..6 {
            s.from[k] = from[k].to_radians();
            s.to[k] = to[k].to_radians();
        }
        s
    }
}

impl RobotPoses for Scripted {
    fn joints_at(&self, t: i64) -> [f64; MAX_AXES] {
        let f = ((t - self.start) as f64 / (self.end - self.start) as f64).clamp(0.0, 1.0);
        let mut q = self.from;
        for (k, x) in q.iter_mut().enumerate() {
            *x += f * (self.to[k] - self.from[k]);
        }
        q
    }

    fn moving_at(&self, t: i64) -> bool {
        self.from != self.to && self.start < t && t < self.end
    }

    fn axis_rate_bounds(&self) -> [f64; MAX_AXES] {
        let secs = (self.end - self.start) as f64 / 1e9;
        let mut rates = [0.0; MAX_AXES];
        for (k, r) in rates.iter_mut().enumerate() {
            *r = (self.to[k] - self.from[k]).abs() / secs;
        }
        rates
    }

    fn tool_at(&self, _t: i64) -> Iso {
        Iso::IDENTITY
    }
}

const HOME: [f64; 6] = [0.0, -30.0, 30.0, 0.0, 60.0, 0.0];
const REACH: [f64; 6] = [0.0, 60.0, -30.0, 0.0, 30.0, 0.0];
const CYCLE: i64 = 4_000_000;
const SECOND: i64 = 1_000_000_000;

fn crash_cell() -> vworks_cell::Cell {
    let cell = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../workcells/crash/cell.toml");
    vworks_cell::load(&cell).unwrap()
}

/// The first boundary (every 4 ms up to 1 s) at which a contact starts, and its bodies.
fn first_boundary_contact(
    cell: &vworks_cell::Cell,
    robots: &[Scripted],
) -> Option<(i64, String, String)> {
    let mut collider = Collider::new(cell);
    for b in (0..=SECOND).step_by(CYCLE as usize) {
        let moving: Vec<bool> = robots.iter().map(|r| r.moving_at(b)).collect();
        for event in collider.check(cell, robots, b, &moving) {
            if let CollisionEvent::Start(c) = event {
                return Some((b, c.a, c.b));
            }
        }
    }
    None
}

#[test]
fn scripted_arms_reaching_into_each_other_touch_and_the_sweep_finds_it_first() {
    let cell = crash_cell();
    let robots = [
        Scripted::degrees(HOME, REACH, 0, SECOND),
        Scripted::degrees(HOME, REACH, 0, SECOND),
    ];
    let (at, a, b) = first_boundary_contact(&cell, &robots).expect("the arms touch");
    assert!(0 < at && at < SECOND, "first contact at {at} ns");
    assert!(
        a.starts_with("left.") && b.starts_with("right."),
        "{a} and {b}"
    );
    // The sweep from the start: the same pair, no later than that boundary and no earlier
    // than the boundary before it (less one minimum step, which it may be late by).
    let mut collider = Collider::new(&cell);
    collider.check(&cell, &robots, 0, &[false, false]);
    let contacts = collider.sweep(&cell, &robots, 0, SECOND);
    let first = contacts.first().expect("the sweep finds the contact");
    assert_eq!((&first.a, &first.b), (&a, &b));
    assert!(
        first.time_ns <= at && first.time_ns > at - CYCLE - SWEEP_MIN_STEP_NS,
        "swept contact at {} ns, boundary contact at {at} ns",
        first.time_ns
    );
}

#[test]
fn scripted_arms_standing_at_home_never_touch() {
    let cell = crash_cell();
    let robots = [
        Scripted::degrees(HOME, HOME, 0, SECOND),
        Scripted::degrees(HOME, HOME, 0, SECOND),
    ];
    assert_eq!(first_boundary_contact(&cell, &robots), None);
    let mut collider = Collider::new(&cell);
    collider.check(&cell, &robots, 0, &[false, false]);
    assert!(collider.sweep(&cell, &robots, 0, SECOND).is_empty());
}

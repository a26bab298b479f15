//! Timings computed by hand (trapezoids where one limit binds all along) and the
//! properties every timing keeps: every limit at every knot, rest at both ends, time
//! scaling with the limits, never slower when a limit loosens.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use super::*;

const BIG: f64 = 1e12;

/// A path whose axes are functions of s.
pub(super) fn path(axes: usize, f: impl Fn(f64, usize) -> f64) -> JointPath {
    let mut p = JointPath::new(axes);
    for k in 0..KNOTS {
        let s = k as f64 / SEGMENTS as f64;
        for i in 0..axes {
            p.q[k][i] = f(s, i);
        }
    }
    p
}

/// The exact time of a rest-to-rest move of `d` at speed `v` and acceleration `a`.
fn trapezoid(d: f64, v: f64, a: f64) -> f64 {
    if d * a >= v * v {
        d / v + v / a
    } else {
        2.0 * (d / a).sqrt()
    }
}

pub(super) fn limits<'a>(speed: &'a [f64], accel: &'a [f64], ps: f64, pa: f64) -> Limits<'a> {
    Limits {
        axis_speed: speed,
        axis_accel: accel,
        path_speed: ps,
        path_accel: pa,
        path_normal: 0.0,
        path_whole: f64::INFINITY,
        along: None,
    }
}

/// Every limit holds at both ends of every step with that step's u (to 1e-12 relative);
/// rest at both ends; times increase.
fn assert_within(p: &JointPath, lim: &Limits<'_>, t: &Timing) {
    assert_eq!(t.x[0], 0.0);
    assert_eq!(t.x[SEGMENTS], 0.0);
    for k in 0..SEGMENTS {
        let delta = p.step(k);
        assert!(t.t[k + 1] > t.t[k], "time stands at step {k}");
        let u = (t.x[k + 1] - t.x[k]) / (2.0 * delta);
        assert!(
            u.abs() <= lim.path_accel * (1.0 + 1e-12),
            "path accel {u} at {k}"
        );
        for end in [k, k + 1] {
            let x = t.x[end];
            assert!(x.sqrt() <= lim.path_speed * (1.0 + 1e-12));
            for i in 0..p.axes {
                let (d1, d2) = p.derivatives(end, i);
                let v = d1.abs() * x.sqrt();
                let a = (d1 * u + d2 * x).abs();
                assert!(
                    v <= lim.axis_speed[i] * (1.0 + 1e-12),
                    "axis {i} speed {v} at {end}"
                );
                assert!(
                    a <= lim.axis_accel[i] * (1.0 + 1e-9) + 1e-12,
                    "axis {i} accel {a} at {end} (step {k})"
                );
            }
        }
    }
}

/// One axis whose slope grows twentyfold towards the end of the path, as near a
/// singularity: q = −ln(1 − 0.95·s). Whatever the path's shape, one axis alone moves as
/// its own trapezoid in q: 2.9957 rad at 2 rad/s and 5 rad/s² take 2.9957/2 + 2/5 =
/// 1.897866 s. Equal steps lose time near the end (a step's one acceleration must keep
/// the axis's at its steeper end: 0.86 %); the graded knots are finer there and within
/// 0.4 %.
#[test]
fn graded_knots_follow_a_slope_that_grows_fast() {
    let q = |s: f64, _: usize| -(1.0 - 0.95 * s).ln();
    let exact = trapezoid(q(1.0, 0), 2.0, 5.0);
    assert!((exact - 1.897866).abs() < 1e-6, "{exact}");
    let lim = limits(&[2.0], &[5.0], BIG, BIG);
    let equal = path(1, q);
    let uniform = Timing::optimal(&equal, &lim).unwrap();
    let knots = equal.grade().expect("a slope growing 20× grades the path");
    assert!(knots.windows(2).all(|w| w[1] > w[0]) && knots[0] == 0.0 && knots[SEGMENTS] == 1.0);
    // Finer at the end than at the start, and neighbours within about GRADE_GROWTH (a
    // knot's step can straddle two of the densities).
    let mut graded = JointPath::new(1);
    graded.set_knots(&knots);
    assert!(graded.step(SEGMENTS - 1) < 0.5 * graded.step(0));
    for k in 1..SEGMENTS {
        let r = graded.step(k) / graded.step(k - 1);
        assert!((1.0 / 1.2..=1.2).contains(&r), "{k}: {r}");
    }
    for (k, row) in graded.q.iter_mut().enumerate() {
        row[0] = q(knots[k], 0);
    }
    let fine = Timing::optimal(&graded, &lim).unwrap();
    assert_within(&graded, &lim, &fine);
    let (u, g) = (uniform.duration() / exact, fine.duration() / exact);
    // (Measured: equal steps 1.0086, graded 1.0028.)
    assert!(u > 1.005, "equal steps {u}");
    assert!((1.0 - 1e-9..1.004).contains(&g), "graded {g}");
    // A straight line needs no grading.
    assert!(path(1, |s, _| 1.2 * s).grade().is_none());
}

#[test]
fn one_axis_in_a_straight_line_is_its_trapezoid() {
    // q = 1.2·s: the axis moves 1.2 rad at 2 rad/s and 5 rad/s²: 0.6 + 0.4 = 1.0 s.
    let p = path(1, |s, _| 1.2 * s);
    let lim = limits(&[2.0], &[5.0], BIG, BIG);
    let t = Timing::optimal(&p, &lim).unwrap();
    assert_within(&p, &lim, &t);
    let exact = trapezoid(1.2, 2.0, 5.0);
    assert!((exact - 1.0).abs() < 1e-12);
    // Never faster than the exact optimum (every step's limits hold all along a line),
    // and the steps cost little: the switch from ramp to cruise falls inside one step.
    assert!(t.duration() >= exact * (1.0 - 1e-12), "{}", t.duration());
    assert!(t.duration() <= exact * 1.002, "{}", t.duration());
    assert!((t.top_speed() * 1.2 - 2.0).abs() < 1e-9);
}

#[test]
fn a_short_move_never_reaches_full_speed() {
    // 0.1 rad at 5 rad/s² and 2 rad/s: a triangle, 2·√(0.1/5) = 0.2828 s.
    let p = path(1, |s, _| -0.1 * s);
    let lim = limits(&[2.0], &[5.0], BIG, BIG);
    let t = Timing::optimal(&p, &lim).unwrap();
    assert_within(&p, &lim, &t);
    let exact = trapezoid(0.1, 2.0, 5.0);
    assert!(t.duration() >= exact * (1.0 - 1e-12));
    assert!(
        t.duration() <= exact * 1.002,
        "{} against {exact}",
        t.duration()
    );
    // Midway it is at half the path (symmetric profile).
    let mid = t.at(0.5 * t.duration());
    assert!((mid.s - 0.5).abs() < 1e-3, "{mid:?}");
}

#[test]
fn the_path_limits_bind_when_the_axes_do_not() {
    // Path speed 0.5/s and acceleration 2/s²: 1/0.5 + 0.5/2 = 2.25 s.
    let p = path(2, |s, i| [0.3, -0.2][i] * s);
    let lim = limits(&[10.0, 10.0], &[100.0, 100.0], 0.5, 2.0);
    let t = Timing::optimal(&p, &lim).unwrap();
    assert_within(&p, &lim, &t);
    let exact = trapezoid(1.0, 0.5, 2.0);
    assert!(t.duration() >= exact * (1.0 - 1e-12));
    assert!(t.duration() <= exact * 1.002);
}

#[test]
fn the_slowest_axis_sets_the_pace_of_a_straight_joint_path() {
    // Axis 1 moves 2 rad at 1 rad/s: the path at 0.5/s; axis 0 (0.5 rad) has room.
    let p = path(2, |s, i| [0.5, 2.0][i] * s);
    let lim = limits(&[3.0, 1.0], &[10.0, 4.0], BIG, BIG);
    let t = Timing::optimal(&p, &lim).unwrap();
    assert_within(&p, &lim, &t);
    let exact = trapezoid(2.0, 1.0, 4.0);
    assert!(t.duration() >= exact * (1.0 - 1e-12));
    assert!(t.duration() <= exact * 1.002);
}

#[test]
fn a_curved_path_slows_only_where_an_axis_binds() {
    // Axis 0 swings out and back (q = 0.8·sin(πs)); axis 1 goes straight. A uniform
    // slow-down to the worst point's speed would take the whole path at that speed.
    let p = path(2, |s, i| {
        if i == 0 {
            0.8 * (std::f64::consts::PI * s).sin()
        } else {
            0.6 * s
        }
    });
    let speed = [1.0, 5.0];
    let accel = [20.0, 20.0];
    let lim = limits(&speed, &accel, BIG, BIG);
    let t = Timing::optimal(&p, &lim).unwrap();
    assert_within(&p, &lim, &t);
    // Axis 0's speed bound on ṡ is 1/(0.8π|cos πs|): tightest at the ends, loose in the
    // middle; the path goes faster in the middle than a uniform 1/(0.8π).
    let uniform = 0.8 * std::f64::consts::PI;
    let mid = t.at(t.time_at(0.5));
    assert!(mid.speed > 1.5 / uniform, "{mid:?}");
    assert!(t.duration() < uniform, "{}", t.duration());
    // Against an independent optimum: Bobrow's forward and backward integration on
    // 200,000 steps with the analytic derivatives.
    let pi = std::f64::consts::PI;
    let reference = bobrow(200_000, &speed, &accel, |s| {
        (
            [0.8 * pi * (pi * s).cos(), 0.6],
            [-0.8 * pi * pi * (pi * s).sin(), 0.0],
        )
    });
    let ratio = t.duration() / reference;
    assert!(
        (1.0 - 1e-3..1.01).contains(&ratio),
        "{} against {reference}",
        t.duration()
    );
}

/// The time-optimal time by Bobrow's method (1985): the fastest forward integration at
/// the largest acceleration and the backward one at the largest deceleration, each under
/// the speed limits, the lower of the two at each step. `derivs(s)` gives two axes'
/// `q'` and `q''`.
fn bobrow(
    steps: usize,
    speed: &[f64; 2],
    accel: &[f64; 2],
    derivs: impl Fn(f64) -> ([f64; 2], [f64; 2]),
) -> f64 {
    let h = 1.0 / steps as f64;
    let bounds = |s: f64, x: f64| {
        let (d1, d2) = derivs(s);
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for i in 0..2 {
            if d1[i] != 0.0 {
                let a = (accel[i] - d2[i] * x) / d1[i];
                let b = (-accel[i] - d2[i] * x) / d1[i];
                lo = lo.max(a.min(b));
                hi = hi.min(a.max(b));
            }
        }
        (lo, hi)
    };
    // The largest x the speeds allow, and below it the largest at which some
    // acceleration is within every axis's limit (by bisection: the feasible x are an
    // interval from 0).
    let mvc = |s: f64| {
        let (d1, d2) = derivs(s);
        let mut top = (0..2)
            .filter(|&i| d1[i] != 0.0)
            .map(|i| (speed[i] / d1[i]).powi(2))
            .fold(f64::INFINITY, f64::min);
        for i in 0..2 {
            if d2[i] != 0.0 {
                top = top.min(accel[i] / d2[i].abs() * 4.0);
            }
        }
        let feasible = |x: f64| {
            let (lo, hi) = bounds(s, x);
            let still = (0..2).all(|i| d1[i] != 0.0 || (d2[i] * x).abs() <= accel[i]);
            lo <= hi && still
        };
        if feasible(top) {
            return top;
        }
        let (mut a, mut b) = (0.0, top);
        for _ in 0..80 {
            let m = 0.5 * (a + b);
            if feasible(m) {
                a = m;
            } else {
                b = m;
            }
        }
        a
    };
    let mut fwd = vec![0.0f64; steps + 1];
    for j in 0..steps {
        let s = j as f64 * h;
        let (_, hi) = bounds(s, fwd[j]);
        fwd[j + 1] = (fwd[j] + 2.0 * h * hi).min(mvc(s + h)).max(0.0);
    }
    let mut x = vec![0.0f64; steps + 1];
    for j in (0..steps).rev() {
        let s = (j + 1) as f64 * h;
        let (lo, _) = bounds(s, x[j + 1]);
        x[j] = (x[j + 1] - 2.0 * h * lo).min(fwd[j]).max(0.0);
    }
    (0..steps)
        .map(|j| 2.0 * h / (x[j].sqrt() + x[j + 1].sqrt()))
        .sum()
}

#[test]
fn faster_limits_give_a_proportionally_shorter_time() {
    // Speeds ×k and accelerations ×k² scale every time by 1/k.
    let p = path(3, |s, i| (i as f64 + 1.0) * 0.3 * (s + 0.4 * s * s * s));
    let (v, a) = ([1.0, 1.5, 2.0], [3.0, 4.0, 6.0]);
    let t1 = Timing::optimal(&p, &limits(&v, &a, 0.8, 3.0)).unwrap();
    let k: f64 = 2.5;
    let vk = v.map(|x| x * k);
    let ak = a.map(|x| x * k * k);
    let t2 = Timing::optimal(&p, &limits(&vk, &ak, 0.8 * k, 3.0 * k * k)).unwrap();
    let ratio = t1.duration() / t2.duration();
    assert!((ratio - k).abs() < 1e-9 * k, "{ratio}");
}

#[test]
fn a_looser_limit_is_never_slower() {
    let p = path(2, |s, i| [0.9, -0.4][i] * (s * s * (3.0 - 2.0 * s)));
    let base = Timing::optimal(&p, &limits(&[1.0, 1.0], &[4.0, 4.0], 2.0, 10.0)).unwrap();
    for (v, a, ps, pa) in [
        ([1.5, 1.0], [4.0, 4.0], 2.0, 10.0),
        ([1.0, 1.0], [8.0, 4.0], 2.0, 10.0),
        ([1.0, 1.0], [4.0, 4.0], 4.0, 10.0),
        ([1.0, 1.0], [4.0, 4.0], 2.0, 20.0),
    ] {
        let looser = Timing::optimal(&p, &limits(&v, &a, ps, pa)).unwrap();
        assert!(looser.duration() <= base.duration() * (1.0 + 1e-12));
    }
}

#[test]
fn position_speed_and_time_agree() {
    let p = path(2, |s, i| [0.7, 0.2][i] * (s + 0.3 * (6.0 * s).sin()));
    let lim = limits(&[1.0, 2.0], &[5.0, 5.0], 3.0, 30.0);
    let t = Timing::optimal(&p, &lim).unwrap();
    assert_within(&p, &lim, &t);
    let total = t.duration();
    let mut last = 0.0;
    for j in 1..200 {
        let time = total * j as f64 / 200.0;
        let st = t.at(time);
        assert!(st.s >= last, "s goes back at {time}");
        last = st.s;
        // time_at inverts at.
        assert!((t.time_at(st.s) - time).abs() < 1e-9, "{time}");
        // The speed is the derivative of the position.
        let h = 1e-6;
        let ds = (t.at(time + h).s - t.at(time - h).s) / (2.0 * h);
        assert!(
            (ds - st.speed).abs() < 1e-4 * (1.0 + st.speed),
            "{ds} vs {}",
            st.speed
        );
    }
    assert_eq!(t.at(total).s, 1.0);
    assert_eq!(t.at(-1.0).s, 0.0);
    assert_eq!(t.time_at(1.0), total);
}

#[test]
fn a_path_that_cannot_move_or_is_not_a_number_is_an_error() {
    // A jump so large that no speed is left (ṡ² underflows to 0) inside the path.
    let p = path(2, |s, i| if i == 1 && s > 0.5 { 1e300 } else { 0.0 });
    let lim = limits(&[1.0, 1.0], &[1.0, 1.0], BIG, BIG);
    assert!(
        matches!(
            Timing::optimal(&p, &lim),
            Err(TimingError::Stuck { axis: 1, knot }) if knot.abs_diff(SEGMENTS / 2) <= 1
        ),
        "{:?}",
        Timing::optimal(&p, &lim)
    );
    let mut p = path(2, |s, _| s);
    p.q[40][1] = f64::NAN;
    assert_eq!(
        Timing::optimal(&p, &lim),
        Err(TimingError::NotFinite { knot: 40, axis: 1 })
    );
}

#[test]
fn bad_limits_are_errors() {
    let p = path(1, |s, _| s);
    for (v, a, ps, pa) in [
        (0.0, 1.0, 1.0, 1.0),
        (1.0, f64::NAN, 1.0, 1.0),
        (1.0, 1.0, -1.0, 1.0),
        (1.0, 1.0, 1.0, 0.0),
    ] {
        let r = Timing::optimal(&p, &limits(&[v], &[a], ps, pa));
        assert!(matches!(r, Err(TimingError::BadLimit(_))), "{r:?}");
    }
    assert!(matches!(
        Timing::optimal(&path(2, |s, _| s), &limits(&[1.0], &[1.0], 1.0, 1.0)),
        Err(TimingError::BadLimit(_))
    ));
}

/// Newton's method on the room for u finds what every pair of bounds finds, without
/// falling back to the pairs, on random line sets that rest satisfies (and, through the
/// timings of the other tests, on the lines of real steps).
#[test]
fn newton_finds_the_largest_x_every_pair_finds() {
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..2000 {
        let m = 3 + (next() * 30.0) as usize;
        let mut lines = Vec::with_capacity(m + 2);
        for j in 0..m {
            let a = if j % 5 == 4 { 0.0 } else { next() * 4.0 - 2.0 };
            let b = next() * 4.0 - 2.0;
            // c ≥ 0: rest (u = 0, x = 0) satisfies every line.
            let c = next() * 3.0;
            lines.push(Line { a, b, c });
        }
        // x bounded alone, as the speed limits bound it.
        lines.push(Line {
            a: 0.0,
            b: 1.0,
            c: 0.5 + next() * 10.0,
        });
        let newton = largest_x_by_newton(&lines).expect("Newton's method settles");
        let pairs = largest_x_by_pairs(&lines);
        assert!(
            (newton - pairs).abs() <= 1e-12 * pairs.max(1.0),
            "{newton} vs {pairs}: {lines:?}"
        );
    }
}

/// An arc's whole acceleration, tangential s̈ and centripetal κ·ṡ² (κ its swept angle),
/// stays within the path's whole acceleration A. With every other limit out of the way the
/// fastest motion accelerates with s̈ = √(A² − κ²ṡ⁴) to the middle and brakes the same
/// way. By hand (x = ṡ², dx/ds = 2s̈, x = (A/κ)·sin θ): θ = 2κ·s, so at the middle θ = κ,
/// and dt = dθ / (2√(Aκ·sin θ)): T = ∫₀^κ dθ/√(Aκ·sin θ), by quadrature below. The
/// timing's polygon lies inside the disk (at most 0.5 %), so it is slower, by little
/// (measured: 1.453069 s against 1.450372 s, 0.19 %).
#[test]
fn an_arc_keeps_its_whole_acceleration_within_the_path_acceleration() {
    let (a, kappa) = (2.0f64, 1.2f64);
    // T with θ = φ²: ∫₀^√κ 2φ dφ / √(Aκ·sin φ²), Simpson's rule on 20,000 steps.
    let f = |phi: f64| {
        if phi == 0.0 {
            2.0 / (a * kappa).sqrt()
        } else {
            2.0 * phi / (a * kappa * (phi * phi).sin()).sqrt()
        }
    };
    let (n, end) = (20_000, kappa.sqrt());
    let h = end / n as f64;
    let mut sum = f(0.0) + f(end);
    for i in 1..n {
        sum += if i % 2 == 1 { 4.0 } else { 2.0 } * f(i as f64 * h);
    }
    let exact = sum * h / 3.0;
    // (Without the centripetal part: 2√(1/A) = 1.414214 s.)
    assert!(exact > 2.0 * (1.0 / a).sqrt());
    let p = path(1, |s, _| s);
    let lim = Limits {
        path_normal: kappa,
        path_whole: a,
        ..limits(&[BIG], &[BIG], BIG, a)
    };
    let t = Timing::optimal(&p, &lim).unwrap();
    assert_within(&p, &lim, &t);
    for k in 0..SEGMENTS {
        let (x, u) = t.step_state(k);
        for x in [x, x + 2.0 * u * p.step(k)] {
            let whole = (u * u + (kappa * x) * (kappa * x)).sqrt();
            assert!(whole <= a * (1.0 + 1e-12), "step {k}: {whole}");
        }
    }
    let ratio = t.duration() / exact;
    assert!(
        (1.0..1.01).contains(&ratio),
        "{} against {exact}",
        t.duration()
    );
}

/// The same arc with its limits given knot by knot ([`KnotLimits`]) times the same, to
/// the bit: a corner's path of pieces uses the same constraints as one arc.
#[test]
fn limits_along_the_path_are_the_scalar_ones_knot_by_knot() {
    let (a, kappa) = (2.0f64, 1.2f64);
    let p = path(1, |s, _| s);
    let scalar = Limits {
        path_normal: kappa,
        path_whole: a,
        ..limits(&[BIG], &[BIG], BIG, a)
    };
    let along = KnotLimits {
        normal: [kappa; KNOTS],
        whole: [a; KNOTS],
        ..KnotLimits::none()
    };
    let knotwise = Limits {
        along: Some(&along),
        ..limits(&[BIG], &[BIG], BIG, a)
    };
    let (t1, t2) = (
        Timing::optimal(&p, &scalar).unwrap(),
        Timing::optimal(&p, &knotwise).unwrap(),
    );
    assert_eq!(t1, t2);
    // A speed limit on the second half only: the path brakes to it before the middle.
    let mut half = KnotLimits::none();
    for k in SEGMENTS / 2..KNOTS {
        half.x_max[k] = 0.25;
    }
    let lim = Limits {
        along: Some(&half),
        ..limits(&[BIG], &[10.0], BIG, BIG)
    };
    let t = Timing::optimal(&p, &lim).unwrap();
    for k in SEGMENTS / 2..KNOTS {
        assert!(t.state_at_knot(k) <= 0.25 * (1.0 + 1e-12));
    }
    // By hand (no speed limit on the first half): up at 10/s² from rest, braking at
    // 10/s² to ṡ = 0.5 at s = 0.5 (ṡ² = 20·s up, 0.25 + 20·(0.5 − s) down: they meet
    // at s = 0.25625, ṡ = √5.125), cruising at 0.5 until 0.0125 is left, stopping.
    let peak = 5.125f64.sqrt();
    let up = peak / 10.0;
    let down = (peak - 0.5) / 10.0;
    let cruise2 = (1.0 - 0.0125 - 0.5) / 0.5;
    let stop = 0.05;
    let exact = up + down + cruise2 + stop;
    assert!(
        t.duration() >= exact * (1.0 - 1e-12) && t.duration() <= exact * 1.004,
        "{} against {exact}",
        t.duration()
    );
}

/// A path started at speed: one axis q = 1.2·s at 2 rad/s and 5 rad/s², entered at full
/// speed, cruises (1.2 − 0.4) / 2 = 0.4 s and brakes 0.4 s: 0.8 s. Faster than the path
/// can stop is an error naming the fastest start: v² = 2·5·1.2 = 12 (rad/s)², so
/// ṡ² = 12 / 1.44.
#[test]
fn a_path_started_at_speed_cruises_and_brakes() {
    let p = path(1, |s, _| 1.2 * s);
    let lim = limits(&[2.0], &[5.0], BIG, BIG);
    let x0 = (2.0f64 / 1.2).powi(2);
    let t = Timing::from_speed(&p, &lim, x0).unwrap();
    assert!(
        t.duration() >= 0.8 * (1.0 - 1e-12) && t.duration() <= 0.8 * 1.002,
        "{}",
        t.duration()
    );
    assert_eq!(t.at(0.0).speed, x0.sqrt());
    assert_eq!(Timing::from_speed(&p, &lim, 0.0), Timing::optimal(&p, &lim));
    let fast = limits(&[BIG], &[5.0], BIG, BIG);
    match Timing::from_speed(&p, &fast, 10.0) {
        Err(TimingError::TooFast { largest }) => {
            assert!((largest - 12.0 / 1.44).abs() < 1e-9, "{largest}")
        }
        other => panic!("{other:?}"),
    }
    // Stopping at the middle instead: ṡ² = 2·5·1.2·(0.5 − s)/1.44 before it.
    let reach = Timing::stopping_at(&p, &fast, SEGMENTS / 2).unwrap();
    for (k, r) in reach.iter().enumerate() {
        let s = k as f64 / SEGMENTS as f64;
        let exact = (2.0 * 5.0 * 1.2 * (0.5 - s) / 1.44).max(0.0);
        assert!((r - exact).abs() < 1e-9, "knot {k}: {r} against {exact}");
    }
}

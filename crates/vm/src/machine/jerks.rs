//! Jerk along a sampled Cartesian path: where an S-curve's path jerk, speed and
//! acceleration are largest around each knot ([`KnotJerks`]), and a bound on each axis's
//! jerk there ([`axis_jerk_load`]), which `path`'s checks hold within the axes' jerk limits.

use vworks_model::RobotModel;
use vworks_model::timing::{JointPath, KNOTS, SEGMENTS};

use super::path::{KnotDerivatives, PHASE_SIDE};
use crate::MAX_AXES;
use crate::motion::Profile;

/// Every axis's jerk limit in `model` (infinite where it has none).
pub(super) fn axis_jerks(model: &RobotModel) -> [f64; MAX_AXES] {
    let mut jerk = [f64::INFINITY; MAX_AXES];
    for (i, j) in jerk.iter_mut().enumerate().take(model.dof()) {
        *j = model.axis(i).max_jerk.unwrap_or(f64::INFINITY);
    }
    jerk
}

/// An S-curve's jerk along a sampled path: at each knot, the time the profile reaches it,
/// and over the steps on either side the largest path jerk |s⃛| (the profile's jerk where
/// one of its jerk phases overlaps a step, else none), speed and acceleration. `None` for
/// a trapezoid.
pub(super) struct KnotJerks {
    /// The profile's time at each knot (s).
    time: [f64; KNOTS],
    /// The largest path jerk, speed and |acceleration| next to each knot (path fraction
    /// per s³, s and s²).
    pub(super) near: [(f64, f64, f64); KNOTS],
}

impl KnotJerks {
    pub(super) fn of(joints: &JointPath, profile: &Profile) -> Option<KnotJerks> {
        if profile.t_jerk <= 0.0 || profile.dist <= 0.0 || !profile.j.is_finite() {
            return None;
        }
        let d = profile.dist;
        let mut time = [0.0f64; KNOTS];
        for (k, t) in time.iter_mut().enumerate() {
            *t = profile.time_at(joints.knot(k) * d);
        }
        let (ta, tt, tj) = (profile.t_acc, profile.t_total, profile.t_jerk);
        let phases = [
            (0.0, tj),
            (ta - tj, ta),
            (tt - ta, tt - ta + tj),
            (tt - tj, tt),
        ];
        let breakpoints = profile.breakpoints();
        let mut near = [(0.0f64, 0.0f64, 0.0f64); KNOTS];
        for k in 0..SEGMENTS {
            let (t0, t1) = (time[k], time[k + 1]);
            let jerk = if phases.iter().any(|&(a, b)| a <= t1 && t0 <= b) {
                profile.j.abs() / d
            } else {
                0.0
            };
            // The speed rises, holds and falls: at most at the step's ends or the top
            // (reached at the end of the acceleration); the acceleration is linear between
            // breakpoints: at most at the ends or a breakpoint inside.
            let mut speed = profile.speed_at(t0).max(profile.speed_at(t1));
            if t0 <= ta && ta <= t1 {
                speed = speed.max(profile.speed_at(ta));
            }
            let mut accel = profile.accel_at(t0).abs().max(profile.accel_at(t1).abs());
            for b in breakpoints.into_iter().filter(|b| t0 <= *b && *b <= t1) {
                accel = accel.max(profile.accel_at(b).abs());
                accel = accel.max(profile.accel_at(b - PHASE_SIDE * tt).abs());
            }
            let step = (jerk, speed / d, accel / d);
            for knot in [k, k + 1] {
                let n = &mut near[knot];
                *n = (n.0.max(step.0), n.1.max(step.1), n.2.max(step.2));
            }
        }
        Some(KnotJerks { time, near })
    }

    /// The path's speed and acceleration at knot `k`.
    pub(super) fn state(&self, profile: &Profile, k: usize) -> (f64, f64) {
        let t = self.time[k];
        let d = profile.dist;
        (profile.speed_at(t) / d, profile.accel_at(t) / d)
    }
}

/// A bound on an axis's jerk around knot `k`, where the path moves at most at `ṡ`,
/// accelerates at most at `s̈` and jerks at most at `s⃛` (`KnotJerks::near`):
/// |q′|·s⃛ + 3|q″|·ṡ·s̈ + |q‴|·ṡ³, with the largest |q′| and |q″| of the knots `k − 1` to
/// `k + 1` and the largest |q‴| of the two steps between them (by differences of q″, or
/// `finer_d3` where the steps' quarter points give a larger one).
pub(super) fn axis_jerk_load(
    joints: &JointPath,
    derivatives: &KnotDerivatives,
    (k, i): (usize, usize),
    (sddd, sd, sdd): (f64, f64, f64),
    finer_d3: f64,
) -> f64 {
    let (lo, hi) = (k.saturating_sub(1), (k + 1).min(SEGMENTS));
    // (The steepest slope and curvature of the three knots, and the steeper change of the
    // curvature over the steps between them: all change between knots.)
    let (mut d1, mut d2, mut d3) = (0.0f64, 0.0f64, 0.0f64);
    for j in lo..=hi {
        d1 = d1.max(derivatives[j][i].0.abs());
        d2 = d2.max(derivatives[j][i].1.abs());
        if j < hi {
            let change = derivatives[j + 1][i].1 - derivatives[j][i].1;
            d3 = d3.max((change / (joints.knot(j + 1) - joints.knot(j))).abs());
        }
    }
    d1 * sddd + 3.0 * d2 * sd * sdd.abs() + d3.max(finer_d3) * sd * sd * sd
}

/// The share of an axis's jerk limit at a knot from which its steps are checked at their
/// quarter points too.
pub(super) const NEAR_JERK: f64 = 0.9;

//! A sampled path checked between its knots: the joints at each step's quarter points
//! ([`Inner`]), solved only where an axis comes near a limit, and every axis's speed and
//! acceleration there (finite differences) and, for an axis near a limit, between them
//! where no phase end of the profile kinks the curve ([`Kink`]): the peak of the cubic
//! through four points for a speed (a chord between two points is the mean speed, below
//! a peak), of the parabola through three for an acceleration.

use vworks_model::timing::{JointPath, SEGMENTS};

use super::plan::PlanError;
use crate::MAX_AXES;

/// The joints at each step's quarter points (`s_k + j·Δ/4`, j = 1, 2, 3), solved only when
/// needed; on the stack (planning allocates nothing).
pub(super) struct Inner {
    filled: [bool; SEGMENTS],
    q: [[[f64; MAX_AXES]; 3]; SEGMENTS],
}

impl Inner {
    pub(super) fn new() -> Inner {
        Inner {
            filled: [false; SEGMENTS],
            q: [[[0.0; MAX_AXES]; 3]; SEGMENTS],
        }
    }

    /// Solves the quarter points of the steps `wanted` that are not solved yet, each
    /// seeded from the point before.
    pub(super) fn fill(
        &mut self,
        joints: &JointPath,
        wanted: &[bool; SEGMENTS],
        joints_at: impl Fn(f64, &[f64; MAX_AXES]) -> Result<[f64; MAX_AXES], PlanError>,
    ) -> Result<(), PlanError> {
        for (k, quarters) in self.q.iter_mut().enumerate() {
            if !wanted[k] || self.filled[k] {
                continue;
            }
            self.filled[k] = true;
            let mut prev = joints.q[k];
            for (j, q) in quarters.iter_mut().enumerate() {
                let s = joints.knot(k) + (j + 1) as f64 / 4.0 * joints.step(k);
                *q = joints_at(s, &prev)?;
                prev = *q;
            }
        }
        Ok(())
    }

    /// Step `k`'s knots and quarter points in order (its start, the three points, its
    /// end), if the step is solved.
    pub(super) fn points(&self, joints: &JointPath, k: usize) -> Option<[[f64; MAX_AXES]; 5]> {
        self.filled[k].then(|| {
            [
                joints.q[k],
                self.q[k][0],
                self.q[k][1],
                self.q[k][2],
                joints.q[k + 1],
            ]
        })
    }

    /// The largest |q‴| of axis `i` within step `k` by third differences of its knots and
    /// quarter points (a quarter step apart: sharper than the knots' differences), if the
    /// step is solved.
    pub(super) fn third_slope(&self, joints: &JointPath, k: usize, i: usize) -> Option<f64> {
        let h = 0.25 * joints.step(k);
        let q = self.points(joints, k)?.map(|p| p[i]);
        let third = |j: usize| (q[j + 3] - 3.0 * q[j + 2] + 3.0 * q[j + 1] - q[j]).abs();
        Some(third(0).max(third(1)) / (h * h * h))
    }

    /// Per solved step, the largest ratio of an axis's speed or acceleration to its limit
    /// at the quarter points (finite differences over the quarter grid), the path at
    /// `state(k, s) = (ṡ², s̈)` (0 for the steps not solved: not near a limit at their
    /// knots); and the largest speed and acceleration ratios overall. For an axis at
    /// [`PEAKS_FROM`] of a limit at the points, also between them, where speeds and
    /// accelerations turn: a speed unless the step has a [`Kink::Speed`], an acceleration
    /// unless it has any [`Kink`].
    pub(super) fn ratios(
        &self,
        joints: &JointPath,
        (speed, accel): (&[f64], &[f64]),
        state: impl Fn(usize, f64) -> (f64, f64),
        kinks: &[Kink; SEGMENTS],
        out: &mut [f64; SEGMENTS],
    ) -> (f64, f64) {
        let (mut rv, mut ra) = (0.0f64, 0.0f64);
        for (k, r) in out.iter_mut().enumerate() {
            let h = 0.25 * joints.step(k);
            let p = |j: usize| match j {
                0 => &joints.q[k],
                4 => &joints.q[k + 1],
                _ => &self.q[k][j - 1],
            };
            *r = 0.0;
            if !self.filled[k] {
                continue;
            }
            let xu = [0, 1, 2, 3, 4].map(|j| state(k, joints.knot(k) + j as f64 * h));
            let sd = xu.map(|(x, _)| x.max(0.0).sqrt());
            let kink = kinks[k];
            for i in 0..joints.axes {
                let q = [0, 1, 2, 3, 4].map(|j| p(j)[i]);
                // Slopes and curvatures: central at the quarter points.
                let mut acc = [0.0f64; 5];
                let mut at_points = 0.0f64;
                for j in 1..4 {
                    let d1 = (q[j + 1] - q[j - 1]) / (2.0 * h);
                    let d2 = (q[j + 1] - 2.0 * q[j] + q[j - 1]) / (h * h);
                    let v = (d1 * sd[j]).abs() / speed[i];
                    acc[j] = d1 * xu[j].1 + d2 * xu[j].0;
                    at_points = worse(worse(at_points, v), acc[j].abs() / accel[i]);
                    rv = worse(rv, v);
                    ra = worse(ra, acc[j].abs() / accel[i]);
                }
                *r = worse(*r, at_points);
                // (A smooth curve rises above its quarter points by far less than
                // [`PEAKS_FROM`] leaves.)
                if at_points < PEAKS_FROM || kink == Kink::Speed {
                    continue;
                }
                // The speed's peak in each quarter: the slope's from the cubic through
                // four points (its chords' quadratic), at the faster end's ṡ (ṡ² is
                // linear in s within a step).
                let chord = [0, 1, 2, 3].map(|j| (q[j + 1] - q[j]) / h);
                let (low, high) = (
                    [chord[0], chord[1], chord[2]],
                    [chord[1], chord[2], chord[3]],
                );
                let slopes = [
                    chord_peak(low, -1.0),
                    chord_peak(low, 0.0),
                    chord_peak(high, 0.0),
                    chord_peak(high, 1.0),
                ];
                for (j, slope) in slopes.iter().enumerate() {
                    let v = slope * sd[j].max(sd[j + 1]) / speed[i];
                    rv = worse(rv, v);
                    *r = worse(*r, v);
                }
                if kink == Kink::Accel {
                    continue;
                }
                // The acceleration's peak: the parabola's through three points in a row
                // (at the knots, slopes and curvatures second-order one-sided), where it
                // turns between them.
                let ends = [
                    (
                        (-3.0 * q[0] + 4.0 * q[1] - q[2]) / (2.0 * h),
                        (2.0 * q[0] - 5.0 * q[1] + 4.0 * q[2] - q[3]) / (h * h),
                    ),
                    (
                        (3.0 * q[4] - 4.0 * q[3] + q[2]) / (2.0 * h),
                        (2.0 * q[4] - 5.0 * q[3] + 4.0 * q[2] - q[1]) / (h * h),
                    ),
                ];
                for (j, (d1, d2)) in [(0, ends[0]), (4, ends[1])] {
                    acc[j] = d1 * xu[j].1 + d2 * xu[j].0;
                }
                for j in 1..4 {
                    let a = parabola_peak([acc[j - 1], acc[j], acc[j + 1]]) / accel[i];
                    ra = worse(ra, a);
                    *r = worse(*r, a);
                }
            }
        }
        (rv, ra)
    }
}

/// The larger of a ratio so far and a new one, where a ratio that is not a number (joints
/// of NaN: never a limit kept) counts as infinitely over (`f64::max` would drop it).
pub(super) fn worse(so_far: f64, ratio: f64) -> f64 {
    if ratio.is_nan() {
        f64::INFINITY
    } else {
        so_far.max(ratio)
    }
}

/// What the state of a path's timing does within a step where it is not smooth (a
/// profile's phase ends there), which the curves through the quarter points cannot follow.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) enum Kink {
    /// Smooth: the peaks between the points are sought.
    #[default]
    None,
    /// The acceleration's slope steps (an S-curve's phase end): the speed stays smooth.
    Accel,
    /// The acceleration steps (a trapezoid's phase end): the speed's slope too.
    Speed,
}

/// The share of a limit an axis must reach at a step's quarter points for the peaks
/// between them to be sought: they rise above the points by a few 1e-5 of a limit.
const PEAKS_FROM: f64 = 0.99;

/// The largest |y| of the parabola through `(−1, y[0])`, `(0, y[1])`, `(1, y[2])` where
/// it turns between −1 and 1 (else the largest |y| given: a parabola that turns outside
/// peaks at one of its points).
fn parabola_peak(y: [f64; 3]) -> f64 {
    let at_points = y[0].abs().max(y[1].abs()).max(y[2].abs());
    let c = 0.5 * (y[0] + y[2]) - y[1];
    let b = 0.5 * (y[2] - y[0]);
    if c == 0.0 {
        return at_points;
    }
    let s = -b / (2.0 * c);
    if s.abs() >= 1.0 {
        return at_points;
    }
    at_points.max((y[1] + s * (b + s * c)).abs())
}

/// The largest |v(s)| over the unit interval centred on `m` (−1, 0 or 1) of the quadratic
/// `v` whose means over the unit intervals centred on −1, 0 and 1 are `d[0]`, `d[1]` and
/// `d[2]` (the mean of `A + B·s + C·s²` over the interval centred on `m` is
/// `A + B·m + C·(m² + 1/12)`): from the chords between four samples of an axis (its mean
/// speeds between them), its peak speed between two of them (the derivative of the cubic
/// through the four), which a chord, a mean, is below where the speed peaks.
pub(super) fn chord_peak(d: [f64; 3], m: f64) -> f64 {
    let c = 0.5 * (d[0] + d[2] - 2.0 * d[1]);
    let b = 0.5 * (d[2] - d[0]);
    let a = d[1] - c / 12.0;
    let v = |s: f64| (a + s * (b + s * c)).abs();
    let (lo, hi) = (m - 0.5, m + 0.5);
    let mut top = v(lo).max(v(hi));
    if c != 0.0 {
        let s = -b / (2.0 * c);
        if s > lo && s < hi {
            top = top.max(v(s));
        }
    }
    top
}

#[cfg(test)]
mod tests {
    use super::{Inner, Kink, chord_peak, parabola_peak};
    use vworks_model::timing::{JointPath, SEGMENTS};

    /// A quarter point whose joint is not a number fails the check (infinitely over),
    /// where `f64::max` would have dropped it and passed the step.
    #[test]
    fn a_joint_that_is_not_a_number_is_never_within_a_limit() {
        let mut joints = JointPath::new(1);
        for (k, q) in joints.q.iter_mut().enumerate() {
            q[0] = k as f64 * 1e-3;
        }
        let mut inner = Inner::new();
        let all = [true; SEGMENTS];
        inner
            .fill(&joints, &all, |s, _| Ok([s * SEGMENTS as f64 * 1e-3; 12]))
            .unwrap();
        let state = |_: usize, _: f64| (1.0, 0.0);
        let mut out = [0.0; SEGMENTS];
        let kinks = [Kink::None; SEGMENTS];
        let (rv, ra) = inner.ratios(&joints, (&[1.0], &[1.0]), state, &kinks, &mut out);
        assert!(rv.is_finite() && ra.is_finite() && rv > 0.0, "{rv} {ra}");
        inner.q[7][1][0] = f64::NAN;
        let (rv, ra) = inner.ratios(&joints, (&[1.0], &[1.0]), state, &kinks, &mut out);
        assert!(rv.is_infinite() && ra.is_infinite(), "{rv} {ra}");
        assert!(out[7].is_infinite());
    }

    /// By hand: v(s) = 1 + 0.2·s − 3·s² has means A + B·m + C·(m² + 1/12) over the unit
    /// intervals centred on m = −1, 0, 1: 1 − 0.2 − 3.25 = −2.45, 1 − 0.25 = 0.75 and
    /// 1 + 0.2 − 3.25 = −2.05. Its peak is at s = 0.2/6, v = 1 + 0.01/3; over the interval
    /// centred on 1 its largest |v| is at s = 1.5: |1 + 0.3 − 6.75| = 5.45.
    #[test]
    fn a_chord_peak_is_the_peak_of_the_quadratic_with_those_means() {
        let d = [-2.45, 0.75, -2.05];
        let peak = chord_peak(d, 0.0);
        assert!((peak - (1.0 + 0.01 / 3.0)).abs() < 1e-12, "{peak}");
        assert!((chord_peak(d, 1.0) - 5.45).abs() < 1e-12);
        // A straight speed peaks at an end: means 1, 2, 3 are v(s) = 2 + s.
        assert!((chord_peak([1.0, 2.0, 3.0], 0.0) - 2.5).abs() < 1e-12);
        assert!((chord_peak([1.0, 2.0, 3.0], -1.0) - 1.5).abs() < 1e-12);
        // Or at the other end, in magnitude.
        assert!((chord_peak([-1.0, -2.0, -3.0], 0.0) - 2.5).abs() < 1e-12);
    }

    /// By hand: y = 2 − (s − 0.5)² through s = −1, 0, 1 is −0.25, 1.75, 1.75; it turns at
    /// 0.5, at 2. A line peaks at a point: −1, 0, 1 gives 1.
    #[test]
    fn a_parabola_peaks_where_it_turns_between_its_points() {
        assert!((parabola_peak([-0.25, 1.75, 1.75]) - 2.0).abs() < 1e-12);
        assert!((parabola_peak([-1.0, 0.0, 1.0]) - 1.0).abs() < 1e-12);
        // Turning outside (at s = −2): its largest point.
        assert!((parabola_peak([-1.0, 0.0, 3.0]) - 3.0).abs() < 1e-12);
    }
}

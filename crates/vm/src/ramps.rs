//! Path profiles made of constant-acceleration phases ([`Ramps`]): what a Cartesian
//! motion follows once it flies by a corner with look-ahead.
//!
//! A rest-to-rest trapezoid ([`crate::motion::Profile`]) is three such phases. A corner
//! (`machine::blend`, docs/engine.md "Zones") changes the two motions around it:
//!
//! - the first keeps its profile up to the moment the next motion is known, holds its
//!   speed, brakes at its own acceleration to the corner speed `v_e` where it enters the
//!   corner, and then runs out over the corner's radius `r` with a *corner ramp*
//!   (constant deceleration `v_e²/2r` to rest at its point): [`Ramps::with_tail`];
//! - the next starts at its point with a ramp from rest (to its own corner speed over its
//!   own length, in the same time) and goes on as a trapezoid: [`Ramps::with_head`].
//!
//! Superposed, the two ramps move the TCP along a parabola inside the zone with a constant
//! acceleration vector (with equal ramps, at a constant path speed: the two speeds add up
//! to it). Every function here is pure and works in the motion's path fraction (distance
//! 1).

/// The most phases a profile has: a head ramp, accelerate, cruise, accelerate again
/// after a hold, brake, a tail ramp — with room to spare.
pub const MAX_PHASES: usize = 8;

/// A profile of up to [`MAX_PHASES`] phases of constant acceleration from rest at
/// distance 0 to rest at distance `dist`: phase `k` runs from `t[k]` to `t[k + 1]`,
/// starting at distance `s[k]` and speed `v[k]` with acceleration `a[k]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ramps {
    phases: usize,
    t: [f64; MAX_PHASES + 1],
    s: [f64; MAX_PHASES + 1],
    v: [f64; MAX_PHASES + 1],
    a: [f64; MAX_PHASES],
    /// The acceleration of its phases outside the corner ramps (the motion's own).
    pub accel: f64,
    /// Its largest speed.
    pub top: f64,
}

/// Why a profile cannot be built as asked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RampsError {
    /// More phases than [`MAX_PHASES`].
    TooManyPhases,
    /// The motion cannot brake to the corner speed by the corner, from where it is.
    CannotBrake,
    /// The motion cannot reach the corner speed by the corner.
    CannotReach,
}

/// Builds a profile phase by phase from rest at distance 0.
struct Builder {
    r: Ramps,
}

impl Builder {
    fn new(accel: f64) -> Builder {
        Builder {
            r: Ramps {
                phases: 0,
                t: [0.0; MAX_PHASES + 1],
                s: [0.0; MAX_PHASES + 1],
                v: [0.0; MAX_PHASES + 1],
                a: [0.0; MAX_PHASES],
                accel,
                top: 0.0,
            },
        }
    }

    /// The state where the profile so far ends: time, distance, speed.
    fn end(&self) -> (f64, f64, f64) {
        let k = self.r.phases;
        (self.r.t[k], self.r.s[k], self.r.v[k])
    }

    /// Appends a phase of acceleration `a` lasting `dt` (nothing if `dt` ≤ 0).
    fn push(&mut self, a: f64, dt: f64) -> Result<(), RampsError> {
        if dt.is_nan() || dt <= 0.0 {
            return Ok(());
        }
        let k = self.r.phases;
        if k == MAX_PHASES {
            return Err(RampsError::TooManyPhases);
        }
        let (t, s, v) = self.end();
        self.r.a[k] = a;
        self.r.t[k + 1] = t + dt;
        self.r.s[k + 1] = s + v * dt + 0.5 * a * dt * dt;
        self.r.v[k + 1] = (v + a * dt).max(0.0);
        self.r.top = self.r.top.max(self.r.v[k + 1]);
        self.r.phases = k + 1;
        Ok(())
    }

    /// Appends a phase from the current speed to `v` at acceleration magnitude `a`.
    fn push_to_speed(&mut self, v: f64, a: f64) -> Result<(), RampsError> {
        let (_, _, v0) = self.end();
        if v > v0 {
            self.push(a, (v - v0) / a)
        } else {
            self.push(-a, (v0 - v) / a)
        }
    }

    /// Appends a cruise at the current speed over distance `d`.
    fn push_cruise(&mut self, d: f64) -> Result<(), RampsError> {
        let (_, _, v) = self.end();
        if v > 0.0 {
            self.push(0.0, d / v)
        } else {
            Ok(())
        }
    }

    /// Ends the profile exactly at distance `dist` and rest (the last float of the
    /// phases' sums is replaced by the exact end).
    fn finish(mut self, dist: f64) -> Ramps {
        let k = self.r.phases;
        self.r.s[k] = dist;
        self.r.v[k] = 0.0;
        self.r
    }
}

impl Ramps {
    /// The trapezoid (or triangle) over `dist` at peak speed `v` and acceleration `a`
    /// (`a` > 0; `v` reached or the peak of the triangle).
    pub fn trapezoid(dist: f64, v: f64, a: f64) -> Ramps {
        let mut b = Builder::new(a);
        // (Three phases always fit.)
        let _ = b.push_to_speed(v, a);
        let _ = b.push_cruise(dist - v * v / a);
        let _ = b.push_to_speed(0.0, a);
        b.finish(dist)
    }

    /// A motion over `dist` that starts with a corner ramp — from rest to `v_e` over
    /// distance `r` — and goes on as a trapezoid at acceleration `a` within speed `vmax`
    /// (its peak: `min(vmax, √(v_e²/2 + a·(dist − r)))`). The caller keeps
    /// `v_e ≤ vmax` and `v_e² ≤ 2a·(dist − r)` (it can still stop).
    pub fn with_head(dist: f64, vmax: f64, a: f64, r: f64, v_e: f64) -> Result<Ramps, RampsError> {
        if v_e <= 0.0
            || r <= 0.0
            || v_e > vmax * (1.0 + 1e-12)
            || v_e * v_e > 2.0 * a * (dist - r) * (1.0 + 1e-12)
        {
            return Err(RampsError::CannotReach);
        }
        let mut b = Builder::new(a);
        b.push(v_e * v_e / (2.0 * r), 2.0 * r / v_e)?;
        let peak = vmax.min((0.5 * v_e * v_e + a * (dist - r)).sqrt()).max(v_e);
        b.push_to_speed(peak, a)?;
        let rest = dist - r - (peak * peak - v_e * v_e) / (2.0 * a) - peak * peak / (2.0 * a);
        b.push_cruise(rest)?;
        b.push_to_speed(0.0, a)?;
        Ok(b.finish(dist))
    }

    /// This profile changed from time `now` on to fly by its end: it goes on as it was
    /// while it accelerates, holds the speed it has, brakes at its acceleration to `v_e`
    /// where `r` of its distance is left, and runs out over `r` with a corner ramp
    /// (deceleration `v_e²/2r`, lasting `2r/v_e`).
    pub fn with_tail(&self, now: f64, r: f64, v_e: f64) -> Result<Ramps, RampsError> {
        let a = self.accel;
        let dist = self.dist();
        let s_z = dist - r;
        if v_e <= 0.0 || r <= 0.0 || s_z <= 0.0 {
            return Err(RampsError::CannotReach);
        }
        let mut b = Builder::new(a);
        // The past, as it was.
        let now = now.clamp(0.0, self.duration());
        let mut k = 0;
        while k < self.phases && self.t[k + 1] <= now {
            b.push(self.a[k], self.t[k + 1] - self.t[k])?;
            k += 1;
        }
        if k < self.phases {
            b.push(self.a[k], now - self.t[k])?;
        }
        // Going on: the phases still accelerating, then a hold; each until it meets the
        // braking curve v² = v_e² + 2a·(s_z − s).
        let brake2 = |s: f64| v_e * v_e + 2.0 * a * (s_z - s);
        let (_, s0, v0) = b.end();
        if v0 * v0 > brake2(s0) * (1.0 + 1e-9) + 1e-18 {
            return Err(RampsError::CannotBrake);
        }
        let mut next = k;
        loop {
            let (_, s, v) = b.end();
            // The accelerating phase going on from here, to the speed it ends with.
            let (af, v_end) = match (next < self.phases).then(|| (self.a[next], self.v[next + 1])) {
                Some((af, v_end)) if af > 0.0 && v_end > v => (af, v_end),
                _ => (0.0, f64::INFINITY),
            };
            // Where v² + 2·af·(x − s) meets the braking curve.
            let meet = s + (brake2(s) - v * v) / (2.0 * (af + a));
            let seg_end = if af > 0.0 {
                s + (v_end * v_end - v * v) / (2.0 * af)
            } else {
                f64::INFINITY
            };
            if meet <= seg_end {
                if meet > s_z * (1.0 + 1e-12) {
                    return Err(RampsError::CannotReach);
                }
                let v_meet = (v * v + 2.0 * af * (meet - s)).max(0.0).sqrt();
                if af > 0.0 {
                    b.push(af, (v_meet - v) / af)?;
                } else {
                    b.push_cruise(meet - s)?;
                }
                break;
            }
            b.push(af, (v_end - v) / af)?;
            next += 1;
        }
        b.push_to_speed(v_e, a)?;
        b.push(-v_e * v_e / (2.0 * r), 2.0 * r / v_e)?;
        Ok(b.finish(dist))
    }

    /// The distance covered (the motion's).
    pub fn dist(&self) -> f64 {
        self.s[self.phases]
    }

    /// How long it lasts (s).
    pub fn duration(&self) -> f64 {
        self.t[self.phases]
    }

    /// The phase at time `t` (the last one at its end).
    fn phase(&self, t: f64) -> usize {
        let mut k = 0;
        while k + 1 < self.phases && t >= self.t[k + 1] {
            k += 1;
        }
        k
    }

    /// Distance covered at `t` (s), clamped to [0, dist].
    pub fn at(&self, t: f64) -> f64 {
        if t <= 0.0 || self.phases == 0 {
            return 0.0;
        }
        if t >= self.duration() {
            return self.dist();
        }
        let k = self.phase(t);
        let dt = t - self.t[k];
        (self.s[k] + self.v[k] * dt + 0.5 * self.a[k] * dt * dt).min(self.dist())
    }

    /// Speed at `t` (s).
    pub fn speed_at(&self, t: f64) -> f64 {
        if t <= 0.0 || t >= self.duration() || self.phases == 0 {
            return 0.0;
        }
        let k = self.phase(t);
        (self.v[k] + self.a[k] * (t - self.t[k])).max(0.0)
    }

    /// The time the profile has covered `d` (clamped to [0, duration]).
    pub fn time_at(&self, d: f64) -> f64 {
        if d <= 0.0 {
            return 0.0;
        }
        if d >= self.dist() {
            return self.duration();
        }
        let mut k = 0;
        while k + 1 < self.phases && d >= self.s[k + 1] {
            k += 1;
        }
        let (v, a, x) = (self.v[k], self.a[k], d - self.s[k]);
        let dt = if a.abs() < 1e-300 {
            if v > 0.0 { x / v } else { 0.0 }
        } else {
            // ½a·τ² + v·τ − x = 0, the root in the phase (stable form).
            let disc = (v * v + 2.0 * a * x).max(0.0).sqrt();
            2.0 * x / (v + disc)
        };
        (self.t[k] + dt).clamp(self.t[k], self.t[k + 1])
    }

    /// The times and accelerations of the phases.
    pub fn phases(&self) -> impl Iterator<Item = (f64, f64, f64)> + '_ {
        (0..self.phases).map(|k| (self.t[k], self.t[k + 1], self.a[k]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_trapezoid_is_three_phases_with_closed_form_times() {
        // 1 over v = 0.5, a = 1: 0.5 s up, 1.75 s cruise, 0.5 s down.
        let r = Ramps::trapezoid(1.0, 0.5, 1.0);
        assert!((r.duration() - 2.5).abs() < 1e-12);
        assert!((r.at(0.5) - 0.125).abs() < 1e-12);
        assert!((r.speed_at(1.0) - 0.5).abs() < 1e-12);
        assert!((r.time_at(0.125) - 0.5).abs() < 1e-12);
        assert_eq!(r.dist(), 1.0);
        // Triangle: 0.25 at v = 0.5, a = 1.
        let t = Ramps::trapezoid(0.25, 0.5, 1.0);
        assert!((t.duration() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_head_ramp_reaches_the_corner_speed_over_the_radius() {
        // r = 0.1 at v_e = 0.4: 0.5 s at 0.8; then 0.4 → 0.5 at a = 1 (0.1 s, 0.045),
        // cruise to where braking from 0.5 takes 0.125: 1 − 0.1 − 0.045 − 0.125 = 0.73.
        let r = Ramps::with_head(1.0, 0.5, 1.0, 0.1, 0.4).unwrap();
        assert!((r.at(0.5) - 0.1).abs() < 1e-12);
        assert!((r.speed_at(0.5) - 0.4).abs() < 1e-12);
        assert!((r.duration() - (0.5 + 0.1 + 0.73 / 0.5 + 0.5)).abs() < 1e-12);
        assert!(Ramps::with_head(1.0, 0.5, 1.0, 0.1, 0.6).is_err());
    }

    #[test]
    fn a_tail_holds_brakes_and_runs_out_over_the_radius() {
        // From the trapezoid 1 @ 0.5, a = 1, changed at 1 s (cruising at 0.25):
        // brake to 0.3 by 0.9 (from 0.5: 0.08 of distance, 0.2 s), then 0.1 at 0.45
        // deceleration (2·0.1/0.3 s).
        let p = Ramps::trapezoid(1.0, 0.5, 1.0);
        let r = p.with_tail(1.0, 0.1, 0.3).unwrap();
        let cruise_end = 0.9 - 0.08;
        let t_brake = 0.5 + (cruise_end - 0.125) / 0.5;
        assert!((r.time_at(cruise_end) - t_brake).abs() < 1e-12);
        assert!((r.speed_at(r.time_at(0.9)) - 0.3).abs() < 1e-9);
        assert!((r.duration() - (t_brake + 0.2 + 2.0 * 0.1 / 0.3)).abs() < 1e-12);
        assert_eq!(r.dist(), 1.0);
        // Before `now` nothing changed.
        assert_eq!(r.at(0.7), p.at(0.7));
        // Too late to brake to 0.1 by 0.9: from 0.5 at 0.875 it cannot.
        assert_eq!(
            p.with_tail(p.time_at(0.875), 0.1, 0.1),
            Err(RampsError::CannotBrake)
        );
    }

    #[test]
    fn a_tail_on_an_accelerating_motion_keeps_its_peak_until_it_must_brake() {
        // Triangle 0.25 at a = 1 (peak 0.5 at 0.125, 0.5 s), changed at 0.1 s, corner
        // r = 0.05 at v_e = 0.4: up to 0.5, hold until v² = 0.16 + 2·(0.2 − s) = 0.25
        // (s = 0.155, 0.03 at 0.5: 0.06 s), brake to 0.4 (0.1 s), ramp (0.25 s).
        let p = Ramps::trapezoid(0.25, 0.5, 1.0);
        let r = p.with_tail(0.1, 0.05, 0.4).unwrap();
        assert!((r.top - 0.5).abs() < 1e-12);
        assert!((r.duration() - (0.5 + 0.06 + 0.1 + 0.25)).abs() < 1e-12);
        assert!((r.time_at(0.155) - 0.56).abs() < 1e-12);
        // Changed at 0.05 s with a corner speed it meets while still accelerating:
        // v_e = 0.2, r = 0.1: 2s = 0.04 + 2·(0.15 − s), s = 0.085, v = √0.17.
        let r = p.with_tail(0.05, 0.1, 0.2).unwrap();
        let vm = 0.17f64.sqrt();
        assert!((r.top - vm).abs() < 1e-12);
        assert!((r.duration() - (vm + (vm - 0.2) + 1.0)).abs() < 1e-12);
    }
}

//! Time-optimal timing of a path: the fastest way to move along a geometric path of the
//! joints, `q(s)` for `s` from 0 to 1, from rest to rest, within every axis's speed and
//! acceleration and the path's own speed and acceleration (the TCP's and the
//! orientation's, as fractions of the path per second).
//!
//! The method is the reachability analysis of TOPP-RA (Pham & Pham, "A New Approach to
//! Time-Optimal Path Parameterization Based on Reachability Analysis", IEEE T-RO 2018;
//! PyPI `toppra`), in the state `x = ṡ²` and control `u = s̈`: the path is cut into
//! [`SEGMENTS`] steps of `s` (equal, or *graded*: finer where the joints' slopes change
//! fast, see [`JointPath::grade`]), `u` is constant on each (so `x` is linear in `s`
//! and `s(t)` is a parabola), and every limit holds at both ends of every step with that
//! step's `u` (TOPP-RA's "interpolation" scheme). With the axis's speed `q'(s)·ṡ` and
//! acceleration `q'(s)·s̈ + q''(s)·ṡ²`, each limit is linear in `(u, x)`:
//!
//! - a backward pass finds at each knot the largest `x` from which the end can still be
//!   reached at rest (the controllable set `[0, K_k]`, a 2-D linear program solved
//!   exactly: the smallest root of the lines its constraints make);
//! - a forward pass from rest takes the largest `u` that stays within them.
//!
//! The result is exact arithmetic on the samples: no iteration, no tolerance, the same
//! bits for the same inputs. Nothing allocates: a [`Timing`] is arrays of [`KNOTS`]
//! numbers (the path speed squared, the time and the place of each knot, each step's
//! curve). With jerk limits, [`Timing::jerk_limited`] (`jerk`, which allocates its
//! linear programs) gives a smooth timing.

use crate::ik::MAX_AXES;

/// Steps the path is cut into.
pub const SEGMENTS: usize = 256;
/// Points where the limits hold: the ends of the steps.
pub const KNOTS: usize = SEGMENTS + 1;

/// The joints along a path at the knots: `q[k]` at `s = k / SEGMENTS` (or at the graded
/// knots, [`JointPath::knot`]), axes first.
#[derive(Clone, Debug)]
pub struct JointPath {
    /// How many axes move.
    pub axes: usize,
    /// The joints at each knot (rad or m).
    pub q: [[f64; MAX_AXES]; KNOTS],
    /// Per step, the fraction of every axis limit it may use: 1, unless a check between
    /// the knots found that the path's curvature there needs room (see
    /// [`Timing::slower`] for the last resort).
    pub room: [f64; SEGMENTS],
    /// Per end (start, end) and axis, the steepest `q'` found close to it (by the caller,
    /// e.g. from points 1/4 to 1/4096 of a step in): where a path starts or ends near a singularity
    /// its slope there is steeper than the knots show. 0 where not known.
    pub end_slopes: [[f64; MAX_AXES]; 2],
    /// Where each knot is (`s`, 0 to 1): `k / SEGMENTS` unless graded.
    knots: [f64; KNOTS],
    graded: bool,
    /// Knots where the path's second derivative may jump (where two pieces of it meet):
    /// there each step takes the derivatives of its own side. 0: none.
    breaks: [usize; 4],
}

impl JointPath {
    /// A path of `axes` axes, every knot at zero.
    pub fn new(axes: usize) -> JointPath {
        JointPath {
            axes: axes.min(MAX_AXES),
            q: [[0.0; MAX_AXES]; KNOTS],
            room: [1.0; SEGMENTS],
            end_slopes: [[0.0; MAX_AXES]; 2],
            knots: std::array::from_fn(|k| k as f64 / SEGMENTS as f64),
            graded: false,
            breaks: [0; 4],
        }
    }

    /// Marks knots (up to four; 0 for none) where the path's second derivative may jump, as
    /// where a curve meets a straight piece: the steps on either side take their
    /// derivatives there from their own side (one-sided differences), so neither sees the
    /// other's curvature.
    pub fn set_breaks(&mut self, breaks: [usize; 4]) {
        self.breaks = breaks.map(|k| if k < SEGMENTS { k } else { 0 });
    }

    /// Axis `i`'s derivatives `(q', q'')` at knot `k` as the step on `side` of it sees them
    /// (`Side::Before`: the step ending there): [`JointPath::derivatives`], except at a
    /// break ([`JointPath::set_breaks`]), where they come from the three knots on that side.
    pub fn derivatives_on(&self, k: usize, i: usize, side: Side) -> (f64, f64) {
        let k = k.min(SEGMENTS);
        if k == 0 || k == SEGMENTS || !self.breaks.contains(&k) {
            return self.derivatives(k, i);
        }
        let (a, b, c) = match side {
            Side::Before if k >= 2 => (k - 2, k - 1, k),
            Side::After if k + 2 <= SEGMENTS => (k, k + 1, k + 2),
            _ => return self.derivatives(k, i),
        };
        let q = |j: usize| self.q[j][i];
        let (s0, s1, s2) = (self.knots[a], self.knots[b], self.knots[c]);
        let (h1, h2) = (s1 - s0, s2 - s1);
        let (d01, d12) = ((q(b) - q(a)) / h1, (q(c) - q(b)) / h2);
        let d2 = 2.0 * (d12 - d01) / (h1 + h2);
        let d1 = d01 + d2 * (self.knots[k] - 0.5 * (s0 + s1));
        (d1, d2)
    }

    /// Where knot `k` is on the path (`s`, 0 to 1).
    pub fn knot(&self, k: usize) -> f64 {
        self.knots[k.min(SEGMENTS)]
    }

    /// Every knot's place on the path.
    pub fn knots(&self) -> &[f64; KNOTS] {
        &self.knots
    }

    /// The step `s` lies in (from its knot up to the next; the last step for `s` = 1).
    pub fn step_at(&self, s: f64) -> usize {
        self.knots[..SEGMENTS]
            .partition_point(|k| *k <= s)
            .saturating_sub(1)
    }

    /// How long step `k` (from knot `k` to `k + 1`) is, in `s`.
    pub fn step(&self, k: usize) -> f64 {
        let k = k.min(SEGMENTS - 1);
        self.knots[k + 1] - self.knots[k]
    }

    /// Whether the knots are graded (not equal steps).
    pub fn graded(&self) -> bool {
        self.graded
    }

    /// The knots that grade a path whose joints are known at equal steps (`self.q` at
    /// `k / SEGMENTS`): each step's share of the knots grows with how fast the axes'
    /// slopes `q'` change across it, relative to their size: from 1 where they change by at
    /// most [`GRADE_CHANGE`] of themselves to [`GRADE_MAX`] times as many (only where an
    /// axis's slope is at least [`GRADE_FLOOR`] of its steepest). A timing with
    /// one `s̈` per step keeps an axis's acceleration at the step's steeper end, so where a
    /// path nears a singularity (a slope growing fivefold over a few steps) equal steps
    /// lose up to a few per cent of its time. `None` where equal steps serve (no step's
    /// slopes change by more than [`GRADE_START`] × [`GRADE_CHANGE`]). The caller samples the joints at the
    /// knots given and sets them with [`JointPath::set_knots`].
    pub fn grade(&self) -> Option<[f64; KNOTS]> {
        if self.graded {
            return None;
        }
        let mut slope = [[0.0f64; MAX_AXES]; KNOTS];
        let mut largest = [0.0f64; MAX_AXES];
        for (k, row) in slope.iter_mut().enumerate() {
            for (i, d) in row.iter_mut().enumerate().take(self.axes) {
                *d = self.derivatives(k, i).0;
                largest[i] = largest[i].max(d.abs());
            }
        }
        // Per step, its density of knots.
        let mut density = [1.0f64; SEGMENTS];
        let mut graded = false;
        for (k, rho) in density.iter_mut().enumerate() {
            for i in 0..self.axes {
                let (a, b) = (slope[k][i], slope[k + 1][i]);
                // (Only where the axis is near its steepest can it bind.)
                let size = a.abs().max(b.abs());
                if size > 0.0 && size >= GRADE_FLOOR * largest[i] {
                    let change = (b - a).abs() / size / GRADE_CHANGE;
                    *rho = rho.max(change.min(GRADE_MAX));
                }
            }
            graded |= *rho > GRADE_START;
        }
        if !graded {
            return None;
        }
        // Neighbouring steps differ by at most GRADE_GROWTH: finite differences across a
        // sudden change of step lose their accuracy.
        for k in 1..SEGMENTS {
            density[k] = density[k].max(density[k - 1] / GRADE_GROWTH);
        }
        for k in (0..SEGMENTS - 1).rev() {
            density[k] = density[k].max(density[k + 1] / GRADE_GROWTH);
        }
        // The rest of the path no coarser than GRADE_COARSEST equal steps: the extra
        // density scaled down where it would take more knots than that leaves.
        let extra: f64 = density.iter().map(|d| d - 1.0).sum();
        let allowed = (GRADE_COARSEST - 1.0) * SEGMENTS as f64;
        if extra > allowed {
            let scale = allowed / extra;
            for d in &mut density {
                *d = 1.0 + (*d - 1.0) * scale;
            }
        }
        // Knots at equal shares of the density's integral (linear within each step).
        let total: f64 = density.iter().sum();
        let mut out = [0.0f64; KNOTS];
        out[SEGMENTS] = 1.0;
        let (mut step, mut before) = (0usize, 0.0f64);
        for (j, s) in out.iter_mut().enumerate().take(SEGMENTS).skip(1) {
            let want = total * j as f64 / SEGMENTS as f64;
            while step < SEGMENTS - 1 && before + density[step] < want {
                before += density[step];
                step += 1;
            }
            let within = ((want - before) / density[step]).clamp(0.0, 1.0);
            *s = (step as f64 + within) / SEGMENTS as f64;
        }
        Some(out)
    }

    /// Puts the knots at `s` (increasing, from 0 to 1); the joints `q` are then the
    /// caller's to sample there.
    pub fn set_knots(&mut self, s: &[f64; KNOTS]) {
        self.knots = *s;
        self.graded = true;
    }

    /// Axis `i`'s derivatives `(q', q'')` at knot `k` by finite differences (central
    /// inside, second-order one-sided at the ends).
    pub fn derivatives(&self, k: usize, i: usize) -> (f64, f64) {
        let n = SEGMENTS as f64;
        let q = |j: usize| self.q[j][i];
        let k = k.min(SEGMENTS);
        let steeper = |d1: f64, end: usize| {
            let s = self.end_slopes[end][i];
            if s.abs() > d1.abs() { s } else { d1 }
        };
        if self.graded {
            // Three knots around k (the first or last three at the ends), by the
            // derivatives of the parabola through them.
            let c = k.clamp(1, SEGMENTS - 1);
            let (s0, s1, s2) = (self.knots[c - 1], self.knots[c], self.knots[c + 1]);
            let (h1, h2) = (s1 - s0, s2 - s1);
            let (d01, d12) = ((q(c) - q(c - 1)) / h1, (q(c + 1) - q(c)) / h2);
            let d2 = 2.0 * (d12 - d01) / (h1 + h2);
            // The slope at knot k: the parabola's, at s_k.
            let mid = 0.5 * (s0 + s1);
            let d1 = d01 + d2 * (self.knots[k] - mid);
            return match k {
                0 => (steeper(d1, 0), d2),
                SEGMENTS => (steeper(d1, 1), d2),
                _ => (d1, d2),
            };
        }
        if k == 0 {
            let d1 = (-3.0 * q(0) + 4.0 * q(1) - q(2)) * 0.5 * n;
            let d2 = (2.0 * q(0) - 5.0 * q(1) + 4.0 * q(2) - q(3)) * n * n;
            (steeper(d1, 0), d2)
        } else if k == SEGMENTS {
            let d1 = (3.0 * q(k) - 4.0 * q(k - 1) + q(k - 2)) * 0.5 * n;
            let d2 = (2.0 * q(k) - 5.0 * q(k - 1) + 4.0 * q(k - 2) - q(k - 3)) * n * n;
            (steeper(d1, 1), d2)
        } else {
            let d1 = (q(k + 1) - q(k - 1)) * 0.5 * n;
            let d2 = (q(k + 1) - 2.0 * q(k) + q(k - 1)) * n * n;
            (d1, d2)
        }
    }
}

/// Which step of a knot: the one that ends there or the one that begins there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// The step ending at the knot.
    Before,
    /// The step beginning at the knot.
    After,
}

/// How much of itself an axis's slope may change across one step before the path is
/// graded ([`JointPath::grade`]): 1 %.
pub const GRADE_CHANGE: f64 = 0.01;
/// The most a graded step may be finer than the rest.
pub const GRADE_MAX: f64 = 12.0;
/// Steps where an axis's slope is below this fraction of its steepest do not grade the
/// path for that axis.
pub const GRADE_FLOOR: f64 = 0.5;
/// The longest a step of a graded path may be, in equal steps (the knots it gives the
/// steep stretch are taken from the rest of the path).
pub const GRADE_COARSEST: f64 = 1.5;
/// The most two neighbouring steps of a graded path differ by (a ratio).
pub const GRADE_GROWTH: f64 = 1.15;
/// A path is graded only where some step's slopes change by more than this many times
/// [`GRADE_CHANGE`].
pub const GRADE_START: f64 = 5.0;

/// The limits a path's timing keeps.
#[derive(Clone, Copy, Debug)]
pub struct Limits<'a> {
    /// Per axis, its largest speed (rad/s or m/s).
    pub axis_speed: &'a [f64],
    /// Per axis, its largest acceleration (rad/s² or m/s²).
    pub axis_accel: &'a [f64],
    /// The largest path speed `ṡ` (1/s): the TCP's speed over the path's length, or the
    /// orientation's over its angle, whichever is less.
    pub path_speed: f64,
    /// The largest path acceleration `|s̈|` (1/s²).
    pub path_accel: f64,
    /// The path's normal acceleration per `ṡ²` (for an arc of length L and radius R,
    /// the TCP's centripetal acceleration L²ṡ²/R over L: L/R, its swept angle; 0 for a
    /// line).
    pub path_normal: f64,
    /// The largest whole acceleration of the path (1/s²), tangential `s̈` and normal
    /// `path_normal·ṡ²` together (`f64::INFINITY`: none): they stay inside a polygon of
    /// [`NORMAL_FACES`] sides inscribed in that half disk (at most 0.5 % inside it, never
    /// outside).
    pub path_whole: f64,
    /// Limits that change along the path, knot by knot (a path of pieces, as a corner's:
    /// [`KnotLimits`]); with them the scalar `path_normal` polygon is not used.
    pub along: Option<&'a KnotLimits>,
}

/// A path's own limits knot by knot, in its fraction `s` (for a TCP path of pieces whose
/// length per unit of `s` and curvature change: a corner between two motions). At each
/// knot the path speed `ṡ² ≤ x_max`, and the TCP's acceleration — along the path
/// `u + tangent·ṡ²` and across it `normal·ṡ²` (`normal ≥ 0`), both per unit of the TCP's
/// length per `s` there — stays inside the polygon of [`NORMAL_FACES`] sides inscribed in
/// the half disk of radius `whole` (as [`Limits::path_whole`]).
#[derive(Clone, Debug, PartialEq)]
pub struct KnotLimits {
    /// The largest `ṡ²` (1/s²).
    pub x_max: [f64; KNOTS],
    /// The tangential acceleration per `ṡ²` the path's own curvature in `s` adds (1).
    pub tangent: [f64; KNOTS],
    /// The normal acceleration per `ṡ²` (1).
    pub normal: [f64; KNOTS],
    /// The largest whole acceleration (1/s²; `f64::INFINITY`: none).
    pub whole: [f64; KNOTS],
}

impl KnotLimits {
    /// No limit anywhere.
    pub fn none() -> KnotLimits {
        KnotLimits {
            x_max: [f64::INFINITY; KNOTS],
            tangent: [0.0; KNOTS],
            normal: [0.0; KNOTS],
            whole: [f64::INFINITY; KNOTS],
        }
    }
}

/// Sides of the polygon that bounds a curved path's whole acceleration
/// ([`Limits::path_normal`]).
pub const NORMAL_FACES: usize = 16;

/// Why a path has no timing.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum TimingError {
    /// A limit is not a positive number (its value).
    BadLimit(f64),
    /// A joint at this knot is not a finite number.
    NotFinite {
        /// The knot (0 to [`SEGMENTS`]).
        knot: usize,
        /// The axis.
        axis: usize,
    },
    /// At this knot the path cannot move at all: an axis would need infinite speed (a
    /// singularity, or the joints jump between two knots).
    Stuck {
        /// The knot (0 to [`SEGMENTS`]).
        knot: usize,
        /// The axis whose limit leaves no speed.
        axis: usize,
    },
    /// No timing within the limits starts as fast as asked ([`Timing::from_speed`]): the
    /// fastest start, `ṡ²`.
    TooFast {
        /// The largest `ṡ²` the path can start with.
        largest: f64,
    },
}

/// The time-optimal timing of a path: `ṡ²` and the time at each knot.
///
/// Within each step `ṡ² = x_k + 2·b_k·σ + c_k·σ²` at `σ = s − s_k`: `s̈ = b_k + c_k·σ`.
/// A timing within the axes' accelerations ([`Timing::optimal`]) has `c_k = 0`: `s̈`
/// is constant on each step, `s(t)` a parabola. A *smooth* one ([`Timing::jerk_limited`])
/// has `s̈` continuous, linear in `s` on each step (`s⃛ = c_k·ṡ`), and its first and last
/// steps move from and to rest at a constant `s⃛` (`s ∝ t³`).
#[derive(Clone, Debug, PartialEq)]
pub struct Timing {
    x: [f64; KNOTS],
    t: [f64; KNOTS],
    /// The path's knots ([`JointPath::knots`]).
    s: [f64; KNOTS],
    /// Per step, `(b_k, c_k)`.
    curve: [(f64, f64); SEGMENTS],
    /// `s̈` continuous (see above).
    smooth: bool,
}

/// Where on the path, how fast and how it accelerates at a time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathState {
    /// The fraction of the path done, 0 to 1.
    pub s: f64,
    /// `ds/dt` (1/s).
    pub speed: f64,
    /// `d²s/dt²` (1/s²).
    pub accel: f64,
}

/// One linear constraint `a·u + b·x ≤ c` of a step (`c ≥ 0`: rest is always allowed).
#[derive(Clone, Copy, Debug)]
struct Line {
    a: f64,
    b: f64,
    c: f64,
}

impl Line {
    /// `0 ≤ 0`: room in a buffer of lines.
    const NONE: Line = Line {
        a: 0.0,
        b: 0.0,
        c: 0.0,
    };
}

/// The constraints of step `k` (from knot `k` to `k + 1`) on `(u, x_k)`: every limit at
/// both knots and halfway, `x = x_k + 2Δ·u·(s − s_k)/Δ` along the step. Halfway the
/// speed `q'` is the exact central difference of the two knots. `out` holds at most
/// `6·axes + 5 + 3·NORMAL_FACES` lines.
fn step_lines(
    path: &JointPath,
    slopes: &KnotSlopes,
    lim: &Limits<'_>,
    k: usize,
    out: &mut [Line],
) -> usize {
    let delta = path.step(k);
    let mut m = 0;
    let mut push = |a: f64, b: f64, c: f64| {
        out[m] = Line { a, b, c };
        m += 1;
    };
    // The path's own acceleration, on u alone (none: the axes alone bound it).
    let curved = lim.path_whole.is_finite() && lim.path_normal > 0.0;
    if lim.path_accel.is_finite() {
        push(1.0, 0.0, lim.path_accel);
        push(-1.0, 0.0, lim.path_accel);
    }
    // (where, x there = x_k + shift·u)
    for (point, shift) in [(0u8, 0.0), (1, delta), (2, 2.0 * delta)] {
        let mut x_max = lim.path_speed * lim.path_speed;
        #[allow(clippy::needless_range_loop)] // (axis i of the knots, the joints and the limits)
        for i in 0..path.axes {
            let (d1, d2) = match point {
                0 => slopes.after[k][i],
                2 => slopes.before[k + 1][i],
                _ => (
                    (path.q[k + 1][i] - path.q[k][i]) / delta,
                    0.5 * (slopes.after[k][i].1 + slopes.before[k + 1][i].1),
                ),
            };
            let amax = lim.axis_accel[i] * path.room[k];
            // -amax ≤ d1·u + d2·(x + shift·u) ≤ amax.
            let (a, b) = (d1 + d2 * shift, d2);
            push(a, b, amax);
            push(-a, -b, amax);
            if d1 != 0.0 {
                let v = lim.axis_speed[i] * path.room[k] / d1.abs();
                x_max = x_max.min(v * v);
            }
        }
        // The limits along the path there (halfway: the tighter speed and whole
        // acceleration, the mean curvature).
        let along = lim.along.map(|al| {
            let (i, j) = match point {
                0 => (k, k),
                2 => (k + 1, k + 1),
                _ => (k, k + 1),
            };
            x_max = x_max.min(al.x_max[i]).min(al.x_max[j]);
            (
                0.5 * (al.tangent[i] + al.tangent[j]),
                0.5 * (al.normal[i] + al.normal[j]),
                al.whole[i].min(al.whole[j]),
            )
        });
        // x + shift·u ≤ x_max.
        if x_max.is_finite() {
            push(shift, 1.0, x_max);
        }
        // A curved path: (u, w = path_normal·x) within the polygon inscribed in the half
        // disk of radius path_whole (w ≥ 0), vertices at angles jπ/M, each side's
        // normal halfway: cos α·u + sin α·w ≤ path_whole·cos(π/2M).
        // Along a path of pieces: (u + tangent·x', normal·x') with x' = x + shift·u.
        if let Some((tg, nm, whole)) = along.filter(|a| a.2.is_finite()) {
            let m = NORMAL_FACES as f64;
            let c = whole * (std::f64::consts::PI / (2.0 * m)).cos();
            for j in 0..NORMAL_FACES {
                let alpha = (j as f64 + 0.5) * std::f64::consts::PI / m;
                let (sin, cos) = alpha.sin_cos();
                let b = cos * tg + sin * nm;
                push(cos + b * shift, b, c);
            }
        } else if curved {
            let m = NORMAL_FACES as f64;
            let c = lim.path_whole * (std::f64::consts::PI / (2.0 * m)).cos();
            for j in 0..NORMAL_FACES {
                let alpha = (j as f64 + 0.5) * std::f64::consts::PI / m;
                let (sin, cos) = alpha.sin_cos();
                let w = sin * lim.path_normal;
                push(cos + w * shift, w, c);
            }
        }
    }
    m
}

/// Every axis's `(q', q'')` at every knot as the step before it and the step after it see
/// them ([`JointPath::derivatives_on`]: the same but at a break).
struct KnotSlopes {
    before: [[(f64, f64); MAX_AXES]; KNOTS],
    after: [[(f64, f64); MAX_AXES]; KNOTS],
}

impl KnotSlopes {
    fn new() -> KnotSlopes {
        KnotSlopes {
            before: [[(0.0, 0.0); MAX_AXES]; KNOTS],
            after: [[(0.0, 0.0); MAX_AXES]; KNOTS],
        }
    }
}

/// The largest `x ≥ 0` for which some `u` satisfies every line. Rest (`u = 0, x = 0`)
/// satisfies them all, so the feasible `x` are an interval from 0: below the lines that
/// bound `x` alone, and where the room for `u`, h(x) = min of the upper bounds − max of
/// the lower bounds (concave, piecewise linear), is not negative. Newton's method on h
/// from the right finds its root in a few passes over the lines (each step's tangent is
/// a pair of lines, whose root is at or right of h's); [`largest_x_by_pairs`], every
/// pair of a lower and an upper bound, is the fallback.
fn largest_x(lines: &[Line]) -> f64 {
    largest_x_by_newton(lines).unwrap_or_else(|| largest_x_by_pairs(lines))
}

/// [`largest_x`] by Newton's method; `None` where it does not settle (then every pair).
fn largest_x_by_newton(lines: &[Line]) -> Option<f64> {
    let right = x_bound(lines);
    if !right.is_finite() {
        return None;
    }
    // The tightest lower (a < 0) and upper (a > 0) bound on u at x.
    let active = |x: f64| {
        let (mut lo, mut lo_at, mut hi, mut hi_at) = (f64::NEG_INFINITY, None, f64::INFINITY, None);
        for l in lines {
            if l.a == 0.0 {
                continue;
            }
            let u = (l.c - l.b * x) / l.a;
            if l.a < 0.0 && u > lo {
                (lo, lo_at) = (u, Some(l));
            } else if l.a > 0.0 && u < hi {
                (hi, hi_at) = (u, Some(l));
            }
        }
        (hi - lo, lo_at, hi_at)
    };
    let mut x = right.max(0.0);
    for _ in 0..NEWTON_STEPS {
        let (room, lo, hi) = active(x);
        if room >= 0.0 {
            return Some(x);
        }
        let (Some(lo), Some(hi)) = (lo, hi) else {
            break;
        };
        // The pair's root, as `largest_x_by_pairs` computes it.
        let g0 = hi.c / hi.a - lo.c / lo.a;
        let g1 = -hi.b / hi.a + lo.b / lo.a;
        if g1 >= 0.0 {
            break;
        }
        let next = (g0 / -g1).max(0.0);
        if next >= x {
            return Some(x.min(next));
        }
        x = next;
    }
    None
}

/// The bound the lines without u put on x alone (`f64::INFINITY` if none does).
fn x_bound(lines: &[Line]) -> f64 {
    lines
        .iter()
        .filter(|l| l.a == 0.0 && l.b > 0.0)
        .map(|l| l.c / l.b)
        .fold(f64::INFINITY, f64::min)
}

/// Passes of [`largest_x`]'s Newton method before it falls back to every pair.
const NEWTON_STEPS: usize = 64;

/// [`largest_x`] by every pair of a lower and an upper bound on u.
fn largest_x_by_pairs(lines: &[Line]) -> f64 {
    let mut best = x_bound(lines);
    // A lower bound on u (a < 0) against an upper one (a > 0): u ≥ (c₁ − b₁x)/a₁ and
    // u ≤ (c₂ − b₂x)/a₂ meet where their difference, linear in x, turns negative.
    for lo in lines.iter().filter(|l| l.a < 0.0) {
        for hi in lines.iter().filter(|l| l.a > 0.0) {
            // g(x) = (c₂ − b₂x)/a₂ − (c₁ − b₁x)/a₁ = g0 + g1·x, g0 ≥ 0.
            let g0 = hi.c / hi.a - lo.c / lo.a;
            let g1 = -hi.b / hi.a + lo.b / lo.a;
            if g1 < 0.0 {
                best = best.min((g0 / -g1).max(0.0));
            }
        }
    }
    best.max(0.0)
}

/// The largest `u` the lines allow at state `x` (`f64::INFINITY` if none bounds it).
fn largest_u(lines: &[Line], x: f64) -> f64 {
    lines
        .iter()
        .filter(|l| l.a > 0.0)
        .map(|l| (l.c - l.b * x) / l.a)
        .fold(f64::INFINITY, f64::min)
}

/// Room for the lines of one step and the two of its next knot.
const LINES: usize = 6 * MAX_AXES + 8 + 3 * NORMAL_FACES;

/// Checks `limits` and `path` and puts every knot's slopes in `slopes`, or gives the
/// error.
fn checked_slopes(
    path: &JointPath,
    limits: &Limits<'_>,
    slopes: &mut KnotSlopes,
) -> Result<(), TimingError> {
    let all = limits
        .axis_speed
        .iter()
        .chain(limits.axis_accel)
        .take(2 * path.axes)
        .chain([&limits.path_speed, &limits.path_accel]);
    for v in all {
        if v.is_nan() || *v <= 0.0 {
            return Err(TimingError::BadLimit(*v));
        }
    }
    if limits.axis_speed.len() < path.axes || limits.axis_accel.len() < path.axes {
        return Err(TimingError::BadLimit(f64::NAN));
    }
    // A curved path's bounds; knots that increase (a step of no length has no slope).
    if limits.path_normal.is_nan() || limits.path_normal < 0.0 || limits.path_normal.is_infinite() {
        return Err(TimingError::BadLimit(limits.path_normal));
    }
    if limits.path_whole.is_nan() || limits.path_whole <= 0.0 {
        return Err(TimingError::BadLimit(limits.path_whole));
    }
    if let Some(al) = limits.along {
        let bad = al
            .x_max
            .iter()
            .chain(&al.whole)
            .find(|v| v.is_nan() || **v <= 0.0)
            .or_else(|| al.tangent.iter().chain(&al.normal).find(|v| !v.is_finite()))
            .or_else(|| al.normal.iter().find(|v| **v < 0.0));
        if let Some(v) = bad {
            return Err(TimingError::BadLimit(*v));
        }
    }
    if let Some(k) = (0..SEGMENTS).find(|&k| path.step(k).is_nan() || path.step(k) <= 0.0) {
        return Err(TimingError::Stuck { knot: k, axis: 0 });
    }
    for (knot, q) in path.q.iter().enumerate() {
        if let Some(axis) = q[..path.axes].iter().position(|v| !v.is_finite()) {
            return Err(TimingError::NotFinite { knot, axis });
        }
    }
    for k in 0..KNOTS {
        for i in 0..path.axes {
            let d = path.derivatives(k, i);
            slopes.before[k][i] = d;
            slopes.after[k][i] = d;
        }
    }
    // (At a break each side has its own.)
    for k in path.breaks.into_iter().filter(|k| *k > 0) {
        for i in 0..path.axes {
            slopes.before[k][i] = path.derivatives_on(k, i, Side::Before);
            slopes.after[k][i] = path.derivatives_on(k, i, Side::After);
        }
    }
    Ok(())
}

/// The backward pass: the controllable sets `[0, reach[k]]` for coming to rest at knot
/// `until` (`reach` is 0 from there on).
fn backward(
    path: &JointPath,
    slopes: &KnotSlopes,
    limits: &Limits<'_>,
    until: usize,
    reach: &mut [f64; KNOTS],
    lines: &mut [Line; LINES],
) -> Result<(), TimingError> {
    for r in reach[until..].iter_mut() {
        *r = 0.0;
    }
    for k in (0..until).rev() {
        let two_delta = 2.0 * path.step(k);
        let mut m = step_lines(path, slopes, limits, k, lines);
        // x_{k+1} = x + 2Δu within [0, K_{k+1}].
        lines[m] = Line {
            a: two_delta,
            b: 1.0,
            c: reach[k + 1],
        };
        lines[m + 1] = Line {
            a: -two_delta,
            b: -1.0,
            c: 0.0,
        };
        m += 2;
        reach[k] = largest_x(&lines[..m]);
        if k > 0 && reach[k] <= 0.0 {
            // No speed at all inside the path: the axis whose speed bound is zero.
            let axis = (0..path.axes)
                .max_by(|&a, &b| {
                    let da = slopes.after[k][a].0.abs() / limits.axis_speed[a];
                    let db = slopes.after[k][b].0.abs() / limits.axis_speed[b];
                    da.total_cmp(&db)
                })
                .unwrap_or(0);
            return Err(TimingError::Stuck { knot: k, axis });
        }
    }
    Ok(())
}

impl Timing {
    /// The time-optimal timing of `path` within `limits`, from rest to rest.
    pub fn optimal(path: &JointPath, limits: &Limits<'_>) -> Result<Timing, TimingError> {
        Timing::from_speed(path, limits, 0.0)
    }

    /// The time-optimal timing of `path` within `limits` from the path speed `ṡ² = x0`
    /// at its start (a robot already moving: a corner taking over from the motion before)
    /// to rest at its end; [`TimingError::TooFast`] where no timing within the limits can
    /// start that fast.
    pub fn from_speed(
        path: &JointPath,
        limits: &Limits<'_>,
        x0: f64,
    ) -> Result<Timing, TimingError> {
        if x0.is_nan() || x0 < 0.0 || x0.is_infinite() {
            return Err(TimingError::BadLimit(x0));
        }
        let mut slopes = KnotSlopes::new();
        checked_slopes(path, limits, &mut slopes)?;
        let mut lines = [Line::NONE; LINES];
        let mut reach = [0.0f64; KNOTS];
        backward(path, &slopes, limits, SEGMENTS, &mut reach, &mut lines)?;
        if x0 > reach[0] {
            return Err(TimingError::TooFast { largest: reach[0] });
        }
        // Forward: from x0, the largest u that keeps x_{k+1} controllable.
        let mut x = [0.0f64; KNOTS];
        let mut t = [0.0f64; KNOTS];
        x[0] = x0;
        for k in 0..SEGMENTS {
            let two_delta = 2.0 * path.step(k);
            let m = step_lines(path, &slopes, limits, k, &mut lines);
            let u_max = largest_u(&lines[..m], x[k]);
            let u = u_max.min((reach[k + 1] - x[k]) / two_delta);
            x[k + 1] = (x[k] + two_delta * u).clamp(0.0, reach[k + 1]);
            let (v0, v1) = (x[k].sqrt(), x[k + 1].sqrt());
            let dt = if v0 + v1 > 0.0 {
                two_delta / (v0 + v1)
            } else {
                0.0
            };
            t[k + 1] = t[k] + dt;
        }
        if x[1..SEGMENTS].iter().any(|v| *v <= 0.0) {
            let knot = x[1..SEGMENTS]
                .iter()
                .position(|v| *v <= 0.0)
                .map_or(0, |p| p + 1);
            return Err(TimingError::Stuck { knot, axis: 0 });
        }
        let mut curve = [(0.0, 0.0); SEGMENTS];
        for (k, bc) in curve.iter_mut().enumerate() {
            bc.0 = (x[k + 1] - x[k]) / (2.0 * path.step(k));
        }
        Ok(Timing {
            x,
            t,
            s: path.knots,
            curve,
            smooth: false,
        })
    }

    /// The controllable sets of `path` within `limits` for stopping at knot `until`: at
    /// each knot up to it, the largest `ṡ²` from which the path can still come to rest at
    /// `until` (TOPP-RA's backward pass; 0 from `until` on). Where the path cannot move at
    /// all before `until`, the error says where.
    pub fn stopping_at(
        path: &JointPath,
        limits: &Limits<'_>,
        until: usize,
    ) -> Result<[f64; KNOTS], TimingError> {
        let mut slopes = KnotSlopes::new();
        checked_slopes(path, limits, &mut slopes)?;
        let mut lines = [Line::NONE; LINES];
        let mut reach = [0.0f64; KNOTS];
        backward(
            path,
            &slopes,
            limits,
            until.min(SEGMENTS),
            &mut reach,
            &mut lines,
        )?;
        Ok(reach)
    }

    /// `ṡ²` at knot `k` (1/s²).
    pub fn state_at_knot(&self, k: usize) -> f64 {
        self.x[k.min(SEGMENTS)]
    }

    /// The time (s) the path reaches knot `k`.
    pub fn time_at_knot(&self, k: usize) -> f64 {
        self.t[k.min(SEGMENTS)]
    }

    /// Where knot `k` is on the path (`s`, 0 to 1).
    pub fn knot(&self, k: usize) -> f64 {
        self.s[k.min(SEGMENTS)]
    }

    /// The same timing `factor` (≥ 1) times slower: every speed divided by it, every
    /// acceleration by its square (a factor that is not a positive finite number: the
    /// same timing).
    pub fn slower(&self, factor: f64) -> Timing {
        let mut out = self.clone();
        if !(factor.is_finite() && factor > 0.0) {
            return out;
        }
        for x in &mut out.x {
            *x /= factor * factor;
        }
        for t in &mut out.t {
            *t *= factor;
        }
        for (b, c) in &mut out.curve {
            *b /= factor * factor;
            *c /= factor * factor;
        }
        out
    }

    /// `ṡ²` at knot `k` and the path acceleration `s̈` over step `k` (from knot `k` to
    /// `k + 1`): the timing's state anywhere on the step is `x_k + 2·s̈·(s − s_k)`. For a
    /// smooth timing, whose `s̈` changes along the step, the step's mean `s̈` (the same
    /// `x` at both its knots; [`Timing::state_at_place`] gives the state anywhere).
    pub fn step_state(&self, k: usize) -> (f64, f64) {
        let k = k.min(SEGMENTS - 1);
        let delta = self.s[k + 1] - self.s[k];
        (self.x[k], (self.x[k + 1] - self.x[k]) / (2.0 * delta))
    }

    /// How long the path takes (s).
    pub fn duration(&self) -> f64 {
        self.t[SEGMENTS]
    }

    /// The largest path speed `ṡ` it reaches (1/s).
    pub fn top_speed(&self) -> f64 {
        let knots = self.x.iter().fold(0.0f64, |m, x| m.max(*x));
        if !self.smooth {
            return knots.sqrt();
        }
        // (A step whose s̈ falls through 0 peaks inside it.)
        let mut top = knots;
        for k in (0..SEGMENTS).filter(|k| !self.rest_step(*k)) {
            let (b, c) = self.curve[k];
            let sigma = if c < 0.0 { -b / c } else { -1.0 };
            if sigma > 0.0 && sigma < self.s[k + 1] - self.s[k] {
                top = top.max(self.x[k] + b * sigma);
            }
        }
        top.sqrt()
    }

    /// Whether `s̈` is continuous ([`Timing::jerk_limited`]).
    pub fn is_smooth(&self) -> bool {
        self.smooth
    }

    /// The path speed at knot `k` (1/s).
    pub fn speed_at_knot(&self, k: usize) -> f64 {
        self.x[k.min(SEGMENTS)].sqrt()
    }

    /// The step a time falls in, and the time into it.
    fn step_of(&self, time: f64) -> (usize, f64) {
        // The last knot at or before `time`.
        let k = self.t[..SEGMENTS]
            .partition_point(|tk| *tk <= time)
            .saturating_sub(1);
        (k, time - self.t[k])
    }

    /// Where the path is at `time` seconds from its start (its start before, its end
    /// after).
    pub fn at(&self, time: f64) -> PathState {
        if self.smooth && self.moving() && time <= 0.0 {
            return self.smooth_at(0, 0.0);
        }
        if time.is_nan() || time <= 0.0 {
            return PathState {
                s: 0.0,
                speed: self.x[0].sqrt(),
                accel: 0.0,
            };
        }
        if time >= self.duration() {
            return PathState {
                s: 1.0,
                speed: 0.0,
                accel: 0.0,
            };
        }
        let (k, tau) = self.step_of(time);
        if self.smooth {
            return self.smooth_at(k, tau);
        }
        let (_, u) = self.step_state(k);
        let v0 = self.x[k].sqrt();
        let s = (self.s[k] + v0 * tau + 0.5 * u * tau * tau).clamp(0.0, 1.0);
        PathState {
            s,
            speed: (v0 + u * tau).max(0.0),
            accel: u,
        }
    }

    /// The time (s) at which the path reaches fraction `s`.
    pub fn time_at(&self, s: f64) -> f64 {
        if s.is_nan() || s <= 0.0 {
            return 0.0;
        }
        if s >= 1.0 {
            return self.duration();
        }
        // The last knot at or before s.
        let k = self.s[..SEGMENTS]
            .partition_point(|sk| *sk <= s)
            .saturating_sub(1);
        let ds = s - self.s[k];
        if self.smooth {
            return self.t[k] + self.smooth_time_in(k, ds);
        }
        let (_, u) = self.step_state(k);
        let v0 = self.x[k].sqrt();
        // ½u·τ² + v0·τ = ds, in the form that does not cancel.
        let root = (v0 * v0 + 2.0 * u * ds).max(0.0).sqrt();
        let tau = if v0 + root > 0.0 {
            2.0 * ds / (v0 + root)
        } else {
            0.0
        };
        self.t[k] + tau
    }
}

mod jerk;
pub use jerk::{JerkStart, StepThirds};
mod lp;
#[cfg(test)]
mod tests;

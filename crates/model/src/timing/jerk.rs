//! Jerk-limited timing of a path ([`Timing::jerk_limited`]): the fastest timing found of
//! `q(s)` from rest (or, [`Timing::jerk_limited_from`], from a robot already moving: a
//! corner taking over) to rest within every axis's speed, acceleration *and jerk* and the
//! path's own speed and acceleration, and what such a *smooth* timing is at any time.
//!
//! **The timing.** `s̈` is continuous: at each knot it is `u_k`, and on each step it is
//! linear in `s` (`s̈ = b_k + c_k·σ` at `σ = s − s_k`, so `ṡ² = x_k + 2b_k·σ + c_k·σ²` and
//! the path's jerk `s⃛ = c_k·ṡ`); the first step starts from rest at a constant `s⃛` (`s ∝
//! t³`, so `x₁ = 3/2·Δ₀·u₁`) and the last comes to rest at one. On a step `σ̈ = b + c·σ` is
//! linear: `σ(t)` is closed-form (hyperbolic, trigonometric, or its series where `c·t²` is
//! small), so the timing is exact at any time, with no integration.
//!
//! **The program.** An axis's jerk is `ṡ·(q′·c + 3q″·u + q‴·x)` (`c` the step's, `u` and
//! `x` the knot's): linear in the unknowns but for the factor `ṡ = √x`. The constraint
//! `|q′c + 3q″u + q‴x| ≤ j/√x` has a convex right-hand side; its tangent at a guess `x̂`,
//! `j·(3/2 − x/(2x̂))/√x̂`, lies below it, so the linear program with the tangents is
//! *inside* the true constraints: every solution keeps them, and the next tangents at it
//! keep it feasible (sequential convex programming, the convex–concave procedure:
//! Debrouwere et al., "Time-optimal path following for robots with convex–concave
//! constraints using sequential convex programming", IEEE T-RO 2013). Every other limit is
//! linear in `(x_k, u_k)`, at the knots and halfway along each step (where `x` and `u` are
//! linear in the unknowns too). The objective is the largest `Σ x_k` (as bench/jerk.py's
//! oracle: without jerk limits this is the time-optimal timing exactly; with them it is a
//! close proxy for the least time). The programs are solved by [`super::lp`], an
//! interior-point solver for programs banded along a path (deterministic; tested against
//! Clarabel). The first tangents are at the timing without jerk limits
//! ([`Timing::optimal`]), capped near the ends by what a constant jerk from rest can
//! reach, and the rounds stop when `Σ x` grows by less than [`SETTLED`] of itself, or a
//! program finds no solution (the best so far is kept; none at all: an error, and the
//! caller keeps its S-curve).
//!
//! The jerk is kept at the knots (with the step's `c` on either side) and the speeds and
//! accelerations at the knots and halfway: between, the path's curvature moves them a
//! little, which the caller's margin and checks take up (as for [`Timing::optimal`]).

use super::lp::{self, Program, SparseRows};
use super::{JointPath, KNOTS, KnotSlopes, Limits, NORMAL_FACES, PathState, SEGMENTS, Timing};
use super::{TimingError, checked_slopes};
use crate::ik::MAX_AXES;

/// Rounds of linear programs at most.
const MAX_ROUNDS: usize = 12;
/// The rounds stop when `Σ x` grows by less than this share of itself.
const SETTLED: f64 = 1e-3;
/// How close (relative) to its tangent's point every knot's `ṡ²` must be for the first
/// program from a given guess to be kept as it is: the tangent `(3/2 − r/2)·√r` of the
/// true bound at `r = x/x̂` is within 0.1 % of it for `r` within 5 % of 1.
const CLOSE_TANGENT: f64 = 0.05;
/// Terms of the series of a step's `σ(t)` where `|c|·t² ≤ 1` (the next is below 1e-19 of
/// the first).
const SERIES_TERMS: usize = 11;

/// The linear program's rows: the equalities (one per step, in order) and the `≤` rows.
#[derive(Clone)]
struct Rows {
    eq: SparseRows,
    ineq: SparseRows,
    /// Column scales: each `x_k` is solved for in units of its first guess (from the
    /// largest without jerk limits, near the ends far less), each `u_k` in units of the
    /// largest `s̈` without jerk limits.
    scale: Vec<f64>,
    /// `x` and `u` at the first knot (given: 0 from rest, else the robot's state).
    start: (f64, f64),
}

/// No column: `x` and `u` at the last knot, which are 0 (rest).
const NONE: usize = usize::MAX;
/// No column: `x` at the first knot, given ([`Rows::start`]).
const X_START: usize = usize::MAX - 1;
/// No column: `u` at the first knot, given.
const U_START: usize = usize::MAX - 2;
/// Unknowns: `x_k` and `u_k` for the knots between the ends.
const UNKNOWNS: usize = 2 * (KNOTS - 2);

impl Rows {
    fn new(scale: Vec<f64>, start: (f64, f64)) -> Rows {
        Rows {
            eq: SparseRows::new(),
            ineq: SparseRows::new(),
            scale,
            start,
        }
    }

    /// Whether the timing starts moving (not from rest).
    fn moving(&self) -> bool {
        self.start.0 > 0.0
    }

    /// `terms` in the scaled unknowns, the ends' left out.
    fn scaled_terms<'a>(
        &'a self,
        terms: &'a [(usize, f64)],
    ) -> impl Iterator<Item = (usize, f64)> + 'a {
        terms
            .iter()
            .filter(|(v, _)| *v < self.scale.len())
            .map(|&(v, a)| (v, a * self.scale[v]))
    }

    /// What `terms` add up to at the ends, where `x` and `u` are given.
    fn given(&self, terms: &[(usize, f64)]) -> f64 {
        terms
            .iter()
            .map(|&(v, a)| match v {
                X_START => a * self.start.0,
                U_START => a * self.start.1,
                _ => 0.0,
            })
            .sum()
    }

    /// One row `Σ coef·var ≤ rhs` over `(var, coef)`, scaled to a right-hand side of 1
    /// where it is positive.
    fn push(&mut self, terms: &[(usize, f64)], rhs: f64) {
        // (No limit: no row. A row of the given start alone — no unknown in it, or none
        // with a coefficient — is the robot's state, not the program's to choose.)
        if rhs.is_infinite() || self.scaled_terms(terms).all(|(_, a)| a == 0.0) {
            return;
        }
        let rhs = rhs - self.given(terms);
        let norm = if rhs > 0.0 {
            rhs
        } else {
            self.scaled_terms(terms)
                .map(|(_, a)| a.abs())
                .fold(0.0, f64::max)
                .max(f64::MIN_POSITIVE)
        };
        let entries: Vec<(usize, f64)> = self
            .scaled_terms(terms)
            .map(|(v, a)| (v, a / norm))
            .collect();
        self.ineq.push(entries, rhs / norm);
    }

    /// One equality `Σ coef·var = 0`.
    fn push_eq(&mut self, terms: &[(usize, f64)]) {
        let entries: Vec<(usize, f64)> = self.scaled_terms(terms).collect();
        let norm = entries
            .iter()
            .map(|(_, a)| a.abs())
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        let rhs = -self.given(terms) / norm;
        self.eq
            .push(entries.into_iter().map(|(v, a)| (v, a / norm)), rhs);
    }
}

/// `x_k`'s column ([`X_START`] and [`NONE`] at the ends).
fn xi(k: usize) -> usize {
    if k == 0 {
        X_START
    } else if k >= SEGMENTS {
        NONE
    } else {
        2 * (k - 1)
    }
}

/// `u_k`'s column ([`U_START`] and [`NONE`] at the ends).
fn ui(k: usize) -> usize {
    if k == 0 {
        U_START
    } else if k >= SEGMENTS {
        NONE
    } else {
        2 * (k - 1) + 1
    }
}

/// The band order of the programs' Newton systems: per knot `x_k`, `u_k`, then the
/// equality of the step after it (the first step's before knot 1): `x_k` at `3k − 2`,
/// `u_k` at `3k − 1`, step `j`'s equality at `3j`. The widest row spans four places: a
/// jerk row at knot `k` with the step after it (`x_k`, `u_k`, `u_{k+1}`) and a step's
/// middle (`x` and `u` of both its knots).
fn band_places() -> Vec<usize> {
    let mut place = vec![0; UNKNOWNS + SEGMENTS];
    for k in 1..SEGMENTS {
        place[xi(k)] = 3 * k - 2;
        place[ui(k)] = 3 * k - 1;
    }
    for j in 0..SEGMENTS {
        place[UNKNOWNS + j] = 3 * j;
    }
    place
}

/// The half-band of the programs' Newton systems ([`band_places`]).
const BAND: usize = 4;

/// Step `j`'s `c` (`s⃛ = c·ṡ`) as terms in the `u`: from rest at a constant jerk on the
/// first step (`u₁/(3Δ)`; unless `moving`), to rest on the last (`−u/(3Δ)`),
/// `(u_{j+1} − u_j)/Δ` between.
fn step_c(j: usize, delta: f64, moving: bool) -> [(usize, f64); 2] {
    if j == 0 && !moving {
        [(ui(1), 1.0 / (3.0 * delta)), (ui(0), 0.0)]
    } else if j == SEGMENTS - 1 {
        [(ui(j), -1.0 / (3.0 * delta)), (ui(j + 1), 0.0)]
    } else {
        [(ui(j + 1), 1.0 / delta), (ui(j), -1.0 / delta)]
    }
}

/// A column and its coefficient in a row.
type Term = (usize, f64);

/// Step `j`'s state halfway as terms: `(x, u)` there (the first step from rest unless
/// `moving`).
fn step_middle(j: usize, delta: f64, moving: bool) -> ([Term; 4], [Term; 2]) {
    // (From and to rest at a constant jerk: x ∝ t⁴ and u ∝ t, t ∝ σ^⅓.)
    let (x_end, u_end) = (0.5f64.powf(4.0 / 3.0), 0.5f64.cbrt());
    if j == 0 && !moving {
        (
            [(xi(1), x_end), (xi(0), 0.0), (ui(0), 0.0), (ui(1), 0.0)],
            [(ui(1), u_end), (ui(0), 0.0)],
        )
    } else if j == SEGMENTS - 1 {
        (
            [
                (xi(j), x_end),
                (xi(j + 1), 0.0),
                (ui(j), 0.0),
                (ui(j + 1), 0.0),
            ],
            [(ui(j), u_end), (ui(j + 1), 0.0)],
        )
    } else {
        (
            [
                (xi(j), 0.5),
                (xi(j + 1), 0.5),
                (ui(j + 1), -0.25 * delta),
                (ui(j), 0.25 * delta),
            ],
            [(ui(j), 0.5), (ui(j + 1), 0.5)],
        )
    }
}

/// `a·(terms)` appended to `out`.
fn scaled(out: &mut Vec<(usize, f64)>, a: f64, terms: &[(usize, f64)]) {
    out.extend(terms.iter().map(|&(v, c)| (v, a * c)));
}

/// Each step's `q‴` per axis at its start and its end: the differences of `q″` across it
/// (the same at both), or `given` (a caller's finer estimate, as from points between the
/// knots: where `q‴` jumps at a knot — a curve whose curvature begins there — differences
/// of the knots' `q″` smear the jump over the steps on both sides).
fn third_slopes(
    path: &JointPath,
    slopes: &KnotSlopes,
    given: Option<&[StepThirds]>,
) -> Vec<StepThirds> {
    (0..SEGMENTS)
        .map(|j| {
            if let Some(d3) = given.and_then(|g| g.get(j)) {
                return *d3;
            }
            let mut d3 = [(0.0, 0.0); MAX_AXES];
            for (i, d) in d3.iter_mut().enumerate().take(path.axes) {
                let v = (slopes.before[j + 1][i].1 - slopes.after[j][i].1) / path.step(j);
                *d = (v, v);
            }
            d3
        })
        .collect()
}

/// A step's `q‴` per axis at its start and at its end ([`Timing::jerk_limited_from`]).
pub type StepThirds = [(f64, f64); MAX_AXES];

/// Where a jerk-limited timing starts, and what its caller knows of the path
/// ([`Timing::jerk_limited_from`]; the default: from rest, knowing nothing more).
#[derive(Clone, Copy, Debug, Default)]
pub struct JerkStart<'a> {
    /// `ṡ²` and `s̈` at the path's start (`(0, 0)`: rest; a corner taking over from the
    /// motion before: the robot's).
    pub state: (f64, f64),
    /// Each step's `q‴` per axis at its start and end where the caller knows it better
    /// than differences of the knots' `q″` (one per step; `None`: those differences).
    pub third: Option<&'a [StepThirds]>,
    /// The first tangents' `ṡ²` per knot (all positive between the ends), where the
    /// caller has a timing close to the one sought — the same path timed before within
    /// other limits — in place of the timing without jerk limits: fewer programs.
    pub guess: Option<&'a [f64; KNOTS]>,
}

/// The rows every round shares: the start given or from rest, rest at the end, the
/// steps' consistency, and every speed and acceleration at the knots and halfway.
fn fixed_rows(path: &JointPath, slopes: &KnotSlopes, lim: &Limits<'_>, rows: &mut Rows) {
    let n = SEGMENTS;
    let moving = rows.moving();
    // Equalities, one per step in order: from rest at a constant jerk (or from the given
    // start as any step); x_{k+1} − x_k = Δ(u_k + u_{k+1}); to rest at a constant jerk.
    // (At the ends x and u are given: no unknowns.)
    if !moving {
        rows.push_eq(&[(xi(1), 1.0), (ui(1), -1.5 * path.step(0))]);
    }
    for k in usize::from(!moving)..n - 1 {
        let d = path.step(k);
        rows.push_eq(&[
            (xi(k + 1), 1.0),
            (xi(k), -1.0),
            (ui(k), -d),
            (ui(k + 1), -d),
        ]);
    }
    rows.push_eq(&[(xi(n - 1), 1.0), (ui(n - 1), 1.5 * path.step(n - 1))]);
    let curved = lim.path_whole.is_finite() && lim.path_normal > 0.0;
    let mut terms: Vec<(usize, f64)> = Vec::with_capacity(8);
    // The limits at a point whose (x, u) are `x` and `u` (terms), slopes `d` per axis,
    // room `room`, and the path's own limits there if they change along it (`x_max`,
    // tangent, normal, whole: [`crate::timing::KnotLimits`]).
    let mut point = |rows: &mut Rows,
                     x: &[(usize, f64)],
                     u: &[(usize, f64)],
                     d: &dyn Fn(usize) -> (f64, f64),
                     room: f64,
                     along: Option<[f64; 4]>| {
        let mut x_max = lim.path_speed * lim.path_speed;
        if let Some([most, ..]) = along {
            x_max = x_max.min(most);
        }
        for i in 0..path.axes {
            let (d1, d2) = d(i);
            let amax = lim.axis_accel[i] * room;
            for sign in [1.0, -1.0] {
                terms.clear();
                scaled(&mut terms, sign * d1, u);
                scaled(&mut terms, sign * d2, x);
                rows.push(&terms, amax);
            }
            if d1 != 0.0 {
                let v = lim.axis_speed[i] * room / d1.abs();
                x_max = x_max.min(v * v);
            }
        }
        if x_max.is_finite() {
            rows.push(x, x_max);
        }
        terms.clear();
        scaled(&mut terms, -1.0, x);
        rows.push(&terms, 0.0);
        if lim.path_accel.is_finite() {
            for sign in [1.0, -1.0] {
                terms.clear();
                scaled(&mut terms, sign, u);
                rows.push(&terms, lim.path_accel);
            }
        }
        // The TCP's acceleration along the path (u + tangent·x) and across it (normal·x)
        // inside the polygon in the half disk of `whole` (as `Timing::optimal`'s).
        let polygon = match along {
            Some([_, tg, nm, whole]) => Some((tg, nm, whole)).filter(|_| whole.is_finite()),
            None => curved.then_some((0.0, lim.path_normal, lim.path_whole)),
        };
        if let Some((tg, nm, whole)) = polygon {
            let face = whole * (std::f64::consts::PI / (2.0 * NORMAL_FACES as f64)).cos();
            // (Where the path does not curve, w = 0: the faces bound the acceleration along
            // it alone, and only the two most nearly along it bind.)
            let binds = |j: &usize| nm != 0.0 || *j == 0 || *j == NORMAL_FACES - 1;
            for j in (0..NORMAL_FACES).filter(binds) {
                let alpha = (j as f64 + 0.5) * std::f64::consts::PI / NORMAL_FACES as f64;
                let (sin, cos) = alpha.sin_cos();
                terms.clear();
                scaled(&mut terms, cos, u);
                scaled(&mut terms, cos * tg + sin * nm, x);
                rows.push(&terms, face);
            }
        }
    };
    // The path's own limits at knot `k`, and halfway along step `j` (the tighter speed
    // and whole acceleration, the mean curvature).
    let at_knot = |k: usize| {
        lim.along
            .map(|al| [al.x_max[k], al.tangent[k], al.normal[k], al.whole[k]])
    };
    let halfway = |j: usize| {
        lim.along.map(|al| {
            [
                al.x_max[j].min(al.x_max[j + 1]),
                0.5 * (al.tangent[j] + al.tangent[j + 1]),
                0.5 * (al.normal[j] + al.normal[j + 1]),
                al.whole[j].min(al.whole[j + 1]),
            ]
        })
    };
    for k in 1..n {
        let (x, u) = ([(xi(k), 1.0)], [(ui(k), 1.0)]);
        let before = |i: usize| slopes.before[k][i];
        let after = |i: usize| slopes.after[k][i];
        point(rows, &x, &u, &before, path.room[k - 1], at_knot(k));
        let same = (0..path.axes).all(|i| slopes.before[k][i] == slopes.after[k][i]);
        if !same || path.room[k] != path.room[k - 1] {
            point(rows, &x, &u, &after, path.room[k], at_knot(k));
        }
    }
    for j in 0..n {
        let delta = path.step(j);
        let (x, u) = step_middle(j, delta, moving);
        let middle = |i: usize| {
            (
                (path.q[j + 1][i] - path.q[j][i]) / delta,
                0.5 * (slopes.after[j][i].1 + slopes.before[j + 1][i].1),
            )
        };
        point(rows, &x, &u, &middle, path.room[j], halfway(j));
    }
}

/// The jerk rows at the tangents at `guess` (`x̂` per knot; at a given start, its `x`: the
/// row is exact there): every axis with a jerk limit, at every knot, with the step's `c`
/// on either side.
fn jerk_rows(
    path: &JointPath,
    slopes: &KnotSlopes,
    d3: &[StepThirds],
    jerk: &[f64],
    guess: &[f64; KNOTS],
    rows: &mut Rows,
) {
    let n = SEGMENTS;
    let moving = rows.moving();
    let mut terms: Vec<(usize, f64)> = Vec::with_capacity(8);
    for (i, &j) in jerk.iter().enumerate().take(path.axes) {
        if !j.is_finite() {
            continue;
        }
        // |g| ≤ j/√x at knot k, by its tangent at x̂: g·sign + j/(2x̂^{3/2})·x ≤ 3j/(2√x̂).
        for k in 0..=n {
            // (At the ends ṡ = 0: the jerk is q′·s⃛ of the end step, s⃛ = c·ṡ of its
            // other knot. A given start is a knot as any other, its step after it.)
            let (at, steps): (usize, &[usize]) = if k == 0 && moving {
                (0, &[0])
            } else if k == 0 {
                (1, &[0])
            } else if k == n {
                (n - 1, &[n - 1])
            } else {
                (k, &[k - 1, k])
            };
            let xh = guess[at];
            if xh <= 0.0 {
                continue;
            }
            let root = xh.sqrt();
            let (rhs, slope) = (1.5 * j / root, 0.5 * j / (xh * root));
            for &step in steps {
                let (d1, d2) = if step < k || k == n {
                    slopes.before[k][i]
                } else {
                    slopes.after[k][i]
                };
                let c = step_c(step, path.step(step), moving);
                for sign in [1.0, -1.0] {
                    terms.clear();
                    scaled(&mut terms, sign * d1, &c);
                    if (k != 0 || moving) && k != n {
                        terms.push((ui(k), sign * 3.0 * d2));
                        // (The step's q‴ at this knot: its end's if it ends here.)
                        let (d3_start, d3_end) = d3[step][i];
                        let d3 = if step < k { d3_end } else { d3_start };
                        terms.push((xi(k), sign * d3));
                    }
                    terms.push((xi(at), slope));
                    rows.push(&terms, rhs);
                }
            }
        }
    }
}

impl Timing {
    /// The fastest timing found of `path` from rest to rest within `limits` and every
    /// axis's jerk `axis_jerk` (`f64::INFINITY`: none): a smooth timing (see the module's
    /// doc). Where the programs find no timing, [`TimingError::Stuck`] (a path that can
    /// move has one: rest is inside every program's rows).
    pub fn jerk_limited(
        path: &JointPath,
        limits: &Limits<'_>,
        axis_jerk: &[f64],
    ) -> Result<Timing, TimingError> {
        Timing::jerk_limited_from(path, limits, axis_jerk, &JerkStart::default())
    }

    /// [`Timing::jerk_limited`] from where `from` says (a robot already moving: its first
    /// step a step as any other), with what it knows of the path. Where no timing within
    /// the limits continues from a moving start (it is too fast to brake in time, or its
    /// acceleration cannot turn soon enough), [`TimingError::Stuck`] or
    /// [`TimingError::TooFast`].
    pub fn jerk_limited_from(
        path: &JointPath,
        limits: &Limits<'_>,
        axis_jerk: &[f64],
        from: &JerkStart<'_>,
    ) -> Result<Timing, TimingError> {
        let JerkStart {
            state: start,
            third,
            guess: given_guess,
        } = *from;
        let (x0, u0) = start;
        if !(x0.is_finite() && x0 >= 0.0) {
            return Err(TimingError::BadLimit(x0));
        }
        if !u0.is_finite() || (x0 == 0.0 && u0 != 0.0) {
            return Err(TimingError::BadLimit(u0));
        }
        let moving = x0 > 0.0;
        if axis_jerk.len() < path.axes {
            return Err(TimingError::BadLimit(f64::NAN));
        }
        if let Some(j) = axis_jerk[..path.axes]
            .iter()
            .find(|j| j.is_nan() || **j <= 0.0)
        {
            return Err(TimingError::BadLimit(*j));
        }
        // (A robot a little faster than the timing without jerk limits can start — its
        // rows at the given start are not the programs' — has its first tangents at the
        // fastest start that timing finds: the programs say whether it can go on.)
        let unjerked = match Timing::from_speed(path, limits, x0) {
            Err(TimingError::TooFast { largest }) if moving && largest > 0.0 => {
                Timing::from_speed(path, limits, largest)?
            }
            found => found?,
        };
        let mut slopes = KnotSlopes::new();
        checked_slopes(path, limits, &mut slopes)?;
        let d3 = third_slopes(path, &slopes, third);
        let x_scale = unjerked.x.iter().fold(0.0f64, |m, x| m.max(*x));
        let u_scale = (0..SEGMENTS)
            .map(|k| unjerked.step_state(k).1.abs())
            .fold(0.0f64, f64::max);
        if !(x_scale > 0.0 && u_scale > 0.0 && x_scale.is_finite() && u_scale.is_finite()) {
            return Err(TimingError::Stuck { knot: 0, axis: 0 });
        }
        // The first tangents: at the timing without jerk limits, but near the ends (the
        // last, and the first from rest) no faster than the largest constant jerk the
        // axes allow there reaches from rest (s = J·t³/6 and ṡ = J·t²/2: ṡ² =
        // 6^{4/3}/4·J^{2/3}·s^{4/3} at s from rest). At a given start, its own `x`.
        let mut guess = unjerked.x;
        if let Some(given) = given_guess.filter(|g| g[1..SEGMENTS].iter().all(|x| *x > 0.0)) {
            guess = *given;
        }
        for (k, g) in guess
            .iter_mut()
            .enumerate()
            .filter(|_| given_guess.is_none())
        {
            let path_jerk = (0..path.axes)
                .filter(|i| axis_jerk[*i].is_finite())
                .map(|i| axis_jerk[i] / slopes.after[k][i].0.abs())
                .fold(f64::INFINITY, f64::min);
            let to_rest = 1.0 - path.knot(k);
            let from_rest = if moving {
                to_rest
            } else {
                path.knot(k).min(to_rest)
            };
            if path_jerk.is_finite() {
                let reach = 6f64.powf(4.0 / 3.0) / 4.0
                    * path_jerk.powf(2.0 / 3.0)
                    * from_rest.powf(4.0 / 3.0);
                *g = g.min(reach);
            }
        }
        let mut scale = vec![u_scale; UNKNOWNS];
        for k in 1..SEGMENTS {
            scale[xi(k)] = guess[k].max(1e-9 * x_scale);
        }
        guess[0] = x0;
        let mut fixed = Rows::new(scale, start);
        fixed_rows(path, &slopes, limits, &mut fixed);
        let place = band_places();
        let mut best: Option<([f64; KNOTS], [f64; KNOTS], f64)> = None;
        for round in 0..MAX_ROUNDS {
            let mut rows = fixed.clone();
            jerk_rows(path, &slopes, &d3, axis_jerk, &guess, &mut rows);
            let Some((mut x, mut u)) = solve(&rows, &place) else {
                break;
            };
            (x[0], u[0]) = start;
            let total: f64 = x.iter().sum();
            // (Tangents at a given timing close to the one sought: settled at once where
            // every knot's x is within CLOSE_TANGENT of its tangent's point — there each
            // jerk row is within 0.1 % of the true bound.)
            let settled = best
                .as_ref()
                .is_some_and(|b| total <= b.2 * (1.0 + SETTLED))
                || (round == 0
                    && given_guess.is_some()
                    && (1..SEGMENTS).all(|k| (x[k] - guess[k]).abs() <= CLOSE_TANGENT * guess[k]));
            if best.as_ref().is_none_or(|b| total > b.2) {
                best = Some((x, u, total));
            }
            if settled {
                break;
            }
            for (g, x) in guess.iter_mut().zip(&x) {
                *g = x.max(1e-9 * x_scale);
            }
        }
        let (x, u, _) = best.ok_or(TimingError::Stuck { knot: 0, axis: 0 })?;
        Timing::smooth_from(path, &x, &u)
    }

    /// The smooth timing with `ṡ²` and `s̈` at the knots `x` and `u` (both 0 at the end,
    /// and at the start unless `x₀ > 0`).
    fn smooth_from(
        path: &JointPath,
        x: &[f64; KNOTS],
        u: &[f64; KNOTS],
    ) -> Result<Timing, TimingError> {
        let n = SEGMENTS;
        if let Some(k) = (1..n).find(|&k| !(x[k] > 0.0 && x[k].is_finite())) {
            return Err(TimingError::Stuck { knot: k, axis: 0 });
        }
        let mut out = Timing {
            x: *x,
            t: [0.0; KNOTS],
            s: path.knots,
            curve: [(0.0, 0.0); SEGMENTS],
            smooth: true,
        };
        out.x[0] = x[0].max(0.0);
        out.x[n] = 0.0;
        let first = usize::from(!out.moving());
        for k in first..n - 1 {
            let d = path.step(k);
            let c = (u[k + 1] - u[k]) / d;
            let b = 0.5 * ((x[k + 1] - x[k]) / d - c * d);
            // (ṡ² stays positive inside the step: its least value.)
            let sigma = if c > 0.0 { -b / c } else { -1.0 };
            if sigma > 0.0 && sigma < d && x[k] + b * sigma <= 0.0 {
                return Err(TimingError::Stuck { knot: k, axis: 0 });
            }
            out.curve[k] = (b, c);
        }
        let mut t = 0.0;
        for k in 0..n {
            let d = path.step(k);
            let dt = if k == 0 && first == 1 {
                3.0 * d / x[1].sqrt()
            } else if k == n - 1 {
                3.0 * d / x[k].sqrt()
            } else {
                let (b, c) = out.curve[k];
                step_duration(x[k].sqrt(), x[k + 1].sqrt(), b, c, d)
                    .ok_or(TimingError::Stuck { knot: k, axis: 0 })?
            };
            t += dt;
            out.t[k + 1] = t;
        }
        Ok(out)
    }

    /// The path's state where it has reached `s`: `(ṡ², s̈, s⃛)` (`s⃛` 0 but on a smooth
    /// timing: a timing within the accelerations changes `s̈` only at its knots).
    pub fn state_at_place(&self, s: f64) -> (f64, f64, f64) {
        let s = s.clamp(0.0, 1.0);
        let k = self.s[..SEGMENTS]
            .partition_point(|sk| *sk <= s)
            .saturating_sub(1);
        let d = self.s[k + 1] - self.s[k];
        let sigma = (s - self.s[k]).clamp(0.0, d);
        let (b, c) = self.curve[k];
        if !self.smooth {
            return (self.x[k] + 2.0 * b * sigma, b, 0.0);
        }
        if self.rest_step(k) {
            // From or to rest at a constant jerk: x ∝ t⁴, s̈ ∝ t, t ∝ (the distance
            // from rest)^⅓.
            let (end, from_rest) = if k == 0 { (1, sigma) } else { (k, d - sigma) };
            let x_end = self.x[end];
            let (_, _, jerk) = self.end_step(k);
            let share = (from_rest / d).clamp(0.0, 1.0);
            let accel = 2.0 * x_end / (3.0 * d) * share.cbrt();
            let x = x_end * share * share.cbrt();
            return if k == 0 {
                (x, accel, jerk)
            } else {
                (x, -accel, jerk)
            };
        }
        let x = (self.x[k] + 2.0 * b * sigma + c * sigma * sigma).max(0.0);
        (x, b + c * sigma, c * x.sqrt())
    }

    /// The largest path speed `ṡ` on step `k` (1/s).
    pub fn step_top_speed(&self, k: usize) -> f64 {
        let k = k.min(SEGMENTS - 1);
        let mut top = self.x[k].max(self.x[k + 1]);
        let (b, c) = self.curve[k];
        if self.smooth && c < 0.0 && !self.rest_step(k) {
            let sigma = -b / c;
            if sigma > 0.0 && sigma < self.s[k + 1] - self.s[k] {
                top = top.max(self.x[k] + b * sigma);
            }
        }
        top.sqrt()
    }

    /// Whether the timing starts moving ([`Timing::jerk_limited_from`]).
    pub fn moving(&self) -> bool {
        self.x[0] > 0.0
    }

    /// Whether step `k` of a smooth timing is from or to rest at a constant jerk (the
    /// last, and the first unless it starts moving).
    pub(super) fn rest_step(&self, k: usize) -> bool {
        (k == 0 && !self.moving()) || k == SEGMENTS - 1
    }

    /// An end step of a smooth timing (the first or the last, from or to rest at a
    /// constant jerk): its length in `s`, its duration `T` and its path jerk `J` (from
    /// rest `ṡ = J·t²/2` and `s = J·t³/6`, so `T = 3Δ/√x` and `J = 2√x/T²`, `x` at its
    /// other knot).
    fn end_step(&self, k: usize) -> (f64, f64, f64) {
        let d = self.s[k + 1] - self.s[k];
        let span = (self.t[k + 1] - self.t[k]).max(0.0);
        let v = self.x[if k == 0 { 1 } else { k }].sqrt();
        (d, span, 2.0 * v / (span * span))
    }

    /// The state `tau` seconds into step `k` of a smooth timing.
    pub(super) fn smooth_at(&self, k: usize, tau: f64) -> PathState {
        let (d, span, jerk) = self.end_step(k);
        let tau = tau.max(0.0).min(span);
        if self.rest_step(k) {
            let (sigma, speed, accel) = if k == 0 {
                (
                    jerk * tau * tau * tau / 6.0,
                    0.5 * jerk * tau * tau,
                    jerk * tau,
                )
            } else {
                let r = span - tau;
                (d - jerk * r * r * r / 6.0, 0.5 * jerk * r * r, -jerk * r)
            };
            return PathState {
                s: (self.s[k] + sigma.clamp(0.0, d)).clamp(0.0, 1.0),
                speed: speed.max(0.0),
                accel,
            };
        }
        let (b, c) = self.curve[k];
        let (sigma, speed) = advance(self.x[k].sqrt(), b, c, tau);
        let sigma = sigma.clamp(0.0, d);
        PathState {
            s: (self.s[k] + sigma).clamp(0.0, 1.0),
            speed: speed.max(0.0),
            accel: b + c * sigma,
        }
    }

    /// The time from knot `k` of a smooth timing to `ds` further along step `k`.
    pub(super) fn smooth_time_in(&self, k: usize, ds: f64) -> f64 {
        let (d, span, jerk) = self.end_step(k);
        let ds = ds.max(0.0).min(d);
        if self.rest_step(k) {
            return if k == 0 {
                (6.0 * ds / jerk).cbrt().min(span)
            } else {
                (span - (6.0 * (d - ds) / jerk).cbrt()).max(0.0)
            };
        }
        let (b, c) = self.curve[k];
        let v = self.x[k].sqrt();
        let there = (self.x[k] + 2.0 * b * ds + c * ds * ds).max(0.0).sqrt();
        let guess = if v + there > 0.0 {
            2.0 * ds / (v + there)
        } else {
            0.0
        };
        time_to(v, b, c, ds, guess, Some(span))
            .unwrap_or(guess)
            .max(0.0)
            .min(span)
    }
}

/// Newton (or bisection) steps at most for a time within a step.
const NEWTON_ROUNDS: usize = 100;

/// How long a step of length `d` takes from speed `v0` (to `v1`, its speed at the end)
/// with `σ̈ = b + c·σ` ([`time_to`] from the time at constant `s̈`).
fn step_duration(v0: f64, v1: f64, b: f64, c: f64, d: f64) -> Option<f64> {
    time_to(v0, b, c, d, 2.0 * d / (v0 + v1), None)
}

/// The time `τ` at which `σ(τ) = target` (`σ` from 0 at speed `v`, `σ̈ = b + c·σ`, its
/// speed positive up to there), from the guess `guess`, within `[0, span]` if given:
/// Newton's method kept inside a bracket that bisection narrows where a Newton step would
/// leave it (`σ` grows exponentially where `c` is large: plain Newton overshoots).
fn time_to(v: f64, b: f64, c: f64, target: f64, guess: f64, span: Option<f64>) -> Option<f64> {
    if target <= 0.0 {
        return Some(0.0);
    }
    // A bracket [lo, hi] with σ(lo) ≤ target ≤ σ(hi).
    let (mut lo, mut hi) = (0.0f64, span.unwrap_or(guess.max(f64::MIN_POSITIVE)));
    if span.is_none() {
        let mut grown = 0;
        while advance(v, b, c, hi).0 < target {
            lo = hi;
            hi *= 2.0;
            grown += 1;
            if grown > 200 || !hi.is_finite() {
                return None;
            }
        }
    }
    let mut tau = guess.clamp(lo, hi);
    for _ in 0..NEWTON_ROUNDS {
        let (sigma, speed) = advance(v, b, c, tau);
        if !sigma.is_finite() || !speed.is_finite() {
            return None;
        }
        if sigma < target {
            lo = tau;
        } else {
            hi = tau;
        }
        let newton = tau - (sigma - target) / speed;
        let next = if speed > 0.0 && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        let settled =
            (next - tau).abs() <= 1e-15 * next.max(f64::MIN_POSITIVE) || hi - lo <= 1e-15 * hi;
        tau = next;
        if settled {
            break;
        }
    }
    Some(tau)
}

/// `σ(τ)` and `σ̇(τ)` from `σ = 0`, `σ̇ = v` with `σ̈ = b + c·σ`.
fn advance(v: f64, b: f64, c: f64, tau: f64) -> (f64, f64) {
    let w = c * tau * tau;
    if w.abs() > 1.0 {
        let om = c.abs().sqrt();
        let z = om * tau;
        return if c > 0.0 {
            let (sh, ch) = (z.sinh(), z.cosh());
            (b / c * (ch - 1.0) + v / om * sh, v * ch + b / om * sh)
        } else {
            let (sn, cs) = z.sin_cos();
            (b / c * (cs - 1.0) + v / om * sn, v * cs + b / om * sn)
        };
    }
    // σ = Σ cⁿ (v·τ^{2n+1}/(2n+1)! + b·τ^{2n+2}/(2n+2)!), σ̇ its derivative.
    let (mut sigma, mut speed) = (0.0, 0.0);
    // τ^m/m! for m = 2n, and cⁿ.
    let (mut even, mut cn) = (1.0f64, 1.0f64);
    for n in 0..SERIES_TERMS {
        let m = 2 * n;
        let odd = even * tau / (m + 1) as f64;
        let next_even = odd * tau / (m + 2) as f64;
        speed += cn * (v * even + b * odd);
        sigma += cn * (v * odd + b * next_even);
        even = next_even;
        cn *= c;
    }
    (sigma, speed)
}

/// Solves the program `rows` (largest `Σ x`): the `x` and `u` at the knots, or `None` if
/// the solver finds no solution.
fn solve(rows: &Rows, place: &[usize]) -> Option<([f64; KNOTS], [f64; KNOTS])> {
    let mut q = vec![0.0; UNKNOWNS];
    for k in 1..SEGMENTS {
        q[xi(k)] = -1.0;
    }
    let program = Program {
        q: &q,
        eq: &rows.eq,
        ineq: &rows.ineq,
        place,
        band: BAND,
    };
    let z = lp::solve(&program).ok()?;
    let mut x = [0.0; KNOTS];
    let mut u = [0.0; KNOTS];
    for k in 1..SEGMENTS {
        x[k] = z[xi(k)] * rows.scale[xi(k)];
        u[k] = z[ui(k)] * rows.scale[ui(k)];
    }
    Some((x, u))
}

#[cfg(test)]
mod tests {
    //! Jerk-limited timings against the exact one-axis S-curve (worked out by hand), and
    //! the limits sampled at 1 kHz on a curved path.
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    use crate::timing::tests::path;

    fn limits<'a>(speed: &'a [f64], accel: &'a [f64]) -> Limits<'a> {
        crate::timing::tests::limits(speed, accel, f64::INFINITY, f64::INFINITY)
    }

    /// Every axis's speed, acceleration and jerk sampled every `dt` (by differences of
    /// `q(s(t))`, `q` given exactly), as ratios to the limits, the largest of each.
    fn sampled(
        t: &Timing,
        q: impl Fn(f64, usize) -> f64,
        axes: usize,
        lim: [&[f64]; 3],
    ) -> [f64; 3] {
        let dt = 1e-3;
        let steps = (t.duration() / dt).ceil() as usize + 4;
        let at = |k: isize| {
            let s = t.at(k as f64 * dt).s;
            (0..axes).map(|i| q(s, i)).collect::<Vec<_>>()
        };
        let mut worst = [0.0f64; 3];
        // (From rest, the differences begin before the start; from a robot moving, there.)
        let first = if t.moving() { 0 } else { -2 };
        for k in first..steps as isize {
            let p: Vec<Vec<f64>> = (0..4).map(|j| at(k + j)).collect();
            for i in 0..axes {
                let v = (p[1][i] - p[0][i]) / dt;
                let a = (p[2][i] - 2.0 * p[1][i] + p[0][i]) / (dt * dt);
                let j = (p[3][i] - 3.0 * p[2][i] + 3.0 * p[1][i] - p[0][i]) / (dt * dt * dt);
                worst[0] = worst[0].max(v.abs() / lim[0][i]);
                worst[1] = worst[1].max(a.abs() / lim[1][i]);
                worst[2] = worst[2].max(j.abs() / lim[2][i]);
            }
        }
        worst
    }

    /// One axis moving 2 rad at 2 rad/s, 4 rad/s², 40 rad/s³: by hand, the jerk ramps
    /// for a/j = 0.1 s, the acceleration phase lasts v/a + a/j = 0.6 s and covers
    /// v·0.6/2 = 0.6 rad, as the deceleration; 0.8 rad cruise at 2 rad/s is 0.4 s: 1.6 s
    /// in all. The timing on 256 steps is no faster and within 1 % of it, and keeps
    /// every limit sampled at 1 kHz (the jerk by third differences, within 1 %).
    #[test]
    fn one_axis_s_curve() {
        let q = |s: f64, _: usize| 2.0 * s;
        let p = path(1, q);
        let (v, a, j) = ([2.0], [4.0], [40.0]);
        let t = Timing::jerk_limited(&p, &limits(&v, &a), &j).unwrap();
        let d = t.duration();
        assert!((1.6..1.6 * 1.01).contains(&d), "{d}");
        let w = sampled(&t, q, 1, [&v, &a, &j]);
        assert!(
            w[0] <= 1.0 + 1e-5 && w[1] <= 1.0 + 1e-5 && w[2] <= 1.01,
            "{w:?}"
        );
    }

    /// The same axis taken over while moving. Cruising at 2 rad/s (`ṡ² = 1` of `q = 2s`,
    /// `s̈ = 0`): it brakes over its last 0.6 rad in 0.6 s and cruises 1.4 rad in 0.7 s,
    /// 1.3 s. At 1 rad/s and 4 rad/s² (`ṡ² = 0.25`, `s̈ = 2`): it keeps 4 rad/s² to
    /// 1.8 rad/s (0.2 s, 0.28 rad), eases to 2 rad/s in 0.1 s (1.8·0.1 + 4·0.1²/2 −
    /// 40·0.1³/6 = 0.19333 rad), brakes over 0.6 rad in 0.6 s and cruises the
    /// 0.92667 rad left in 0.46333 s: 1.36333 s. Both within 1 % and no faster, their
    /// limits kept sampled at 1 kHz from the start.
    #[test]
    fn one_axis_taken_over_while_moving() {
        let q = |s: f64, _: usize| 2.0 * s;
        let p = path(1, q);
        let (v, a, j) = ([2.0], [4.0], [40.0]);
        for (start, by_hand) in [((1.0, 0.0), 1.3), ((0.25, 2.0), 1.363_333)] {
            let from = JerkStart {
                state: start,
                ..JerkStart::default()
            };
            let t = Timing::jerk_limited_from(&p, &limits(&v, &a), &j, &from).unwrap();
            let d = t.duration();
            assert!(
                (by_hand * (1.0 - 1e-6)..by_hand * 1.01).contains(&d),
                "{start:?}: {d}"
            );
            let at0 = t.at(0.0);
            assert!((at0.speed * at0.speed - start.0).abs() < 1e-12, "{at0:?}");
            assert!((at0.accel - start.1).abs() < 1e-9, "{at0:?}");
            let w = sampled(&t, q, 1, [&v, &a, &j]);
            assert!(
                w[0] <= 1.0 + 1e-5 && w[1] <= 1.0 + 1e-5 && w[2] <= 1.01,
                "{start:?}: {w:?}"
            );
        }
        // Too fast to brake in 2 rad (1 rad/s more than the limit): no timing.
        let too_fast = JerkStart {
            state: (2.25, 0.0),
            ..JerkStart::default()
        };
        assert!(Timing::jerk_limited_from(&p, &limits(&v, &a), &j, &too_fast).is_err());
    }

    /// A curved path of two axes, and their speeds, accelerations and jerks.
    fn curved(s: f64, i: usize) -> f64 {
        if i == 0 { (3.0 * s).sin() } else { s * s }
    }
    const CURVED_LIMITS: ([f64; 2], [f64; 2], [f64; 2]) = ([1.0, 0.8], [3.0, 2.0], [30.0, 25.0]);

    /// The timing is continuous: the time of a place and the place at that time agree.
    #[test]
    fn time_and_place_agree() {
        let (q, p) = (curved, path(2, curved));
        let (v, a, j) = CURVED_LIMITS;
        let t = Timing::jerk_limited(&p, &limits(&v, &a), &j).unwrap();
        for k in 1..1000 {
            let s = k as f64 / 1000.0;
            let back = t.at(t.time_at(s)).s;
            assert!((back - s).abs() < 1e-9, "{s} -> {back}");
        }
        let w = sampled(&t, q, 2, [&v, &a, &j]);
        assert!(
            w[0] <= 1.0 + 1e-3 && w[1] <= 1.0 + 1e-3 && w[2] <= 1.01,
            "{w:?}"
        );
    }

    /// The banded interior-point solver against an independent one (Clarabel, PyPI's and
    /// crates.io's conic solver): the first program of a two-axis curved path with jerk
    /// limits has the same optimum (largest `Σ x`) to 1e-7, and the solution found keeps
    /// every row to 1e-8.
    #[test]
    fn banded_solver_agrees_with_clarabel() {
        use clarabel::algebra::CscMatrix;
        use clarabel::solver::{
            DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus,
            ZeroConeT,
        };
        let p = path(2, curved);
        let (v, a, j) = CURVED_LIMITS;
        let lim = limits(&v, &a);
        let unjerked = Timing::optimal(&p, &lim).unwrap();
        let mut slopes = KnotSlopes::new();
        checked_slopes(&p, &lim, &mut slopes).unwrap();
        let d3 = third_slopes(&p, &slopes, None);
        let mut rows = Rows::new(
            (0..UNKNOWNS)
                .map(|v| if v % 2 == 0 { 20.0 } else { 50.0 })
                .collect(),
            (0.0, 0.0),
        );
        fixed_rows(&p, &slopes, &lim, &mut rows);
        jerk_rows(&p, &slopes, &d3, &j, &unjerked.x, &mut rows);
        let (ours, ours_u) = solve(&rows, &band_places()).unwrap();
        let ours_total: f64 = ours.iter().sum();
        // Clarabel: the equalities, then the rows.
        let (mut ri, mut ci, mut vi, mut b) = (vec![], vec![], vec![], vec![]);
        for (r, m) in [&rows.eq, &rows.ineq].into_iter().enumerate() {
            let offset = if r == 0 { 0 } else { rows.eq.len() };
            for row in 0..m.len() {
                for e in m.starts[row]..m.starts[row + 1] {
                    ri.push(offset + row);
                    ci.push(m.col[e]);
                    vi.push(m.val[e]);
                }
                b.push(m.rhs[row]);
            }
        }
        let total_rows = rows.eq.len() + rows.ineq.len();
        let a_mat = CscMatrix::new_from_triplets(total_rows, UNKNOWNS, ri, ci, vi);
        let p_mat = CscMatrix::<f64>::zeros((UNKNOWNS, UNKNOWNS));
        let mut c = vec![0.0; UNKNOWNS];
        for k in 1..SEGMENTS {
            c[xi(k)] = -1.0;
        }
        let cones = [ZeroConeT(rows.eq.len()), NonnegativeConeT(rows.ineq.len())];
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .build()
            .unwrap();
        let mut solver = DefaultSolver::new(&p_mat, &c, &a_mat, &b, &cones, settings).unwrap();
        solver.solve();
        assert_eq!(solver.solution.status, SolverStatus::Solved);
        let theirs_total: f64 = (1..SEGMENTS)
            .map(|k| solver.solution.x[xi(k)] * rows.scale[xi(k)])
            .sum();
        assert!(
            (ours_total - theirs_total).abs() <= 1e-7 * theirs_total,
            "{ours_total} vs {theirs_total}"
        );
        let mut z = vec![0.0; UNKNOWNS];
        for k in 1..SEGMENTS {
            z[xi(k)] = ours[k] / rows.scale[xi(k)];
        }
        for k in 1..SEGMENTS {
            z[ui(k)] = ours_u[k] / rows.scale[ui(k)];
        }
        for r in 0..rows.ineq.len() {
            assert!(rows.ineq.dot(r, &z) <= rows.ineq.rhs[r] + 1e-8, "row {r}");
        }
    }
}

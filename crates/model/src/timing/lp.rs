//! A linear-program solver for programs whose variables lie along a path: every row
//! couples only variables a few places apart in a given order, so the Newton systems of an
//! interior-point method are banded and each is solved in `O(n·b²)` (b the band) with no
//! fill outside the band. Used by the jerk-limited timing ([`super::jerk`]), whose programs
//! have 510 unknowns and about 14,300 rows (a six-axis arm) of at most four entries each.
//!
//! The method is Mehrotra's predictor–corrector primal–dual interior-point method (S. J.
//! Wright, *Primal–Dual Interior-Point Methods*, SIAM 1997, ch. 10) for
//! `min qᵀz` subject to `E·z = e` and `G·z ≤ h`, started from `z = 0` (it need not be
//! feasible). Each step solves the quasi-definite system
//! `[[GᵀDG + δI, Eᵀ], [E, −δI]]·[dz; dy] = r` (`D` the duals over the slacks, `δ` a small
//! regularisation) by an `LDLᵀ` factorisation of its band in a caller's order that
//! interleaves the unknowns with the equalities that tie them; quasi-definite matrices
//! factor without pivoting in any order (Vanderbei, "Symmetric quasi-definite matrices",
//! SIAM J. Optim. 1995). Deterministic: the same arithmetic in the same order.

/// Rows of a sparse matrix, each a run of `(column, value)` entries, with a right-hand
/// side per row.
#[derive(Clone, Debug, Default)]
pub(super) struct SparseRows {
    /// Where each row's entries begin; one more than the rows (the last is the end).
    pub(super) starts: Vec<usize>,
    pub(super) col: Vec<usize>,
    pub(super) val: Vec<f64>,
    pub(super) rhs: Vec<f64>,
}

impl SparseRows {
    pub(super) fn new() -> SparseRows {
        SparseRows {
            starts: vec![0],
            ..SparseRows::default()
        }
    }

    /// How many rows.
    pub(super) fn len(&self) -> usize {
        self.rhs.len()
    }

    /// Appends the row `Σ value·z[column] (≤ or =) rhs`: entries of one column summed,
    /// those of value 0 left out.
    pub(super) fn push(&mut self, entries: impl IntoIterator<Item = (usize, f64)>, rhs: f64) {
        let start = self.col.len();
        for (c, v) in entries {
            match self.col[start..].iter().position(|x| *x == c) {
                Some(at) => self.val[start + at] += v,
                None => {
                    self.col.push(c);
                    self.val.push(v);
                }
            }
        }
        // (Zeros out, in place.)
        let mut kept = start;
        for e in start..self.col.len() {
            if self.val[e] != 0.0 {
                self.col[kept] = self.col[e];
                self.val[kept] = self.val[e];
                kept += 1;
            }
        }
        self.col.truncate(kept);
        self.val.truncate(kept);
        self.starts.push(self.col.len());
        self.rhs.push(rhs);
    }

    /// Row `r`'s entries.
    fn row(&self, r: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        (self.starts[r]..self.starts[r + 1]).map(|e| (self.col[e], self.val[e]))
    }

    /// `row r · z`.
    pub(super) fn dot(&self, r: usize, z: &[f64]) -> f64 {
        self.row(r).map(|(c, v)| v * z[c]).sum()
    }
}

/// A program `min qᵀz, E·z = e, G·z ≤ h` and the band order of its Newton systems.
pub(super) struct Program<'a> {
    pub(super) q: &'a [f64],
    pub(super) eq: &'a SparseRows,
    pub(super) ineq: &'a SparseRows,
    /// The place of each unknown (`0..q.len()`), then of each equality row, in the
    /// banded order: a permutation of `0..q.len() + eq.len()`.
    pub(super) place: &'a [usize],
    /// The most two places coupled by a row (or an equality and its unknowns) are apart.
    pub(super) band: usize,
}

/// Interior-point iterations at most.
const MAX_ITERATIONS: usize = 100;
/// The accuracy of a solution: the rows' and equalities' residuals (the rows are scaled to
/// right-hand sides of 1), the dual residual (relative to the objective's largest
/// coefficient) and the duality gap (relative to the objective).
const PRIMAL_ACCURACY: f64 = 1e-9;
const DUAL_ACCURACY: f64 = 1e-8;
const GAP_ACCURACY: f64 = 1e-8;
/// The regularisation of the Newton systems (static; and a pivot of the wrong sign or
/// below [`DYNAMIC_EPS`] becomes [`DYNAMIC_DELTA`] of its sign: Clarabel's values).
const REGULARISATION: f64 = 1e-8;
const DYNAMIC_EPS: f64 = 1e-13;
const DYNAMIC_DELTA: f64 = 2e-7;
/// Rounds of iterative refinement of each Newton step.
const REFINEMENTS: usize = 1;
/// How far towards the boundary of the positive slacks and duals a step goes.
const TO_BOUNDARY: f64 = 0.995;

/// Why a program has no solution found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum LpError {
    /// The band given is narrower than a row's coupling, or the places are not a
    /// permutation.
    Shape,
    /// The iterations ran out, or a factorisation broke down (a program with no solution,
    /// or no bounded one).
    NotSolved,
}

/// A symmetric band matrix: its lower band, row by row (`b + 1` entries per row, the
/// diagonal last).
struct Band {
    n: usize,
    b: usize,
    a: Vec<f64>,
}

impl Band {
    fn new(n: usize, b: usize) -> Band {
        Band {
            n,
            b,
            a: vec![0.0; n * (b + 1)],
        }
    }

    /// Where `(i, j)` (either way round, within the band) is kept.
    fn index(&self, i: usize, j: usize) -> usize {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        i * (self.b + 1) + self.b - (i - j)
    }

    /// Adds `v` at `(i, j)`.
    fn add(&mut self, i: usize, j: usize, v: f64) {
        let at = self.index(i, j);
        self.a[at] += v;
    }

    fn at(&self, i: usize, j: usize) -> f64 {
        self.a[i * (self.b + 1) + self.b - (i - j)]
    }

    fn at_mut(&mut self, i: usize, j: usize) -> &mut f64 {
        &mut self.a[i * (self.b + 1) + self.b - (i - j)]
    }

    /// Factors in place into `L·D·Lᵀ` (unit `L` below the diagonal, `D` on it); the sign of
    /// each pivot is `sign[i]` (quasi-definite): a pivot of the wrong sign or too small is
    /// replaced by a small one of the right sign (dynamic regularisation). `None` if a pivot is
    /// not a number.
    fn factor(&mut self, sign: &[f64]) -> Option<()> {
        let (n, b) = (self.n, self.b);
        for (j, sign_j) in sign.iter().enumerate().take(n) {
            let lo = j.saturating_sub(b);
            let mut d = self.at(j, j);
            for k in lo..j {
                let l = self.at(j, k);
                d -= l * l * self.at(k, k);
            }
            if !d.is_finite() {
                return None;
            }
            if d * sign_j <= DYNAMIC_EPS {
                d = sign_j * DYNAMIC_DELTA;
            }
            *self.at_mut(j, j) = d;
            for i in j + 1..(j + b + 1).min(n) {
                let lo_i = i.saturating_sub(b).max(lo);
                let mut v = self.at(i, j);
                for k in lo_i..j {
                    v -= self.at(i, k) * self.at(j, k) * self.at(k, k);
                }
                *self.at_mut(i, j) = v / d;
            }
        }
        Some(())
    }

    /// Solves `L·D·Lᵀ·x = r` in place.
    fn solve(&self, r: &mut [f64]) {
        let (n, b) = (self.n, self.b);
        for i in 0..n {
            let lo = i.saturating_sub(b);
            let mut v = r[i];
            for (k, rk) in r.iter().enumerate().take(i).skip(lo) {
                v -= self.at(i, k) * rk;
            }
            r[i] = v;
        }
        for (i, v) in r.iter_mut().enumerate() {
            *v /= self.at(i, i);
        }
        for i in (0..n).rev() {
            let hi = (i + b + 1).min(n);
            let mut v = r[i];
            for (k, rk) in r.iter().enumerate().take(hi).skip(i + 1) {
                v -= self.at(k, i) * rk;
            }
            r[i] = v;
        }
    }
}

/// [`TO_BOUNDARY`] of the largest step that keeps `v + α·dv ≥ 0`, at most 1: never onto
/// the boundary (a slack or dual of 0 would end the method).
fn step_to_boundary(v: &[f64], dv: &[f64]) -> f64 {
    let mut alpha = 1.0f64;
    for (x, d) in v.iter().zip(dv) {
        if *d < 0.0 {
            alpha = alpha.min(-x / d);
        }
    }
    (TO_BOUNDARY * alpha).min(1.0)
}

fn norm_inf(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Solves `program`: the unknowns `z` at the optimum.
pub(super) fn solve(program: &Program<'_>) -> Result<Vec<f64>, LpError> {
    let Program {
        q,
        eq,
        ineq,
        place,
        band,
    } = *program;
    let (n, p, m) = (q.len(), eq.len(), ineq.len());
    let size = n + p;
    if place.len() != size {
        return Err(LpError::Shape);
    }
    let mut seen = vec![false; size];
    for &pl in place {
        if pl >= size || std::mem::replace(&mut seen[pl], true) {
            return Err(LpError::Shape);
        }
    }
    let apart = |a: usize, b: usize| a.abs_diff(b) <= band;
    for r in 0..m {
        for (c1, _) in ineq.row(r) {
            if c1 >= n
                || !ineq
                    .row(r)
                    .all(|(c2, _)| c2 < n && apart(place[c1], place[c2]))
            {
                return Err(LpError::Shape);
            }
        }
    }
    for r in 0..p {
        if !eq
            .row(r)
            .all(|(c, _)| c < n && apart(place[c], place[n + r]))
        {
            return Err(LpError::Shape);
        }
    }
    let mut sign = vec![1.0; size];
    for r in 0..p {
        sign[place[n + r]] = -1.0;
    }
    let scale_h = 1.0 + norm_inf(&ineq.rhs);
    let scale_q = 1.0 + norm_inf(q);
    let (mut z, mut y) = (vec![0.0; n], vec![0.0; p]);
    let (mut s, mut w) = (vec![1.0; m], vec![1.0; m]);
    let mut kkt = Band::new(size, band);
    // The matrix's part that stays (regularisation, equalities), and where each row's
    // products of two entries go in the band, with their value.
    let mut fixed = Band::new(size, band);
    for (c, _) in q.iter().enumerate() {
        fixed.add(place[c], place[c], REGULARISATION);
    }
    for r in 0..p {
        fixed.add(place[n + r], place[n + r], -REGULARISATION);
        for (c, v) in eq.row(r) {
            fixed.add(place[n + r], place[c], v);
        }
    }
    let mut pairs: Vec<(usize, f64)> = Vec::with_capacity(8 * ineq.col.len());
    let mut pair_starts = Vec::with_capacity(m + 1);
    pair_starts.push(0);
    for r in 0..m {
        let (lo, hi) = (ineq.starts[r], ineq.starts[r + 1]);
        for e1 in lo..hi {
            for e2 in lo..=e1 {
                let (i, j) = (place[ineq.col[e1]], place[ineq.col[e2]]);
                pairs.push((kkt.index(i, j), ineq.val[e1] * ineq.val[e2]));
            }
        }
        pair_starts.push(pairs.len());
    }
    let (mut rd, mut re, mut rp) = (vec![0.0; n], vec![0.0; p], vec![0.0; m]);
    let mut rhs = vec![0.0; size];
    let (mut ds, mut dw) = (vec![0.0; m], vec![0.0; m]);
    let (mut ds_aff, mut dw_aff) = (vec![0.0; m], vec![0.0; m]);
    let mut rc = vec![0.0; m];
    let mut feasible: Vec<f64> = Vec::new();
    for _ in 0..MAX_ITERATIONS {
        // Residuals.
        rd.copy_from_slice(q);
        for r in 0..p {
            for (c, v) in eq.row(r) {
                rd[c] += v * y[r];
            }
            re[r] = eq.dot(r, &z) - eq.rhs[r];
        }
        for r in 0..m {
            for (c, v) in ineq.row(r) {
                rd[c] += v * w[r];
            }
            rp[r] = ineq.dot(r, &z) + s[r] - ineq.rhs[r];
        }
        let mu = s.iter().zip(&w).map(|(a, b)| a * b).sum::<f64>() / m.max(1) as f64;
        let primal = norm_inf(&rp).max(norm_inf(&re)) <= PRIMAL_ACCURACY * scale_h;
        let objective: f64 = q.iter().zip(&z).map(|(a, b)| a * b).sum();
        if primal
            && norm_inf(&rd) <= DUAL_ACCURACY * scale_q
            && mu * m as f64 <= GAP_ACCURACY * (1.0 + objective.abs())
        {
            return Ok(z);
        }
        if primal {
            feasible.clone_from(&z);
        }
        if !(mu.is_finite() && mu > 0.0) {
            break;
        }
        // The Newton system's matrix: its fixed part, and each row's products weighted.
        kkt.a.copy_from_slice(&fixed.a);
        for r in 0..m {
            let d = w[r] / s[r];
            for &(at, product) in &pairs[pair_starts[r]..pair_starts[r + 1]] {
                kkt.a[at] += d * product;
            }
        }
        kkt.factor(&sign).ok_or(LpError::NotSolved)?;
        // Predictor (affine, σ = 0), then corrector with σ = (μ_aff/μ)³.
        let newton = |rc: &[f64], ds: &mut [f64], dw: &mut [f64], dz_dy: &mut [f64]| {
            dz_dy.iter_mut().for_each(|v| *v = 0.0);
            for c in 0..n {
                dz_dy[place[c]] = -rd[c];
            }
            for r in 0..m {
                let t = (rc[r] - w[r] * rp[r]) / s[r];
                for (c, v) in ineq.row(r) {
                    dz_dy[place[c]] += v * t;
                }
            }
            for r in 0..p {
                dz_dy[place[n + r]] = -re[r];
            }
            // (Solved, then refined against the system without its regularisation.)
            let target = dz_dy.to_vec();
            kkt.solve(dz_dy);
            for _ in 0..REFINEMENTS {
                let mut residual = target.clone();
                for r in 0..m {
                    let d = w[r] / s[r];
                    let g_dz: f64 = ineq.row(r).map(|(c, v)| v * dz_dy[place[c]]).sum();
                    for (c, v) in ineq.row(r) {
                        residual[place[c]] -= d * v * g_dz;
                    }
                }
                for r in 0..p {
                    let dy = dz_dy[place[n + r]];
                    let mut e_dz = 0.0;
                    for (c, v) in eq.row(r) {
                        residual[place[c]] -= v * dy;
                        e_dz += v * dz_dy[place[c]];
                    }
                    residual[place[n + r]] -= e_dz;
                }
                kkt.solve(&mut residual);
                for (x, d) in dz_dy.iter_mut().zip(&residual) {
                    *x += d;
                }
            }
            for r in 0..m {
                let g_dz: f64 = ineq.row(r).map(|(c, v)| v * dz_dy[place[c]]).sum();
                ds[r] = -rp[r] - g_dz;
                dw[r] = (-rc[r] - w[r] * ds[r]) / s[r];
            }
        };
        for r in 0..m {
            rc[r] = s[r] * w[r];
        }
        newton(&rc, &mut ds_aff, &mut dw_aff, &mut rhs);
        let (ap, ad) = (step_to_boundary(&s, &ds_aff), step_to_boundary(&w, &dw_aff));
        let mu_aff = s
            .iter()
            .zip(&ds_aff)
            .zip(w.iter().zip(&dw_aff))
            .map(|((s, ds), (w, dw))| (s + ap * ds) * (w + ad * dw))
            .sum::<f64>()
            / m.max(1) as f64;
        let ratio = mu_aff / mu;
        let sigma = if ratio.is_finite() {
            ratio.clamp(0.0, 1.0).powi(3)
        } else {
            0.1
        };
        for r in 0..m {
            rc[r] = s[r] * w[r] + ds_aff[r] * dw_aff[r] - sigma * mu;
        }
        newton(&rc, &mut ds, &mut dw, &mut rhs);
        let (ap, ad) = (step_to_boundary(&s, &ds), step_to_boundary(&w, &dw));
        for c in 0..n {
            z[c] += ap * rhs[place[c]];
        }
        for r in 0..p {
            y[r] += ad * rhs[place[n + r]];
        }
        for r in 0..m {
            s[r] += ap * ds[r];
            w[r] += ad * dw[r];
        }
        if z.iter()
            .chain(&y)
            .chain(&s)
            .chain(&w)
            .any(|v| !v.is_finite())
        {
            break;
        }
    }
    // (Not solved to its accuracy: the last iterate that kept every row, if any — the
    // caller needs a feasible point more than the last digits of the optimum.)
    if feasible.is_empty() {
        Err(LpError::NotSolved)
    } else {
        Ok(feasible)
    }
}

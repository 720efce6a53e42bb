//! Rauch–Tung–Striebel fixed-interval smoother for the closed-loop error-state filter
//! of [`super::ekf`] (Groves 2nd ed. §3.4.2, eqs. (3.89)–(3.91); Rauch, Tung & Striebel
//! 1965), one backward step per covariance epoch. No allocation: the caller keeps the
//! forward records ([`CovEpoch`]) and walks them backwards.
//!
//! ## Closed-loop resets
//! The forward filter feeds every estimate back into the navigation state, so its error
//! state after each epoch is zero. Write `e⁺_k` for the error (estimate − truth) of the
//! corrected state at epoch k and `e⁻_{k+1}` for the error of the state predicted from it
//! at epoch k+1 (before that epoch's corrections); `e⁻_{k+1} = Φ e⁺_k + w_k` and
//! `e⁺_{k+1} = e⁻_{k+1} − δx̂_{k+1}` with `δx̂_{k+1}` the sum of the corrections applied at
//! k+1 (`CovEpoch::dx`). Taking the corrected state at k and the predicted state at k+1
//! as the linearisation points, the forward estimates of both errors are zero and the
//! smoother of Groves (3.89)–(3.91) becomes
//!
//! * `A_k = P(k|k) Φᵀ P(k+1|k)⁻¹`
//! * `ê⁺_k = A_k (ê⁺_{k+1} + δx̂_{k+1})`
//! * `P_s(k) = P(k|k) + A_k (P_s(k+1) − P(k+1|k)) A_kᵀ`
//!
//! started from `ê⁺_N = 0`, `P_s(N) = P(N|N)`. The smoothed state at epoch k is the
//! forward corrected state minus `ê⁺_k` (the same correction as the forward filter's,
//! `Ĉ ← exp(−[ε̂×]) Ĉ` for the attitude).
//!
//! States with zero predicted variance (a bias with no prior and no process noise) carry
//! no information; their columns of `A` are set to zero instead of inverting a singular
//! `P(k+1|k)`.

use super::ekf::{CovEpoch, FilterError};
use super::layout::{Cov, XVec, MAX_STATES};
use super::linalg::{chol_solve, cholesky, mul, mul_tr, mul_vec, symmetrize};

/// The smoothed error estimate and covariance at one epoch (leading `n` entries).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Smoothed {
    /// `ê⁺_k`: smoothed estimate of the error of the forward corrected state
    pub dx: XVec,
    /// smoothed covariance `P_s(k)`
    pub p: Cov,
}

impl Smoothed {
    /// The start of the backward pass at the last epoch: `ê = 0`, `P_s = P(N|N)`.
    pub fn last(epoch: &CovEpoch) -> Self {
        Self {
            dx: XVec::zeros(),
            p: epoch.p_post,
        }
    }
}

/// One backward step: from the smoothed result at epoch k+1 (`next`, whose forward record
/// is `rec_next`) to epoch k (forward record `rec`), over the active dimension of
/// `rec_next`.
pub fn rts_step(
    rec: &CovEpoch,
    rec_next: &CovEpoch,
    next: &Smoothed,
) -> Result<Smoothed, FilterError> {
    let n = rec_next.n.min(MAX_STATES);
    let pp = &rec_next.p_pred;
    // P(k+1|k) restricted to the states that carry variance
    let mut scale = 0.0f64;
    for i in 0..n {
        let d = pp[(i, i)].abs();
        if d > scale {
            scale = d;
        }
    }
    let scale = scale.max(f64::MIN_POSITIVE);
    let mut active = [false; MAX_STATES];
    let mut m = *pp;
    for (i, a) in active.iter_mut().enumerate().take(n) {
        *a = pp[(i, i)] > scale * 1e-300;
        if !*a {
            m.row_mut(i).fill(0.0);
            m.column_mut(i).fill(0.0);
            m[(i, i)] = 1.0;
        }
    }
    if !cholesky(m.as_mut_slice(), MAX_STATES, n) {
        return Err(FilterError::NotPositiveDefinite {
            t_s: rec_next.t_s,
            what: "predicted covariance P(k+1|k) in the smoother",
        });
    }
    // A = P Φᵀ M⁻¹  ⇔  M Aᵀ = Φ P
    let mut b = Cov::zeros();
    mul(&mut b, &rec_next.phi, &rec.p_post, n);
    let mut a = Cov::zeros();
    let mut col = [0.0; MAX_STATES];
    for j in 0..n {
        for (i, c) in col.iter_mut().enumerate().take(n) {
            *c = b[(i, j)];
        }
        chol_solve(m.as_slice(), MAX_STATES, n, &mut col);
        // column j of Aᵀ = row j of A
        for (i, c) in col.iter().enumerate().take(n) {
            a[(j, i)] = *c;
        }
    }
    for (j, act) in active.iter().enumerate().take(n) {
        if !act {
            a.column_mut(j).fill(0.0);
        }
    }
    let v = next.dx + rec_next.dx;
    let dx = mul_vec(&a, &v, n);
    let mut d = Cov::zeros();
    for j in 0..n {
        for i in 0..n {
            d[(i, j)] = next.p[(i, j)] - pp[(i, j)];
        }
    }
    let (mut t, mut u) = (Cov::zeros(), Cov::zeros());
    mul(&mut t, &a, &d, n);
    mul_tr(&mut u, &t, &a, n);
    let mut p = Cov::zeros();
    for j in 0..n {
        for i in 0..n {
            p[(i, j)] = rec.p_post[(i, j)] + u[(i, j)];
        }
    }
    symmetrize(&mut p, n);
    let finite = (0..n).all(|j| dx[j].is_finite() && (0..n).all(|i| p[(i, j)].is_finite()));
    if !finite {
        return Err(FilterError::NotPositiveDefinite {
            t_s: rec.t_s,
            what: "smoothed covariance",
        });
    }
    Ok(Smoothed { dx, p })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// A scalar random walk observed directly, with open-loop truth: the closed-loop
    /// smoother must give the same smoothed *state* as the textbook open-loop RTS
    /// smoother (computed independently here), to rounding.
    #[test]
    fn closed_loop_equals_open_loop_rts_on_a_random_walk() {
        // 1-D: x_{k+1} = x_k + w (q), z_k = x_k + v (r); embed in state 0 of the 15.
        let (q, r, p0) = (0.3, 0.5, 2.0);
        let z = [0.7, -0.2, 1.1, 0.4, 0.9, 1.6, 1.2];
        // open loop forward
        const N: usize = 7;
        let n = N;
        let (mut xf, mut pf, mut xp, mut pp) = ([0.0; N], [0.0; N], [0.0; N], [0.0; N]);
        let (mut x, mut p) = (0.0, p0);
        for k in 0..n {
            if k > 0 {
                p += q;
            }
            xp[k] = x;
            pp[k] = p;
            let kg = p / (p + r);
            x += kg * (z[k] - x);
            p *= 1.0 - kg;
            xf[k] = x;
            pf[k] = p;
        }
        let mut xs = xf;
        let mut ps = pf;
        for k in (0..n - 1).rev() {
            let a = pf[k] / pp[k + 1];
            xs[k] = xf[k] + a * (xs[k + 1] - xp[k + 1]);
            ps[k] = pf[k] + a * (ps[k + 1] - pp[k + 1]) * a;
        }
        // closed loop: the nominal is reset to the estimate at each epoch; the error
        // state is (nominal − truth); the correction δx̂ = K (nominal − z)
        let blank = CovEpoch {
            t_s: 0.0,
            n: 15,
            phi: Cov::identity(),
            p_pred: Cov::identity(),
            p_post: Cov::identity(),
            dx: XVec::zeros(),
        };
        let mut recs = [blank; N];
        let mut nominal = [0.0; N];
        let (mut nom, mut p) = (0.0, p0);
        for k in 0..n {
            let mut rec = blank;
            rec.t_s = k as f64;
            if k > 0 {
                p += q;
            }
            rec.p_pred[(0, 0)] = p;
            let kg = p / (p + r);
            let dx = kg * (nom - z[k]);
            nom -= dx;
            p *= 1.0 - kg;
            rec.p_post[(0, 0)] = p;
            rec.dx[0] = dx;
            nominal[k] = nom;
            recs[k] = rec;
        }
        let mut s = Smoothed::last(&recs[n - 1]);
        let mut out = [s; N];
        for k in (0..n - 1).rev() {
            s = rts_step(&recs[k], &recs[k + 1], &s).unwrap();
            out[k] = s;
        }
        for k in 0..n {
            assert!((nominal[k] - xf[k]).abs() < 1e-14);
            let smoothed_state = nominal[k] - out[k].dx[0];
            assert!((smoothed_state - xs[k]).abs() < 1e-14, "k {k}");
            assert!((out[k].p[(0, 0)] - ps[k]).abs() < 1e-14, "k {k}");
            assert!(out[k].p[(0, 0)] <= pf[k] + 1e-15);
        }
        // the other 14 states have P = I, no process noise and Φ = I: the smoother
        // leaves them alone
        assert!((out[0].p[(5, 5)] - 1.0).abs() < 1e-14);
    }

    #[test]
    fn zero_variance_states_do_not_break_the_step() {
        let mut rec = CovEpoch {
            t_s: 0.0,
            n: 15,
            phi: Cov::identity(),
            p_pred: Cov::identity(),
            p_post: Cov::identity(),
            dx: XVec::zeros(),
        };
        rec.p_post[(14, 14)] = 0.0;
        let mut next = rec;
        next.p_pred[(14, 14)] = 0.0;
        next.dx[3] = 0.5;
        let s = rts_step(&rec, &next, &Smoothed::last(&next)).unwrap();
        assert!(s.dx.iter().all(|x| x.is_finite()));
        assert!((s.dx[3] - 0.5).abs() < 1e-15);
        assert_eq!(s.p[(14, 14)], 0.0);
    }
}

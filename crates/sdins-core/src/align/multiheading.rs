//! Multi-heading alignment, Algorithm B of docs/theory/alignment.md §"Multi-heading alignment" (the
//! \[P1\] "pseudo-error / multiple" method): per heading k a filter estimates the observable pseudo
//! vector `p_k = [φ'_N, φ'_E, φ'_D, ε'_N, ε'_D, δa_D]` at time `t_k`; the unknowns
//! `θ = [φ(t_0) (3), b_a^b (3), b_g^b (3)]` follow from stacking
//!
//! ```text
//! p_k = P_φ φ(t_k) + P_β(C_k) [b_a; b_g],   φ(t_k) = Φ_k φ(t_0) + Γ_k b_g
//! ```
//!
//! and solving weighted least squares (weights = inverse per-position covariances).
//! `Φ_k, Γ_k` integrate `φ̇ = −ω_ie^n × φ + C_b^n(t) b_g` exactly (augmented matrix
//! exponential per piece-wise constant step, [`AttitudeErrorTransition`]).
//! (Algorithm A, the recommended one, is [`super::fine::FineAlign`] with
//! [`super::model::BiasFrame::Body`].)

use super::observability::{from_accumulator, Observability, RowAccumulator};
use super::Site;
use crate::math::{skew, Mat3};
use nalgebra::{SMatrix, SVector};

/// Matrix exponential by scaling and squaring with a 16-term Taylor series (exact to
/// roundoff for the small, well-conditioned matrices used here).
pub fn expm<const N: usize>(a: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
    let norm = a.abs().row_sum().max();
    let mut s = 0u32;
    let mut scale = 1.0;
    while norm * scale > 0.5 && s < 60 {
        scale *= 0.5;
        s += 1;
    }
    let x = a * scale;
    let mut term = SMatrix::<f64, N, N>::identity();
    let mut sum = term;
    for k in 1..=16 {
        term = term * x / (k as f64);
        sum += term;
    }
    for _ in 0..s {
        sum = sum * sum;
    }
    sum
}

/// Attitude-error transition since `t_0`: `φ(t) = Φ φ(t_0) + Γ b_g` for
/// `φ̇ = −[ω_ie^n×] φ + C_b^n(t) b_g` (docs/theory/alignment.md §"Multi-heading alignment").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeErrorTransition {
    /// Φ
    pub phi: Mat3,
    /// Γ
    pub gamma: Mat3,
}

impl Default for AttitudeErrorTransition {
    fn default() -> Self {
        Self {
            phi: Mat3::identity(),
            gamma: Mat3::zeros(),
        }
    }
}

impl AttitudeErrorTransition {
    /// Advance by `dt_s` with `C_b^n` held constant over the step:
    /// `exp([[−[ω×], C], [0, 0]] dt) = [[E, G], [0, I]]`, `Φ ← E Φ`, `Γ ← E Γ + G`.
    pub fn step(&mut self, c_b_n: &Mat3, dt_s: f64, site: &Site) {
        let mut a = SMatrix::<f64, 6, 6>::zeros();
        a.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(-skew(&site.omega_ie_n()) * dt_s));
        a.fixed_view_mut::<3, 3>(0, 3).copy_from(&(c_b_n * dt_s));
        let ex = expm(&a);
        let e = ex.fixed_view::<3, 3>(0, 0).into_owned();
        let g = ex.fixed_view::<3, 3>(0, 3).into_owned();
        self.phi = e * self.phi;
        self.gamma = e * self.gamma + g;
    }
}

/// `P_β(C_k)` of docs/theory/alignment.md §"Multi-heading alignment": pseudo vector from the body
/// biases `[b_a; b_g]`, with `c_N, c_E, c_D` the rows of `C_k = C_b^n`:
///
/// ```text
/// φ'_N: [ c_E/g ,              0            ]
/// φ'_E: [ −c_N/g ,             0            ]
/// φ'_D: [ −tan L · c_E/g ,     c_E/(Ω cos L) ]
/// ε'_N: [ −Ω sin L · c_N/g ,   c_N          ]
/// ε'_D: [ −Ω cos L · c_N/g ,   c_D          ]
/// δa_D: [ c_D ,                0            ]
/// ```
pub fn p_beta(c_b_n: &Mat3, site: &Site) -> SMatrix<f64, 6, 6> {
    let g = site.g_mps2;
    let (cn, ce, cd) = (c_b_n.row(0), c_b_n.row(1), c_b_n.row(2));
    let mut m = SMatrix::<f64, 6, 6>::zeros();
    m.fixed_view_mut::<1, 3>(0, 0).copy_from(&(ce / g));
    m.fixed_view_mut::<1, 3>(1, 0).copy_from(&(-cn / g));
    m.fixed_view_mut::<1, 3>(2, 0)
        .copy_from(&(-ce * (site.tan_lat() / g)));
    m.fixed_view_mut::<1, 3>(2, 3)
        .copy_from(&(ce / site.omega_n()));
    m.fixed_view_mut::<1, 3>(3, 0)
        .copy_from(&(cn * (site.omega_d() / g)));
    m.fixed_view_mut::<1, 3>(3, 3).copy_from(&cn);
    m.fixed_view_mut::<1, 3>(4, 0)
        .copy_from(&(-cn * (site.omega_n() / g)));
    m.fixed_view_mut::<1, 3>(4, 3).copy_from(&cd);
    m.fixed_view_mut::<1, 3>(5, 0).copy_from(&cd);
    m
}

/// Design block `A_k` (6×9) with `p_k = A_k θ`, `θ = [φ(t_0), b_a, b_g]`:
/// `A_k = [P_φ Φ_k,  P_β,a,  P_φ Γ_k + P_β,g]`, `P_φ = [I3; 0]`.
pub fn design_block(tr: &AttitudeErrorTransition, c_b_n: &Mat3, site: &Site) -> SMatrix<f64, 6, 9> {
    let pb = p_beta(c_b_n, site);
    let mut a = SMatrix::<f64, 6, 9>::zeros();
    a.fixed_view_mut::<3, 3>(0, 0).copy_from(&tr.phi);
    a.fixed_view_mut::<6, 3>(0, 3)
        .copy_from(&pb.fixed_view::<6, 3>(0, 0));
    a.fixed_view_mut::<6, 3>(0, 6)
        .copy_from(&pb.fixed_view::<6, 3>(0, 3));
    let g = a.fixed_view::<3, 3>(0, 6).into_owned() + tr.gamma;
    a.fixed_view_mut::<3, 3>(0, 6).copy_from(&g);
    a
}

/// Column scaling of θ for rank and conditioning: 1 mrad, 1e-3 m/s², 1e-7 rad/s.
pub fn theta_scale() -> SVector<f64, 9> {
    SVector::<f64, 9>::from_fn(|i, _| if i < 6 { 1e-3 } else { 1e-7 })
}

/// Weighted least-squares accumulator of Algorithm B (docs/theory/alignment.md
/// §"Multi-heading alignment").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlgorithmB {
    site: Site,
    ls: RowAccumulator<10>,
    rank_acc: RowAccumulator<9>,
    positions: usize,
}

/// Solution of Algorithm B.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlgorithmBSolution {
    /// θ = \[φ(t_0) (NED, rad), b_a^b (m/s²), b_g^b (rad/s)\]
    pub theta: SVector<f64, 9>,
    /// covariance of θ
    pub cov: SMatrix<f64, 9, 9>,
}

impl AlgorithmB {
    /// Empty problem at `site`.
    pub fn new(site: Site) -> Self {
        let mut s10 = SVector::<f64, 10>::from_element(1.0);
        s10.fixed_rows_mut::<9>(0).copy_from(&theta_scale());
        Self {
            site,
            ls: RowAccumulator::new(s10, false),
            rank_acc: RowAccumulator::new(theta_scale(), true),
            positions: 0,
        }
    }

    /// Add the pseudo estimate `p` (covariance `cov`) of one position at attitude
    /// `c_b_n`, with the transition `tr` from `t_0` to the estimation time. Returns
    /// `false` (nothing added) if `cov` is not positive definite.
    pub fn add_position(
        &mut self,
        tr: &AttitudeErrorTransition,
        c_b_n: &Mat3,
        p: &SVector<f64, 6>,
        cov: &SMatrix<f64, 6, 6>,
    ) -> bool {
        let Some(ch) = nalgebra::Cholesky::new(*cov) else {
            return false;
        };
        let Some(li) = ch.l().try_inverse() else {
            return false;
        };
        let a = design_block(tr, c_b_n, &self.site);
        let aw = li * a;
        let pw = li * p;
        for i in 0..6 {
            let mut row = SVector::<f64, 10>::zeros();
            row.fixed_rows_mut::<9>(0).copy_from(&aw.row(i).transpose());
            row[9] = pw[i];
            self.ls.add_row(&row);
            self.rank_acc.add_row(&a.row(i).transpose());
        }
        self.positions += 1;
        true
    }

    /// Rank of the stacked design (docs/validation.md §"multi-heading" T8: 6 for one heading, 9 for
    /// two or four).
    pub fn observability(&self, tol: f64) -> Observability<9> {
        from_accumulator(&self.rank_acc, tol)
    }

    /// Least-squares solution by back substitution on the triangular factor; `None`
    /// unless the stacked problem has full rank 9 (tolerance 1e-9).
    pub fn solve(&self) -> Option<AlgorithmBSolution> {
        if self.observability(1e-9).rank < 9 {
            return None;
        }
        let r = self.ls.r();
        let r9 = r.fixed_view::<9, 9>(0, 0).into_owned();
        let c = r.fixed_view::<9, 1>(0, 9).into_owned();
        let r9i = r9.try_inverse()?;
        let y = r9i * c;
        let d = SMatrix::<f64, 9, 9>::from_diagonal(&theta_scale());
        Some(AlgorithmBSolution {
            theta: d * y,
            cov: d * r9i * r9i.transpose() * d,
        })
    }

    /// Number of positions added.
    pub fn positions(&self) -> usize {
        self.positions
    }
}

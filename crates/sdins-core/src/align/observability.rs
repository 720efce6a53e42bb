//! Numerical observability analysis of piece-wise constant linear systems
//! (docs/theory/alignment.md §"Observability at one heading": numerical rank, stripped
//! observability matrix).
//!
//! For segments `j = 1..J` with system matrices `F_j` and a common `H`, the stripped
//! observability matrix is `SOM = [O_1; …; O_J]`, `O_j = [H; H F_j; …; H F_j^{N−1}]`
//! (Goshen-Meskin & Bar-Itzhack; valid here because `null(O_j) ⊂ null(F_j)`,
//! docs/theory/alignment.md §"Observability at one heading"). Procedure (docs/theory/alignment.md
//! §"Observability at one heading"):
//!
//! 1. build the rows of O in f64;
//! 2. scale the columns by `D` (`scale`), i.e. use `O D`;
//! 3. normalise every row to unit 2-norm;
//! 4. take the SVD and count `σ_i > tol · σ_1` (spec: tol = 1e-9).
//!
//! Without allocation: the rows are folded one by one into an N×N upper-triangular
//! factor `R` by Givens rotations (`RᵀR = OᵀO` exactly in exact arithmetic, backward
//! stable in floating point), and the SVD of `R` — same singular values and right
//! singular vectors as `O` — is computed by one-sided Jacobi.

use nalgebra::{SMatrix, SVector};

/// Folds rows into an upper-triangular factor `R` with `RᵀR = Σ rowᵀ row`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RowAccumulator<const N: usize> {
    r: SMatrix<f64, N, N>,
    scale: SVector<f64, N>,
    normalize: bool,
    rows: usize,
}

impl<const N: usize> RowAccumulator<N> {
    /// Empty accumulator; rows are multiplied element-wise by `scale` (column scaling
    /// `D`) and, if `normalize`, scaled to unit norm before folding.
    pub fn new(scale: SVector<f64, N>, normalize: bool) -> Self {
        Self {
            r: SMatrix::zeros(),
            scale,
            normalize,
            rows: 0,
        }
    }

    /// Fold one row (in physical units). Exactly-zero rows are ignored.
    pub fn add_row(&mut self, row: &SVector<f64, N>) {
        let mut v = row.component_mul(&self.scale);
        let n = v.norm();
        if n == 0.0 || !n.is_finite() {
            return;
        }
        if self.normalize {
            v /= n;
        }
        self.rows += 1;
        for j in 0..N {
            if v[j] == 0.0 {
                continue;
            }
            let a = self.r[(j, j)];
            let b = v[j];
            let h = libm::hypot(a, b);
            let (c, s) = (a / h, b / h);
            for k in j..N {
                let rj = self.r[(j, k)];
                let vk = v[k];
                self.r[(j, k)] = c * rj + s * vk;
                v[k] = -s * rj + c * vk;
            }
        }
    }

    /// Number of rows folded in.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The triangular factor (scaled coordinates).
    pub fn r(&self) -> &SMatrix<f64, N, N> {
        &self.r
    }
}

/// One-sided Jacobi SVD of a square matrix: returns `(σ, V)` with the singular values in
/// descending order and the right singular vectors as the columns of `V` (`A V = U Σ`).
pub fn jacobi_svd<const N: usize>(a: &SMatrix<f64, N, N>) -> (SVector<f64, N>, SMatrix<f64, N, N>) {
    let mut a = *a;
    let mut v = SMatrix::<f64, N, N>::identity();
    for _sweep in 0..60 {
        let mut rotated = false;
        for p in 0..N {
            for q in (p + 1)..N {
                let (mut al, mut be, mut ga) = (0.0, 0.0, 0.0);
                for i in 0..N {
                    al += a[(i, p)] * a[(i, p)];
                    be += a[(i, q)] * a[(i, q)];
                    ga += a[(i, p)] * a[(i, q)];
                }
                if ga == 0.0 || libm::fabs(ga) <= 1e-15 * libm::sqrt(al * be) {
                    continue;
                }
                rotated = true;
                let zeta = (be - al) / (2.0 * ga);
                let t =
                    libm::copysign(1.0, zeta) / (libm::fabs(zeta) + libm::sqrt(1.0 + zeta * zeta));
                let c = 1.0 / libm::sqrt(1.0 + t * t);
                let s = c * t;
                for i in 0..N {
                    let (x, y) = (a[(i, p)], a[(i, q)]);
                    a[(i, p)] = c * x - s * y;
                    a[(i, q)] = s * x + c * y;
                    let (x, y) = (v[(i, p)], v[(i, q)]);
                    v[(i, p)] = c * x - s * y;
                    v[(i, q)] = s * x + c * y;
                }
            }
        }
        if !rotated {
            break;
        }
    }
    let mut sig = SVector::<f64, N>::from_fn(|j, _| a.column(j).norm());
    // selection sort, descending, permuting V's columns alike
    for i in 0..N {
        let mut m = i;
        for j in (i + 1)..N {
            if sig[j] > sig[m] {
                m = j;
            }
        }
        if m != i {
            sig.swap_rows(i, m);
            v.swap_columns(i, m);
        }
    }
    (sig, v)
}

/// Result of an observability analysis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Observability<const N: usize> {
    /// numerical rank (count of `σ_i > tol·σ_1`)
    pub rank: usize,
    /// singular values relative to the largest, descending
    pub sigma_rel: SVector<f64, N>,
    /// right singular vectors mapped back to physical units (`x = D y`) and normalised,
    /// as columns in the order of `sigma_rel`; columns `rank..N` span the unobservable
    /// subspace
    pub directions: SMatrix<f64, N, N>,
}

impl<const N: usize> Observability<N> {
    /// Singular-value gap `σ_rank / σ_{rank+1}` (∞ at full rank).
    pub fn gap(&self) -> f64 {
        if self.rank == 0 || self.rank >= N {
            f64::INFINITY
        } else {
            self.sigma_rel[self.rank - 1] / self.sigma_rel[self.rank]
        }
    }
}

/// Fold the rows `H F^k`, `k = 0..N−1`, of one segment into `acc`.
pub fn add_segment<const N: usize, const M: usize>(
    acc: &mut RowAccumulator<N>,
    f: &SMatrix<f64, N, N>,
    h: &SMatrix<f64, M, N>,
) {
    let mut block = *h;
    for _ in 0..N {
        for i in 0..M {
            acc.add_row(&block.row(i).transpose());
        }
        block *= f;
    }
}

/// Rank and unobservable directions of the stripped observability matrix of the
/// segments `fs` with measurement `h`, by the docs/theory/alignment.md
/// §"Observability at one heading" procedure (column scaling `scale` = diag D, unit rows,
/// `σ_i > tol σ_1`).
pub fn analyze<const N: usize, const M: usize>(
    fs: &[SMatrix<f64, N, N>],
    h: &SMatrix<f64, M, N>,
    scale: &SVector<f64, N>,
    tol: f64,
) -> Observability<N> {
    let mut acc = RowAccumulator::new(*scale, true);
    for f in fs {
        add_segment(&mut acc, f, h);
    }
    from_accumulator(&acc, tol)
}

/// Rank and directions from an accumulator (see [`analyze`]).
pub fn from_accumulator<const N: usize>(acc: &RowAccumulator<N>, tol: f64) -> Observability<N> {
    let (sig, v) = jacobi_svd(acc.r());
    let s1 = sig[0];
    let sigma_rel = if s1 > 0.0 { sig / s1 } else { sig };
    let rank = if s1 > 0.0 {
        sigma_rel.iter().filter(|&&s| s > tol).count()
    } else {
        0
    };
    let mut directions = v;
    for j in 0..N {
        let mut c = directions.column(j).component_mul(&acc.scale);
        let n = c.norm();
        if n > 0.0 {
            c /= n;
        }
        directions.set_column(j, &c);
    }
    Observability {
        rank,
        sigma_rel,
        directions,
    }
}

/// `‖O_s D⁻¹ x‖ / (‖O_s‖_F ‖D⁻¹ x‖)` for the scaled, row-normalised SOM `O_s`
/// (docs/theory/alignment.md §"Observability at one heading" T3 null-space check: < 1e-12 for a
/// null vector).
pub fn null_residual<const N: usize, const M: usize>(
    fs: &[SMatrix<f64, N, N>],
    h: &SMatrix<f64, M, N>,
    scale: &SVector<f64, N>,
    x: &SVector<f64, N>,
) -> f64 {
    let y = x.component_div(scale);
    let (mut sum, mut rows) = (0.0, 0usize);
    for f in fs {
        let mut block = *h;
        for _ in 0..N {
            for i in 0..M {
                let r = block.row(i).transpose().component_mul(scale);
                let n = r.norm();
                if n > 0.0 {
                    let d = r.dot(&y) / n;
                    sum += d * d;
                    rows += 1;
                }
            }
            block *= f;
        }
    }
    libm::sqrt(sum) / (libm::sqrt(rows as f64) * y.norm())
}

/// Column scaling of docs/theory/alignment.md §"Observability at one heading" for the 12-state
/// model: `D = diag(1 m/s ×3, 1e-3 rad ×3, 1e-3 m/s² ×3, 1e-7 rad/s ×3)`.
pub fn scale12() -> SVector<f64, 12> {
    SVector::<f64, 12>::from_fn(|i, _| match i / 3 {
        0 => 1.0,
        1 => 1e-3,
        2 => 1e-3,
        _ => 1e-7,
    })
}

/// Column scaling for the pseudo 9-state model `[δv, φ', δa_D, ε'_N, ε'_D]`.
pub fn scale9() -> SVector<f64, 9> {
    SVector::<f64, 9>::from_fn(|i, _| match i {
        0..=2 => 1.0,
        3..=5 => 1e-3,
        6 => 1e-3,
        _ => 1e-7,
    })
}

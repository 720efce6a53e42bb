//! Dense kernels over the active dimension of the fixed-capacity matrices of
//! [`super::layout`] (no allocation). Every kernel touches only the leading block it is
//! given the size of and leaves the rest of its output alone.
//!
//! Order of operations: products accumulate `Σ_k a_ik b_kj` in increasing `k`, the
//! Cholesky factorisation and its solves follow nalgebra's column-oriented algorithms
//! (axpy updates; the back substitution uses nalgebra's eight-accumulator dot product),
//! so that the results equal nalgebra's fixed-size operations on the same `n × n`
//! matrices bit for bit.

use super::layout::{Cov, XVec, MAX_STATES};
use nalgebra::{SMatrix, SVector};

/// Largest number of rows of one measurement.
pub const MAX_ROWS: usize = 12;

/// Measurement-Jacobian storage: `MAX_ROWS × MAX_STATES`.
pub type HMat = SMatrix<f64, MAX_ROWS, MAX_STATES>;
/// Measurement vector storage.
pub type MVec = SVector<f64, MAX_ROWS>;
/// Measurement covariance storage.
pub type RMat = SMatrix<f64, MAX_ROWS, MAX_ROWS>;
/// `MAX_STATES × MAX_ROWS` (P Hᵀ, the gain K).
pub type KMat = SMatrix<f64, MAX_STATES, MAX_ROWS>;

/// `out = a · b` over the leading `n × n` blocks.
pub fn mul(out: &mut Cov, a: &Cov, b: &Cov, n: usize) {
    const L: usize = MAX_STATES;
    let (a, b) = (a.as_slice(), b.as_slice());
    let o = out.as_mut_slice();
    for j in 0..n {
        let oj = &mut o[j * L..j * L + n];
        let x0 = b[j * L];
        for (y, ai) in oj.iter_mut().zip(&a[..n]) {
            *y = ai * x0;
        }
        for k in 1..n {
            let xk = b[j * L + k];
            for (y, ai) in oj.iter_mut().zip(&a[k * L..k * L + n]) {
                *y += ai * xk;
            }
        }
    }
}

/// `out = a · bᵀ` over the leading `n × n` blocks.
pub fn mul_tr(out: &mut Cov, a: &Cov, b: &Cov, n: usize) {
    let mut bt = Cov::zeros();
    for j in 0..n {
        for i in 0..n {
            bt[(i, j)] = b[(j, i)];
        }
    }
    mul(out, a, &bt, n);
}

/// `(p + pᵀ)/2` in place over the leading `n × n` block.
pub fn symmetrize(p: &mut Cov, n: usize) {
    for j in 0..n {
        for i in j..n {
            let v = (p[(i, j)] + p[(j, i)]) * 0.5;
            p[(i, j)] = v;
            p[(j, i)] = v;
        }
    }
}

/// Zero the whole matrix.
pub fn zero(m: &mut Cov) {
    m.fill(0.0);
}

/// `Φ = I + A + A²/2 + A³/6`, `A = F Δt`, over the leading `n × n` block (Horner form, the
/// operations of `error_model::transition`); the rest of `phi` is zero.
pub fn transition(phi: &mut Cov, f: &Cov, dt: f64, n: usize) {
    let mut a = Cov::zeros();
    let mut t = Cov::zeros();
    for j in 0..n {
        for i in 0..n {
            a[(i, j)] = f[(i, j)] * dt;
        }
    }
    // t = I + A/3
    for j in 0..n {
        for i in 0..n {
            t[(i, j)] = delta(i, j) + a[(i, j)] / 3.0;
        }
    }
    // phi = A t ; t = I + phi/2 ; phi = A t ; phi = I + phi
    zero(phi);
    mul(phi, &a, &t, n);
    for j in 0..n {
        for i in 0..n {
            t[(i, j)] = delta(i, j) + phi[(i, j)] / 2.0;
        }
    }
    mul(phi, &a, &t, n);
    for j in 0..n {
        for i in 0..n {
            phi[(i, j)] += delta(i, j);
        }
    }
}

#[inline]
fn delta(i: usize, j: usize) -> f64 {
    if i == j {
        1.0
    } else {
        0.0
    }
}

/// `P ← Φ P Φᵀ + Q` over the leading `n × n` blocks, then symmetrised.
pub fn propagate(p: &mut Cov, phi: &Cov, q: &Cov, n: usize) {
    let mut t = Cov::zeros();
    mul(&mut t, phi, p, n);
    mul_tr(p, &t, phi, n);
    for j in 0..n {
        for i in 0..n {
            p[(i, j)] += q[(i, j)];
        }
    }
    symmetrize(p, n);
}

/// nalgebra's dot product `Σ a_i b_i` (eight partial sums over whole chunks of eight, then
/// the remainder in order).
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let len = a.len().min(b.len());
    let mut acc = [0.0f64; 8];
    let mut i = 0;
    while len - i >= 8 {
        for (k, s) in acc.iter_mut().enumerate() {
            *s += a[i + k] * b[i + k];
        }
        i += 8;
    }
    let mut res = 0.0;
    res += acc[0] + acc[4];
    res += acc[1] + acc[5];
    res += acc[2] + acc[6];
    res += acc[3] + acc[7];
    for k in i..len {
        res += a[k] * b[k];
    }
    res
}

/// Cholesky factor `L` (lower triangle, column-major, leading dimension `ld`) of the
/// symmetric positive-definite leading `m × m` block of `s`, in place (nalgebra's
/// algorithm). `false` when a pivot is zero, negative or not a number.
pub fn cholesky(s: &mut [f64], ld: usize, m: usize) -> bool {
    for j in 0..m {
        for k in 0..j {
            let factor = -s[k * ld + j];
            for r in j..m {
                s[j * ld + r] += factor * s[k * ld + r];
            }
        }
        let diag = s[j * ld + j];
        // nalgebra: zero → None, try_sqrt of a negative (or NaN) → None
        if diag.is_nan() || diag <= 0.0 {
            return false;
        }
        let denom = libm::sqrt(diag);
        s[j * ld + j] = denom;
        for r in j + 1..m {
            s[j * ld + r] /= denom;
        }
    }
    true
}

/// Solve `L Lᵀ x = b` in place for one right-hand side (`b` of length ≥ m).
pub fn chol_solve(l: &[f64], ld: usize, m: usize, b: &mut [f64]) {
    // forward: L y = b
    for i in 0..m {
        let coeff = b[i] / l[i * ld + i];
        b[i] = coeff;
        for r in i + 1..m {
            b[r] += -coeff * l[i * ld + r];
        }
    }
    // backward: Lᵀ x = y
    for i in (0..m).rev() {
        let d = dot(&l[i * ld + i + 1..i * ld + m], &b[i + 1..m]);
        b[i] = (b[i] - d) / l[i * ld + i];
    }
}

/// `y = a · x` over the leading `n` (column-oriented, increasing k).
pub fn mul_vec(a: &Cov, x: &XVec, n: usize) -> XVec {
    let mut y = XVec::zeros();
    if n == 0 {
        return y;
    }
    for i in 0..n {
        y[i] = a[(i, 0)] * x[0];
    }
    for k in 1..n {
        let xk = x[k];
        for i in 0..n {
            y[i] += a[(i, k)] * xk;
        }
    }
    y
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use nalgebra::SMatrix;

    fn filled<const N: usize>(seed: u64) -> SMatrix<f64, N, N> {
        let mut s = seed;
        SMatrix::<f64, N, N>::from_fn(|_, _| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        })
    }

    fn embed<const N: usize>(m: &SMatrix<f64, N, N>) -> Cov {
        let mut c = Cov::zeros();
        c.fixed_view_mut::<N, N>(0, 0).copy_from(m);
        c
    }

    /// The kernels give nalgebra's fixed-size results bit for bit (15 and 21 states).
    #[test]
    fn kernels_equal_nalgebra_fixed_size_bit_for_bit() {
        fn check<const N: usize>() {
            let a = filled::<N>(1);
            let b = filled::<N>(2);
            let (ca, cb) = (embed(&a), embed(&b));
            let mut out = Cov::zeros();
            mul(&mut out, &ca, &cb, N);
            assert_eq!(out.fixed_view::<N, N>(0, 0).into_owned(), a * b);
            mul_tr(&mut out, &ca, &cb, N);
            assert_eq!(out.fixed_view::<N, N>(0, 0).into_owned(), a * b.transpose());
            let mut phi = Cov::zeros();
            transition(&mut phi, &ca, 0.1, N);
            assert_eq!(
                phi.fixed_view::<N, N>(0, 0).into_owned(),
                crate::aiding::error_model::transition(&a, 0.1)
            );
            // SPD matrix, Cholesky and solve
            let s = a * a.transpose() + SMatrix::<f64, N, N>::identity();
            let mut l = embed(&s);
            assert!(cholesky(l.as_mut_slice(), MAX_STATES, N));
            let chol = s.cholesky().unwrap();
            let mut rhs = [0.0; MAX_STATES];
            for (i, r) in rhs.iter_mut().enumerate().take(N) {
                *r = b[(i, 0)];
            }
            chol_solve(l.as_slice(), MAX_STATES, N, &mut rhs);
            let want = chol.solve(&b.column(0).into_owned());
            for i in 0..N {
                assert_eq!(rhs[i].to_bits(), want[i].to_bits(), "{i}");
            }
            let col = b.column(1).into_owned();
            let d = dot(col.as_slice(), want.as_slice());
            assert_eq!(d.to_bits(), col.dot(&want).to_bits());
        }
        check::<15>();
        check::<21>();
        check::<6>();
        check::<3>();
        check::<2>();
    }

    #[test]
    fn cholesky_refuses_indefinite() {
        let mut s = [1.0, 2.0, 2.0, 1.0];
        assert!(!cholesky(&mut s, 2, 2));
        let mut z = [0.0];
        assert!(!cholesky(&mut z, 1, 1));
        let mut nan = [f64::NAN];
        assert!(!cholesky(&mut nan, 1, 1));
    }
}

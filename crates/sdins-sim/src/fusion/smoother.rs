//! Post-processing with the Rauch–Tung–Striebel smoother (`sdins_core::aiding::rts`):
//! the forward filter's covariance epochs are logged compactly at the filter's active dimension, walked backwards, and the
//! smoothed corrections re-applied to the forward navigation states at full rate.
//!
//! ## Storage
//! Per covariance epoch the log keeps `Φ` (N × N), `P(k|k−1)` and `P(k|k)` (symmetric,
//! packed upper triangles of N(N+1)/2 values) and the applied correction δx̂: for the
//! 15-state filter 3 848 bytes, so an hour at 1 Hz is 13.9 MB and at 10 Hz 139 MB; for the
//! 21-state filter 7 400 bytes. [`SmootherLog::bytes`] reports it.
//!
//! ## Full-rate output
//! Between epochs k and k+1 the forward state is propagated from the corrected state at
//! k, so its error runs from `ê⁺_k` to `ê⁻_{k+1} = ê⁺_{k+1} + δx̂_{k+1}`; the correction
//! at a navigation update at time t in between is interpolated linearly in time,
//! `ê(t) = ê⁺_k + (t − t_k)/(t_{k+1} − t_k) (ê⁻_{k+1} − ê⁺_k)` (the error changes on the
//! Schuler time scale, and epochs are ≤ 1 s apart), and applied with
//! `sdins_core::aiding::ekf::correct_nav_state`. A state recorded at an epoch (after
//! its measurements) takes `ê⁺_k`.

use crate::cancel::{CancelToken, Cancelled};
use sdins_core::aiding::ekf::{CovEpoch, FilterError};
use sdins_core::aiding::layout::{Cov, XVec};
use sdins_core::aiding::rts::{rts_step, Smoothed};

/// Length of the packed upper triangle of a symmetric n × n matrix.
const fn packed_len(n: usize) -> usize {
    n * (n + 1) / 2
}

/// Append the packed upper triangle of the leading `n × n` block of `m` to `out`.
fn pack_into(m: &Cov, n: usize, out: &mut Vec<f64>) {
    for i in 0..n {
        for j in i..n {
            out.push(m[(i, j)]);
        }
    }
}

/// The symmetric matrix of a packed upper triangle (missing values read as 0).
fn unpack(p: &[f64], n: usize) -> Cov {
    let mut m = Cov::zeros();
    let mut k = 0;
    for i in 0..n {
        for j in i..n {
            let v = p.get(k).copied().unwrap_or(0.0);
            m[(i, j)] = v;
            m[(j, i)] = v;
            k += 1;
        }
    }
    m
}

/// Why smoothing stopped.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SmootherError {
    /// Nothing was logged.
    #[error("the smoother log is empty (no covariance epoch was recorded)")]
    Empty,
    /// Epochs out of time order.
    #[error("smoother epoch at t = {t_s} s does not follow the one at {prev_s} s")]
    Order {
        /// the offending epoch's time \[s\]
        t_s: f64,
        /// the previous epoch's time \[s\]
        prev_s: f64,
    },
    /// An epoch of another dimension than the first.
    #[error("smoother epoch at t = {t_s} s has {n} states, the log {want}")]
    Dimension {
        /// the offending epoch's time \[s\]
        t_s: f64,
        /// its dimension
        n: usize,
        /// the log's
        want: usize,
    },
    /// A backward step failed (names the epoch).
    #[error(transparent)]
    Filter(#[from] FilterError),
    /// Cancelled.
    #[error("cancelled")]
    Cancelled(#[from] Cancelled),
}

/// The forward filter's covariance epochs, in time order, at the active dimension n of
/// the first epoch: per epoch `t`, Φ (n × n), δx̂ (n), packed P(k|k−1) and P(k|k).
#[derive(Clone, Debug, Default)]
pub struct SmootherLog {
    n: usize,
    data: Vec<f64>,
    len: usize,
}

impl SmootherLog {
    /// An empty log.
    pub fn new() -> Self {
        Self::default()
    }
    /// An empty log with room for `epochs` epochs of `n` states.
    pub fn with_capacity(epochs: usize, n: usize) -> Self {
        Self {
            n,
            data: Vec::with_capacity(epochs * Self::record_len(n)),
            len: 0,
        }
    }
    /// f64 values per epoch: t, Φ, δx̂, two packed covariances.
    const fn record_len(n: usize) -> usize {
        1 + n * n + n + 2 * packed_len(n)
    }
    /// Append an epoch (from `Ekf::initial_epoch` first, then `Ekf::take_epoch`).
    pub fn push(&mut self, e: &CovEpoch) -> Result<(), SmootherError> {
        if self.len == 0 {
            self.n = e.n;
        } else if e.n != self.n {
            return Err(SmootherError::Dimension {
                t_s: e.t_s,
                n: e.n,
                want: self.n,
            });
        }
        if let Some(prev) = self.t_s(self.len.wrapping_sub(1)) {
            if e.t_s.partial_cmp(&prev) != Some(std::cmp::Ordering::Greater) {
                return Err(SmootherError::Order {
                    t_s: e.t_s,
                    prev_s: prev,
                });
            }
        }
        let n = self.n;
        self.data.push(e.t_s);
        for j in 0..n {
            for i in 0..n {
                self.data.push(e.phi[(i, j)]);
            }
        }
        self.data.extend((0..n).map(|i| e.dx[i]));
        pack_into(&e.p_pred, n, &mut self.data);
        pack_into(&e.p_post, n, &mut self.data);
        self.len += 1;
        Ok(())
    }
    /// Number of epochs.
    pub fn len(&self) -> usize {
        self.len
    }
    /// No epoch logged.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// Active dimension of the epochs.
    pub fn dim(&self) -> usize {
        self.n
    }
    /// Bytes held by the log (its allocation).
    pub fn bytes(&self) -> usize {
        self.data.capacity() * std::mem::size_of::<f64>()
    }
    fn record(&self, k: usize) -> Option<&[f64]> {
        let l = Self::record_len(self.n);
        if k >= self.len {
            return None;
        }
        self.data.get(k * l..(k + 1) * l)
    }
    /// Time of epoch `k` \[s\].
    pub fn t_s(&self, k: usize) -> Option<f64> {
        self.record(k).map(|r| r[0])
    }
    /// The forward record of epoch `k`.
    pub fn epoch(&self, k: usize) -> Option<CovEpoch> {
        let r = self.record(k)?;
        let n = self.n;
        let mut phi = Cov::zeros();
        for j in 0..n {
            for i in 0..n {
                phi[(i, j)] = r[1 + j * n + i];
            }
        }
        let o = 1 + n * n;
        let mut dx = XVec::zeros();
        for i in 0..n {
            dx[i] = r[o + i];
        }
        let o = o + n;
        let p = packed_len(n);
        Some(CovEpoch {
            t_s: r[0],
            n,
            phi,
            p_pred: unpack(&r[o..o + p], n),
            p_post: unpack(&r[o + p..o + 2 * p], n),
            dx,
        })
    }

    /// Run the backward pass. `visit(k, forward, smoothed)` sees every epoch from the last
    /// to the first; the returned corrections `ê⁺_k` are in time order (feed them to
    /// [`SmoothedCorrections`]).
    pub fn smooth(
        &self,
        cancel: &CancelToken,
        mut visit: impl FnMut(usize, &CovEpoch, &Smoothed),
    ) -> Result<SmoothedCorrections, SmootherError> {
        let n = self.len;
        let Some(last) = n.checked_sub(1).and_then(|k| self.epoch(k)) else {
            return Err(SmootherError::Empty);
        };
        let d = self.n;
        let mut dx = vec![0.0; n * d];
        let mut s = Smoothed::last(&last);
        visit(n - 1, &last, &s);
        let mut next = last;
        for k in (0..n - 1).rev() {
            if k % 4096 == 0 {
                cancel.check()?;
            }
            let Some(rec) = self.epoch(k) else {
                return Err(SmootherError::Empty);
            };
            s = rts_step(&rec, &next, &s)?;
            for i in 0..d {
                dx[k * d + i] = s.dx[i];
            }
            visit(k, &rec, &s);
            next = rec;
        }
        let l = Self::record_len(d);
        let mut applied = Vec::with_capacity(n * d);
        let mut t_s = Vec::with_capacity(n);
        for k in 0..n {
            let r = &self.data[k * l..(k + 1) * l];
            t_s.push(r[0]);
            applied.extend_from_slice(&r[1 + d * d..1 + d * d + d]);
        }
        Ok(SmoothedCorrections {
            n: d,
            t_s,
            applied,
            dx,
        })
    }
}

/// The smoothed corrections of every epoch, to be re-applied at full rate.
#[derive(Clone, Debug, PartialEq)]
pub struct SmoothedCorrections {
    n: usize,
    t_s: Vec<f64>,
    applied: Vec<f64>,
    dx: Vec<f64>,
}

impl SmoothedCorrections {
    /// Number of epochs.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }
    /// No epochs.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }
    fn vec(v: &[f64], k: usize, n: usize) -> XVec {
        let mut x = XVec::zeros();
        if let Some(s) = v.get(k * n..(k + 1) * n) {
            for (i, a) in s.iter().enumerate() {
                x[i] = *a;
            }
        }
        x
    }
    /// `ê⁺_k` of epoch `k`.
    pub fn at_epoch(&self, k: usize) -> Option<XVec> {
        (k < self.len()).then(|| Self::vec(&self.dx, k, self.n))
    }
    /// The correction for a forward state at time `t_s` \[s\] (see the module
    /// documentation); `epoch` is the index of the latest epoch at or before `t_s`
    /// (the caller tracks it as it walks forward). Before the first and after the last
    /// epoch the nearest epoch's correction is used.
    pub fn at(&self, epoch: usize, t_s: f64) -> XVec {
        let n = self.t_s.len();
        if n == 0 {
            return XVec::zeros();
        }
        let k = epoch.min(n - 1);
        let tk = self.t_s[k];
        let dk = Self::vec(&self.dx, k, self.n);
        if k + 1 >= n || t_s <= tk {
            return dk;
        }
        let t1 = self.t_s[k + 1];
        let w = ((t_s - tk) / (t1 - tk)).clamp(0.0, 1.0);
        let pre_next = Self::vec(&self.dx, k + 1, self.n) + Self::vec(&self.applied, k + 1, self.n);
        dk + (pre_next - dk) * w
    }
    /// Index of the latest epoch with time ≤ `t_s` (binary search).
    pub fn epoch_index(&self, t_s: f64) -> usize {
        self.t_s.partition_point(|t| *t <= t_s).saturating_sub(1)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn roundtrip(n: usize) -> usize {
        let mut m = Cov::zeros();
        for i in 0..n {
            for j in 0..n {
                m[(i, j)] = (i.min(j) * 100 + i.max(j)) as f64;
            }
        }
        let mut v = Vec::new();
        pack_into(&m, n, &mut v);
        assert_eq!(v.len(), packed_len(n));
        assert_eq!(unpack(&v, n), m);
        8 * SmootherLog::record_len(n)
    }

    #[test]
    fn pack_roundtrip_and_size() {
        // the bytes per epoch of the fixed-size logs of earlier versions
        assert_eq!(roundtrip(15), 3848);
        assert_eq!(roundtrip(21), 7400);
    }

    /// Identity blocks of dimension `n` (only the leading `n × n` blocks are meaningful:
    /// the log keeps those and gives zeros outside).
    fn epoch(t: f64, n: usize) -> CovEpoch {
        let mut eye = Cov::zeros();
        for i in 0..n {
            eye[(i, i)] = 1.0;
        }
        CovEpoch {
            t_s: t,
            n,
            phi: eye,
            p_pred: eye,
            p_post: eye,
            dx: XVec::zeros(),
        }
    }

    #[test]
    fn log_refuses_epochs_out_of_order_other_dimensions_and_empty_smoothing() {
        let mut log = SmootherLog::new();
        assert!(matches!(
            log.smooth(&CancelToken::new(), |_, _, _| {}),
            Err(SmootherError::Empty)
        ));
        log.push(&epoch(1.0, 15)).unwrap();
        assert!(matches!(
            log.push(&epoch(1.0, 15)),
            Err(SmootherError::Order { .. })
        ));
        assert!(matches!(
            log.push(&epoch(2.0, 21)),
            Err(SmootherError::Dimension { .. })
        ));
        let mut e = epoch(2.0, 15);
        e.phi[(3, 4)] = 0.5;
        e.dx[14] = 2.0;
        e.p_post[(1, 2)] = 0.25;
        e.p_post[(2, 1)] = 0.25;
        log.push(&e).unwrap();
        assert_eq!(log.epoch(1).unwrap(), e);
        assert!(log.bytes() >= 2 * 3848);
    }

    #[test]
    fn interpolation_runs_from_post_to_pre_correction() {
        let c = SmoothedCorrections {
            n: 15,
            t_s: vec![0.0, 1.0],
            applied: [vec![0.0; 15], vec![2.0; 15]].concat(),
            dx: [vec![1.0; 15], vec![-1.0; 15]].concat(),
        };
        assert_eq!(c.at(0, 0.0)[0], 1.0);
        // pre-correction at t1: −1 + 2 = 1 → constant 1 in between
        assert!((c.at(0, 0.5)[3] - 1.0).abs() < 1e-15);
        assert_eq!(c.at(1, 1.0)[0], -1.0);
        assert_eq!(c.at(1, 1.0)[15], 0.0);
        assert_eq!(c.epoch_index(0.5), 0);
        assert_eq!(c.epoch_index(1.0), 1);
    }
}

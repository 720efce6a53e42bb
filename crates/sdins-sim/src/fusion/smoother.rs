//! Post-processing with the Rauch–Tung–Striebel smoother (`sdins_core::aiding::rts`):
//! the forward filter's covariance epochs are logged compactly, walked backwards, and the
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
use sdins_core::aiding::error_model::{StateMatN, StateVecN, N_STATES};
use sdins_core::aiding::rts::{rts_step, Smoothed};

/// Length of the packed upper triangle of a symmetric N × N matrix.
const fn packed_len(n: usize) -> usize {
    n * (n + 1) / 2
}

/// Append the packed upper triangle of `m` to `out`.
fn pack_into<const N: usize>(m: &StateMatN<N>, out: &mut Vec<f64>) {
    for i in 0..N {
        for j in i..N {
            out.push(m[(i, j)]);
        }
    }
}

/// The symmetric matrix of a packed upper triangle (`p.len() ≥ N(N+1)/2`).
fn unpack<const N: usize>(p: &[f64]) -> StateMatN<N> {
    let mut m = StateMatN::<N>::zeros();
    let mut k = 0;
    for i in 0..N {
        for j in i..N {
            let v = p.get(k).copied().unwrap_or(0.0);
            m[(i, j)] = v;
            m[(j, i)] = v;
            k += 1;
        }
    }
    m
}

#[derive(Clone, Debug)]
struct Record<const N: usize> {
    t_s: f64,
    phi: StateMatN<N>,
    dx: StateVecN<N>,
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
    /// A backward step failed (names the epoch).
    #[error(transparent)]
    Filter(#[from] FilterError),
    /// Cancelled.
    #[error("cancelled")]
    Cancelled(#[from] Cancelled),
}

/// The forward filter's covariance epochs, in time order (`N` = 15 or 21 states).
#[derive(Clone, Debug)]
pub struct SmootherLog<const N: usize = N_STATES> {
    recs: Vec<Record<N>>,
    /// per epoch the packed P(k|k−1) then P(k|k)
    packed: Vec<f64>,
}

impl<const N: usize> Default for SmootherLog<N> {
    fn default() -> Self {
        Self {
            recs: Vec::new(),
            packed: Vec::new(),
        }
    }
}

impl<const N: usize> SmootherLog<N> {
    const PACKED: usize = packed_len(N);

    /// An empty log.
    pub fn new() -> Self {
        Self::default()
    }
    /// An empty log with room for `n` epochs.
    pub fn with_capacity(n: usize) -> Self {
        Self {
            recs: Vec::with_capacity(n),
            packed: Vec::with_capacity(n * 2 * Self::PACKED),
        }
    }
    /// Append an epoch (from `Ekf::initial_epoch` first, then `Ekf::take_epoch`).
    pub fn push(&mut self, e: &CovEpoch<N>) -> Result<(), SmootherError> {
        if let Some(prev) = self.recs.last() {
            if e.t_s.partial_cmp(&prev.t_s) != Some(std::cmp::Ordering::Greater) {
                return Err(SmootherError::Order {
                    t_s: e.t_s,
                    prev_s: prev.t_s,
                });
            }
        }
        self.recs.push(Record {
            t_s: e.t_s,
            phi: e.phi,
            dx: e.dx,
        });
        pack_into(&e.p_pred, &mut self.packed);
        pack_into(&e.p_post, &mut self.packed);
        Ok(())
    }
    /// Number of epochs.
    pub fn len(&self) -> usize {
        self.recs.len()
    }
    /// No epoch logged.
    pub fn is_empty(&self) -> bool {
        self.recs.is_empty()
    }
    /// Bytes held by the log (its allocation).
    pub fn bytes(&self) -> usize {
        self.recs.capacity() * std::mem::size_of::<Record<N>>()
            + self.packed.capacity() * std::mem::size_of::<f64>()
    }
    /// Time of epoch `k` \[s\].
    pub fn t_s(&self, k: usize) -> Option<f64> {
        self.recs.get(k).map(|r| r.t_s)
    }
    /// The forward record of epoch `k`.
    pub fn epoch(&self, k: usize) -> Option<CovEpoch<N>> {
        let r = self.recs.get(k)?;
        let p = Self::PACKED;
        let packed = self.packed.get(2 * p * k..2 * p * (k + 1))?;
        Some(CovEpoch {
            t_s: r.t_s,
            phi: r.phi,
            p_pred: unpack(&packed[..p]),
            p_post: unpack(&packed[p..]),
            dx: r.dx,
        })
    }

    /// Run the backward pass. `visit(k, forward, smoothed)` sees every epoch from the last
    /// to the first; the returned corrections `ê⁺_k` are in time order (feed them to
    /// [`SmoothedCorrections`]).
    pub fn smooth(
        &self,
        cancel: &CancelToken,
        mut visit: impl FnMut(usize, &CovEpoch<N>, &Smoothed<N>),
    ) -> Result<SmoothedCorrections<N>, SmootherError> {
        let n = self.recs.len();
        let Some(last) = n.checked_sub(1).and_then(|k| self.epoch(k)) else {
            return Err(SmootherError::Empty);
        };
        let mut dx = vec![StateVecN::<N>::zeros(); n];
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
            dx[k] = s.dx;
            visit(k, &rec, &s);
            next = rec;
        }
        Ok(SmoothedCorrections {
            t_s: self.recs.iter().map(|r| r.t_s).collect(),
            applied: self.recs.iter().map(|r| r.dx).collect(),
            dx,
        })
    }
}

/// The smoothed corrections of every epoch, to be re-applied at full rate.
#[derive(Clone, Debug, PartialEq)]
pub struct SmoothedCorrections<const N: usize = N_STATES> {
    t_s: Vec<f64>,
    applied: Vec<StateVecN<N>>,
    dx: Vec<StateVecN<N>>,
}

impl<const N: usize> SmoothedCorrections<N> {
    /// Number of epochs.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }
    /// No epochs.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }
    /// `ê⁺_k` of epoch `k`.
    pub fn at_epoch(&self, k: usize) -> Option<&StateVecN<N>> {
        self.dx.get(k)
    }
    /// The correction for a forward state at time `t_s` \[s\] (see the module
    /// documentation); `epoch` is the index of the latest epoch at or before `t_s`
    /// (the caller tracks it as it walks forward). Before the first and after the last
    /// epoch the nearest epoch's correction is used.
    pub fn at(&self, epoch: usize, t_s: f64) -> StateVecN<N> {
        let n = self.t_s.len();
        if n == 0 {
            return StateVecN::<N>::zeros();
        }
        let k = epoch.min(n - 1);
        let tk = self.t_s[k];
        if k + 1 >= n || t_s <= tk {
            return self.dx[k];
        }
        let t1 = self.t_s[k + 1];
        let w = ((t_s - tk) / (t1 - tk)).clamp(0.0, 1.0);
        let pre_next = self.dx[k + 1] + self.applied[k + 1];
        self.dx[k] + (pre_next - self.dx[k]) * w
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
    use sdins_core::aiding::error_model::{StateMat, StateVec, N_STATES_SF};

    fn roundtrip<const N: usize>() -> usize {
        let mut m = StateMatN::<N>::zeros();
        for i in 0..N {
            for j in 0..N {
                m[(i, j)] = (i.min(j) * 100 + i.max(j)) as f64;
            }
        }
        let mut v = Vec::new();
        pack_into(&m, &mut v);
        assert_eq!(v.len(), packed_len(N));
        assert_eq!(unpack::<N>(&v), m);
        std::mem::size_of::<Record<N>>() + 2 * 8 * packed_len(N)
    }

    #[test]
    fn pack_roundtrip_and_size() {
        assert_eq!(roundtrip::<N_STATES>(), 3848);
        assert_eq!(roundtrip::<N_STATES_SF>(), 7400);
    }

    #[test]
    fn log_refuses_epochs_out_of_order_and_empty_smoothing() {
        let e = CovEpoch {
            t_s: 1.0,
            phi: StateMat::identity(),
            p_pred: StateMat::identity(),
            p_post: StateMat::identity(),
            dx: StateVec::zeros(),
        };
        let mut log = SmootherLog::<N_STATES>::new();
        assert!(matches!(
            log.smooth(&CancelToken::new(), |_, _, _| {}),
            Err(SmootherError::Empty)
        ));
        log.push(&e).unwrap();
        assert!(matches!(log.push(&e), Err(SmootherError::Order { .. })));
    }

    #[test]
    fn interpolation_runs_from_post_to_pre_correction() {
        let c = SmoothedCorrections {
            t_s: vec![0.0, 1.0],
            applied: vec![StateVec::zeros(), StateVec::repeat(2.0)],
            dx: vec![StateVec::repeat(1.0), StateVec::repeat(-1.0)],
        };
        assert_eq!(c.at(0, 0.0)[0], 1.0);
        // pre-correction at t1: −1 + 2 = 1 → constant 1 in between
        assert!((c.at(0, 0.5)[3] - 1.0).abs() < 1e-15);
        assert_eq!(c.at(1, 1.0)[0], -1.0);
        assert_eq!(c.epoch_index(0.5), 0);
        assert_eq!(c.epoch_index(1.0), 1);
    }
}

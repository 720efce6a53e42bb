//! The filter's short history for measurements whose time of validity lies in the past
//! (fixed-capacity ring buffers, no allocation):
//!
//! * per navigation update, the interval's start and end states as the on-time
//!   interpolation uses them (the end state after that update's corrections, the start
//!   shifted with them), and the compensated body rate: [`HIST_UPDATES`] updates;
//! * per covariance epoch, what its transition matrix Φ was built from (the state, the
//!   interval-mean specific force and scale-factor terms, the interval) and the sum of the
//!   corrections applied at the epoch: [`HIST_EPOCHS`] epochs. Φ is rebuilt from them
//!   bit for bit when a delayed measurement needs it.
//!
//! The method (back-propagation of the measurement model) is in [`super::ekf`] and
//! `docs/theory/ins-gnss.md` §"Measurement timing".

use super::layout::XVec;
use crate::math::{Mat3, Vec3};
use crate::nav::NavState;

/// Navigation updates kept (the longest usable latency is 255 update intervals: 1.02 s
/// at 250 Hz, 2.55 s at 100 Hz).
pub const HIST_UPDATES: usize = 256;
/// Covariance epochs kept.
pub const HIST_EPOCHS: usize = 64;

/// One navigation update: the interval `(t_prev, t]` as the interpolation sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavEntry {
    /// start of the interval (the previous state, shifted by this update's corrections)
    pub prev: NavState,
    /// end of the interval (after this update's corrections)
    pub cur: NavState,
    /// compensated body rate over the interval \[rad/s\]
    pub omega_ib_b: Vec3,
}

/// One covariance epoch: the inputs of its Φ and the corrections applied at it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EpochEntry {
    /// epoch time \[s\]
    pub t_s: f64,
    /// interval from the previous epoch \[s\]
    pub tau_s: f64,
    /// latitude \[rad\]
    pub lat_rad: f64,
    /// height \[m\]
    pub h_m: f64,
    /// NED velocity \[m/s\]
    pub v_n_mps: Vec3,
    /// attitude
    pub c_b_n: Mat3,
    /// interval-mean specific force, NED \[m/s²\]
    pub f_n_mps2: Vec3,
    /// interval mean of `Ĉ diag(f^b)` (accelerometer scale-factor columns)
    pub sa: Mat3,
    /// interval mean of `Ĉ diag(ω_ib^b)` (gyro scale-factor columns)
    pub sg: Mat3,
    /// sum of the corrections applied at the epoch
    pub dx: XVec,
}

/// A ring buffer of `CAP` values (oldest overwritten).
#[derive(Clone, Debug)]
pub struct Ring<T: Copy, const CAP: usize> {
    buf: [T; CAP],
    head: usize,
    len: usize,
}

impl<T: Copy, const CAP: usize> Ring<T, CAP> {
    /// An empty ring (every slot holds `fill`).
    pub fn new(fill: T) -> Self {
        Self {
            buf: [fill; CAP],
            head: 0,
            len: 0,
        }
    }
    /// Append (the oldest value is dropped when full).
    pub fn push(&mut self, v: T) {
        self.buf[self.head] = v;
        self.head = (self.head + 1) % CAP;
        self.len = (self.len + 1).min(CAP);
    }
    /// Number of values.
    pub fn len(&self) -> usize {
        self.len
    }
    /// No value.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// The `k`-th newest value (0 = newest).
    pub fn back(&self, k: usize) -> Option<&T> {
        if k >= self.len {
            return None;
        }
        Some(&self.buf[(self.head + CAP - 1 - k) % CAP])
    }
    /// The `k`-th newest value, mutable.
    pub fn back_mut(&mut self, k: usize) -> Option<&mut T> {
        if k >= self.len {
            return None;
        }
        Some(&mut self.buf[(self.head + CAP - 1 - k) % CAP])
    }
    /// Forget everything.
    pub fn clear(&mut self) {
        self.len = 0;
    }
}

/// The navigation entry whose interval `(prev.t, cur.t]` holds `t_s`, searched from the
/// newest.
pub fn nav_entry_at<const CAP: usize>(r: &Ring<NavEntry, CAP>, t_s: f64) -> Option<&NavEntry> {
    (0..r.len())
        .filter_map(|k| r.back(k))
        .take_while(|e| e.cur.t_s >= t_s)
        .find(|e| e.prev.t_s < t_s && t_s <= e.cur.t_s)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn ring_keeps_the_newest() {
        let mut r = Ring::<u32, 3>::new(0);
        assert!(r.is_empty() && r.back(0).is_none());
        for v in 1..=5 {
            r.push(v);
        }
        assert_eq!(r.len(), 3);
        assert_eq!(
            (r.back(0), r.back(1), r.back(2), r.back(3)),
            (Some(&5), Some(&4), Some(&3), None)
        );
        *r.back_mut(1).unwrap() = 9;
        assert_eq!(r.back(1), Some(&9));
        r.clear();
        assert!(r.is_empty());
    }

    #[test]
    fn nav_entry_lookup() {
        let s = |t: f64| NavState {
            t_s: t,
            lat_rad: 0.0,
            lon_rad: 0.0,
            h_m: 0.0,
            v_n_mps: Vec3::zeros(),
            c_b_n: Mat3::identity(),
        };
        let mut r = Ring::<NavEntry, 4>::new(NavEntry {
            prev: s(0.0),
            cur: s(0.0),
            omega_ib_b: Vec3::zeros(),
        });
        for k in 0..6 {
            r.push(NavEntry {
                prev: s(k as f64),
                cur: s(k as f64 + 1.0),
                omega_ib_b: Vec3::zeros(),
            });
        }
        // entries (2,3], (3,4], (4,5], (5,6]
        assert_eq!(nav_entry_at(&r, 4.5).unwrap().cur.t_s, 5.0);
        assert_eq!(nav_entry_at(&r, 3.0).unwrap().cur.t_s, 3.0);
        assert!(nav_entry_at(&r, 2.0).is_none());
        assert!(nav_entry_at(&r, 6.5).is_none());
    }
}

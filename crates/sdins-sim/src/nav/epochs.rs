//! Output epochs without drift (docs/conventions.md §"Output epochs").
//!
//! Navigation updates happen on a uniform grid `t_j = t0 + j·Δt` (`j = 0` is the initial
//! state, `Δt` = samples per update × sample period). Output row `k` is the update
//! **nearest** to `t0 + k·every` (ties to the earlier update) and carries that update's own
//! time, never a relabelled or interpolated one: at Mach 1 a 3 ms relabel is 1 m. The last
//! update of a run is an output row too when it is not already one, so that every output
//! ends with the final state.
//!
//! With `every` a multiple of `Δt` the rows fall exactly on the grid; otherwise each row
//! is within `Δt/2` of `t0 + k·every`, and the error does not accumulate (the old rule,
//! every `round(every/Δt)` updates, drifted: 1.002, 2.004, … s for `every = 1` s and
//! `Δt = 6` ms). When `every < Δt` several grid times can share one update; it is output
//! once.

use crate::nav::options::OptionError;

/// The output-epoch rule of a run: updates `t0 + j·Δt`, rows near `t0 + k·every`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EpochGrid {
    /// update interval Δt \[s\]
    pub dt_update_s: f64,
    /// output spacing \[s\]
    pub every_s: f64,
}

impl EpochGrid {
    /// A grid; `every_s` must be positive and finite (message names `--every-s`), and the
    /// update interval positive and finite.
    pub fn new(every_s: f64, dt_update_s: f64) -> Result<Self, OptionError> {
        if !(every_s.is_finite() && every_s > 0.0) {
            return Err(OptionError::Bad(format!(
                "--every-s {every_s}: expected a positive number of seconds"
            )));
        }
        if !(dt_update_s.is_finite() && dt_update_s > 0.0) {
            return Err(OptionError::Bad(format!(
                "update interval {dt_update_s} s: expected a positive number of seconds"
            )));
        }
        Ok(Self {
            dt_update_s,
            every_s,
        })
    }

    /// Index of the update nearest to `t0 + k·every` (ties to the earlier one).
    pub fn update_of(&self, k: u64) -> u64 {
        let target = k as f64 * self.every_s;
        let x = target / self.dt_update_s;
        if !x.is_finite() || x >= u64::MAX as f64 {
            return u64::MAX;
        }
        let lo = x.floor() as u64;
        // distances in time, from the same products the grid times are formed with
        let d_lo = target - lo as f64 * self.dt_update_s;
        let d_hi = (lo + 1) as f64 * self.dt_update_s - target;
        if d_hi < d_lo {
            lo + 1
        } else {
            lo
        }
    }

    /// A cursor over the output updates of a run of `last` updates (update indices
    /// `0..=last`).
    pub fn cursor(&self, last: u64) -> EpochCursor {
        EpochCursor {
            grid: *self,
            k: 0,
            next: self.update_of(0),
            last,
        }
    }

    /// Every output update index of a run of `last` updates, ascending.
    pub fn updates(&self, last: u64) -> Vec<u64> {
        let mut c = self.cursor(last);
        (0..=last).filter(|&j| c.is_output(j)).collect()
    }
}

/// Walks the updates of a run in order and says which are output rows.
#[derive(Clone, Debug)]
pub struct EpochCursor {
    grid: EpochGrid,
    k: u64,
    next: u64,
    last: u64,
}

impl EpochCursor {
    /// Whether update `j` is an output row. Call it for `j = 0, 1, 2, …` in order (skipping
    /// indices is allowed; an index below the next output is simply not one).
    pub fn is_output(&mut self, j: u64) -> bool {
        if j == self.last {
            return true;
        }
        if j < self.next {
            return false;
        }
        // advance past every grid time this update (or an earlier one) serves
        while self.next <= j {
            self.k += 1;
            self.next = self.grid.update_of(self.k);
        }
        true
    }

    /// The next output update index after the calls so far (the last update at most).
    pub fn next_output(&self) -> u64 {
        self.next.min(self.last)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn mach1_every_second_is_on_the_grid_without_drift() {
        // 500 Hz, 3 samples per update: Δt = 6 ms; 5400 s = 900 000 updates
        let g = EpochGrid::new(1.0, 3.0 / 500.0).unwrap();
        let rows = g.updates(900_000);
        assert_eq!(rows.len(), 5401);
        for (k, &j) in rows.iter().enumerate() {
            let t = j as f64 * 3.0 / 500.0;
            assert!((t - k as f64).abs() <= 0.003 + 1e-12, "row {k}: t = {t}");
        }
        assert_eq!(*rows.last().unwrap(), 900_000);
        // nearest: 1 s / 6 ms = 166.67 → update 167 (1.002 s), 2 s → 333 (1.998 s)
        assert_eq!(&rows[..4], &[0, 167, 333, 500]);
    }

    #[test]
    fn ties_go_to_the_earlier_update_and_rows_are_unique() {
        // every = 1.5 Δt: t = 1.5 lies half-way between updates 1 and 2
        let g = EpochGrid::new(1.5, 1.0).unwrap();
        assert_eq!(g.update_of(1), 1);
        assert_eq!(g.update_of(2), 3);
        // every < Δt: one row per update, never twice
        let g = EpochGrid::new(0.3, 1.0).unwrap();
        assert_eq!(g.updates(4), vec![0, 1, 2, 3, 4]);
    }

    #[test]
    fn the_last_update_is_always_a_row() {
        let g = EpochGrid::new(1.0, 0.25).unwrap();
        assert_eq!(g.updates(10), vec![0, 4, 8, 10]);
        assert!(EpochGrid::new(0.0, 0.1).is_err());
        assert!(EpochGrid::new(f64::NAN, 0.1).is_err());
        assert!(EpochGrid::new(1.0, 0.0).is_err());
    }
}

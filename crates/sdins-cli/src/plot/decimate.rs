//! Min/max-per-column decimation: series longer than the plot width keep, per pixel
//! column, their smallest and largest sample, so that short events (a 2 s turn in an hour)
//! stay visible and every column's vertical extent is exact.

/// (x, y) of the minimum and (x, y) of the maximum of one column.
type MinMax = ((f64, f64), (f64, f64));

/// Online min/max-per-column decimation of one or more channels sharing an x axis: the
/// x range `[x0, x1]` is cut into `cols` columns and each column keeps, per channel, the
/// sample with the smallest and the one with the largest y. Drawing the kept points in
/// x order gives, at `cols` pixel columns or fewer, the same picture as all samples:
/// every column's vertical extent is preserved exactly. Non-finite values are skipped.
#[derive(Clone, Debug)]
pub struct MinMaxColumns {
    x0: f64,
    width: f64,
    cols: usize,
    channels: usize,
    /// per column and channel: ((x, y) of the minimum, (x, y) of the maximum)
    cells: Vec<Option<MinMax>>,
}

impl MinMaxColumns {
    /// `cols` columns over `[x0, x1]` for `channels` channels.
    pub fn new(x0: f64, x1: f64, cols: usize, channels: usize) -> Self {
        let cols = cols.max(1);
        let width = if x1 > x0 { x1 - x0 } else { 1.0 };
        Self {
            x0,
            width,
            cols,
            channels,
            cells: vec![None; cols * channels],
        }
    }

    fn column(&self, x: f64) -> usize {
        let k = ((x - self.x0) / self.width * self.cols as f64).floor();
        if k.is_finite() {
            (k.max(0.0) as usize).min(self.cols - 1)
        } else {
            0
        }
    }

    /// Add one sample at `x` of every channel (`ys.len()` = channels; extra values are
    /// ignored).
    pub fn push(&mut self, x: f64, ys: &[f64]) {
        if !x.is_finite() {
            return;
        }
        let c = self.column(x);
        for (ch, &y) in ys.iter().enumerate().take(self.channels) {
            if !y.is_finite() {
                continue;
            }
            let cell = &mut self.cells[c * self.channels + ch];
            match cell {
                None => *cell = Some(((x, y), (x, y))),
                Some((lo, hi)) => {
                    if y < lo.1 {
                        *lo = (x, y);
                    }
                    if y > hi.1 {
                        *hi = (x, y);
                    }
                }
            }
        }
    }

    /// The kept points of channel `ch` in x order (one or two per non-empty column).
    pub fn series(&self, ch: usize) -> Vec<(f64, f64)> {
        let mut out = Vec::new();
        for c in 0..self.cols {
            if let Some(Some((lo, hi))) = self.cells.get(c * self.channels + ch) {
                if lo == hi {
                    out.push(*lo);
                } else if lo.0 <= hi.0 {
                    out.extend([*lo, *hi]);
                } else {
                    out.extend([*hi, *lo]);
                }
            }
        }
        out
    }
}

/// Decimate `points` (in x order) to at most two per column of `cols` columns over
/// `[x0, x1]`, keeping each column's minimum and maximum ([`MinMaxColumns`]); series of
/// at most `2 cols` points are returned unchanged.
pub fn decimate(points: &[(f64, f64)], x0: f64, x1: f64, cols: usize) -> Vec<(f64, f64)> {
    if points.len() <= 2 * cols {
        return points.to_vec();
    }
    let mut m = MinMaxColumns::new(x0, x1, cols, 1);
    for &(x, y) in points {
        m.push(x, &[y]);
    }
    m.series(0)
}

/// Decimate a band `(x, low, high)`: per column the lowest low and the highest high.
pub fn decimate_band(
    points: &[(f64, f64, f64)],
    x0: f64,
    x1: f64,
    cols: usize,
) -> Vec<(f64, f64, f64)> {
    if points.len() <= 2 * cols {
        return points.to_vec();
    }
    let mut m = MinMaxColumns::new(x0, x1, cols, 2);
    for &(x, lo, hi) in points {
        m.push(x, &[lo, hi]);
    }
    let lo = m.series(0);
    let hi = m.series(1);
    // one point per column: column center, min of lows, max of highs
    let mut out = Vec::new();
    let (mut i, mut j) = (0, 0);
    for c in 0..m.cols {
        let in_col = |x: f64| m.column(x) == c;
        let mut l = f64::INFINITY;
        let mut h = f64::NEG_INFINITY;
        let mut xs = f64::NAN;
        while i < lo.len() && in_col(lo[i].0) {
            l = l.min(lo[i].1);
            xs = lo[i].0;
            i += 1;
        }
        while j < hi.len() && in_col(hi[j].0) {
            h = h.max(hi[j].1);
            j += 1;
        }
        if l.is_finite() && h.is_finite() {
            out.push((xs, l, h));
        }
    }
    out
}

//! Running moments (count, mean, M2) with Welford's update and Chan's parallel merge.
//!
//! For samples `x_1 … x_n`: `mean = Σx/n`, `M2 = Σ(x − mean)²`, sample variance
//! `s² = M2/(n − 1)`.
//!
//! * Welford (1962) update with one sample:
//!   `n ← n + 1`, `δ = x − mean`, `mean ← mean + δ/n`, `M2 ← M2 + δ·(x − mean_new)`.
//! * Chan, Golub & LeVeque (1979), "Updating formulae and a pairwise algorithm for
//!   computing sample variances", for two disjoint sets A and B:
//!   `n = n_A + n_B`, `δ = mean_B − mean_A`, `mean = mean_A + δ·n_B/n`,
//!   `M2 = M2_A + M2_B + δ²·n_A·n_B/n`.
//!
//! Both are numerically stable (no cancellation of `Σx²` against `n·mean²`). Floating-point
//! addition is not associative, so the result depends on the **order** of the updates and
//! merges; the Monte Carlo fixes that order (see [`super::plan`](mod@super::plan)) to make results
//! bit-identical for any thread count and any sharding.

use serde::{Deserialize, Serialize};

/// Count, mean and sum of squared deviations of a set of samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Moments {
    /// number of samples
    pub n: u64,
    /// mean
    #[serde(with = "super::bits")]
    pub mean: f64,
    /// Σ (x − mean)²
    #[serde(with = "super::bits")]
    pub m2: f64,
}

impl Moments {
    /// Add one sample (Welford).
    #[inline]
    pub fn push(&mut self, x: f64) {
        self.n += 1;
        let d = x - self.mean;
        self.mean += d / self.n as f64;
        self.m2 += d * (x - self.mean);
    }

    /// The moments of the union of `self` (first) and `o` (second), Chan's formula.
    #[inline]
    pub fn merged(&self, o: &Moments) -> Moments {
        if self.n == 0 {
            return *o;
        }
        if o.n == 0 {
            return *self;
        }
        let (na, nb) = (self.n as f64, o.n as f64);
        let n = self.n + o.n;
        let nf = n as f64;
        let d = o.mean - self.mean;
        Moments {
            n,
            mean: self.mean + d * nb / nf,
            m2: self.m2 + o.m2 + d * d * na * nb / nf,
        }
    }

    /// Sample variance `M2/(n − 1)` (0 for n < 2).
    pub fn variance(&self) -> f64 {
        if self.n < 2 {
            0.0
        } else {
            self.m2 / (self.n - 1) as f64
        }
    }

    /// Sample standard deviation `√(M2/(n − 1))`.
    pub fn std_dev(&self) -> f64 {
        self.variance().max(0.0).sqrt()
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn welford_and_chan_match_two_pass() {
        let xs: Vec<f64> = (0..1000)
            .map(|i| 1e6 + ((i * 7919) % 1013) as f64 * 1e-3)
            .collect();
        let n = xs.len() as f64;
        let mean = xs.iter().sum::<f64>() / n;
        let m2: f64 = xs.iter().map(|x| (x - mean) * (x - mean)).sum();
        let mut all = Moments::default();
        xs.iter().for_each(|&x| all.push(x));
        let mut a = Moments::default();
        let mut b = Moments::default();
        xs[..333].iter().for_each(|&x| a.push(x));
        xs[333..].iter().for_each(|&x| b.push(x));
        let ab = a.merged(&b);
        for m in [all, ab] {
            assert_eq!(m.n, 1000);
            assert!((m.mean - mean).abs() < 1e-8);
            assert!((m.m2 - m2).abs() < 1e-9 * m2, "{} vs {m2}", m.m2);
        }
        assert_eq!(Moments::default().merged(&a), a);
        assert_eq!(a.merged(&Moments::default()), a);
        assert_eq!(Moments::default().std_dev(), 0.0);
    }
}

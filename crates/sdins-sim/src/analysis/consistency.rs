//! The one filter-consistency criterion (docs/validation.md §"Filter consistency"), used by
//! every consistency test: a Monte Carlo of R runs with gating off; after convergence, at
//! every epoch, the mean over the runs of a normalised error statistic with d degrees of
//! freedom (NEES of a state block, NIS of a measurement kind) is a sample of `χ²(Rd)/R`
//! when the filter is consistent. The criterion:
//!
//! * (a) at least 90 % of the epochs inside the two-sided 95 % band
//!   `[χ²_{0.025}(Rd)/R, χ²_{0.975}(Rd)/R]`;
//! * (b) at least 97 % inside the 99 % band `[χ²_{0.005}(Rd)/R, χ²_{0.995}(Rd)/R]`;
//! * where the epochs are correlated (always: the same R runs at every epoch) the share
//!   inside a band is a binomial share over the effective number of independent epochs
//!   `n_eff` ([`effective_epochs`]), so (a) and (b) ask for at least `min(90 %, 95 % − 3σ)`
//!   and `min(97 %, 99 % − 3σ)`, `σ = √(p(1 − p)/n_eff)`: the nominal shares when the
//!   epochs are many and independent, wider by theory when they are not;
//! * (c) the grand mean over the epochs inside the 95 % band; with `m` windows or outages
//!   tested at once, inside the `1 − 0.05/m` band (Bonferroni).
//!
//! (R = 100, d = 3: 95 % band [2.54, 3.50], 99 % band [2.41, 3.67].) The χ² quantiles are
//! Wilson–Hilferty's, `χ²_p(k) ≈ k (1 − 2/(9k) + z_p √(2/(9k)))³` (the exact χ² tail
//! probability at each band edge is within 10 % of its nominal α/2 for k = Rd ≥ 20,
//! checked in this module's test), and `z_p` the standard normal quantile (Acklam's
//! rational approximation refined by one Halley step on `erfc`, absolute error below
//! 1e-12 on the tested points).

use serde::Serialize;

/// Standard normal quantile `z_p` (`P(Z ≤ z_p) = p`), `0 < p < 1`.
pub fn normal_quantile(p: f64) -> f64 {
    if !(p > 0.0 && p < 1.0) {
        return f64::NAN;
    }
    // Acklam's coefficients
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let tail = |q: f64| {
        let r = (-2.0 * q.ln()).sqrt();
        (((((C[0] * r + C[1]) * r + C[2]) * r + C[3]) * r + C[4]) * r + C[5])
            / ((((D[0] * r + D[1]) * r + D[2]) * r + D[3]) * r + 1.0)
    };
    let x = if p < 0.02425 {
        tail(p)
    } else if p > 1.0 - 0.02425 {
        -tail(1.0 - p)
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    };
    // one Halley step on Φ(x) − p, Φ(x) = erfc(−x/√2)/2
    let e = 0.5 * libm::erfc(-x / std::f64::consts::SQRT_2) - p;
    let u = e * (2.0 * std::f64::consts::PI).sqrt() * (x * x / 2.0).exp();
    x - u / (1.0 + x * u / 2.0)
}

/// Wilson–Hilferty quantile of `χ²(k)/R` with `k = R·d` at the normal quantile `z`: the
/// band of the mean of R independent χ²(d) values.
pub fn chi2_mean_quantile(dof: f64, runs: f64, z: f64) -> f64 {
    let k = dof * runs;
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3) / runs
}

/// The two-sided band of the mean of R χ²(d) values at level `1 − alpha`.
pub fn band(dof: f64, runs: f64, alpha: f64) -> (f64, f64) {
    let z = normal_quantile(1.0 - alpha / 2.0);
    (
        chi2_mean_quantile(dof, runs, -z),
        chi2_mean_quantile(dof, runs, z),
    )
}

/// The verdict of the criterion on one statistic.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Consistency {
    /// what was tested
    pub name: String,
    /// degrees of freedom d
    pub dof: f64,
    /// runs R
    pub runs: f64,
    /// epochs tested
    pub epochs: usize,
    /// grand mean of the per-epoch means
    pub grand_mean: f64,
    /// 95 % band of one epoch's mean
    pub band95: (f64, f64),
    /// 99 % band
    pub band99: (f64, f64),
    /// the grand mean's band (95 %, Bonferroni-widened for `tests` at once)
    pub band_grand: (f64, f64),
    /// fraction of the epochs in the 95 % band
    pub in95: f64,
    /// fraction in the 99 % band
    pub in99: f64,
    /// largest per-epoch mean
    pub max: f64,
    /// effective number of independent epochs `n / τ_int` ([`effective_epochs`])
    pub epochs_eff: f64,
    /// the fraction (a) requires in the 95 % band: `min(0.90, 0.95 − 3 σ)`
    pub need95: f64,
    /// the fraction (b) requires in the 99 % band: `min(0.97, 0.99 − 3 σ)`
    pub need99: f64,
    /// criteria (a), (b), (c) all met
    pub pass: bool,
}

impl std::fmt::Display for Consistency {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: grand mean {:.3} (band [{:.2}, {:.2}]), {:.1} % of {} epochs ({:.0} effective) in the 95 % band [{:.2}, {:.2}] (≥ {:.1} %), {:.1} % in the 99 % band [{:.2}, {:.2}] (≥ {:.1} %), max {:.2}: {}",
            self.name,
            self.grand_mean,
            self.band_grand.0,
            self.band_grand.1,
            100.0 * self.in95,
            self.epochs,
            self.epochs_eff,
            self.band95.0,
            self.band95.1,
            100.0 * self.need95,
            100.0 * self.in99,
            self.band99.0,
            self.band99.1,
            100.0 * self.need99,
            self.max,
            if self.pass { "consistent" } else { "NOT consistent" }
        )
    }
}

/// Fewest effective epochs for which the shares (a) and (b) are judged: below it the
/// per-epoch means are a handful of independent values (a sensor parameter that the data
/// barely inform changes over the whole run, so its means move together), the share
/// inside a band is 0 or 1 with the grand mean's luck, and only (c) is judged.
pub const MIN_EFFECTIVE_EPOCHS: f64 = 20.0;

/// Apply the criterion to per-epoch means (after convergence) of R runs of a statistic
/// with `dof` degrees of freedom; `tests` statistics or windows judged together
/// (Bonferroni on the grand mean; 1 for one). With fewer than
/// [`MIN_EFFECTIVE_EPOCHS`] effective epochs only the grand mean is judged.
pub fn check(name: &str, means: &[f64], dof: f64, runs: f64, tests: usize) -> Consistency {
    let b95 = band(dof, runs, 0.05);
    let b99 = band(dof, runs, 0.01);
    let bg = band(dof, runs, 0.05 / tests.max(1) as f64);
    let n = means.len();
    let nf = n.max(1) as f64;
    let grand = means.iter().sum::<f64>() / nf;
    let inside = |b: (f64, f64)| means.iter().filter(|m| (b.0..=b.1).contains(*m)).count();
    let in95 = inside(b95) as f64 / nf;
    let in99 = inside(b99) as f64 / nf;
    let max = means.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let n_eff = effective_epochs(means);
    let need = |p: f64, nominal: f64| nominal.min(p - 3.0 * (p * (1.0 - p) / n_eff).sqrt());
    let (need95, need99) = (need(0.95, 0.90), need(0.99, 0.97));
    Consistency {
        name: name.to_string(),
        dof,
        runs,
        epochs: n,
        grand_mean: grand,
        band95: b95,
        band99: b99,
        band_grand: bg,
        in95,
        in99,
        max,
        epochs_eff: n_eff,
        need95,
        need99,
        pass: n > 0
            && (n_eff < MIN_EFFECTIVE_EPOCHS || (in95 >= need95 && in99 >= need99))
            && (bg.0..=bg.1).contains(&grand),
    }
}

/// Effective number of independent epochs of a sequence of per-epoch means, `n / τ_int`,
/// `τ_int = 1 + 2 Σ ρ_k` by Geyer's initial positive sequence (Geyer 1992, "Practical
/// Markov chain Monte Carlo", Statist. Sci. 7(4), §3.3: sums of adjacent autocorrelation
/// pairs added while positive). The per-epoch means of one Monte Carlo are computed from
/// the same runs at every epoch, so consecutive epochs are strongly correlated (a bias
/// block's error changes over minutes, the epochs come at 10 Hz): the fraction of epochs
/// inside a band then scatters like a binomial share over `n_eff`, not `n`, epochs. The
/// indicator of a band has a smaller autocorrelation than the means themselves (for a
/// Gaussian process, `(2/π) arcsin ρ` at the median), so `τ_int` of the means bounds it.
pub fn effective_epochs(means: &[f64]) -> f64 {
    let n = means.len();
    if n < 4 {
        return n as f64;
    }
    let nf = n as f64;
    let mu = means.iter().sum::<f64>() / nf;
    let c = |k: usize| -> f64 {
        means[..n - k]
            .iter()
            .zip(&means[k..])
            .map(|(a, b)| (a - mu) * (b - mu))
            .sum::<f64>()
            / nf
    };
    let c0 = c(0);
    if c0.is_nan() || c0 <= 0.0 {
        return nf;
    }
    let mut tau = -1.0; // 1 + 2 Σ_{k≥1} ρ_k = −1 + 2 Σ_{m≥0} (ρ_{2m} + ρ_{2m+1})
    let mut m = 0;
    while 2 * m + 1 < n {
        let pair = (c(2 * m) + c(2 * m + 1)) / c0;
        if pair <= 0.0 {
            break;
        }
        tau += 2.0 * pair;
        m += 1;
    }
    (nf / tau.max(1.0)).min(nf)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// `n_eff` of white noise is n (within sampling: ±15 % at n = 20 000), of an AR(1)
    /// sequence with ρ = 0.9 it is n (1 − ρ)/(1 + ρ) = n/19 (within 25 %).
    #[test]
    fn effective_epochs_of_white_and_ar1_sequences() {
        let mut state = 0x2545_F491_4F6C_DD1D_u64;
        let mut normal = move || {
            let mut u = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
            };
            let (a, b) = (u(), u());
            (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
        };
        let n = 20_000;
        let white: Vec<f64> = (0..n).map(|_| normal()).collect();
        let e = effective_epochs(&white) / n as f64;
        assert!((e - 1.0).abs() < 0.15, "{e}");
        let mut x = 0.0;
        let ar: Vec<f64> = (0..n)
            .map(|_| {
                x = 0.9 * x + normal();
                x
            })
            .collect();
        let e = effective_epochs(&ar) * 19.0 / n as f64;
        assert!((e - 1.0).abs() < 0.25, "{e}");
    }

    /// Regularised lower incomplete gamma P(a, x) by its series (x < a + 1) or continued
    /// fraction: the exact χ² CDF for the Wilson–Hilferty check.
    fn gamma_p(a: f64, x: f64) -> f64 {
        let ln_g = libm::lgamma(a);
        if x < a + 1.0 {
            let (mut sum, mut term, mut ap) = (1.0 / a, 1.0 / a, a);
            for _ in 0..10_000 {
                ap += 1.0;
                term *= x / ap;
                sum += term;
                if term.abs() < sum.abs() * 1e-16 {
                    break;
                }
            }
            sum * (-x + a * x.ln() - ln_g).exp()
        } else {
            let (mut b, mut c, mut d) = (x + 1.0 - a, 1e300, 1.0 / (x + 1.0 - a));
            let mut h = d;
            for i in 1..10_000 {
                let an = -(i as f64) * (i as f64 - a);
                b += 2.0;
                d = an * d + b;
                d = 1.0 / d;
                c = b + an / c;
                let del = d * c;
                h *= del;
                if (del - 1.0).abs() < 1e-16 {
                    break;
                }
            }
            1.0 - (-x + a * x.ln() - ln_g).exp() * h
        }
    }

    #[test]
    fn normal_quantiles() {
        assert!((normal_quantile(0.975) - 1.959_963_984_540_054).abs() < 1e-12);
        assert!((normal_quantile(0.995) - 2.575_829_303_548_901).abs() < 1e-12);
        assert!((normal_quantile(0.5)).abs() < 1e-15);
        assert!((normal_quantile(1e-6) + 4.753_424_308_822_899).abs() < 1e-10);
        assert!(normal_quantile(0.0).is_nan() && normal_quantile(1.0).is_nan());
    }

    /// The issue's numbers, and Wilson–Hilferty against the exact χ² CDF (R·d ≥ 30).
    #[test]
    fn bands_of_the_issue_and_wilson_hilferty_accuracy() {
        let b95 = band(3.0, 100.0, 0.05);
        let b99 = band(3.0, 100.0, 0.01);
        assert_eq!(
            [b95.0, b95.1, b99.0, b99.1].map(|x| (x * 100.0).round() / 100.0),
            [2.54, 3.50, 2.41, 3.67]
        );
        for (d, r) in [
            (3.0, 100.0),
            (6.0, 100.0),
            (3.0, 10.0),
            (2.0, 15.0),
            (1.0, 30.0),
        ] {
            for alpha in [0.05, 0.01] {
                let (lo, hi) = band(d, r, alpha);
                let k = d * r;
                let p_lo = gamma_p(k / 2.0, lo * r / 2.0);
                let p_hi = gamma_p(k / 2.0, hi * r / 2.0);
                assert!(
                    (p_lo - alpha / 2.0).abs() < 0.1 * alpha / 2.0,
                    "{d} {r} {p_lo}"
                );
                assert!(
                    (1.0 - p_hi - alpha / 2.0).abs() < 0.1 * alpha / 2.0,
                    "{d} {r} {p_hi}"
                );
            }
        }
    }

    #[test]
    fn criterion() {
        let good = vec![3.0; 100];
        let c = check("x", &good, 3.0, 100.0, 1);
        assert!(c.pass && c.in95 == 1.0, "{c}");
        // 1000 epochs with no serial correlation beyond their pattern: the shares asked
        // for are the nominal 90 % and 97 %
        let good = vec![3.0; 1000];
        // 11.1 % of the epochs (every 9th) outside the 95 % band fails (a)
        let a: Vec<f64> = (0..1000)
            .map(|k| if k % 9 == 0 { 3.55 } else { 3.0 })
            .collect();
        let ca = check("x", &a, 3.0, 100.0, 1);
        assert!(ca.need95 == 0.90 && !ca.pass, "{ca}");
        // 4 % (every 25th) beyond the 99 % band fails (b)
        let b: Vec<f64> = (0..1000)
            .map(|k| if k % 25 == 0 { 3.7 } else { 3.0 })
            .collect();
        let cb = check("x", &b, 3.0, 100.0, 1);
        assert!(cb.in95 >= 0.9 && cb.need99 == 0.97 && !cb.pass, "{cb}");
        // the same shares in one block of consecutive epochs: a slowly changing statistic
        // (n_eff of a few epochs) asks for less, by theory
        let mut blk = good.clone();
        for m in blk.iter_mut().take(111) {
            *m = 3.55;
        }
        let cblk = check("x", &blk, 3.0, 100.0, 1);
        assert!(cblk.epochs_eff < 20.0 && cblk.need95 < 0.85, "{cblk}");
        // a biased grand mean fails (c) alone, unless Bonferroni widens its band enough
        let mut c = vec![2.545; 92];
        c.extend([2.42; 8]);
        let cc = check("x", &c, 3.0, 100.0, 1);
        assert!(cc.in95 >= 0.9 && cc.in99 >= 0.97 && !cc.pass, "{cc}");
        assert!(check("x", &c, 3.0, 100.0, 20).pass);
        assert!(!check("x", &[], 3.0, 100.0, 1).pass);
    }
}

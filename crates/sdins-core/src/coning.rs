//! Coning (attitude) and sculling (velocity) compensation over N sensor samples
//! (docs/theory/coning-sculling.md §"Coning and sculling"; docs/theory/coning-sculling.md
//! §"Coefficient sets").
//!
//! For a coefficient set `k_ij` the rotation vector over the update interval is
//! `Δφ = Σ Δθ_j + Σ_{i<j} k_ij Δθ_i × Δθ_j` (docs/theory/coning-sculling.md
//! §"Coning and sculling"), and by the Ignagni duality the sculling term is
//! `ΔV_scul = Σ_{i<j} k_ij (Δθ_i × Δv_j + Δv_i × Δθ_j)` (§"Coefficient sets"; for
//! `three_poly` this is exactly S1 eq. (27)).

use crate::math::Vec3;

/// One sensor sample: body-frame integrals of the raw gyro and accelerometer outputs
/// over the sample interval (docs/conventions.md §"IMU increments").
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Increment {
    /// Δθ = ∫ ω_ib^b dt \[rad\]
    pub dtheta_b_rad: Vec3,
    /// Δv = ∫ f^b dt \[m/s\]
    pub dv_b_mps: Vec3,
}

impl Increment {
    /// Build from the two vectors.
    pub const fn new(dtheta_b_rad: Vec3, dv_b_mps: Vec3) -> Self {
        Self {
            dtheta_b_rad,
            dv_b_mps,
        }
    }
}

/// Coning/sculling coefficient set (docs/theory/coning-sculling.md §"Coefficient sets" table).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ConingSet {
    /// no compensation: Δφ = ΣΔθ
    None,
    /// one-sample with the previous update: + (1/12) Δθ_{k−1} × Δθ_k
    OnePrev,
    /// two-sample, k12 = 2/3 (polynomial fit = coning-optimal)
    Two,
    /// three-sample polynomial fit (S1 eq. 4): k13 = 33/80, k12 = k23 = 57/80
    ThreePoly,
    /// three-sample coning-optimal (Miller 1983): k13 = 9/20, k12 = k23 = 27/40
    ThreeOpt,
    /// four-sample polynomial fit (exact for cubic ω)
    FourPoly,
    /// four-sample coning-optimal (Lee et al. 1990)
    FourOpt,
}

const TWO: [(usize, usize, f64); 1] = [(0, 1, 2.0 / 3.0)];
const THREE_POLY: [(usize, usize, f64); 3] = [
    (0, 1, 57.0 / 80.0),
    (1, 2, 57.0 / 80.0),
    (0, 2, 33.0 / 80.0),
];
const THREE_OPT: [(usize, usize, f64); 3] =
    [(0, 1, 27.0 / 40.0), (1, 2, 27.0 / 40.0), (0, 2, 9.0 / 20.0)];
const FOUR_POLY: [(usize, usize, f64); 6] = [
    (0, 1, 736.0 / 945.0),
    (2, 3, 736.0 / 945.0),
    (0, 2, 334.0 / 945.0),
    (1, 3, 334.0 / 945.0),
    (0, 3, 526.0 / 945.0),
    (1, 2, 654.0 / 945.0),
];
const FOUR_OPT: [(usize, usize, f64); 6] = [
    (0, 1, 214.0 / 315.0),
    (1, 2, 214.0 / 315.0),
    (2, 3, 214.0 / 315.0),
    (0, 2, 46.0 / 105.0),
    (1, 3, 46.0 / 105.0),
    (0, 3, 54.0 / 105.0),
];

impl ConingSet {
    /// Every set, in table order.
    pub const ALL: [ConingSet; 7] = [
        ConingSet::None,
        ConingSet::OnePrev,
        ConingSet::Two,
        ConingSet::ThreePoly,
        ConingSet::ThreeOpt,
        ConingSet::FourPoly,
        ConingSet::FourOpt,
    ];

    /// The canonical name (`none`, `1prev`, `two`, `three_poly`, `three_opt`, `four_poly`,
    /// `four_opt`).
    pub const fn name(self) -> &'static str {
        match self {
            ConingSet::None => "none",
            ConingSet::OnePrev => "1prev",
            ConingSet::Two => "two",
            ConingSet::ThreePoly => "three_poly",
            ConingSet::ThreeOpt => "three_opt",
            ConingSet::FourPoly => "four_poly",
            ConingSet::FourOpt => "four_opt",
        }
    }

    /// Parse a canonical name, or the aliases `polynomial` / `optimal` for the N-sample set
    /// (`samples` = N; for N = 2 both aliases are `two`, for N = 1 `polynomial` is `none`
    /// and `optimal` is `1prev`).
    pub fn parse(name: &str, samples: usize) -> Option<ConingSet> {
        Some(match (name, samples) {
            ("polynomial" | "poly", 1) => ConingSet::None,
            ("optimal" | "opt", 1) => ConingSet::OnePrev,
            ("polynomial" | "poly" | "optimal" | "opt", 2) => ConingSet::Two,
            ("polynomial" | "poly", 3) => ConingSet::ThreePoly,
            ("optimal" | "opt", 3) => ConingSet::ThreeOpt,
            ("polynomial" | "poly", 4) => ConingSet::FourPoly,
            ("optimal" | "opt", 4) => ConingSet::FourOpt,
            (n, _) => return ConingSet::ALL.iter().copied().find(|s| s.name() == n),
        })
    }

    /// Number of samples the set is derived for; `None` and `OnePrev` work with any N
    /// (they act on the summed increment) and report 1.
    pub const fn samples(self) -> usize {
        match self {
            ConingSet::None | ConingSet::OnePrev => 1,
            ConingSet::Two => 2,
            ConingSet::ThreePoly | ConingSet::ThreeOpt => 3,
            ConingSet::FourPoly | ConingSet::FourOpt => 4,
        }
    }

    /// Whether the set can be used with `n` samples per update.
    pub const fn accepts(self, n: usize) -> bool {
        match self {
            ConingSet::None | ConingSet::OnePrev => n >= 1,
            _ => self.samples() == n,
        }
    }

    /// The `(i, j, k_ij)` cross-product coefficients (0-based sample indices).
    pub const fn coefficients(self) -> &'static [(usize, usize, f64)] {
        match self {
            ConingSet::None | ConingSet::OnePrev => &[],
            ConingSet::Two => &TWO,
            ConingSet::ThreePoly => &THREE_POLY,
            ConingSet::ThreeOpt => &THREE_OPT,
            ConingSet::FourPoly => &FOUR_POLY,
            ConingSet::FourOpt => &FOUR_OPT,
        }
    }

    /// The set a user gets when they name none (CLI, Python, scenario files): the best the
    /// method offers for N samples. For N = 1 that is `1prev` (the current sample plus the
    /// previous one, Savage *Strapdown Analytics* §7.1.1.1 / Groves eq. 5.97 — the method
    /// every peer tool uses), not "none"; for N ≥ 2 the polynomial set of N.
    pub const fn recommended_for(n: usize) -> ConingSet {
        match n {
            1 => ConingSet::OnePrev,
            _ => Self::default_for(n),
        }
    }

    /// Polynomial set for N samples, as in S1 (`three_poly` for N = 3); no correction for
    /// N = 1 (the papers' single-sample baseline). Reproductions of the papers use this;
    /// users get [`ConingSet::recommended_for`].
    pub const fn default_for(n: usize) -> ConingSet {
        match n {
            2 => ConingSet::Two,
            3 => ConingSet::ThreePoly,
            4 => ConingSet::FourPoly,
            _ => ConingSet::None,
        }
    }
}

/// Result of combining the N samples of one update.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Compensated {
    /// Δθ = Σ Δθ_j \[rad\]
    pub dtheta_b_rad: Vec3,
    /// Δv = Σ Δv_j \[m/s\]
    pub dv_b_mps: Vec3,
    /// rotation vector Δφ of the body over the interval (coning-compensated) \[rad\]
    pub dphi_b_rad: Vec3,
    /// sculling term ΔV_scul \[m/s\]
    pub dv_scul_b_mps: Vec3,
}

/// Combine the samples of one update with the coefficient set (docs/theory/coning-sculling.md
/// §"Coning and sculling"). `prev` is the previous update's summed increment (used by `1prev`
/// only).
#[inline(always)]
pub fn compensate(set: ConingSet, samples: &[Increment], prev: &Increment) -> Compensated {
    // the common shapes without loops: N = 3 with a three-sample set, N = 1 (the default
    // of `sdins nav`) with 1prev or none
    match (set, samples) {
        (ConingSet::ThreePoly | ConingSet::ThreeOpt, [s1, s2, s3]) => {
            compensate_three(set, s1, s2, s3)
        }
        (ConingSet::OnePrev, [s]) => one_prev(s.dtheta_b_rad, s.dv_b_mps, prev),
        (ConingSet::None, [s]) => Compensated {
            dtheta_b_rad: s.dtheta_b_rad,
            dv_b_mps: s.dv_b_mps,
            dphi_b_rad: s.dtheta_b_rad,
            dv_scul_b_mps: Vec3::zeros(),
        },
        _ => compensate_general(set, samples, prev),
    }
}

/// [`compensate`] for any N and set: sums, then the pairs of the coefficient table.
#[inline(never)]
fn compensate_general(set: ConingSet, samples: &[Increment], prev: &Increment) -> Compensated {
    let mut dth = Vec3::zeros();
    let mut dv = Vec3::zeros();
    for s in samples {
        dth += s.dtheta_b_rad;
        dv += s.dv_b_mps;
    }
    let mut cone = Vec3::zeros();
    let mut scul = Vec3::zeros();
    match set {
        ConingSet::None => {}
        ConingSet::OnePrev => return one_prev(dth, dv, prev),
        _ => {
            for &(i, j, k) in set.coefficients() {
                if let (Some(a), Some(b)) = (samples.get(i), samples.get(j)) {
                    cone += k * a.dtheta_b_rad.cross(&b.dtheta_b_rad);
                    scul +=
                        k * (a.dtheta_b_rad.cross(&b.dv_b_mps) + a.dv_b_mps.cross(&b.dtheta_b_rad));
                }
            }
        }
    }
    Compensated {
        dtheta_b_rad: dth,
        dv_b_mps: dv,
        dphi_b_rad: dth + cone,
        dv_scul_b_mps: scul,
    }
}

/// The one-plus-previous correction of the summed increments `Δθ`, `Δv` with the previous
/// update's (Savage *Strapdown Analytics* §7.1.1.1, Groves eq. 5.97):
/// `Δφ = Δθ + (1/12) Δθ_{k−1} × Δθ`, `ΔV_scul = (1/12)(Δθ_{k−1} × Δv + Δv_{k−1} × Δθ)`.
#[inline(always)]
fn one_prev(dth: Vec3, dv: Vec3, prev: &Increment) -> Compensated {
    // written out per component (what `cross` computes), which compiles to fewer
    // instructions than the vector expression on x86-64's two-wide SSE2
    let (a, b) = (&prev.dtheta_b_rad, &prev.dv_b_mps);
    let cone = Vec3::new(
        (a.y * dth.z - a.z * dth.y) / 12.0,
        (a.z * dth.x - a.x * dth.z) / 12.0,
        (a.x * dth.y - a.y * dth.x) / 12.0,
    );
    let scul = Vec3::new(
        ((a.y * dv.z - a.z * dv.y) + (b.y * dth.z - b.z * dth.y)) / 12.0,
        ((a.z * dv.x - a.x * dv.z) + (b.z * dth.x - b.x * dth.z)) / 12.0,
        ((a.x * dv.y - a.y * dv.x) + (b.x * dth.y - b.y * dth.x)) / 12.0,
    );
    Compensated {
        dtheta_b_rad: dth,
        dv_b_mps: dv,
        dphi_b_rad: dth + cone,
        dv_scul_b_mps: scul,
    }
}

/// The three-sample sets (k12 = k23 = a, k13 = b in the table above) regrouped as in S1
/// eqs. 4 and 27: cone `a Δθ2×(Δθ3−Δθ1) + b Δθ1×Δθ3`, sculling
/// `a [(Δθ1−Δθ3)×Δv2 + (Δv1−Δv3)×Δθ2] + b [Δθ1×Δv3 + Δv1×Δθ3]` (2 + 4 cross products
/// instead of 3 + 6, no loops; equal to the pair sum up to rounding, the sums bit for bit).
#[inline(always)]
fn compensate_three(set: ConingSet, s1: &Increment, s2: &Increment, s3: &Increment) -> Compensated {
    let c = set.coefficients();
    let (a, b) = (c[0].2, c[2].2);
    let (t1, t2, t3) = (&s1.dtheta_b_rad, &s2.dtheta_b_rad, &s3.dtheta_b_rad);
    let (v1, v2, v3) = (&s1.dv_b_mps, &s2.dv_b_mps, &s3.dv_b_mps);
    let dth = t1 + t2 + t3;
    let cone = a * t2.cross(&(t3 - t1)) + b * t1.cross(t3);
    Compensated {
        dtheta_b_rad: dth,
        dv_b_mps: v1 + v2 + v3,
        dphi_b_rad: dth + cone,
        dv_scul_b_mps: a * ((t1 - t3).cross(v2) + (v1 - v3).cross(t2))
            + b * (t1.cross(v3) + v1.cross(t3)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_poly_sculling_is_s1_eq_27() {
        let s = [
            Increment::new(Vec3::new(0.01, -0.02, 0.03), Vec3::new(0.5, 0.1, -9.0)),
            Increment::new(Vec3::new(0.015, -0.01, 0.02), Vec3::new(0.4, 0.3, -9.1)),
            Increment::new(Vec3::new(0.02, 0.005, 0.01), Vec3::new(0.2, 0.5, -9.3)),
        ];
        let c = compensate(ConingSet::ThreePoly, &s, &Increment::default());
        let (t1, t2, t3) = (s[0].dtheta_b_rad, s[1].dtheta_b_rad, s[2].dtheta_b_rad);
        let (v1, v2, v3) = (s[0].dv_b_mps, s[1].dv_b_mps, s[2].dv_b_mps);
        let eq27 = (57.0 / 80.0) * ((t1 - t3).cross(&v2) + (v1 - v3).cross(&t2))
            + (33.0 / 80.0) * (t1.cross(&v3) + v1.cross(&t3));
        assert!((c.dv_scul_b_mps - eq27).norm() < 1e-16);
        let eq4 =
            t1 + t2 + t3 + (33.0 / 80.0) * t1.cross(&t3) + (57.0 / 80.0) * t2.cross(&(t3 - t1));
        assert!((c.dphi_b_rad - eq4).norm() < 1e-17);
    }

    #[test]
    fn regrouped_three_sample_form_equals_the_pair_sum() {
        // the specialised N = 3 branch against Σ k_ij over the table's pairs
        let s = [
            Increment::new(Vec3::new(3e-4, -2e-4, 1e-4), Vec3::new(0.05, 0.01, -0.098)),
            Increment::new(Vec3::new(-1e-4, 4e-4, 2e-4), Vec3::new(0.04, 0.03, -0.099)),
            Increment::new(Vec3::new(2e-4, 1e-4, -3e-4), Vec3::new(0.02, 0.05, -0.097)),
        ];
        for set in [ConingSet::ThreePoly, ConingSet::ThreeOpt] {
            let (mut cone, mut scul) = (Vec3::zeros(), Vec3::zeros());
            for &(i, j, k) in set.coefficients() {
                let (a, b) = (&s[i], &s[j]);
                cone += k * a.dtheta_b_rad.cross(&b.dtheta_b_rad);
                scul += k * (a.dtheta_b_rad.cross(&b.dv_b_mps) + a.dv_b_mps.cross(&b.dtheta_b_rad));
            }
            let c = compensate(set, &s, &Increment::default());
            let dth = s[0].dtheta_b_rad + s[1].dtheta_b_rad + s[2].dtheta_b_rad;
            // the cone term (|Δθ|² ≈ 1e-7) differs by a few of its own roundings, but
            // it is only seen through Δφ = Δθ + cone, rounded at ε|Δφ|; sculling terms
            // (|Δθ||Δv| ≈ 4e-5) differ by a few roundings ε|Δθ||Δv|
            let eps = f64::EPSILON;
            assert!(
                (c.dphi_b_rad - dth - cone).norm() <= 4.0 * eps * c.dphi_b_rad.norm(),
                "{}",
                set.name()
            );
            assert!((c.dv_scul_b_mps - scul).norm() <= 1e-20, "{}", set.name());
            assert!(cone.norm() > 1e-8 && scul.norm() > 1e-6);
        }
    }

    #[test]
    fn constant_rates_give_zero_sculling_and_coning() {
        // Unit check: for constant ω and f the sculling term is exactly zero (catches the (30)-OCR
        // coefficients, which would give (11/120)ΔT² f×ω).
        let inc = Increment::new(Vec3::new(1e-4, -2e-4, 3e-4), Vec3::new(0.01, 0.02, -0.0196));
        for set in ConingSet::ALL {
            let n = set.samples().max(1);
            let samples = [inc; 4];
            let c = compensate(
                set,
                &samples[..n],
                &Increment::new(inc.dtheta_b_rad * n as f64, inc.dv_b_mps * n as f64),
            );
            assert!(c.dv_scul_b_mps.norm() < 1e-20, "{}", set.name());
            assert!(
                (c.dphi_b_rad - c.dtheta_b_rad).norm() < 1e-21,
                "{}",
                set.name()
            );
        }
    }

    #[test]
    fn coefficient_sums_match_spec() {
        // Classical coning constrains S_d = Σ_{j−i=d} k_ij (docs/theory/coning-sculling.md
        // §"Coefficient sets").
        let sums = |set: ConingSet| {
            let mut s = [0.0; 3];
            for &(i, j, k) in set.coefficients() {
                s[j - i - 1] += k;
            }
            s
        };
        let t = sums(ConingSet::ThreeOpt);
        assert!((t[0] - 27.0 / 20.0).abs() < 1e-15 && (t[1] - 9.0 / 20.0).abs() < 1e-15);
        let f = sums(ConingSet::FourOpt);
        assert!((f[0] - 214.0 / 105.0).abs() < 1e-15);
        assert!((f[1] - 92.0 / 105.0).abs() < 1e-15);
        assert!((f[2] - 18.0 / 35.0).abs() < 1e-15);
    }

    #[test]
    fn names_and_aliases() {
        for set in ConingSet::ALL {
            assert_eq!(ConingSet::parse(set.name(), set.samples()), Some(set));
        }
        assert_eq!(
            ConingSet::parse("polynomial", 3),
            Some(ConingSet::ThreePoly)
        );
        assert_eq!(ConingSet::parse("optimal", 3), Some(ConingSet::ThreeOpt));
        assert_eq!(ConingSet::parse("optimal", 4), Some(ConingSet::FourOpt));
        assert_eq!(ConingSet::parse("bogus", 3), None);
    }
}

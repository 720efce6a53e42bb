//! Random vibration from a PSD: input errors, power bookkeeping, exactness of the
//! increments, refinement, and (ignored, release) Welch estimates of the realised
//! specific force and angular rate against the specified PSD.
#![allow(clippy::unwrap_used)]
use sdins_core::math::Vec3;
use sdins_sim::scenario::{Scenario, ScenarioError};
use sdins_sim::truth::random_vibration::{PsdTable, RandomVibration, RandomVibrationSpec};
use sdins_sim::truth::{TruthGenerator, TruthSample};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

fn data_dir() -> Option<PathBuf> {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/gnss_ins_sim");
    if d.join("vib_psd.csv").exists() {
        Some(d)
    } else {
        println!("skipped: {} is absent", d.display());
        None
    }
}

fn scenario(duration_s: f64, earth: &str, overlay: &str) -> String {
    format!(
        "[start]\nlat_deg = 30.0\nlon_deg = 120.0\n[imu]\nrate_hz = 100.0\nseed = 11\n[nav]\nearth = \"{earth}\"\n[[segment]]\ntype = \"static\"\nduration_s = {duration_s}\n[[overlay]]\ntype = \"random_vibration\"\n{overlay}\n"
    )
}

fn err_of(text: &str) -> String {
    match Scenario::from_toml(text, "/tmp/sdins-vib-test/s.toml") {
        Err(e) => e.to_string(),
        Ok(_) => panic!("expected an error for\n{text}"),
    }
}

#[test]
fn bad_psd_input_is_a_located_error() {
    // missing file: names the file (relative to the scenario's folder)
    let e = err_of(&scenario(10.0, "wgs84", "accel_psd_file = \"nope.csv\""));
    assert!(
        e.contains("/tmp/sdins-vib-test/nope.csv") && e.contains("cannot read"),
        "{e}"
    );
    // bad rows in a file: file:line:column
    let dir = std::env::temp_dir().join(format!("sdins-vib-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (body, want) in [
        (
            "freq,x,y,z\n0,1e-3,1e-3,1e-3\n1,1e-3,-1e-3,1e-3\n",
            "p.csv:3:8: negative PSD",
        ),
        (
            "freq,x,y,z\n0,1e-3,1e-3,1e-3\n0,1e-3,1e-3,1e-3\n",
            "p.csv:3:1: frequency 0 Hz does not increase",
        ),
        (
            "freq,x,y,z\n0,1e-3,1e-3,1e-3\n1,1e-3,NaN,1e-3\n",
            "p.csv:3:8: NaN: must be finite",
        ),
        (
            "freq,x,y,z\n0,1e-3,1e-3,1e-3\n1,1e-3,1e-3\n",
            "p.csv:3:1: expected 2 (freq, psd) or 4 (freq, x, y, z) columns, found 3",
        ),
    ] {
        let p = dir.join("p.csv");
        std::fs::write(&p, body).unwrap();
        let text = scenario(
            10.0,
            "wgs84",
            &format!("accel_psd_file = \"{}\"", p.display()),
        );
        let e = match Scenario::from_toml(&text, "s.toml") {
            Err(ScenarioError::Invalid {
                line, key, message, ..
            }) => {
                assert_eq!((line, key.as_str()), (14, "overlay.accel_psd_file"));
                message
            }
            other => panic!("{other:?}"),
        };
        assert!(e.contains(want), "{e}\nwanted {want}");
    }
    let _ = std::fs::remove_dir_all(&dir);
    // inline breakpoints: row and entry
    for (bp, want) in [
        (
            "[[1.0, 1e-3], [0.5, 1e-3]]",
            "breakpoint 2, entry 1: frequency 0.5 Hz does not increase",
        ),
        (
            "[[1.0, 1e-3], [2.0, -1e-3]]",
            "breakpoint 2, entry 2: PSD -0.001",
        ),
        (
            "[[1.0, 1e-3], [2.0, nan]]",
            "breakpoint 2, entry 2: PSD NaN",
        ),
        (
            "[[1.0, 1e-3, 2.0], [2.0, 1e-3]]",
            "breakpoint 1, entry 1: expected [f_hz, psd]",
        ),
    ] {
        let e = err_of(&scenario(
            10.0,
            "wgs84",
            &format!("gyro_psd_breakpoints = {bp}"),
        ));
        assert!(
            e.contains(want) && e.contains("gyro_psd_breakpoints"),
            "{e}"
        );
    }
    // no spectrum, keys of other overlay types, both forms at once
    let e = err_of(&scenario(10.0, "wgs84", "seed = 3"));
    assert!(e.contains("needs accel_psd_file"), "{e}");
    let e = err_of(&scenario(
        10.0,
        "wgs84",
        "accel_psd_breakpoints = [[1.0, 1e-3], [2.0, 1e-3]]\nfreq_hz = 3.0",
    ));
    assert!(
        e.contains("overlay.freq_hz") && e.contains("not a key"),
        "{e}"
    );
    let e = err_of(&scenario(
        10.0,
        "wgs84",
        "accel_psd_breakpoints = [[1.0, 1e-3], [2.0, 1e-3]]\naccel_psd_file = \"x.csv\"",
    ));
    assert!(e.contains("not both"), "{e}");
}

#[test]
fn envelope_sees_the_vibration() {
    // 2e5 (m/s²)²/Hz over 10–40 Hz: σ = 2450 m/s², far above the 100 g limit
    let e = err_of(&scenario(
        5.0,
        "wgs84",
        "accel_psd_breakpoints = [[10.0, 2e5], [40.0, 2e5]]",
    ));
    assert!(e.contains("acceleration") && e.contains("overlay 1"), "{e}");
    let e = err_of(&scenario(
        5.0,
        "wgs84",
        "gyro_psd_breakpoints = [[10.0, 100.0], [40.0, 100.0]]",
    ));
    assert!(e.contains("angular rate"), "{e}");
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn vib_psd_csv_power_report() {
    let Some(d) = data_dir() else { return };
    let t = PsdTable::read_csv(&d.join("vib_psd.csv")).unwrap();
    assert_eq!(t.freq_hz.len(), 8193);
    let spec = RandomVibrationSpec {
        accel: Some(t.clone()),
        gyro: None,
        seed: 1,
    };
    let (rv, rep) = RandomVibration::realise(&spec, 600.0, 50.0, 0).unwrap();
    println!("{}", rep.summary());
    let p = rep.accel.unwrap()[2];
    // the pieces, each against its own integral of the table (trapezoids of the rows)
    let df = 1.0 / 600.0;
    assert_eq!(rep.components, rv.len());
    assert!((p.specified - t.integral(2, 0.0, 100.0)).abs() <= 1e-15);
    assert!((p.dropped_dc - t.integral(2, 0.0, 0.5 * df)).abs() <= 1e-20);
    assert!((p.dropped_above_nyquist - t.integral(2, 50.0, 100.0)).abs() <= 1e-25);
    // the threshold skips a tiny share: ≤ 1e-9·max per component over ≤ 6e4 components
    let smax = 0.444_149_975;
    assert!(p.dropped_below_threshold <= 1e-9 * smax * df * 30_000.0);
    // rectangle (components) vs trapezoid (table) rule: within 1e-4 of the total
    let sum = p.realised + p.dropped();
    assert!(
        (sum - p.specified).abs() <= 1e-4 * p.specified,
        "{sum} vs {}",
        p.specified
    );
    // the realised variance of the draws: Σ(a²+b²)/2 ~ P(1 ± 3.29 σ), σ² = Σ(S Δf)²/P²
    let (lin, _) = rv.coefficient_power();
    let var: f64 = (1..30_000)
        .map(|k| (t.at(2, k as f64 * df) * df).powi(2))
        .sum();
    for x in lin {
        assert!(
            (x - p.realised).abs() <= 3.29 * var.sqrt(),
            "{x} vs {}",
            p.realised
        );
    }
}

/// The truth of a scenario text, with its scenario.
fn truth(text: &str) -> (Scenario, Vec<TruthSample>) {
    let s = Scenario::from_toml(text, "t.toml").unwrap();
    let g = TruthGenerator::new(&s.trajectory, s.truth_config());
    let v = g.collect();
    (s, v)
}

#[test]
fn increments_are_the_exact_velocity_change() {
    // flat non-rotating earth, static, linear vibration only: f^b = C_n^b (v̇ − g) with C
    // constant, so Δv^b = C_n^b (v(t₁) − v(t₀) − g δt) exactly; the Gauss remainder bound
    // keeps the quadrature below ε·g·δt = 2.2e-17 m/s, the rest is rounding of sums of
    // ~1 m/s terms (|Δv| ≈ 0.098 m/s, ulp 1.4e-17)
    let (s, v) = truth(&scenario(
        20.0,
        "flat",
        "accel_psd_breakpoints = [[2.0, 0.01], [10.0, 0.05], [30.0, 0.001]]",
    ));
    let rv = &s.trajectory.random_vibrations()[0];
    println!("{} components, substeps {}", rv.len(), s.nav.substeps);
    let k0 = s.trajectory.kinematics(0.0, 0.0);
    let g = Vec3::new(0.0, 0.0, 9.806_65);
    let c_n_b = k0.c_b_n.transpose();
    let dt = s.imu.dt_s();
    let mut prev = k0.v_n_mps;
    let mut worst: f64 = 0.0;
    for x in &v {
        let want = c_n_b * (x.v_n_mps - prev - g * dt);
        worst = worst.max((x.inc.dv_b_mps - want).amax());
        prev = x.v_n_mps;
        assert_eq!(x.c_b_n, k0.c_b_n);
    }
    println!("worst |Δv − C(v₁ − v₀ − gδt)| = {worst:e} m/s");
    assert!(worst <= 1e-16, "{worst:e}");
    // the mean square of Δv/δt over the whole (periodic) window is exactly
    // Σ (a² + b²)/2 · sinc²(ω δt/2) (discrete orthogonality of the N-sample grid)
    let n = v.len() as f64;
    let mut ms = [0.0; 3];
    for x in &v {
        let y = c_n_b.transpose() * (x.inc.dv_b_mps / dt) + g;
        for (m, y) in ms.iter_mut().zip(y.iter()) {
            *m += y * y / n;
        }
    }
    let (lin, _) = rv.coefficient_power();
    let want = rv.coefficient_power_filtered(dt);
    println!("mean square {ms:?}, Σ(a²+b²)/2 {lin:?}, with sinc² {want:?}");
    for ax in 0..3 {
        // the velocity starts from rest: the mean of Δv/δt is (u(T) − u(0))/T = 0 up to
        // rounding, so the mean square is the variance
        assert!(
            (ms[ax] - want[ax]).abs() <= 1e-12 * want[ax],
            "{ax}: {} vs {}",
            ms[ax],
            want[ax]
        );
    }
}

#[test]
fn refinement_and_determinism_with_vibration() {
    // a turn with linear and angular vibration on the WGS-84 earth: the automatic
    // resolution against twice as many 4-node panels (the Gauss remainder bound is
    // ε·g·δt m/s and ε·max(ω_ie, σ_ω)·δt rad per sample, below one rounding)
    let text = "[start]\nlat_deg = 45.0\nlon_deg = 7.0\nspeed_mps = 20.0\n[imu]\nrate_hz = 100.0\nseed = 5\n[[segment]]\ntype = \"turn\"\nrate_dps = 6.0\nduration_s = 4.0\n[[overlay]]\ntype = \"random_vibration\"\naccel_psd_breakpoints = [[1.0, 0.02], [20.0, 0.02], [45.0, 1e-4]]\ngyro_psd_breakpoints = [[1.0, 1e-5, 2e-5, 4e-6], [30.0, 1e-6]]\nstart_s = 0.5\nend_s = 3.3\n";
    let s = Scenario::from_toml(text, "t.toml").unwrap();
    let c = s.truth_config();
    let mut c2 = c;
    c2.substeps = 2 * c.substeps.max(32);
    let a: Vec<TruthSample> = TruthGenerator::new(&s.trajectory, c).collect();
    let b: Vec<TruthSample> = TruthGenerator::new(&s.trajectory, c2).collect();
    let (mut dth, mut dv) = (0.0f64, 0.0f64);
    for (x, y) in a.iter().zip(&b) {
        dth = dth.max((x.inc.dtheta_b_rad - y.inc.dtheta_b_rad).amax());
        dv = dv.max((x.inc.dv_b_mps - y.inc.dv_b_mps).amax());
        assert_eq!(x.v_n_mps, y.v_n_mps);
        assert_eq!(x.c_b_n, y.c_b_n);
    }
    println!(
        "substeps {} vs {}: max |Δθ diff| {dth:e} rad, |Δv diff| {dv:e} m/s",
        c.substeps, c2.substeps
    );
    assert!(dth <= 2e-18, "{dth:e}");
    assert!(dv <= 1e-16, "{dv:e}");
    // same seed: same numbers; another seed: others
    let again: Vec<TruthSample> =
        TruthGenerator::new(&Scenario::from_toml(text, "t.toml").unwrap().trajectory, c).collect();
    assert_eq!(a, again);
    let other = Scenario::from_toml(&text.replace("seed = 5", "seed = 6"), "t.toml").unwrap();
    let o: Vec<TruthSample> = TruthGenerator::new(&other.trajectory, c).collect();
    assert_ne!(a[100].inc, o[100].inc);
    // the overlay seed key overrides the IMU seed
    let keyed = Scenario::from_toml(
        &text
            .replace("end_s = 3.3", "end_s = 3.3\nseed = 5")
            .replace("seed = 5\n[[segment]]", "seed = 6\n[[segment]]"),
        "t.toml",
    )
    .unwrap();
    let k: Vec<TruthSample> = TruthGenerator::new(&keyed.trajectory, c).collect();
    assert_eq!(a, k);
    // before the window: at rest relative to the turn; after: rates zero, state frozen
    let k0 = s.trajectory.kinematics(0.25, 0.25);
    let bare = Scenario::from_toml(&text[..text.find("[[overlay]]").unwrap()], "t.toml").unwrap();
    assert_eq!(k0, bare.trajectory.kinematics(0.25, 0.25));
    let k1 = s.trajectory.kinematics(3.6, 3.6);
    let kb = bare.trajectory.kinematics(3.6, 3.6);
    assert!(
        (k1.omega_nb_b_rps - k1.c_b_n.transpose() * kb.c_b_n * kb.omega_nb_b_rps).norm() < 1e-15
    );
}

// ---------------------------------------------------------------------------------------
// Welch estimates (ignored: release, tens of seconds)

/// In-place radix-2 FFT (test helper).
fn fft(re: &mut [f64], im: &mut [f64]) {
    let n = re.len();
    let mut j = 0;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            re.swap(i, j);
            im.swap(i, j);
        }
    }
    let mut len = 2;
    while len <= n {
        let ang = -2.0 * PI / len as f64;
        for start in (0..n).step_by(len) {
            for k in 0..len / 2 {
                let (s, c) = (ang * k as f64).sin_cos();
                let (a, b) = (start + k, start + k + len / 2);
                let (xr, xi) = (re[b] * c - im[b] * s, re[b] * s + im[b] * c);
                re[b] = re[a] - xr;
                im[b] = im[a] - xi;
                re[a] += xr;
                im[a] += xi;
            }
        }
        len <<= 1;
    }
}

/// Welch one-sided PSD: periodic Hann segments of `nseg` samples, 50 % overlap.
fn welch(x: &[f64], nseg: usize, fs: f64) -> (Vec<f64>, usize) {
    let w: Vec<f64> = (0..nseg)
        .map(|n| 0.5 - 0.5 * (2.0 * PI * n as f64 / nseg as f64).cos())
        .collect();
    let u: f64 = w.iter().map(|w| w * w).sum();
    let mut p = vec![0.0; nseg / 2 + 1];
    let mut k = 0;
    let mut start = 0;
    while start + nseg <= x.len() {
        let seg = &x[start..start + nseg];
        let mean = seg.iter().sum::<f64>() / nseg as f64;
        let mut re: Vec<f64> = seg.iter().zip(&w).map(|(x, w)| (x - mean) * w).collect();
        let mut im = vec![0.0; nseg];
        fft(&mut re, &mut im);
        for (j, p) in p.iter_mut().enumerate() {
            *p += 2.0 * (re[j] * re[j] + im[j] * im[j]) / (fs * u);
        }
        k += 1;
        start += nseg / 2;
    }
    for p in &mut p {
        *p /= k as f64;
    }
    (p, k)
}

/// `|W(θ)|²` of the periodic Hann window of length `n`: `W = ½D(θ) − ¼D(θ − 2π/n) −
/// ¼D(θ + 2π/n)`, `D(θ) = Σ e^{−iθm} = (1 − e^{−iθn})/(1 − e^{−iθ})`.
fn hann_response2(theta: f64, n: usize) -> f64 {
    let d = |t: f64| -> (f64, f64) {
        let t = t.rem_euclid(2.0 * PI);
        if t.abs() < 1e-12 || (2.0 * PI - t).abs() < 1e-12 {
            return (n as f64, 0.0);
        }
        let (nr, ni) = (1.0 - (t * n as f64).cos(), (t * n as f64).sin());
        let (dr, di) = (1.0 - t.cos(), t.sin());
        let q = dr * dr + di * di;
        ((nr * dr + ni * di) / q, (ni * dr - nr * di) / q)
    };
    let dw = 2.0 * PI / n as f64;
    let (a, b, c) = (d(theta), d(theta - dw), d(theta + dw));
    let re = 0.5 * a.0 - 0.25 * (b.0 + c.0);
    let im = 0.5 * a.1 - 0.25 * (b.1 + c.1);
    re * re + im * im
}

/// Regularised lower incomplete gamma `P(a, x)` (series / continued fraction, Press et
/// al., Numerical Recipes 3rd ed. §6.2).
fn gamma_p(a: f64, x: f64) -> f64 {
    let lg = libm::lgamma(a);
    if x < a + 1.0 {
        let (mut sum, mut del, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        sum * (-x + a * x.ln() - lg).exp()
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        1.0 - (-x + a * x.ln() - lg).exp() * h
    }
}

/// χ²_ν quantile by bisection on `P(ν/2, x/2)`.
fn chi2_quantile(nu: f64, p: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 10.0 * nu + 100.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if gamma_p(0.5 * nu, 0.5 * mid) < p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Welch of each axis of `y` against the exact expectation of the estimator for the
/// realised component grid; returns the worst fraction of tested bins outside the 99 %
/// band.
fn welch_check(
    name: &str,
    y: &[[f64; 3]],
    rv: &RandomVibration,
    psd: &PsdTable,
    df: f64,
    dt: f64,
) -> f64 {
    let fs = 1.0 / dt;
    let nseg = 8192; // 81.92 s at 100 Hz
    let theta_of = |f: f64| 2.0 * PI * f * dt;
    // equivalent degrees of freedom of Welch's estimate with overlapping segments:
    // ν = 2K / (1 + 2 Σ_{m=1}^{K−1} (1 − m/K) ρ²(m)), ρ(m) = Σ w_n w_{n+mS} / Σ w_n²
    // (Welch 1967; Percival & Walden 1993, eq. 292b); for 50 % overlap only ρ(1) ≠ 0
    let w: Vec<f64> = (0..nseg)
        .map(|n| 0.5 - 0.5 * (2.0 * PI * n as f64 / nseg as f64).cos())
        .collect();
    let u: f64 = w.iter().map(|w| w * w).sum();
    let rho1: f64 = (0..nseg / 2).map(|n| w[n] * w[n + nseg / 2]).sum::<f64>() / u;
    let mut worst: f64 = 0.0;
    for ax in 0..3 {
        let x: Vec<f64> = y.iter().map(|v| v[ax]).collect();
        let (p, k) = welch(&x, nseg, fs);
        let kf = k as f64;
        let nu = 2.0 * kf / (1.0 + 2.0 * (1.0 - 1.0 / kf) * rho1 * rho1);
        let (lo, hi) = (chi2_quantile(nu, 0.005) / nu, chi2_quantile(nu, 0.995) / nu);
        // expectation of the estimator: Σ_k (σ_k²/2)(|W(θ_j − ω_k δt)|² + |W(θ_j + ω_k δt)|²)
        // · sinc²(ω_k δt/2) · 2/(fs Σw²), σ_k² = S(f_k)Δf (the segment mean removal is
        // neglected: it acts on bin 0 only, up to the window's leakage)
        let comps: Vec<(f64, f64)> = rv
            .omega_rps()
            .iter()
            .map(|&om| {
                let f = om / (2.0 * PI);
                let x = 0.5 * om * dt;
                (theta_of(f), psd.at(ax, f) * df * (x.sin() / x).powi(2))
            })
            .filter(|c| c.1 > 0.0)
            .collect();
        // components within 64 bins of bin j (the Hann response |W|² beyond is below
        // 1e-10 of its peak: |W| falls as 1/Δ³); the mirror term only matters near 0 Hz
        let bin = 2.0 * PI / nseg as f64;
        let expect: Vec<f64> = (0..=nseg / 2)
            .map(|j| {
                let th = j as f64 * bin;
                let a = comps.partition_point(|c| c.0 < th - 64.0 * bin);
                let b = comps.partition_point(|c| c.0 <= th + 64.0 * bin);
                let near0 = comps.partition_point(|c| c.0 <= 64.0 * bin - th);
                let mirror: f64 = comps[..near0]
                    .iter()
                    .map(|&(tk, v)| 0.5 * v * hann_response2(th + tk, nseg))
                    .sum();
                let direct: f64 = comps[a..b]
                    .iter()
                    .map(|&(tk, v)| 0.5 * v * hann_response2(th - tk, nseg))
                    .sum();
                (mirror + direct) * 2.0 / (fs * u)
            })
            .collect();
        let emax = expect.iter().copied().fold(0.0, f64::max);
        let tested: Vec<usize> = (1..nseg / 2)
            .filter(|&j| expect[j] >= 1e-4 * emax)
            .collect();
        let outside = tested
            .iter()
            .filter(|&&j| {
                let r = p[j] / expect[j];
                r < lo || r > hi
            })
            .count();
        let frac = outside as f64 / tested.len() as f64;
        println!(
            "{name} axis {ax}: {k} segments, ν = {nu:.2} (ρ(1) = {rho1:.4}), band [{lo:.3}, {hi:.3}], {} bins ≥ 1e-4 of max, {outside} outside ({:.2} %)",
            tested.len(),
            100.0 * frac
        );
        worst = worst.max(frac);
    }
    worst
}

/// Total power: the mean square over the whole window (one period of the realisation,
/// `N` samples with every component below N/2 cycles) is exactly `Σ (a²+b²)/2·sinc²`;
/// against the PSD its expectation is `P = Σ S_k Δf sinc²_k` with standard deviation
/// `√Σ (S_k Δf sinc²_k)²` (each `(a²+b²)/2` is `S_k Δf·χ²₂/2`). Bound: 3.29 σ (99.9 %).
fn power_check(name: &str, y: &[[f64; 3]], rv: &RandomVibration, psd: &PsdTable, df: f64, dt: f64) {
    let n = y.len() as f64;
    for ax in 0..3 {
        let mean = y.iter().map(|v| v[ax]).sum::<f64>() / n;
        let ms = y.iter().map(|v| (v[ax] - mean).powi(2)).sum::<f64>() / n;
        let (mut p, mut var) = (0.0, 0.0);
        for &om in rv.omega_rps() {
            let x = 0.5 * om * dt;
            let v = psd.at(ax, om / (2.0 * PI)) * df * (x.sin() / x).powi(2);
            p += v;
            var += v * v;
        }
        let z = (ms - p) / var.sqrt();
        println!(
            "{name} axis {ax}: mean square {ms:.6e}, expected {p:.6e} ± {:.3e} (z = {z:.2})",
            var.sqrt()
        );
        assert!(z.abs() <= 3.29, "{name} axis {ax}: z = {z}");
    }
}

fn welch_case(overlay: &str, name: &str, gyro: bool, psd: PsdTable) {
    // 491.52 s = 6 × 81.92 s: 11 Welch segments with 50 % overlap
    let t = std::time::Instant::now();
    let (s, v) = truth(&scenario(491.52, "wgs84", overlay));
    println!(
        "{name}: truth of {} samples in {:.1?}",
        v.len(),
        t.elapsed()
    );
    let rv = &s.trajectory.random_vibrations()[0];
    let rep = &s.vibration[0];
    println!("{}", rep.summary());
    let dt = s.imu.dt_s();
    let y: Vec<[f64; 3]> = v
        .iter()
        .map(|x| {
            let q = if gyro {
                x.inc.dtheta_b_rad
            } else {
                x.inc.dv_b_mps
            } / dt;
            [q.x, q.y, q.z]
        })
        .collect();
    let frac = welch_check(name, &y, rv, &psd, rep.df_hz, dt);
    assert!(frac <= 0.02, "{name}: {frac}");
    power_check(name, &y, rv, &psd, rep.df_hz, dt);
    println!("{name}: whole test {:.1?}", t.elapsed());
}

#[test]
#[ignore = "release: Welch estimate over 491.52 s (about a minute)"]
fn welch_specific_force_matches_vib_psd_csv() {
    let Some(d) = data_dir() else { return };
    let f = d.join("vib_psd.csv");
    let psd = PsdTable::read_csv(&f).unwrap();
    welch_case(
        &format!("accel_psd_file = \"{}\"", f.display()),
        "specific force (vib_psd.csv)",
        false,
        psd,
    );
}

#[test]
#[ignore = "release: Welch estimate over 491.52 s (about a minute)"]
fn welch_angular_rate_matches_breakpoints() {
    let bp = vec![
        vec![0.5, 1e-7, 2e-7, 5e-8],
        vec![2.0, 4e-6, 8e-6, 2e-6],
        vec![5.0, 4e-6, 8e-6, 2e-6],
        vec![10.0, 1e-8, 2e-8, 5e-9],
    ];
    let psd = PsdTable::from_breakpoints(&bp, "bp").unwrap();
    let rows: Vec<String> = bp
        .iter()
        .map(|r| {
            format!(
                "[{}]",
                r.iter()
                    .map(|x| format!("{x:e}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        })
        .collect();
    welch_case(
        &format!("gyro_psd_breakpoints = [{}]", rows.join(", ")),
        "angular rate (breakpoints)",
        true,
        psd,
    );
}

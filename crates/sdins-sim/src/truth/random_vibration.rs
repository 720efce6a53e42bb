//! Random vibration from a power spectral density (docs/theory/imu-errors.md, "Random
//! vibration from a PSD").
//!
//! Input: a one-sided PSD per body axis, of specific force in (m/s²)²/Hz and of angular
//! rate in (rad/s)²/Hz, either as a table in the gnss-ins-sim `vib_psd.csv` layout
//! (`freq, x, y, z` rows, linear interpolation in frequency) or as MIL-STD-810-style
//! breakpoints `[f_hz, psd]` / `[f_hz, x, y, z]` with log-log interpolation
//! (`S(f) = S₁ (f/f₁)^n`, `n = ln(S₂/S₁)/ln(f₂/f₁)`, MIL-STD-810H Method 514.8).
//!
//! Realisation over a window of length `T`: the Fourier components
//! `x(τ) = Σ_k a_k cos ω_k τ + b_k sin ω_k τ`, `ω_k = 2π k/T`, `k ≥ 1`, with independent
//! `a_k, b_k ~ N(0, S(f_k)·Δf)`, `Δf = 1/T`, so that `E[x²] = Σ S(f_k) Δf` and the process
//! is Gaussian and stationary with period `T` (the component spacing must be `1/T` or
//! finer: with a coarser grid the process repeats inside the window and a Welch estimate
//! over it does not average independent segments). The acceleration components enter the
//! velocity through their exact integrals `(a_k sin ω_k τ − b_k cos ω_k τ)/ω_k`, the
//! angular-rate components the attitude through their exact integrals, as rotation angles
//! about the three body axes composed in the fixed order `R_x(θ_x) R_y(θ_y) R_z(θ_z)`,
//! whose body rate `ω = R_zᵀR_yᵀ θ̇_x e_x + R_zᵀ θ̇_y e_y + θ̇_z e_z` is exact (the sensed
//! rate equals `θ̇` to first order in the vibration angles). Both start from rest at the
//! window start (velocity and angles zero, as the sinusoidal `vibration` overlay).
//!
//! Dropped (and reported, [`VibrationReport`]): the band below `Δf/2` (the 0 Hz row of a
//! table), everything at or above the IMU's Nyquist frequency, and components whose PSD is
//! below `1e-9` of the axis's largest component PSD.

use rand::SeedableRng;
use rand_chacha::ChaCha20Rng;
use rand_distr::{Distribution, StandardNormal};
use std::f64::consts::PI;
use std::path::Path;

/// Components below this fraction of an axis's largest component PSD are skipped.
pub const SKIP_BELOW_REL: f64 = 1e-9;
/// Most components one overlay may realise (memory and run time grow with it).
pub const MAX_COMPONENTS: usize = 400_000;
/// First random stream of the vibration draws (`ChaCha20Rng::set_stream`), far from the
/// IMU error streams `6·run + channel`.
const STREAM_BASE: u64 = 1 << 62;

/// A PSD input error, located.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PsdError {
    /// The file could not be read.
    #[error("{file}: cannot read PSD table: {reason}")]
    Read {
        /// file name
        file: String,
        /// OS message
        reason: String,
    },
    /// A bad row, value or ordering.
    #[error("{file}:{line}:{column}: {message}")]
    Invalid {
        /// file name (or the scenario key of inline breakpoints)
        file: String,
        /// 1-based line (row of the breakpoint list)
        line: usize,
        /// 1-based column
        column: usize,
        /// what is wrong
        message: String,
    },
}

/// How a [`PsdTable`] is interpolated between its rows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interp {
    /// linear in frequency and PSD (gnss-ins-sim tables)
    Linear,
    /// straight lines in log f – log PSD (MIL-STD-810 breakpoints)
    LogLog,
}

/// A one-sided PSD per body axis versus frequency; zero outside its frequency range.
#[derive(Clone, Debug, PartialEq)]
pub struct PsdTable {
    /// frequencies \[Hz\], strictly increasing
    pub freq_hz: Vec<f64>,
    /// PSD per axis x, y, z at each frequency (unit of the quantity squared per Hz)
    pub psd: Vec<[f64; 3]>,
    /// interpolation between rows
    pub interp: Interp,
}

fn invalid(file: &str, line: usize, column: usize, message: impl Into<String>) -> PsdError {
    PsdError::Invalid {
        file: file.to_string(),
        line,
        column,
        message: message.into(),
    }
}

impl PsdTable {
    /// Parse a CSV table: an optional header line, then rows `freq_hz, x, y, z` (or
    /// `freq_hz, psd` for all three axes); frequencies ≥ 0 and strictly increasing, PSD
    /// finite and ≥ 0. `file` names the source in errors (`file:line:column`).
    pub fn parse_csv(text: &str, file: &str) -> Result<PsdTable, PsdError> {
        let mut freq_hz = Vec::new();
        let mut psd = Vec::new();
        let mut width = None;
        let mut first_data = true;
        for (i, line) in text.lines().enumerate() {
            let ln = i + 1;
            let trimmed = line.trim();
            if trimmed.is_empty() || trimmed.starts_with('#') {
                continue;
            }
            // fields with their 1-based character columns
            let mut fields = Vec::new();
            let mut col = 1;
            for f in line.split(',') {
                let lead = f.len() - f.trim_start().len();
                fields.push((col + lead, f.trim()));
                col += f.chars().count() + 1;
            }
            if first_data && fields[0].1.parse::<f64>().is_err() {
                // a header line (gnss-ins-sim: `freq,x,y,z`)
                first_data = false;
                continue;
            }
            first_data = false;
            let n = fields.len();
            if n != 2 && n != 4 {
                return Err(invalid(
                    file,
                    ln,
                    1,
                    format!("expected 2 (freq, psd) or 4 (freq, x, y, z) columns, found {n}"),
                ));
            }
            if let Some(w) = width {
                if w != n {
                    return Err(invalid(
                        file,
                        ln,
                        1,
                        format!("{n} columns where earlier rows have {w}"),
                    ));
                }
            }
            width = Some(n);
            let mut vals = [0.0; 4];
            for (j, (c, f)) in fields.iter().enumerate() {
                let v: f64 = f
                    .parse()
                    .map_err(|_| invalid(file, ln, *c, format!("`{f}` is not a number")))?;
                if !v.is_finite() {
                    return Err(invalid(file, ln, *c, format!("{f}: must be finite")));
                }
                if v < 0.0 {
                    let what = if j == 0 { "frequency" } else { "PSD" };
                    return Err(invalid(file, ln, *c, format!("negative {what} {v}")));
                }
                vals[j] = v;
            }
            if let Some(&prev) = freq_hz.last() {
                if vals[0] <= prev {
                    return Err(invalid(
                        file,
                        ln,
                        fields[0].0,
                        format!(
                            "frequency {} Hz does not increase (previous row {prev} Hz)",
                            vals[0]
                        ),
                    ));
                }
            }
            freq_hz.push(vals[0]);
            psd.push(if n == 2 {
                [vals[1]; 3]
            } else {
                [vals[1], vals[2], vals[3]]
            });
        }
        if freq_hz.len() < 2 {
            return Err(invalid(file, 1, 1, "a PSD table needs at least two rows"));
        }
        Ok(PsdTable {
            freq_hz,
            psd,
            interp: Interp::Linear,
        })
    }

    /// Read a CSV table ([`PsdTable::parse_csv`]).
    pub fn read_csv(path: &Path) -> Result<PsdTable, PsdError> {
        let file = path.display().to_string();
        let bytes = crate::input::read_capped(path).map_err(|e| PsdError::Read {
            file: file.clone(),
            reason: e.to_string(),
        })?;
        let text = String::from_utf8(bytes).map_err(|e| PsdError::Read {
            file: file.clone(),
            reason: format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
        })?;
        PsdTable::parse_csv(&text, &file)
    }

    /// Breakpoints `[f_hz, psd]` or `[f_hz, x, y, z]` with log-log interpolation:
    /// frequencies > 0 and strictly increasing, PSD finite and > 0. `key` names the list
    /// in errors (line = 1-based row of the list, column = 1-based entry).
    pub fn from_breakpoints(rows: &[Vec<f64>], key: &str) -> Result<PsdTable, PsdError> {
        let mut freq_hz = Vec::new();
        let mut psd = Vec::new();
        for (i, r) in rows.iter().enumerate() {
            let ln = i + 1;
            if r.len() != 2 && r.len() != 4 {
                return Err(invalid(
                    key,
                    ln,
                    1,
                    format!(
                        "expected [f_hz, psd] or [f_hz, x, y, z], found {} numbers",
                        r.len()
                    ),
                ));
            }
            for (j, &v) in r.iter().enumerate() {
                if !v.is_finite() || v <= 0.0 {
                    let what = if j == 0 { "frequency" } else { "PSD" };
                    return Err(invalid(
                        key,
                        ln,
                        j + 1,
                        format!("{what} {v}: breakpoints need finite values > 0 (log-log)"),
                    ));
                }
            }
            if let Some(&prev) = freq_hz.last() {
                if r[0] <= prev {
                    return Err(invalid(
                        key,
                        ln,
                        1,
                        format!(
                            "frequency {} Hz does not increase (previous {prev} Hz)",
                            r[0]
                        ),
                    ));
                }
            }
            freq_hz.push(r[0]);
            psd.push(if r.len() == 2 {
                [r[1]; 3]
            } else {
                [r[1], r[2], r[3]]
            });
        }
        if freq_hz.len() < 2 {
            return Err(invalid(key, 1, 1, "at least two breakpoints are needed"));
        }
        Ok(PsdTable {
            freq_hz,
            psd,
            interp: Interp::LogLog,
        })
    }

    /// Highest frequency with a PSD \[Hz\].
    pub fn f_max_hz(&self) -> f64 {
        self.freq_hz.last().copied().unwrap_or(0.0)
    }

    /// The PSD of axis `ax` at `f` (zero outside the table).
    pub fn at(&self, ax: usize, f: f64) -> f64 {
        let fr = &self.freq_hz;
        if fr.is_empty() || f < fr[0] || f > fr[fr.len() - 1] {
            return 0.0;
        }
        let j = fr.partition_point(|&x| x <= f).clamp(1, fr.len() - 1);
        let (f1, f2) = (fr[j - 1], fr[j]);
        let (s1, s2) = (self.psd[j - 1][ax], self.psd[j][ax]);
        match self.interp {
            Interp::Linear => s1 + (s2 - s1) * (f - f1) / (f2 - f1),
            Interp::LogLog => s1 * (f / f1).powf((s2 / s1).ln() / (f2 / f1).ln()),
        }
    }

    /// `∫_a^b S_ax(f) df` of the interpolant (exact for both interpolations).
    pub fn integral(&self, ax: usize, a: f64, b: f64) -> f64 {
        let fr = &self.freq_hz;
        let mut sum = 0.0;
        for j in 1..fr.len() {
            let (lo, hi) = (fr[j - 1].max(a), fr[j].min(b));
            if hi <= lo {
                continue;
            }
            let (f1, f2) = (fr[j - 1], fr[j]);
            let (s1, s2) = (self.psd[j - 1][ax], self.psd[j][ax]);
            sum += match self.interp {
                Interp::Linear => {
                    let sl = s1 + (s2 - s1) * (lo - f1) / (f2 - f1);
                    let sh = s1 + (s2 - s1) * (hi - f1) / (f2 - f1);
                    0.5 * (sl + sh) * (hi - lo)
                }
                Interp::LogLog => {
                    let n = (s2 / s1).ln() / (f2 / f1).ln();
                    let c = s1 / f1.powf(n);
                    if (n + 1.0).abs() < 1e-12 {
                        c * (hi / lo).ln()
                    } else {
                        c * (hi.powf(n + 1.0) - lo.powf(n + 1.0)) / (n + 1.0)
                    }
                }
            };
        }
        sum
    }
}

/// A random-vibration specification (one `random_vibration` overlay).
#[derive(Clone, Debug, PartialEq)]
pub struct RandomVibrationSpec {
    /// specific-force PSD per body axis \[(m/s²)²/Hz\]
    pub accel: Option<PsdTable>,
    /// angular-rate PSD per body axis \[(rad/s)²/Hz\]
    pub gyro: Option<PsdTable>,
    /// seed of the Gaussian coefficients
    pub seed: u64,
}

/// Power bookkeeping of one axis \[unit²\] (variance of the quantity).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AxisPower {
    /// `∫ S df` over the whole input
    pub specified: f64,
    /// the realised variance `Σ S(f_k) Δf` over the kept components
    pub realised: f64,
    /// dropped below `Δf/2` (the 0 Hz row of a table)
    pub dropped_dc: f64,
    /// dropped at and above the Nyquist frequency
    pub dropped_above_nyquist: f64,
    /// dropped components below `1e-9` of the largest
    pub dropped_below_threshold: f64,
}

impl AxisPower {
    /// All dropped power.
    pub fn dropped(&self) -> f64 {
        self.dropped_dc + self.dropped_above_nyquist + self.dropped_below_threshold
    }
}

/// What a realisation kept and dropped (returned by [`RandomVibration::realise`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VibrationReport {
    /// component spacing Δf = 1/T \[Hz\]
    pub df_hz: f64,
    /// number of frequencies realised
    pub components: usize,
    /// specific force per axis \[(m/s²)²\]
    pub accel: Option<[AxisPower; 3]>,
    /// angular rate per axis \[(rad/s)²\]
    pub gyro: Option<[AxisPower; 3]>,
}

impl VibrationReport {
    /// One line per quantity: realised and dropped power, for `sdins truth`/`run`.
    pub fn summary(&self) -> String {
        let mut s = format!(
            "random vibration: {} components, Δf = {:.6} Hz",
            self.components, self.df_hz
        );
        for (name, unit, p) in [
            ("specific force", "(m/s²)²", &self.accel),
            ("angular rate", "(rad/s)²", &self.gyro),
        ] {
            if let Some(p) = p {
                s += &format!("\n  {name} [{unit}] x/y/z:");
                for (ax, a) in ["x", "y", "z"].iter().zip(p) {
                    s += &format!(
                        "\n    {ax}: specified {:.6e}, realised {:.6e}, dropped {:.3e} (DC {:.3e}, ≥ Nyquist {:.3e}, below 1e-9 of max {:.3e})",
                        a.specified,
                        a.realised,
                        a.dropped(),
                        a.dropped_dc,
                        a.dropped_above_nyquist,
                        a.dropped_below_threshold
                    );
                }
            }
        }
        s
    }
}

/// `(base, offset)` phases `(sin, cos)` per component, whose angle sums are the phases.
pub(crate) type Phases<'a> = (&'a [(f64, f64)], &'a [(f64, f64)]);

/// Components per block of the vectorised sums.
const LANES: usize = 2;
/// Floats per block: per axis `a`, `b`, `a/ω`, `b/ω` of the `LANES` components.
const BLOCK: usize = 12 * LANES;

/// Per-axis coefficients of the components `a`, `b`, `a/ω`, `b/ω`, interleaved in blocks of
/// `LANES` components (`[axis][quantity][lane]` within a block), so that the sums run
/// through one contiguous array; the last block is padded with zeros.
#[derive(Clone, Debug, Default, PartialEq)]
struct Coefs {
    n: usize,
    data: Vec<f64>,
}

impl Coefs {
    fn new(n: usize) -> Self {
        Coefs {
            n,
            data: vec![0.0; n.div_ceil(LANES) * BLOCK],
        }
    }
    fn is_empty(&self) -> bool {
        self.n == 0
    }
    #[inline]
    fn idx(k: usize, ax: usize, q: usize) -> usize {
        (k / LANES) * BLOCK + (4 * ax + q) * LANES + k % LANES
    }
    fn get(&self, k: usize, ax: usize, q: usize) -> f64 {
        self.data[Self::idx(k, ax, q)]
    }
    fn set(&mut self, k: usize, ax: usize, q: usize, x: f64) {
        let i = Self::idx(k, ax, q);
        self.data[i] = x;
    }
    fn amp(&self, k: usize, ax: usize) -> f64 {
        self.get(k, ax, 0).hypot(self.get(k, ax, 1))
    }
}

/// `Σ_k (a cos + b sin)` and `Σ_k (a/ω sin − b/ω cos)` per axis, with the `(sin, cos)`
/// of component `k`'s phase being the angle sum of `base[k]` and `off[k]`; summed in
/// `LANES` partial sums per axis (fixed order: the same numbers on every machine and
/// thread count).
#[inline(always)]
fn sums(c: &Coefs, base: &[(f64, f64)], off: &[(f64, f64)]) -> ([f64; 3], [f64; 3]) {
    let mut d = [[0.0; LANES]; 3];
    let mut v = [[0.0; LANES]; 3];
    let n = c.n.min(base.len()).min(off.len());
    let full = n / LANES;
    let blocks = c.data.chunks_exact(BLOCK);
    for ((blk, b2), o2) in blocks
        .clone()
        .zip(base.chunks_exact(LANES))
        .zip(off.chunks_exact(LANES))
        .take(full)
    {
        let mut sn = [0.0; LANES];
        let mut cs = [0.0; LANES];
        for l in 0..LANES {
            let ((sb, cb), (so, co)) = (b2[l], o2[l]);
            sn[l] = sb * co + cb * so;
            cs[l] = cb * co - sb * so;
        }
        for ax in 0..3 {
            let q = &blk[4 * LANES * ax..4 * LANES * (ax + 1)];
            for l in 0..LANES {
                d[ax][l] += q[l] * cs[l] + q[LANES + l] * sn[l];
                v[ax][l] += q[2 * LANES + l] * sn[l] - q[3 * LANES + l] * cs[l];
            }
        }
    }
    for k in full * LANES..n {
        let ((sb, cb), (so, co)) = (base[k], off[k]);
        let (sn, cs) = (sb * co + cb * so, cb * co - sb * so);
        let l = k % LANES;
        for ax in 0..3 {
            d[ax][l] += c.get(k, ax, 0) * cs + c.get(k, ax, 1) * sn;
            v[ax][l] += c.get(k, ax, 2) * sn - c.get(k, ax, 3) * cs;
        }
    }
    let red = |x: [f64; LANES]| x.iter().sum::<f64>();
    (
        [red(v[0]), red(v[1]), red(v[2])],
        [red(d[0]), red(d[1]), red(d[2])],
    )
}

/// A realised random vibration: the kept frequencies and their coefficients.
#[derive(Clone, Debug, PartialEq)]
pub struct RandomVibration {
    /// angular frequencies ω_k \[rad/s\]
    omega: Vec<f64>,
    /// specific-force coefficients (empty without an accel PSD)
    lin: Coefs,
    /// angular-rate coefficients (empty without a gyro PSD)
    ang: Coefs,
    /// `U(0)`, `Θ(0)`: subtracted so that the motion starts from rest
    u0: [f64; 3],
    th0: [f64; 3],
    /// the state at the window end (frozen afterwards): u, θ
    end: Option<([f64; 3], [f64; 3])>,
}

/// The vibration's state at one instant, in the body axes it is applied in.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VibState {
    /// velocity `u` \[m/s\]
    pub u: [f64; 3],
    /// acceleration `u̇` \[m/s²\]
    pub u_dot: [f64; 3],
    /// rotation angles about x, y, z \[rad\]
    pub theta: [f64; 3],
    /// their rates \[rad/s\]
    pub theta_dot: [f64; 3],
}

/// The Gauss–Legendre remainder of the vibration per sample for `P` panels: the
/// remainder of a panel is `H^(2N+1) f^(2N)(ξ)/D_N`, and `f^(2N)` of the realised sum is
/// itself a Gaussian sum `Σ_k ω_k^(2N) (a_k cos + b_k sin)` of variance
/// `Σ_k ω_k^(4N) (a_k² + b_k²)/2` per axis; its peak over ≤ 1e8 nodes stays below 6σ
/// (two-sided 2e-9), so the bound is `6·√(Σ_k (a_k² + b_k²)/2 · (ω_k H)^(4N)) · δt/D_N`
/// summed over the axes (a strict `Σ |A_k|` bound would charge every component at its
/// peak at once, ~√K/6 times more).
fn gauss_bound(omega: &[f64], coef: &Coefs, dt: f64, p: f64, two_n: i32, d: f64) -> f64 {
    if coef.is_empty() {
        return 0.0;
    }
    (0..3)
        .map(|ax| {
            let var: f64 = omega
                .iter()
                .enumerate()
                .map(|(k, &w)| 0.5 * coef.amp(k, ax).powi(2) * (w * dt / p).powi(2 * two_n))
                .sum();
            6.0 * var.sqrt() * dt / d
        })
        .sum()
}

impl RandomVibration {
    /// Realise `spec` over a window of `window_s` seconds for an IMU whose Nyquist
    /// frequency is `nyquist_hz`; `index` numbers the overlay (its own random streams).
    pub fn realise(
        spec: &RandomVibrationSpec,
        window_s: f64,
        nyquist_hz: f64,
        index: u64,
    ) -> Result<(RandomVibration, VibrationReport), String> {
        if !(window_s.is_finite() && window_s > 0.0) {
            return Err(format!(
                "the vibration window must be > 0 s, got {window_s}"
            ));
        }
        let df = 1.0 / window_s;
        let tables: [Option<&PsdTable>; 2] = [spec.accel.as_ref(), spec.gyro.as_ref()];
        let f_top = tables
            .iter()
            .flatten()
            .map(|t| t.f_max_hz())
            .fold(0.0, f64::max)
            .min(nyquist_hz);
        // components k·Δf < min(f_max, Nyquist)
        let mut k_max = (f_top / df).floor() as usize;
        if k_max as f64 * df >= nyquist_hz {
            k_max = k_max.saturating_sub(1);
        }
        if k_max > MAX_COMPONENTS {
            return Err(format!(
                "{k_max} components (window {window_s} s × band {f_top} Hz) exceed the limit {MAX_COMPONENTS}: shorten the overlay window or the PSD band"
            ));
        }
        let mut report = VibrationReport {
            df_hz: df,
            ..VibrationReport::default()
        };
        // per kind and axis: the coefficient draws and the kept mask
        let mut keep = vec![false; k_max + 1];
        let mut sig: [[Vec<f64>; 3]; 2] = Default::default();
        for (kind, t) in tables.iter().enumerate() {
            let Some(t) = t else { continue };
            let mut pw = [AxisPower::default(); 3];
            for ax in 0..3 {
                let s: Vec<f64> = (0..=k_max).map(|k| t.at(ax, k as f64 * df)).collect();
                let smax = s.iter().skip(1).copied().fold(0.0, f64::max);
                let p = &mut pw[ax];
                p.specified = t.integral(ax, 0.0, f64::INFINITY);
                p.dropped_dc = t.integral(ax, 0.0, 0.5 * df);
                p.dropped_above_nyquist = t.integral(ax, nyquist_hz, f64::INFINITY);
                let mut sg = vec![0.0; k_max + 1];
                for k in 1..=k_max {
                    if s[k] > 0.0 && s[k] >= SKIP_BELOW_REL * smax {
                        p.realised += s[k] * df;
                        sg[k] = (s[k] * df).sqrt();
                        keep[k] = true;
                    } else {
                        p.dropped_below_threshold += s[k] * df;
                    }
                }
                sig[kind][ax] = sg;
            }
            if kind == 0 {
                report.accel = Some(pw);
            } else {
                report.gyro = Some(pw);
            }
        }
        let kept: Vec<usize> = (1..=k_max).filter(|&k| keep[k]).collect();
        let omega: Vec<f64> = kept.iter().map(|&k| 2.0 * PI * k as f64 * df).collect();
        let mut coefs: [Coefs; 2] = Default::default();
        for kind in 0..2 {
            if tables[kind].is_none() {
                continue;
            }
            let mut c = Coefs::new(kept.len());
            for (ax, sig_ax) in sig[kind].iter().enumerate() {
                // one stream per (overlay, kind, axis); draws for every k ≤ k_max in order,
                // so the threshold does not shift the numbers of other components
                let mut rng = ChaCha20Rng::seed_from_u64(spec.seed);
                rng.set_stream(STREAM_BASE + 8 * index + 3 * kind as u64 + ax as u64);
                let mut draws = vec![(0.0, 0.0); k_max + 1];
                for d in draws.iter_mut().skip(1) {
                    let a: f64 = StandardNormal.sample(&mut rng);
                    let b: f64 = StandardNormal.sample(&mut rng);
                    *d = (a, b);
                }
                for (j, &k) in kept.iter().enumerate() {
                    let s = sig_ax[k];
                    let (a, b) = (s * draws[k].0, s * draws[k].1);
                    let w = omega[j];
                    for (q, x) in [a, b, a / w, b / w].into_iter().enumerate() {
                        c.set(j, ax, q, x);
                    }
                }
            }
            coefs[kind] = c;
        }
        let [lin, ang] = coefs;
        let mut rv = RandomVibration {
            omega,
            lin,
            ang,
            u0: [0.0; 3],
            th0: [0.0; 3],
            end: None,
        };
        let z = rv.raw(0.0, None);
        rv.u0 = z.u;
        rv.th0 = z.theta;
        report.components = rv.omega.len();
        Ok((rv, report))
    }

    /// Freeze the state at `tau_end` (window length): used after the window.
    pub(crate) fn freeze_at(&mut self, tau_end: f64) {
        if tau_end.is_finite() {
            let s = self.state(tau_end, None);
            self.end = Some((s.u, s.theta));
        }
    }

    /// Number of frequencies.
    pub fn len(&self) -> usize {
        self.omega.len()
    }

    /// Whether there are no components.
    pub fn is_empty(&self) -> bool {
        self.omega.is_empty()
    }

    /// Angular frequencies \[rad/s\].
    pub fn omega_rps(&self) -> &[f64] {
        &self.omega
    }

    /// The Gauss remainder bounds `(m/s, rad)` per sample of `dt_s` for `panels` panels
    /// of `nodes` (3 or 4) nodes: the 6σ bound of the realised sum (`D₃ = 2 016 000`, `D₄ = 1 778 112 000`;
    /// [`crate::truth::TruthScheme::Gauss`]).
    pub fn gauss_remainder(&self, dt_s: f64, panels: usize, nodes: usize) -> (f64, f64) {
        let (two_n, d) = if nodes == 3 {
            (6, 2_016_000.0)
        } else {
            (8, 1_778_112_000.0)
        };
        let p = panels as f64;
        (
            gauss_bound(&self.omega, &self.lin, dt_s, p, two_n, d),
            gauss_bound(&self.omega, &self.ang, dt_s, p, two_n, d),
        )
    }

    /// Gauss panels of 4 nodes per sample of `dt_s` that keep the remainder bound
    /// ([`RandomVibration::gauss_remainder`]) of the vibration below one rounding of the
    /// increments, `ε·g·δt` m/s and `ε·max(ω_ie, σ_ω)·δt` rad (`ε = 2.2e-16`, `σ_ω` the
    /// realised RMS angular rate); 0 if one 3-node panel does.
    pub fn gauss_panels(&self, dt_s: f64) -> usize {
        let eps = f64::EPSILON;
        let tol_v = eps * 9.81 * dt_s;
        let (_, pw) = self.coefficient_power();
        let sigma_w = (pw[0] + pw[1] + pw[2]).sqrt();
        let tol_th = eps * sigma_w.max(7.292_115e-5) * dt_s;
        let ok = |p: usize, n: usize| {
            let (v, th) = self.gauss_remainder(dt_s, p, n);
            v <= tol_v && th <= tol_th
        };
        if ok(1, 3) {
            return 0;
        }
        (1..=128).find(|&p| ok(p, 4)).unwrap_or(128)
    }

    /// Realised variance of the specific force (per axis) from the coefficients:
    /// `Σ (a_k² + b_k²)/2`, the exact mean square over a whole window.
    pub fn coefficient_power(&self) -> ([f64; 3], [f64; 3]) {
        let p = |c: &Coefs| {
            let mut s = [0.0; 3];
            for (ax, s) in s.iter_mut().enumerate() {
                for k in 0..c.n {
                    let (a, b) = (c.get(k, ax, 0), c.get(k, ax, 1));
                    *s += 0.5 * (a * a + b * b);
                }
            }
            s
        };
        (p(&self.lin), p(&self.ang))
    }

    /// The specific-force variance per axis of the sample means over `dt_s` (what
    /// `Δv/δt` carries): `Σ (a_k² + b_k²)/2 · sinc²(ω_k δt/2)`.
    pub fn coefficient_power_filtered(&self, dt_s: f64) -> [f64; 3] {
        let mut s = [0.0; 3];
        for (ax, s) in s.iter_mut().enumerate() {
            for (k, &w) in self.omega.iter().enumerate().take(self.lin.n) {
                let x = 0.5 * w * dt_s;
                let (a, b) = (self.lin.get(k, ax, 0), self.lin.get(k, ax, 1));
                *s += 0.5 * (a * a + b * b) * (x.sin() / x).powi(2);
            }
        }
        s
    }

    /// `(sin, cos)` of `ω_k τ` for every component, appended to `out`.
    pub(crate) fn push_phases(&self, tau: f64, out: &mut Vec<(f64, f64)>) {
        out.extend(self.omega.iter().map(|w| (w * tau).sin_cos()));
    }

    /// `U(τ)`, `u̇`, `Θ(τ)`, `θ̇` without the start offsets; `phases`: `(sin, cos)` of
    /// `ω_k τ` (else computed).
    fn raw(&self, tau: f64, phases: Option<Phases<'_>>) -> VibState {
        let mut st = VibState::default();
        let acc = |coef: &Coefs, val: &mut [f64; 3], der: &mut [f64; 3]| {
            if coef.is_empty() {
                return;
            }
            (*val, *der) = match phases {
                Some((base, off)) => sums(coef, base, off),
                None => {
                    let ph: Vec<(f64, f64)> =
                        self.omega.iter().map(|w| (w * tau).sin_cos()).collect();
                    sums(coef, &ph, &vec![(0.0, 1.0); ph.len()])
                }
            };
        };
        acc(&self.lin, &mut st.u, &mut st.u_dot);
        acc(&self.ang, &mut st.theta, &mut st.theta_dot);
        st
    }

    /// The state at `τ` into the window (from rest at τ = 0); `phases`: `(base, offset)`
    /// sin/cos whose angle sum is `ω_k τ`.
    pub(crate) fn state(&self, tau: f64, phases: Option<Phases<'_>>) -> VibState {
        let mut s = self.raw(tau, phases);
        for ax in 0..3 {
            s.u[ax] -= self.u0[ax];
            s.theta[ax] -= self.th0[ax];
        }
        s
    }

    /// The frozen state after the window (velocity and angles held, rates zero).
    pub(crate) fn frozen(&self, tau_end: f64) -> VibState {
        match self.end {
            Some((u, theta)) => VibState {
                u,
                theta,
                ..VibState::default()
            },
            None => {
                let s = self.state(tau_end, None);
                VibState {
                    u: s.u,
                    theta: s.theta,
                    ..VibState::default()
                }
            }
        }
    }

    /// Whether there is an angular part.
    pub fn has_rotation(&self) -> bool {
        !self.ang.is_empty()
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn csv_errors_are_located() {
        let bad = [
            ("freq,x,y,z\n0,1,1,1\n1,1,-2,1\n", 3, 5, "negative PSD"),
            ("freq,x,y,z\n0,1,1,1\n1,1,nan,1\n", 3, 5, "finite"),
            ("freq,x,y,z\n0,1,1,1\n0,1,1,1\n", 3, 1, "does not increase"),
            ("freq,x,y,z\n0,1,1,1\n1,1,1\n", 3, 1, "columns"),
            ("freq,x,y,z\n0,1,1,1\n1,1,abc,1\n", 3, 5, "not a number"),
            ("freq,x,y,z\n0,1,1,1\n", 1, 1, "two rows"),
        ];
        for (text, line, column, what) in bad {
            match PsdTable::parse_csv(text, "p.csv") {
                Err(PsdError::Invalid {
                    line: l,
                    column: c,
                    message,
                    ..
                }) => {
                    assert_eq!((l, c), (line, column), "{text}: {message}");
                    assert!(message.contains(what), "{message}");
                }
                other => panic!("{text}: {other:?}"),
            }
        }
    }

    #[test]
    fn interpolation_and_integrals_are_exact() {
        let t = PsdTable::parse_csv("f,x,y,z\n0,1,2,0\n2,3,2,4\n", "t").unwrap();
        assert_eq!(t.at(0, 1.0), 2.0);
        assert_eq!(t.at(0, 3.0), 0.0);
        // ∫₀² (1 + f) df = 4; over [0.5, 1]: 0.5·(1.5 + 2)/2
        assert!((t.integral(0, 0.0, 10.0) - 4.0).abs() < 1e-15);
        assert!((t.integral(0, 0.5, 1.0) - 0.875).abs() < 1e-15);
        // log-log: S = f² on [1, 2]: ∫ = 7/3; S = 1/f on [2, 4]: ∫ = 4 ln 2 · ... (S(2)=4 → 8/f)
        let b = PsdTable::from_breakpoints(&[vec![1.0, 1.0], vec![2.0, 4.0], vec![4.0, 2.0]], "bp")
            .unwrap();
        assert!((b.at(1, 1.5) - 2.25).abs() < 1e-14);
        assert!((b.integral(2, 0.0, 2.0) - 7.0 / 3.0).abs() < 1e-14);
        assert!((b.integral(0, 2.0, 4.0) - 8.0 * 2f64.ln()).abs() < 1e-14);
    }

    #[test]
    fn realisation_keeps_the_power_and_is_deterministic() {
        let spec = RandomVibrationSpec {
            accel: Some(
                PsdTable::from_breakpoints(&[vec![1.0, 0.01], vec![20.0, 0.01]], "a").unwrap(),
            ),
            gyro: None,
            seed: 7,
        };
        let (a, ra) = RandomVibration::realise(&spec, 100.0, 50.0, 0).unwrap();
        let (b, _) = RandomVibration::realise(&spec, 100.0, 50.0, 0).unwrap();
        assert_eq!(a, b);
        // components at k/100 Hz in [1, 20]: 1901
        assert_eq!(ra.components, 1901);
        let p = ra.accel.unwrap()[0];
        assert!((p.specified - 0.19).abs() < 1e-15);
        // rectangle rule over 1901 points of 0.01 Hz: 0.1901
        assert!((p.realised - 0.1901).abs() < 1e-14, "{}", p.realised);
        // realised power of the draws: Σ(a²+b²)/2 ~ P·χ²(2K)/(2K), σ = P/√K
        let (lin, _) = a.coefficient_power();
        for x in lin {
            assert!((x - 0.1901).abs() < 3.3 * 0.1901 / (1901f64).sqrt(), "{x}");
        }
        // the motion starts from rest
        let s = a.state(0.0, None);
        assert!(s.u.iter().all(|x| x.abs() < 1e-15));
    }
}

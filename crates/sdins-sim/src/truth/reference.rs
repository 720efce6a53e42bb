//! Recorded trajectories as exact truth: a C² interpolant of position and attitude
//! through the rows of a reference file, whose analytic derivatives drive the truth
//! generator (docs/theory/mechanizations.md §"Recorded trajectories").
//!
//! Six channels are interpolated: latitude, longitude, height and the ZYX Euler angles
//! roll, pitch, yaw (docs/conventions.md §"Euler angles"; longitude, roll and yaw are
//! unwrapped first). Each channel is a **quintic Hermite** interpolant: on
//! `[t_i, t_{i+1}]`, with `s = (t − t_i)/h`, the quintic that takes the knot values
//! `f_i, f_{i+1}`, first derivatives `m_i, m_{i+1}` and second derivatives `M_i, M_{i+1}`
//! (de Boor, *A Practical Guide to Splines*, ch. II, osculatory interpolation). The knot
//! derivatives are those of the degree-6 polynomial through the 7 nearest rows (Fornberg's
//! finite-difference weights on the actual, possibly uneven, times; Fornberg 1988,
//! *Math. Comp.* 51, 699–706): `m` to `O(h⁶)`, `M` to `O(h⁵)`. So the interpolant
//!
//! * passes through every row (by construction),
//! * is C² (value, rate and acceleration continuous; the third derivative jumps at the
//!   knots by `O(h³ f⁽⁶⁾)` for a smooth underlying motion),
//! * is local (a row influences only the six intervals around it; no global system, no
//!   ringing across the file, O(n) time and memory).
//!
//! Velocity and attitude rates follow exactly from the interpolant:
//! `v_N = (R_M + h) L̇`, `v_E = (R_N + h) cos L · λ̇`, `v_D = −ḣ` (Groves 2nd ed. eq. 2.111),
//! their derivatives with `dR_N/dL = R_N e² sin L cos L /(1 − e² sin²L)` and
//! `dR_M/dL = 3 R_M e² sin L cos L /(1 − e² sin²L)`, and
//! `ω_nb^b = [φ̇ − ψ̇ sin θ, θ̇ cos φ + ψ̇ cos θ sin φ, −θ̇ sin φ + ψ̇ cos θ cos φ]`
//! (Groves 2nd ed. eq. 2.58 inverted; Titterton & Weston eq. 3.15). Acceleration and
//! angular rate are continuous, so the increments of the generator (a quadrature that
//! splits its panels at the knots) are exact for this motion.

use crate::truth::trajectory::Kinematics;
use sdins_core::earth::EarthModel;
use sdins_core::math::{Euler, Vec3};
use std::f64::consts::PI;

/// Fewest rows a reference needs (the 7-point derivative stencil).
pub const MIN_ROWS: usize = 7;
/// Largest accepted |pitch| \[deg\]: the Euler-rate map is singular at ±90°.
pub const MAX_PITCH_DEG: f64 = 89.0;

/// One row of a recorded trajectory, in sdins conventions (NED, body FRD, ZYX Euler).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceSample {
    /// time \[s\]
    pub t_s: f64,
    /// latitude \[rad\]
    pub lat_rad: f64,
    /// longitude \[rad\]
    pub lon_rad: f64,
    /// height \[m\]
    pub h_m: f64,
    /// attitude body→NED as ZYX Euler angles
    pub euler: Euler,
    /// the file's own NED velocity, if it has one \[m/s\] (compared, not used)
    pub v_n_mps: Option<Vec3>,
}

/// Why a reference cannot be interpolated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ReferenceError {
    /// Fewer than [`MIN_ROWS`] rows.
    #[error("a reference trajectory needs at least {MIN_ROWS} rows, this one has {rows}")]
    TooFewRows {
        /// rows found
        rows: usize,
    },
    /// Times not strictly increasing.
    #[error("row {row} (1-based, data rows): time {t_s} s does not increase on the previous row's {prev_s} s")]
    NotIncreasing {
        /// data row, 1-based
        row: usize,
        /// its time \[s\]
        t_s: f64,
        /// the previous time \[s\]
        prev_s: f64,
    },
    /// A value is NaN or infinite.
    #[error("row {row} (1-based, data rows): {field} is not finite")]
    NotFinite {
        /// data row, 1-based
        row: usize,
        /// which value
        field: &'static str,
    },
    /// Pitch too close to ±90°.
    #[error("row {row} (1-based, data rows): pitch {pitch_deg:.3} deg is beyond ±{MAX_PITCH_DEG} deg, where the Euler-angle interpolant is singular")]
    Pitch {
        /// data row, 1-based
        row: usize,
        /// the pitch \[deg\]
        pitch_deg: f64,
    },
}

/// Weights of the derivatives 0..=2 at `z` of the polynomial through `x` (Fornberg 1988):
/// `f⁽ᵏ⁾(z) ≈ Σ_j w[k][j] f(x_j)`, exact for polynomials of degree < `x.len()`.
fn fornberg(z: f64, x: &[f64; 7]) -> [[f64; 7]; 3] {
    const M: usize = 2;
    let n = x.len();
    let mut c = [[0.0; 7]; 3];
    c[0][0] = 1.0;
    let mut c1 = 1.0;
    let mut c4 = x[0] - z;
    for i in 1..n {
        let mn = i.min(M);
        let mut c2 = 1.0;
        let c5 = c4;
        c4 = x[i] - z;
        for j in 0..i {
            let c3 = x[i] - x[j];
            c2 *= c3;
            if j == i - 1 {
                for k in (1..=mn).rev() {
                    c[k][i] = c1 * (k as f64 * c[k - 1][i - 1] - c5 * c[k][i - 1]) / c2;
                }
                c[0][i] = -c1 * c5 * c[0][i - 1] / c2;
            }
            for k in (1..=mn).rev() {
                c[k][j] = (c4 * c[k][j] - k as f64 * c[k - 1][j]) / c3;
            }
            c[0][j] = c4 * c[0][j] / c3;
        }
        c1 = c2;
    }
    c
}

/// One interpolated channel: knot values and first and second derivatives.
#[derive(Clone, Debug, PartialEq)]
struct Channel {
    f: Vec<f64>,
    d1: Vec<f64>,
    d2: Vec<f64>,
}

impl Channel {
    /// Knot derivatives from the 7 nearest knots (shifted inwards at the ends), with the
    /// times and values taken relative to the knot for accuracy.
    fn new(t: &[f64], f: Vec<f64>) -> Self {
        let n = t.len();
        let mut d1 = vec![0.0; n];
        let mut d2 = vec![0.0; n];
        for i in 0..n {
            let a = i.saturating_sub(3).min(n - 7);
            let mut x = [0.0; 7];
            for (j, xj) in x.iter_mut().enumerate() {
                *xj = t[a + j] - t[i];
            }
            let w = fornberg(0.0, &x);
            let (mut s1, mut s2) = (0.0, 0.0);
            for j in 0..7 {
                let df = f[a + j] - f[i];
                s1 += w[1][j] * df;
                s2 += w[2][j] * df;
            }
            d1[i] = s1;
            d2[i] = s2;
        }
        Self { f, d1, d2 }
    }

    /// Value and first two time derivatives on interval `i` at `tau = t − t_i`, `h` its length.
    #[inline]
    fn eval(&self, i: usize, tau: f64, h: f64) -> [f64; 3] {
        let (f0, f1) = (self.f[i], self.f[i + 1]);
        let (m0, m1) = (h * self.d1[i], h * self.d1[i + 1]);
        let (a0, a1) = (h * h * self.d2[i], h * h * self.d2[i + 1]);
        let df = f1 - f0;
        // p(s) = f0 + m0 s + a0/2 s² + c3 s³ + c4 s⁴ + c5 s⁵ with p, p', p'' at s = 1
        // equal to f1, m1, a1 (quintic Hermite)
        let c3 = 10.0 * df - 6.0 * m0 - 4.0 * m1 - 1.5 * a0 + 0.5 * a1;
        let c4 = -15.0 * df + 8.0 * m0 + 7.0 * m1 + 1.5 * a0 - a1;
        let c5 = 6.0 * df - 3.0 * m0 - 3.0 * m1 - 0.5 * a0 + 0.5 * a1;
        let s = tau / h;
        let p = m0 + s * (0.5 * a0 + s * (c3 + s * (c4 + s * c5)));
        let dp = m0 + s * (a0 + s * (3.0 * c3 + s * (4.0 * c4 + s * 5.0 * c5)));
        let ddp = a0 + s * (6.0 * c3 + s * (12.0 * c4 + s * 20.0 * c5));
        [f0 + s * p, dp / h, ddp / (h * h)]
    }
}

/// Unwrap an angle sequence in place (steps taken modulo 2π to (−π, π]).
fn unwrap(a: &mut [f64]) {
    for i in 1..a.len() {
        let d = a[i] - a[i - 1];
        let k = ((d + PI) / (2.0 * PI)).floor();
        if k != 0.0 {
            a[i] -= k * 2.0 * PI;
        }
    }
}

/// The file's own velocity against the interpolant's at the rows that have one.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VelocityComparison {
    /// rows compared
    pub rows: usize,
    /// largest |v_interp − v_file| \[m/s\]
    pub max_mps: f64,
    /// where the largest difference is (reference time) \[s\]
    pub t_max_s: f64,
    /// RMS of |v_interp − v_file| \[m/s\]
    pub rms_mps: f64,
}

/// Position and kinematics of the interpolant at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferencePoint {
    /// latitude \[rad\]
    pub lat_rad: f64,
    /// longitude \[rad\]
    pub lon_rad: f64,
    /// height \[m\]
    pub h_m: f64,
    /// velocity, acceleration, attitude, body rate
    pub kin: Kinematics,
}

/// The C² interpolant of a recorded trajectory (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceTrack {
    /// reference time of the first row \[s\]; the trajectory's time is `t − t0_s`
    t0_s: f64,
    /// knot times relative to `t0_s` \[s\]
    t: Vec<f64>,
    lat: Channel,
    lon: Channel,
    h: Channel,
    roll: Channel,
    pitch: Channel,
    yaw: Channel,
    a_m: f64,
    e2: f64,
    velocity: Option<VelocityComparison>,
}

impl ReferenceTrack {
    /// Interpolate `rows` (in time order) under `earth` (its radii turn the position rates
    /// into velocity; use the navigation's own model).
    pub fn new(rows: &[ReferenceSample], earth: &EarthModel) -> Result<Self, ReferenceError> {
        if rows.len() < MIN_ROWS {
            return Err(ReferenceError::TooFewRows { rows: rows.len() });
        }
        for (k, r) in rows.iter().enumerate() {
            let row = k + 1;
            for (v, field) in [
                (r.t_s, "time"),
                (r.lat_rad, "latitude"),
                (r.lon_rad, "longitude"),
                (r.h_m, "height"),
                (r.euler.roll_rad, "roll"),
                (r.euler.pitch_rad, "pitch"),
                (r.euler.yaw_rad, "yaw"),
            ] {
                if !v.is_finite() {
                    return Err(ReferenceError::NotFinite { row, field });
                }
            }
            if r.euler.pitch_rad.abs() > MAX_PITCH_DEG.to_radians() {
                return Err(ReferenceError::Pitch {
                    row,
                    pitch_deg: r.euler.pitch_rad.to_degrees(),
                });
            }
            if k > 0 && r.t_s <= rows[k - 1].t_s {
                return Err(ReferenceError::NotIncreasing {
                    row,
                    t_s: r.t_s,
                    prev_s: rows[k - 1].t_s,
                });
            }
        }
        let t0_s = rows[0].t_s;
        let t: Vec<f64> = rows.iter().map(|r| r.t_s - t0_s).collect();
        let col = |g: &dyn Fn(&ReferenceSample) -> f64, wrap: bool| {
            let mut v: Vec<f64> = rows.iter().map(g).collect();
            if wrap {
                unwrap(&mut v);
            }
            Channel::new(&t, v)
        };
        let mut track = Self {
            t0_s,
            lat: col(&|r| r.lat_rad, false),
            lon: col(&|r| r.lon_rad, true),
            h: col(&|r| r.h_m, false),
            roll: col(&|r| r.euler.roll_rad, true),
            pitch: col(&|r| r.euler.pitch_rad, false),
            yaw: col(&|r| r.euler.yaw_rad, true),
            t,
            a_m: earth.a_m,
            e2: earth.e2,
            velocity: None,
        };
        let mut cmp = VelocityComparison::default();
        let mut sum2 = 0.0;
        for (k, r) in rows.iter().enumerate() {
            let Some(v) = r.v_n_mps else { continue };
            if !v.iter().all(|x| x.is_finite()) {
                return Err(ReferenceError::NotFinite {
                    row: k + 1,
                    field: "velocity",
                });
            }
            let d = (track.at(track.t[k], track.t[k]).kin.v_n_mps - v).norm();
            cmp.rows += 1;
            sum2 += d * d;
            if d > cmp.max_mps {
                cmp.max_mps = d;
                cmp.t_max_s = r.t_s;
            }
        }
        if cmp.rows > 0 {
            cmp.rms_mps = (sum2 / cmp.rows as f64).sqrt();
            track.velocity = Some(cmp);
        }
        Ok(track)
    }

    /// Reference time of the first row \[s\] (trajectory time 0).
    pub fn t0_s(&self) -> f64 {
        self.t0_s
    }

    /// Duration from the first to the last row \[s\].
    pub fn duration_s(&self) -> f64 {
        self.t.last().copied().unwrap_or(0.0)
    }

    /// Knot times relative to the first row \[s\].
    pub fn knots(&self) -> &[f64] {
        &self.t
    }

    /// The file's velocity against the interpolant's (`None`: the file has none).
    pub fn velocity_comparison(&self) -> Option<VelocityComparison> {
        self.velocity
    }

    /// The shortest step between two rows \[s\].
    pub fn min_step_s(&self) -> f64 {
        self.t
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min)
    }

    /// Interval whose branch `t_sel` selects (clamped to the first and last).
    #[inline]
    fn interval(&self, t_sel: f64) -> usize {
        let n = self.t.len();
        self.t.partition_point(|&x| x <= t_sel).clamp(1, n - 1) - 1
    }

    /// Position and exact kinematics at trajectory time `t`, on the interval that `t_sel`
    /// selects (the module documentation gives the equations).
    pub fn at(&self, t: f64, t_sel: f64) -> ReferencePoint {
        self.at_split(t, 0.0, t_sel)
    }

    /// [`ReferenceTrack::at`] at `t_base + off`, with the time into the row formed as
    /// `(t_base − t_i) + off`: a sample's node times `t_base + off` would be rounded to the
    /// ulp of `t` (7e-15 s at 59 s), which where a row turns a rate step (ω̇ ≈ 80 rad/s²)
    /// puts ~3e-16 rad of time-quantisation noise on an increment.
    pub fn at_split(&self, t_base: f64, off: f64, t_sel: f64) -> ReferencePoint {
        let i = self.interval(t_sel);
        let (tau, hk) = ((t_base - self.t[i]) + off, self.t[i + 1] - self.t[i]);
        let [lat, lat1, lat2] = self.lat.eval(i, tau, hk);
        let [lon, lon1, lon2] = self.lon.eval(i, tau, hk);
        let [h, h1, h2] = self.h.eval(i, tau, hk);
        let [r, r1, _] = self.roll.eval(i, tau, hk);
        let [p, p1, _] = self.pitch.eval(i, tau, hk);
        let [y, y1, _] = self.yaw.eval(i, tau, hk);
        let (sl, cl) = libm::sincos(lat);
        let w2 = 1.0 - self.e2 * sl * sl;
        let r_n = self.a_m / libm::sqrt(w2);
        let r_m = r_n * (1.0 - self.e2) / w2;
        let k = self.e2 * sl * cl / w2;
        let (dr_n, dr_m) = (r_n * k, 3.0 * r_m * k);
        let v = Vec3::new((r_m + h) * lat1, (r_n + h) * cl * lon1, -h1);
        let v_dot = Vec3::new(
            (dr_m * lat1 + h1) * lat1 + (r_m + h) * lat2,
            (dr_n * lat1 + h1) * cl * lon1 - (r_n + h) * sl * lat1 * lon1 + (r_n + h) * cl * lon2,
            -h2,
        );
        let (sr, cr) = libm::sincos(r);
        let (sp, cp) = libm::sincos(p);
        let c_b_n = sdins_core::math::c_b_n_from_sin_cos((sr, cr), (sp, cp), libm::sincos(y));
        let w = Vec3::new(
            r1 - y1 * sp,
            p1 * cr + y1 * cp * sr,
            -p1 * sr + y1 * cp * cr,
        );
        ReferencePoint {
            lat_rad: lat,
            lon_rad: lon,
            h_m: h,
            kin: Kinematics {
                v_n_mps: v,
                v_dot_n_mps2: v_dot,
                c_b_n,
                omega_nb_b_rps: w,
            },
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn fornberg_is_exact_for_degree_six() {
        let x = [-0.3, -0.2, -0.1, 0.0, 0.1, 0.25, 0.4];
        let w = fornberg(0.0, &x);
        // f = 1 + 2x + 3x² + x⁶: f(0) = 1, f'(0) = 2, f''(0) = 6
        let f = |x: f64| 1.0 + 2.0 * x + 3.0 * x * x + x.powi(6);
        let d: Vec<f64> = (0..3)
            .map(|k| (0..7).map(|j| w[k][j] * f(x[j])).sum())
            .collect();
        assert!((d[0] - 1.0).abs() < 1e-14);
        assert!((d[1] - 2.0).abs() < 1e-11);
        assert!((d[2] - 6.0).abs() < 1e-9);
    }

    /// A quintic is reproduced exactly (value, rate, acceleration) between the knots on an
    /// uneven grid: the stencil is exact for degree ≤ 6 and the Hermite quintic for degree 5.
    #[test]
    fn channel_reproduces_a_quintic() {
        let t: Vec<f64> = (0..20)
            .map(|i| i as f64 * 0.1 + 0.013 * (i % 3) as f64)
            .collect();
        let p = |x: f64| {
            [
                0.5 - x + 0.3 * x.powi(3) - 0.02 * x.powi(5),
                -1.0 + 0.9 * x * x - 0.1 * x.powi(4),
                1.8 * x - 0.4 * x.powi(3),
            ]
        };
        let ch = Channel::new(&t, t.iter().map(|&x| p(x)[0]).collect());
        for i in 0..t.len() - 1 {
            let h = t[i + 1] - t[i];
            for s in [0.0, 0.3, 0.77, 1.0] {
                let x = t[i] + s * h;
                let e = ch.eval(i, s * h, h);
                let q = p(x);
                assert!((e[0] - q[0]).abs() < 1e-13, "{i} {s}");
                assert!((e[1] - q[1]).abs() < 1e-10, "{i} {s} {} {}", e[1], q[1]);
                assert!((e[2] - q[2]).abs() < 1e-7, "{i} {s} {} {}", e[2], q[2]);
            }
        }
    }

    /// C²: value, rate and acceleration agree across a knot from both sides for a
    /// non-polynomial signal.
    #[test]
    fn channel_is_c2_at_knots() {
        let t: Vec<f64> = (0..30).map(|i| i as f64 * 0.05).collect();
        let ch = Channel::new(&t, t.iter().map(|&x| (3.0 * x).sin() + x.exp()).collect());
        for i in 1..t.len() - 1 {
            let (hl, hr) = (t[i] - t[i - 1], t[i + 1] - t[i]);
            let l = ch.eval(i - 1, hl, hl);
            let r = ch.eval(i, 0.0, hr);
            for k in 0..3 {
                assert!((l[k] - r[k]).abs() <= 1e-12 * (1.0 + r[k].abs()), "{i} {k}");
            }
        }
    }

    #[test]
    fn unwrap_removes_jumps() {
        let mut a = [3.1, -3.1, -3.0, 3.0, 0.1];
        unwrap(&mut a);
        for w in a.windows(2) {
            assert!((w[1] - w[0]).abs() < PI);
        }
        assert!((a[1] - (2.0 * PI - 3.1)).abs() < 1e-15);
    }

    #[test]
    fn rejects_bad_rows() {
        let e = EarthModel::WGS84;
        let row = |t: f64| ReferenceSample {
            t_s: t,
            lat_rad: 0.5,
            lon_rad: 1.0,
            h_m: 0.0,
            euler: Euler::new(0.0, 0.0, 0.0),
            v_n_mps: None,
        };
        let mut rows: Vec<_> = (0..8).map(|i| row(i as f64)).collect();
        assert!(ReferenceTrack::new(&rows[..5], &e).is_err());
        rows[4].t_s = 3.0;
        assert_eq!(
            ReferenceTrack::new(&rows, &e),
            Err(ReferenceError::NotIncreasing {
                row: 5,
                t_s: 3.0,
                prev_s: 3.0
            })
        );
        rows[4].t_s = 4.0;
        rows[2].euler.pitch_rad = 1.56;
        assert!(matches!(
            ReferenceTrack::new(&rows, &e),
            Err(ReferenceError::Pitch { row: 3, .. })
        ));
        rows[2].euler.pitch_rad = 0.0;
        rows[6].h_m = f64::NAN;
        assert!(matches!(
            ReferenceTrack::new(&rows, &e),
            Err(ReferenceError::NotFinite { row: 7, .. })
        ));
        rows[6].h_m = 0.0;
        assert!(ReferenceTrack::new(&rows, &e).is_ok());
    }

    /// The interpolant's velocity is the derivative of its position: a finite difference
    /// of `at(...)` positions matches `v_n` (consistency of the radii terms).
    #[test]
    fn velocity_is_the_position_rate() {
        let e = EarthModel::WGS84;
        let rows: Vec<_> = (0..40)
            .map(|i| {
                let t = i as f64 * 0.1;
                ReferenceSample {
                    t_s: 100.0 + t,
                    lat_rad: 0.6 + 1e-5 * (0.7 * t).sin(),
                    lon_rad: 2.0 + 2e-5 * t + 1e-6 * t * t,
                    h_m: 50.0 + 3.0 * (0.4 * t).cos(),
                    euler: Euler::new(0.1 * (0.5 * t).sin(), 0.05 * t.cos(), 0.3 * t),
                    v_n_mps: None,
                }
            })
            .collect();
        let tr = ReferenceTrack::new(&rows, &e).unwrap();
        assert_eq!(tr.t0_s(), 100.0);
        // central differences of step dt: truncation dt²/6·|x⃛| (|v⃛| ≈ 22 m/s⁴ here: 4e-6
        // m/s) against the rounding ulp(L)/(2dt)·R ≈ 4e-7 m/s
        let dt = 1e-3;
        for t in [0.55, 1.33, 2.02, 3.7] {
            let a = tr.at(t - dt, t);
            let b = tr.at(t + dt, t);
            let m = tr.at(t, t);
            let le = e.radii(m.lat_rad);
            let v_fd = Vec3::new(
                (b.lat_rad - a.lat_rad) / (2.0 * dt) * (le.r_m_m + m.h_m),
                (b.lon_rad - a.lon_rad) / (2.0 * dt) * (le.r_n_m + m.h_m) * m.lat_rad.cos(),
                -(b.h_m - a.h_m) / (2.0 * dt),
            );
            assert!((v_fd - m.kin.v_n_mps).norm() < 1e-5, "{t}");
            let a_fd = (b.kin.v_n_mps - a.kin.v_n_mps) / (2.0 * dt);
            assert!((a_fd - m.kin.v_dot_n_mps2).norm() < 1e-5, "{t}");
            // ω_nb^b against the attitude difference: C(t−)ᵀC(t+) ≈ I + [ω×]·2dt
            let d = a.kin.c_b_n.transpose() * b.kin.c_b_n;
            let w_fd = Vec3::new(
                d[(2, 1)] - d[(1, 2)],
                d[(0, 2)] - d[(2, 0)],
                d[(1, 0)] - d[(0, 1)],
            ) / (4.0 * dt);
            assert!((w_fd - m.kin.omega_nb_b_rps).norm() < 1e-6, "{t}");
        }
    }
}

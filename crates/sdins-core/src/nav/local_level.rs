//! Local-level (NED) mechanizations: Savage baseline (SAV), Song–Lee paper mode (SL)
//! and Song–Lee complete (SLC) (docs/theory/mechanizations.md
//! §"Song–Lee three-sample local-level algorithm").
//!
//! Computation order per update (S1 §IV, docs/theory/mechanizations.md §"Order per update"):
//! velocity, then position, then attitude; every rate term is evaluated at t_{k−1}.

use super::{wrap_pi, InitialState, Mechanization, NavState};
use crate::coning::{compensate, ConingSet, Increment};
use crate::earth::{sin_cos_step, EarthCoeffs, EarthModel, SinCosTrack};
use crate::math::{Quat, Vec3};

/// Velocity-update formula (docs/theory/mechanizations.md §"Velocity").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VelocityMode {
    /// `v_k = v_{k−1} + C(Δv + ½Δθ×Δv + ΔV_scul) + ΔT[g − (2ω_ie + ω_en)×v_{k−1}]`
    Savage,
    /// SL: Savage's terms (with ½Δφ×Δv) plus S1's (29), (19), (17), signs corrected:
    /// `− (ΔT/2)[(3ω_ie + 2ω_en)×](CΔv) − (ΔT²/2)(2ω_ie + ω_en)×g`
    SongLee,
    /// SLC: SL plus the second-order homogeneous term `+ (ΔT²/2) W×(W×v_{k−1})`, W = 2ω_ie + ω_en
    SongLeeComplete,
}

/// Attitude-update formula (docs/theory/mechanizations.md §"Attitude by DCM separation";
/// docs/theory/mechanizations.md §"Order per update").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AttitudeMode {
    /// S1 eq. (6)/(32): gyro-only quaternion `Q_k = Q_{k−1} ⊗ q(Δφ)`, `C_b^n = T(L, l, t) C(Q)`
    Transport,
    /// S1 eq. (5) method: n-relative increments `Δθ_j − C_n^b ω_in ΔT/N`, then coning
    Five,
    /// Savage Part 1: `q_k = q(−ζ) ⊗ q_{k−1} ⊗ q(Δφ)`, `ζ = (ω_ie + ω_en)_{k−1} ΔT`
    Savage,
}

/// Which rotation vector the rotation compensation `½ x × Δv` uses (docs/theory/coning-sculling.md
/// §"Coning and sculling").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RotVector {
    /// `½ Δθ × Δv`, Savage's `α_m × υ_m` (the summed gyro increment)
    Theta,
    /// `½ Δφ × Δv`, S1 eq. (30) (the coning-compensated rotation vector). Differs from
    /// `Theta` by O(ΔT³)·coning; under 1 Hz coning (docs/validation.md
    /// §"dual-quaternion paper case") it is the more exact one (closer to the dual-quaternion screw
    /// exponential, which contains it).
    Phi,
}

/// Configuration of a [`LocalLevel`] mechanization.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalLevelConfig {
    /// velocity formula
    pub velocity: VelocityMode,
    /// attitude formula
    pub attitude: AttitudeMode,
    /// coning/sculling coefficient set
    pub coning: ConingSet,
    /// samples per update N
    pub samples: usize,
    /// rotation vector of the rotation compensation
    pub rot_vector: RotVector,
    /// evaluate ω_ie, ω_en and g of the velocity update at the interval midpoint,
    /// extrapolated linearly from the last two updates (`1.5 x_{k−1} − 0.5 x_{k−2}`).
    /// Holding them at t_{k−1} (S1, Savage baseline) leaves a per-step error
    /// `½ΔT² Ȧ v`, i.e. first order globally; near the poles Ȧ is large (tanL grows with
    /// the northward motion) and this dominates. Used by `songlee-complete`.
    pub midpoint_rates: bool,
    /// third-order rotation compensation `+ (1/6) Δφ×(Δφ×Δv)` (docs/theory/coning-sculling.md
    /// §"Coning and sculling")
    pub rot3: bool,
    /// earth model (must equal the truth's)
    pub earth: EarthModel,
    /// sensor sample period δt \[s\]
    pub dt_s: f64,
}

/// Local-level NED strapdown mechanization (SAV, SL, SLC).
///
/// Cost notes (docs/performance.md §"The navigation update near its instruction floor"): the update calls no libm
/// function and builds no matrix product.
/// * The transport matrix of S1 eq. (32) factors into elementary rotations,
///   `T = R_y(L) R_x(−Δ) R_y(−L0)` with `Δ = Δλ + Ω_e t` (so `T(0) = I`), and the
///   Transport attitude keeps `P = q_y(−L0) ⊗ Q_b^{n0ⁱ}` instead of `Q_b^{n0ⁱ}`: the gyro
///   update `P_k = P_{k−1} ⊗ q(Δφ)` is the same right product, and
///   `q_b^n = q_y(L) ⊗ q_x(−Δ) ⊗ P`, two sparse products before the one quaternion → DCM.
/// * The sines and cosines of `L/2` and `Δ/2` are [`SinCosTrack`]s (one series shift from
///   a libm reference, ≈ 1 ulp, a new reference every 1e-4 rad); `sin L = 2 s c`,
///   `cos L = (c − s)(c + s)` from the half angle (an error equivalent to one ulp of L).
///   `sin/cos L_k` of the end of an update are the `sin/cos L_{k−1}` of the next.
/// * The quaternion is renormalized by a Newton step ([`Quat::renormalized`]) and `q(Δφ)`
///   is a series below 1e-2 rad ([`Quat::from_rotvec`]).
/// * The three algorithms with their default options (`savage`, `songlee`,
///   `songlee-complete`) run an instance of the update with the options as constants
///   (no branch on them); any other combination runs the general instance.
///
/// The equations and their order are those of the papers; only the rounding differs from
/// evaluating every trigonometric term by libm and T as a matrix.
#[derive(Clone, Debug)]
pub struct LocalLevel {
    cfg: LocalLevelConfig,
    /// the earth model's constant factors
    earth: EarthCoeffs,
    /// which instance of the update runs (see [`Shape`])
    shape: u8,
    /// which coning instance [`Mechanization::update_many`] runs (see [`Shape::coning`])
    coning_shape: u8,
    dt_update_s: f64,
    // position carried as offsets from the start (docs/theory/mechanizations.md §"Position"
    // roundoff recommendation)
    lat0_rad: f64,
    lon0_rad: f64,
    s_lat0: f64,
    c_lat0: f64,
    /// sin, cos of L0/2
    s_half_lat0: f64,
    c_half_lat0: f64,
    dlat_rad: f64,
    dlon_rad: f64,
    /// Transport mode: `P = q_y(−L0) ⊗ Q_b^{n0ⁱ}` (the gyro-only quaternion of S1 eq. 6
    /// referred to the start's earth axes); Five, Savage modes: q_b^n
    q: Quat,
    /// updates until the next renormalization of `q`
    renorm_in: u8,
    /// the state: time, position (from the offsets), height, velocity, attitude, kept as
    /// the value [`Mechanization::state`] returns (one copy per hand-off)
    out: NavState,
    /// updates done, as a float (exact below 2⁵³)
    updates: f64,
    prev: Increment,
    /// ω_ie, ω_en, g at t_{k−2} (for midpoint extrapolation)
    rates_prev: Rates,
    /// whether `rates_prev` holds an epoch yet
    has_rates_prev: bool,
    /// sin L, cos L of the current latitude `lat0 + dlat`
    sin_lat: f64,
    cos_lat: f64,
    /// sin/cos of half the latitude, `(lat0 + dlat)/2`
    half_lat: SinCosTrack,
    /// sin/cos of half the transport angle, `(Δλ + Ω_e t)/2`
    half_delta: SinCosTrack,
}

/// Updates between two renormalizations of the attitude quaternion.
///
/// Error bound. Each component of a Hamilton product `a ⊗ b` is a 4-term dot product of `a`
/// with a signed permutation of `b`, so its rounding error is ≤ γ₄|a||b| (γ₄ = 4u/(1 − 4u)
/// ≈ 4.4e-16, u = 2⁻⁵³) and the norm of the product moves by ≤ 2γ₄ ≈ 8.9e-16; `q(Δφ)` is
/// unit to ≤ 3e-16 and [`Quat::renormalized`] leaves `|q|² − 1` at rounding (≤ 4u). One
/// product and one `q(Δφ)` per update for the transport and five-rate attitudes (≤ 1.2e-15
/// per update), two of each for savage's (≤ 2.4e-15), so after the 8 updates of one period
/// `||q| − 1| ≤ 8·2.4e-15 + 4.4e-16 ≈ 2e-14` at worst; observed: < 1e-15 over 200 000
/// updates (it random-walks; tested). The DCM `to_dcm` gives is the homogeneous quadratic
/// form, i.e. exactly `|q|²` times a rotation: the velocity increment `C Δv` is scaled by
/// ≤ 4e-14 of itself (at 1 g ≤ 4e-13 m/s²: 1.4e-9 m/s and 2.6e-6 m after an hour even if
/// it never changed sign), and the attitude error (the antisymmetric part of `C C_trueᵀ`)
/// not at all. `state()`'s `c_b_n` is orthonormal to ≤ 4e-14.
const RENORM_EVERY: u8 = 8;

/// The options that select branches of the update, as constants of an instance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Shape {
    velocity: VelocityMode,
    attitude: AttitudeMode,
    rot_vector: RotVector,
    rot3: bool,
    midpoint_rates: bool,
}

impl Shape {
    /// Instance numbers (the const parameter of `LocalLevel::step`).
    const GENERAL: u8 = 0;
    const SLC: u8 = 1;
    const SL: u8 = 2;
    const SAV: u8 = 3;

    /// `songlee-complete` with its default options.
    const SONG_LEE_COMPLETE: Shape = Shape {
        velocity: VelocityMode::SongLeeComplete,
        attitude: AttitudeMode::Transport,
        rot_vector: RotVector::Phi,
        rot3: true,
        midpoint_rates: true,
    };
    /// `songlee` with its default options.
    const SONG_LEE: Shape = Shape {
        velocity: VelocityMode::SongLee,
        attitude: AttitudeMode::Transport,
        rot_vector: RotVector::Phi,
        rot3: false,
        midpoint_rates: false,
    };
    /// `savage` with its default options.
    const SAVAGE: Shape = Shape {
        velocity: VelocityMode::Savage,
        attitude: AttitudeMode::Savage,
        rot_vector: RotVector::Theta,
        rot3: false,
        midpoint_rates: false,
    };

    fn of(cfg: &LocalLevelConfig) -> Shape {
        Shape {
            velocity: cfg.velocity,
            attitude: cfg.attitude,
            rot_vector: cfg.rot_vector,
            rot3: cfg.rot3,
            midpoint_rates: cfg.midpoint_rates,
        }
    }

    /// The instance that runs `cfg` (the dedicated ones assume the transport rate, i.e.
    /// not the flat model).
    fn instance(cfg: &LocalLevelConfig) -> u8 {
        match Shape::of(cfg) {
            _ if !cfg.earth.transport => Shape::GENERAL,
            s if s == Shape::SONG_LEE_COMPLETE => Shape::SLC,
            s if s == Shape::SONG_LEE => Shape::SL,
            s if s == Shape::SAVAGE => Shape::SAV,
            _ => Shape::GENERAL,
        }
    }

    /// Coning instances of the batch update: the set as a constant for the defaults of
    /// N = 1 (`1prev`) and N = 3 (`three_poly`), else read from the configuration.
    const CONING_ANY: u8 = 0;
    const CONING_1PREV: u8 = 1;
    const CONING_THREE_POLY: u8 = 3;

    fn coning(cfg: &LocalLevelConfig) -> u8 {
        match (cfg.coning, cfg.samples) {
            (ConingSet::OnePrev, 1) => Shape::CONING_1PREV,
            (ConingSet::ThreePoly, 3) => Shape::CONING_THREE_POLY,
            _ => Shape::CONING_ANY,
        }
    }

    /// The coning set of coning instance `K`.
    #[inline(always)]
    fn coning_set<const K: u8>(cfg: &LocalLevelConfig) -> ConingSet {
        match K {
            Shape::CONING_1PREV => ConingSet::OnePrev,
            Shape::CONING_THREE_POLY => ConingSet::ThreePoly,
            _ => cfg.coning,
        }
    }

    /// The shape of instance `S` (a constant unless `S` is the general instance).
    #[inline(always)]
    fn get<const S: u8>(cfg: &LocalLevelConfig) -> Shape {
        match S {
            Shape::SLC => Shape::SONG_LEE_COMPLETE,
            Shape::SL => Shape::SONG_LEE,
            Shape::SAV => Shape::SAVAGE,
            _ => Shape::of(cfg),
        }
    }
}

/// The rate terms of the velocity update at one epoch: `ω_ie^n = [Ω cos L, 0, −Ω sin L]`,
/// `ω_en^n`, `g`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Rates {
    /// ω_ie^n north component \[rad/s\]
    w_ie_n: f64,
    /// ω_ie^n down component \[rad/s\]
    w_ie_d: f64,
    w_en: Vec3,
    g_mps2: f64,
}

impl Rates {
    /// `1.5 self − 0.5 prev`: the midpoint of the coming interval by linear extrapolation.
    #[inline(always)]
    fn extrapolate(&self, prev: &Rates) -> Rates {
        Rates {
            w_ie_n: 1.5 * self.w_ie_n - 0.5 * prev.w_ie_n,
            w_ie_d: 1.5 * self.w_ie_d - 0.5 * prev.w_ie_d,
            w_en: 1.5 * self.w_en - 0.5 * prev.w_en,
            g_mps2: 1.5 * self.g_mps2 - 0.5 * prev.g_mps2,
        }
    }
}

/// `q_y(θ) ⊗ p` with `q_y(θ) = [cos θ/2, 0, sin θ/2, 0]` (rotation by θ about y), from
/// `s = sin θ/2`, `c = cos θ/2`.
#[inline(always)]
fn y_mul(s: f64, c: f64, p: &Quat) -> Quat {
    Quat::new(
        c * p.w - s * p.y,
        c * p.x + s * p.z,
        c * p.y + s * p.w,
        c * p.z - s * p.x,
    )
}

/// `q_x(θ) ⊗ p` with `q_x(θ) = [cos θ/2, sin θ/2, 0, 0]`, from `s = sin θ/2`, `c = cos θ/2`.
#[inline(always)]
fn x_mul(s: f64, c: f64, p: &Quat) -> Quat {
    Quat::new(
        c * p.w - s * p.x,
        c * p.x + s * p.w,
        c * p.y - s * p.z,
        c * p.z + s * p.y,
    )
}

/// `sin L`, `cos L` from `s = sin L/2`, `c = cos L/2`.
#[inline(always)]
fn full_angle(s: f64, c: f64) -> (f64, f64) {
    (2.0 * s * c, (c - s) * (c + s))
}

impl LocalLevel {
    /// Initialise at t = 0 from the given state.
    pub fn new(cfg: LocalLevelConfig, init: &InitialState) -> Self {
        let q = Quat::from_dcm(&init.c_b_n);
        let half_lat = SinCosTrack::new(0.5 * init.lat_rad, 0.0);
        let (s_half_lat0, c_half_lat0) = half_lat.sin_cos_ref();
        let (sin_lat, cos_lat) = (libm::sin(init.lat_rad), libm::cos(init.lat_rad));
        let q_state = match cfg.attitude {
            AttitudeMode::Transport => y_mul(-s_half_lat0, c_half_lat0, &q),
            AttitudeMode::Savage | AttitudeMode::Five => q,
        };
        Self {
            shape: Shape::instance(&cfg),
            coning_shape: Shape::coning(&cfg),
            earth: cfg.earth.coeffs(),
            dt_update_s: cfg.dt_s * cfg.samples as f64,
            cfg,
            lat0_rad: init.lat_rad,
            lon0_rad: init.lon_rad,
            s_lat0: sin_lat,
            c_lat0: cos_lat,
            s_half_lat0,
            c_half_lat0,
            dlat_rad: 0.0,
            dlon_rad: 0.0,
            q: q_state,
            renorm_in: RENORM_EVERY,
            out: NavState {
                t_s: 0.0,
                lat_rad: init.lat_rad,
                lon_rad: wrap_pi(init.lon_rad),
                h_m: init.h_m,
                v_n_mps: init.v_n_mps,
                c_b_n: q.to_dcm(),
            },
            updates: 0.0,
            prev: Increment::default(),
            rates_prev: Rates::default(),
            has_rates_prev: false,
            sin_lat,
            cos_lat,
            half_lat,
            half_delta: SinCosTrack::new(0.0, 0.0),
        }
    }

    /// The configuration.
    pub fn config(&self) -> &LocalLevelConfig {
        &self.cfg
    }

    #[inline]
    fn lat(&self) -> f64 {
        self.lat0_rad + self.dlat_rad
    }

    /// `q`, renormalized ([`Quat::renormalized`]) every [`RENORM_EVERY`] updates.
    /// (`countdown` is `renorm_in`.)
    #[inline(always)]
    fn renorm(countdown: &mut u8, q: Quat) -> Quat {
        *countdown -= 1;
        if *countdown == 0 {
            *countdown = RENORM_EVERY;
            q.renormalized()
        } else {
            q
        }
    }

    /// `sin/cos` of half the transport angle, `(Δλ + Ω_e t)/2` (S1 eq. 32; on the flat model
    /// without transport `Ω_e t`).
    #[inline]
    fn half_delta(&mut self, transport: bool, dlon_rad: f64, t_s: f64) -> (f64, f64) {
        let e = &self.cfg.earth;
        let delta = if transport {
            dlon_rad + e.omega_ie_rps * t_s
        } else {
            e.omega_ie_rps * t_s
        };
        self.half_delta.sin_cos(0.5 * delta)
    }

    /// [`Mechanization::update_many`] with instances `S`, `K` (the dispatch once per call).
    #[inline(never)]
    fn steps<const S: u8, const K: u8>(
        &mut self,
        samples: &[Increment],
        states: &mut [NavState],
    ) -> usize {
        // N as a constant where the coning instance fixes it (its instance requires it)
        let n = match K {
            Shape::CONING_1PREV => 1,
            Shape::CONING_THREE_POLY => 3,
            _ => self.cfg.samples.max(1),
        };
        let m = (samples.len() / n).min(states.len());
        let mut chunks = samples.chunks_exact(n);
        let (Some(first), Some(slot0)) = (chunks.next(), states.first_mut()) else {
            return 0;
        };
        let cur = self.out;
        *slot0 = self.step::<S, K>(first, &cur);
        // the state of update k is read from slot k − 1 and written into slot k (not via
        // `out`: one copy of the 128-byte state less per update)
        for (k, chunk) in (1..m).zip(chunks) {
            let (done, rest) = states.split_at_mut(k);
            rest[0] = self.step::<S, K>(chunk, &done[k - 1]);
        }
        self.out = states[m - 1];
        m
    }

    /// One update (see [`Mechanization::update`]) from the state `cur` (height, velocity
    /// and attitude are read from it, the rest of the state is `self`'s); returns the new
    /// state. `S` and `K` are the instances of [`Shape`] (options, coning set).
    #[inline(always)]
    fn step<const S: u8, const K: u8>(
        &mut self,
        samples: &[Increment],
        cur: &NavState,
    ) -> NavState {
        let shape = Shape::get::<S>(&self.cfg);
        // the dedicated instances run with the transport rate only
        let transport = S != Shape::GENERAL || self.cfg.earth.transport;
        let n = self.cfg.samples.min(samples.len());
        // (the coning instances are run with chunks of exactly N samples)
        let samples = match K {
            Shape::CONING_ANY => &samples[..n],
            _ => samples,
        };
        let e = &self.cfg.earth;
        let dt = self.dt_update_s;
        let (s_lat, c_lat) = (self.sin_lat, self.cos_lat);
        let h = cur.h_m;
        let v = cur.v_n_mps;

        // 1.–2. increments and rates at t_{k−1}
        let comp = compensate(Shape::coning_set::<K>(&self.cfg), samples, &self.prev);
        if shape.attitude == AttitudeMode::Transport {
            // the gyro-only part of the attitude (step 5 below) needs nothing else: done
            // here, it does not keep Δφ through the velocity and position updates
            self.q = Self::renorm(
                &mut self.renorm_in,
                self.q.mul(&Quat::from_rotvec(&comp.dphi_b_rad)),
            );
        }
        let ec = &self.earth;
        let le = ec.local_sc(s_lat, c_lat, h);
        // ω_en^n = [v_E/(R_N+h), −v_N/(R_M+h), −v_E tan L/(R_N+h)] (EarthModel::omega_en_n)
        //  (v_E tan L/(R_N+h) as (v_E/(R_N+h)) tan L: one division less, ≤ 1 ulp apart)
        let w_en = if transport {
            let rn = le.r_n_m + h;
            let ve_rn = v.y / rn;
            Vec3::new(ve_rn, -v.x / (le.r_m_m + h), -ve_rn * (s_lat / c_lat))
        } else {
            Vec3::zeros()
        };
        let now = Rates {
            w_ie_n: e.omega_ie_rps * c_lat,
            w_ie_d: -e.omega_ie_rps * s_lat,
            w_en,
            g_mps2: le.g_mps2,
        };
        let r = if shape.midpoint_rates && self.has_rates_prev {
            now.extrapolate(&self.rates_prev)
        } else {
            now
        };
        if shape.midpoint_rates {
            self.rates_prev = now;
            self.has_rates_prev = true;
        }
        // ω_in = ω_ie + ω_en and the Coriolis rate W = 2ω_ie + ω_en
        let w_in = Vec3::new(r.w_ie_n + r.w_en.x, r.w_en.y, r.w_ie_d + r.w_en.z);
        let w_cor = Vec3::new(
            2.0 * r.w_ie_n + r.w_en.x,
            r.w_en.y,
            2.0 * r.w_ie_d + r.w_en.z,
        );

        // 3. velocity. With u = g − W×v_{k−1} (the rate of the homogeneous part):
        //    v_k = v_{k−1} + CΔv + C(½x×Δv [+ (1/6)x×(x×Δv)] + ΔV_scul) + ΔT u   (Savage)
        //    SL adds −(ΔT/2)(ω_in + W)×(CΔv) (S1 29 + 19) and −(ΔT²/2) W×g (S1 17);
        //    SLC also +(ΔT²/2) W×(W×v_{k−1}); together −(ΔT²/2) W×u.
        let x = match shape.rot_vector {
            RotVector::Theta => comp.dtheta_b_rad,
            RotVector::Phi => comp.dphi_b_rad,
        };
        let dv_b = comp.dv_b_mps;
        let x_dv = x.cross(&dv_b);
        let mut dv_rot = 0.5 * x_dv + comp.dv_scul_b_mps;
        if shape.rot3 {
            dv_rot += x.cross(&x_dv) * (1.0 / 6.0);
        }
        let c = &cur.c_b_n;
        let c_dv = c * dv_b;
        let u = Vec3::new(0.0, 0.0, r.g_mps2) - w_cor.cross(&v);
        let mut v_new = v + c_dv + c * dv_rot + dt * u;
        match shape.velocity {
            VelocityMode::Savage => {}
            VelocityMode::SongLee => {
                // W×g with g = [0, 0, g]
                let w_x_g = Vec3::new(w_cor.y * r.g_mps2, -w_cor.x * r.g_mps2, 0.0);
                v_new -= (0.5 * dt) * ((w_in + w_cor).cross(&c_dv) + dt * w_x_g);
            }
            VelocityMode::SongLeeComplete => {
                v_new -= (0.5 * dt) * ((w_in + w_cor).cross(&c_dv) + dt * w_cor.cross(&u));
            }
        }

        // 4. position, trapezoid with a latitude predictor (docs/theory/mechanizations.md
        //    §"Position"). sin/cos of the predicted and the mean latitude are shifted from
        //    sin/cos L_{k−1} ([`sin_cos_step`]).
        let h_new = h - 0.5 * (v.z + v_new.z) * dt;
        let h_bar = 0.5 * (h + h_new);
        let vn_bar = 0.5 * (v.x + v_new.x);
        let ve_bar = 0.5 * (v.y + v_new.y);
        //    The radii are those of the predicted midpoint; the corrected one is
        //    δ = ½(step − pred_step) away (δ ≈ 0.005 step², 5e-17 rad at Mach 1 north and
        //    6 ms, 5e-15 rad at 6 m per update), which moves R_N by e² sinL cosL δ (< 2e-17
        //    of it) and enters cos L̄ to first order.
        let (dlat_step, r_n_bar, c_bar) = if transport {
            let pred_step = vn_bar * dt / (le.r_m_m + h_bar);
            let (s_m, c_m) = sin_cos_step(s_lat, c_lat, 0.5 * pred_step);
            let r_mid = ec.radii_sin(s_m);
            let step = vn_bar * dt / (r_mid.r_m_m + h_bar);
            (step, r_mid.r_n_m, c_m - s_m * (0.5 * (step - pred_step)))
        } else {
            let (s0, c0) = (self.s_lat0, self.c_lat0);
            let r0 = ec.radii_sin(s0);
            (vn_bar * dt / (r0.r_m_m + h_bar), r0.r_n_m, c0)
        };
        let dlat_new = self.dlat_rad + dlat_step;
        let dlon_new = self.dlon_rad + ve_bar * dt / ((r_n_bar + h_bar) * c_bar);
        // sin/cos of L_k/2: the transport rotation's, and (as sin/cos L) L_{k−1} of the next
        // update
        let (s_half, c_half) = self.half_lat.sin_cos(0.5 * dlat_new);

        // 5. attitude
        self.updates += 1.0;
        let t = self.updates * dt;
        let c_b_n = match shape.attitude {
            AttitudeMode::Transport => {
                // S1 eq. (6)/(32): Q_k = Q_{k−1} ⊗ q(Δφ), C_b^n = T(L_k, Δλ_k + Ω_e t_k) C(Q_k),
                // with T = R_y(L) R_x(−Δ) R_y(−L0) and P = q_y(−L0) ⊗ Q (see the type's notes);
                // P was advanced after the coning compensation
                let (s_l, c_l) = if transport {
                    (s_half, c_half)
                } else {
                    (self.s_half_lat0, self.c_half_lat0)
                };
                let (s_d, c_d) = self.half_delta(transport, dlon_new, t);
                y_mul(s_l, c_l, &x_mul(-s_d, c_d, &self.q)).to_dcm()
            }
            AttitudeMode::Savage => {
                let zeta = w_in * dt;
                self.q = Self::renorm(
                    &mut self.renorm_in,
                    Quat::from_rotvec(&(-zeta))
                        .mul(&self.q)
                        .mul(&Quat::from_rotvec(&comp.dphi_b_rad)),
                );
                self.q.to_dcm()
            }
            AttitudeMode::Five => {
                let w_in_b = cur.c_b_n.transpose() * w_in * (dt / n.max(1) as f64);
                let mut rel = [Increment::default(); 4];
                for (r, s) in rel.iter_mut().zip(samples.iter()) {
                    *r = Increment::new(s.dtheta_b_rad - w_in_b, s.dv_b_mps);
                }
                let prev_rel = Increment::new(
                    self.prev.dtheta_b_rad - w_in_b * n as f64,
                    self.prev.dv_b_mps,
                );
                let comp_rel = compensate(self.cfg.coning, &rel[..n.min(4)], &prev_rel);
                self.q = Self::renorm(
                    &mut self.renorm_in,
                    self.q.mul(&Quat::from_rotvec(&comp_rel.dphi_b_rad)),
                );
                self.q.to_dcm()
            }
        };
        self.dlat_rad = dlat_new;
        self.dlon_rad = dlon_new;
        (self.sin_lat, self.cos_lat) = full_angle(s_half, c_half);
        self.prev = Increment::new(comp.dtheta_b_rad, comp.dv_b_mps);
        NavState {
            t_s: t,
            lat_rad: self.lat(),
            lon_rad: wrap_pi(self.lon0_rad + dlon_new),
            h_m: h_new,
            v_n_mps: v_new,
            c_b_n,
        }
    }
}

impl Mechanization for LocalLevel {
    #[inline]
    fn samples_per_update(&self) -> usize {
        self.cfg.samples
    }

    fn update(&mut self, samples: &[Increment]) {
        const ANY: u8 = Shape::CONING_ANY;
        let cur = self.out;
        self.out = match self.shape {
            Shape::SLC => self.step::<{ Shape::SLC }, ANY>(samples, &cur),
            Shape::SL => self.step::<{ Shape::SL }, ANY>(samples, &cur),
            Shape::SAV => self.step::<{ Shape::SAV }, ANY>(samples, &cur),
            _ => self.step::<{ Shape::GENERAL }, ANY>(samples, &cur),
        };
    }

    fn update_many(&mut self, samples: &[Increment], states: &mut [NavState]) -> usize {
        const ANY: u8 = Shape::CONING_ANY;
        match (self.shape, self.coning_shape) {
            (Shape::SLC, Shape::CONING_1PREV) => {
                self.steps::<{ Shape::SLC }, { Shape::CONING_1PREV }>(samples, states)
            }
            (Shape::SLC, Shape::CONING_THREE_POLY) => {
                self.steps::<{ Shape::SLC }, { Shape::CONING_THREE_POLY }>(samples, states)
            }
            (Shape::SLC, _) => self.steps::<{ Shape::SLC }, ANY>(samples, states),
            (Shape::SL, _) => self.steps::<{ Shape::SL }, ANY>(samples, states),
            (Shape::SAV, _) => self.steps::<{ Shape::SAV }, ANY>(samples, states),
            _ => self.steps::<{ Shape::GENERAL }, ANY>(samples, states),
        }
    }

    #[inline]
    fn state(&self) -> NavState {
        self.out
    }

    #[inline]
    fn state_into(&self, out: &mut NavState) {
        *out = self.out;
    }

    fn hold_vertical(&mut self, h_m: f64, v_d_mps: f64) {
        self.out.h_m = h_m;
        self.out.v_n_mps.z = v_d_mps;
    }

    fn correct_state(&mut self, s: &NavState) {
        // offsets from the start stay continuous (no wrap of dlon across ±180°)
        self.dlat_rad += s.lat_rad - self.lat();
        self.dlon_rad += wrap_pi(s.lon_rad - wrap_pi(self.lon0_rad + self.dlon_rad));
        self.out.lat_rad = self.lat();
        self.out.lon_rad = wrap_pi(self.lon0_rad + self.dlon_rad);
        self.out.h_m = s.h_m;
        self.out.v_n_mps = s.v_n_mps;
        // the latitude jumped: a new reference for its sine and cosine
        self.half_lat = SinCosTrack::new(0.5 * self.lat0_rad, 0.5 * self.dlat_rad);
        let (s_half, c_half) = self.half_lat.sin_cos_ref();
        (self.sin_lat, self.cos_lat) = full_angle(s_half, c_half);
        let q_b_n = Quat::from_dcm(&s.c_b_n);
        self.q = match self.cfg.attitude {
            AttitudeMode::Transport => {
                // q_b^n = q_y(L) ⊗ q_x(−Δ) ⊗ P, so P = q_x(Δ) ⊗ q_y(−L) ⊗ q_b^n
                let (s_l, c_l) = if self.cfg.earth.transport {
                    (s_half, c_half)
                } else {
                    (self.s_half_lat0, self.c_half_lat0)
                };
                let (s_d, c_d) =
                    self.half_delta(self.cfg.earth.transport, self.dlon_rad, self.out.t_s);
                x_mul(s_d, c_d, &y_mul(-s_l, c_l, &q_b_n)).normalized()
            }
            AttitudeMode::Savage | AttitudeMode::Five => q_b_n,
        };
        self.out.c_b_n = s.c_b_n;
        self.renorm_in = RENORM_EVERY;
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    extern crate std;
    use super::*;
    use crate::math::{c_b_n_from_euler, Euler, Mat3};
    use crate::nav::{transport_matrix, AlgorithmKind, AlgorithmSpec, AnyMechanization};
    use std::{vec, vec::Vec};

    #[test]
    fn transport_factors_into_elementary_rotations() {
        // T(L, Δ) of S1 eq. (32) = R_y(L) R_x(−Δ) R_y(−L0), as quaternions of half angles
        let (l0, l, delta) = (0.65_f64, 0.7_f64, 0.31_f64);
        let t = transport_matrix(l, l0.sin(), l0.cos(), delta);
        let (s0, c0) = (0.5 * l0).sin_cos();
        let (sl, cl) = (0.5 * l).sin_cos();
        let (sd, cd) = (0.5 * delta).sin_cos();
        let q = y_mul(sl, cl, &x_mul(-sd, cd, &y_mul(-s0, c0, &Quat::IDENTITY)));
        assert!((q.to_dcm() - t).abs().max() < 1e-15);
        let (s, c) = full_angle(sl, cl);
        assert!((s - l.sin()).abs() < 2e-16 && (c - l.cos()).abs() < 2e-16);
    }

    fn init() -> InitialState {
        InitialState {
            lat_rad: 0.61,
            lon_rad: 2.2,
            h_m: 300.0,
            v_n_mps: Vec3::new(180.0, -240.0, 2.0),
            c_b_n: c_b_n_from_euler(&Euler::new(0.05, -0.1, 2.3)),
        }
    }

    /// A rotating, accelerating body: increments of a slow coning plus a turn.
    fn increments(count: usize, dt: f64) -> Vec<Increment> {
        (0..count)
            .map(|k| {
                let t = k as f64 * dt;
                Increment::new(
                    Vec3::new(
                        1e-3 * (3.0 * t).sin(),
                        1e-3 * (3.0 * t).cos(),
                        0.05 + 1e-3 * t.sin(),
                    ) * dt,
                    Vec3::new(0.5 * t.cos(), 0.2, -9.8 + 0.1 * t.sin()) * dt,
                )
            })
            .collect()
    }

    #[test]
    fn update_many_gives_the_states_of_update_and_state() {
        // every instance (the three defaults with 1prev at N = 1 and three_poly at N = 3,
        // the general one with other options and the flat model) hands over the same bits
        let dt = 0.01;
        let incs = increments(3000, dt);
        let mut specs = Vec::new();
        for n in [1, 2, 3] {
            for kind in [
                AlgorithmKind::Savage,
                AlgorithmKind::SongLee,
                AlgorithmKind::SongLeeComplete,
            ] {
                let mut spec = AlgorithmSpec::new(kind, n);
                spec.coning = ConingSet::recommended_for(n);
                specs.push((spec, EarthModel::WGS84));
                let mut five = spec;
                five.attitude = Some(AttitudeMode::Five);
                specs.push((five, EarthModel::WGS84));
                specs.push((spec, EarthModel::flat(9.80665)));
            }
        }
        for (spec, earth) in specs {
            let mut a = AnyMechanization::new(&spec, earth, dt, &init());
            let mut b = a.clone();
            let n = spec.samples;
            let one: Vec<NavState> = incs
                .chunks_exact(n)
                .map(|c| {
                    a.update(c);
                    a.state()
                })
                .collect();
            let mut many = vec![b.state(); 700];
            let mut done = 0;
            while done < one.len() {
                let k = b.update_many(&incs[done * n..], &mut many);
                assert_eq!(&many[..k], &one[done..done + k], "{spec:?} {earth:?}");
                done += k;
            }
            assert_eq!(b.state(), a.state());
        }
    }

    #[test]
    fn lazy_renormalization_keeps_the_attitude_unit() {
        let dt = 0.002;
        let incs = increments(200_000, dt);
        let mut spec = AlgorithmSpec::new(AlgorithmKind::SongLeeComplete, 1);
        spec.coning = ConingSet::OnePrev;
        let AnyMechanization::LocalLevel(mut m) =
            AnyMechanization::new(&spec, EarthModel::WGS84, dt, &init())
        else {
            unreachable!()
        };
        let mut worst: f64 = 0.0;
        for c in incs.chunks_exact(1) {
            m.update(c);
            worst = worst.max((m.q.norm() - 1.0).abs());
        }
        assert!(worst < 1e-15, "{worst:e}");
        let c = m.state().c_b_n;
        assert!((c * c.transpose() - Mat3::identity()).abs().max() < 4e-15);
    }

    #[test]
    fn correct_state_with_the_own_state_changes_nothing_but_rounding() {
        let dt = 0.01;
        let incs = increments(2000, dt);
        let spec = AlgorithmSpec::new(AlgorithmKind::SongLeeComplete, 2);
        let mut a = AnyMechanization::new(&spec, EarthModel::WGS84, dt, &init());
        let mut b = a.clone();
        for (k, c) in incs.chunks_exact(2).enumerate() {
            a.update(c);
            b.update(c);
            if k % 100 == 50 {
                let s = b.state();
                b.correct_state(&s);
                assert_eq!(b.state().c_b_n, s.c_b_n);
            }
        }
        let (sa, sb) = (a.state(), b.state());
        assert!((sa.c_b_n - sb.c_b_n).abs().max() < 1e-14);
        assert!((sa.v_n_mps - sb.v_n_mps).norm() < 1e-11);
        assert!((sa.lat_rad - sb.lat_rad).abs() < 1e-15);
    }
}

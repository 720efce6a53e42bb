//! Exact truth: trajectory state and IMU increments per sensor sample
//! (docs/theory/mechanizations.md §"Truth generation").
//!
//! * Constant-state cases (static, or cruise along a parallel): closed form
//!   `Δθ = C_n^b (ω_ie + ω_en) δt`, `Δv = C_n^b ((2ω_ie + ω_en) × v − g) δt`,
//!   `l(t) = l0 + v_E t / ((R_N + h) cos L)`.
//! * Everything else: the increments are quadratures of
//!   `ω_ib^b = ω_nb^b + C_n^b (ω_ie + ω_en)` and `f^b = C_n^b (v̇ + (2ω_ie + ω_en) × v − g)`
//!   over the sample, where attitude, rates, velocity and v̇ are analytic functions of time
//!   ([`Trajectory::kinematics_split`]) and the position `(L, l, h)` enters only through
//!   the slowly varying earth terms `ω_ie(L)`, `ω_en(L, h, v)`, `g(L, h)`. The default
//!   scheme ([`TruthScheme::Gauss`]) integrates the whole state
//!   `[L, l, h, ∫ω_ib^b, ∫f^b]` with Gauss–Legendre collocation: one 3-node panel per
//!   sample up to 16 substeps, else 4-node panels, `⌈substeps/32⌉` per sample (split
//!   further at segment and overlay boundaries inside a sample, so that no panel straddles
//!   a kink); see [`TruthScheme::Gauss`] for the error bound. The classical RK4
//!   (docs/theory/mechanizations.md §"Truth generation"), with `substeps` steps per sample and
//!   the analytic branch selected by the substep midpoint, is kept as the independent
//!   reference ([`TruthGenerator::reference_rk4`], [`TruthScheme::Rk4`]).

use crate::truth::trajectory::{Kinematics, OverlayPhases, Trajectory};
use sdins_core::coning::Increment;
use sdins_core::earth::{sin_cos_shift, EarthModel};
use sdins_core::math::{Mat3, Vec3};
use sdins_core::nav::{wrap_pi, InitialState};

/// Truth at the end of one sensor sample, with the sample's increments.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TruthSample {
    /// sample end time \[s\]
    pub t_s: f64,
    /// exact increments over the sample
    pub inc: Increment,
    /// latitude \[rad\]
    pub lat_rad: f64,
    /// longitude \[rad\]
    pub lon_rad: f64,
    /// height \[m\]
    pub h_m: f64,
    /// NED velocity \[m/s\]
    pub v_n_mps: Vec3,
    /// attitude body→NED
    pub c_b_n: Mat3,
    /// `(sin L, cos L)` of `lat_rad`, so that every algorithm's error evaluation against
    /// this sample shares one `sincos` (build samples with [`TruthSample::new`])
    pub sin_cos_lat: (f64, f64),
}

impl TruthSample {
    /// A sample, with `sin_cos_lat` computed from `lat_rad`.
    pub fn new(
        t_s: f64,
        inc: Increment,
        lat_rad: f64,
        lon_rad: f64,
        h_m: f64,
        v_n_mps: Vec3,
        c_b_n: Mat3,
    ) -> Self {
        Self {
            t_s,
            inc,
            lat_rad,
            lon_rad,
            h_m,
            v_n_mps,
            c_b_n,
            sin_cos_lat: libm::sincos(lat_rad),
        }
    }
}

/// Where the truth generator starts and how finely it integrates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TruthConfig {
    /// earth model (the navigation must use the same)
    pub earth: EarthModel,
    /// sensor sample period δt \[s\]
    pub dt_s: f64,
    /// start latitude \[rad\]
    pub lat0_rad: f64,
    /// start longitude \[rad\]
    pub lon0_rad: f64,
    /// start height \[m\]
    pub h0_m: f64,
    /// integration resolution: RK4 substeps per sample for [`TruthScheme::Rk4`] (at least 16,
    /// docs/theory/mechanizations.md §"Truth generation"; the refinement test compares with 32);
    /// [`TruthScheme::Gauss`] uses one
    /// 3-node panel per sample up to 16, else `⌈substeps/32⌉` 4-node panels
    pub substeps: usize,
}

/// How the general (non-closed-form) path integrates a sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TruthScheme {
    /// Default: Gauss–Legendre collocation. Up to 16
    /// substeps, one 3-node panel per sample (order 6, stage order 3; nodes
    /// `c = ½ ∓ √15/10, ½`, weights `5/18, 4/9, 5/18`); above, `P = ⌈substeps/32⌉` 4-node
    /// panels (order 8, stage order 4; nodes `½ ∓ ½√(3/7 ± (2/7)√(6/5))`, weights
    /// `(18 ∓ √30)/72`), which replace `2P` 3-node panels with `4P` instead of `6P` nodes
    /// and a smaller remainder (below). The panels are equal, of length `H`, per piece
    /// between segment/overlay boundaries inside the sample, if any; each panel selects its
    /// analytic branch by its midpoint. Per panel:
    ///
    /// * the kinematics are evaluated once per node, with the overlay phases'
    ///   sin/cos shared ([`Trajectory::kinematics_phased`]: once per sample for the sample
    ///   start, once per generator for the node offsets);
    /// * height at the nodes is the collocation (Butcher `A`) quadrature of `−v_D`;
    ///   latitude at the nodes the same for `v_N/(R_M + h)`, with `R_M` first at the panel
    ///   start latitude and then once corrected at the predicted node latitudes (one
    ///   fixed-point step: the contraction factor is `H·|∂L̇/∂L| ≈ H·v_N·R_M'/R_M² ≈ 1e-10`);
    ///   sin/cos of the node latitudes by [`sin_cos_shift`] from the panel start;
    /// * the earth terms, `ω_ib^b`, `f^b`, `L̇`, `l̇` at the nodes, and the panel sums
    ///   `H·Σ b_i y'_i`.
    ///
    /// Error: for the increments (pure quadratures given the position) the Gauss remainder
    /// is `H⁷ f⁽⁶⁾(ξ)/2 016 000` (3 nodes) and `H⁹ f⁽⁸⁾(ξ)/1 778 112 000` (4 nodes); for an
    /// oscillation of amplitude `A` and frequency `Ω` that is `A·H·(ΩH)⁶/2 016 000` and
    /// `A·H·(ΩH)⁸/1 778 112 000`. [`auto_substeps`] gives `Ω·δt/substeps ≤ 2e-3`, hence
    /// `ΩH ≤ 0.032` on 3-node panels and `ΩH ≤ 0.064` on 4-node panels, relative remainders
    /// `≤ 5.3e-16` and `≤ 1.6e-19` of `A·H` (below one rounding of the increment; RK4 at the
    /// same `substeps` is Simpson's rule with `(Ωh)⁴/2880 = 5.6e-15`). `dq-paper` (1 Hz,
    /// 0.5° coning, `A = Ω sin α = 0.055 rad/s`, 32 substeps: one 4-node panel, `H = 10 ms`):
    /// 7e-23 rad per sample (3-node panels of 5 ms: 2.6e-19); its specific-force
    /// oscillation (`g sin α = 0.086 m/s²`) 1e-22 m/s. `turn-90dps`
    /// (`f_y = s ψ̇`, a raised cosine of amplitude 267 m/s² at `Ω = π rad/s`, `H = 2 ms`):
    /// 2e-20 m/s. The node positions carry the collocation stage error `O(H⁴·|v⁽³⁾|)`
    /// with 3 nodes, `O(H⁵·|v⁽⁴⁾|)` with 4 (≲ 1e-10 m in the 90°/s turn, ≲ 1e-14 m in
    /// `dq-paper`), which enters the increments only through `∂g/∂h ≈ 3e-6 s⁻²` and
    /// `∂ω_ie/∂L ≈ 1e-4 s⁻¹` (< 1e-20 per sample); the position at the panel end is the
    /// order-6 (order-8) Gauss quadrature of the rates at the nodes,
    /// where the node errors enter only through `∂L̇/∂L ≈ 1e-8 s⁻¹`.
    /// Equal to the RK4 reference at doubled substeps within 2e-17 rad / 2e-16 m/s per sample
    /// (tests/truth.rs, `gauss_matches_rk4_reference_*`), with 3 or 4 kinematics evaluations
    /// per panel instead of 3 per RK4 substep.
    Gauss,
    /// Classical RK4 on `[L − L0, l − l0, h, ∫ω_ib^b, ∫f^b]` with `substeps` steps per
    /// sample, the integrals reset at every sample boundary and the analytic branch
    /// selected by the substep midpoint (docs/theory/mechanizations.md §"Truth generation"). The
    /// independent reference.
    Rk4,
}

#[derive(Clone, Copy, Debug)]
struct ClosedForm {
    inc: Increment,
    lon_rate_rps: f64,
    /// the (constant) velocity and attitude, so that no sample re-evaluates them
    v_n_mps: Vec3,
    c_b_n: Mat3,
    /// sin/cos of the (constant) latitude
    sin_cos_lat: (f64, f64),
}

/// The difference of the gravitational attraction between the IMU at `d_n = C_b^n l` and
/// the reference point, in the reference point's NED axes, under the navigation's own
/// earth model: `γ = g + ω_ie×(ω_ie×r)` (plumb-bob gravity `g` minus the centrifugal term),
/// so `Δγ = C_{n'}^n g^{n'} − g^n + ω_ie×(ω_ie×d_n)`. The local vertical at the IMU is tilted
/// by `(δE/(R_N+h), −δN/(R_M+h))`, which puts `−g·(δN/(R_M+h), δE/(R_N+h))` on the
/// horizontal axes (flat model: one vertical, no tilt); `g2 − g` is the model's gravity
/// change to the IMU's latitude and height. Neglected: second order in `|l|/R`
/// (≈ 1e-13 g per m² of lever arm). The IMU senses `f^b = … − C_n^b Δγ`
/// ([`ImuMount`]).
fn gravity_difference(
    e: &EarthModel,
    le: &sdins_core::earth::LocalEarth,
    h: f64,
    w_ie: &Vec3,
    d_n: &Vec3,
    g2: f64,
) -> Vec3 {
    let g = le.g_mps2;
    let tilt = if e.transport {
        Vec3::new(
            -g * d_n.x / (le.r_m_m + h),
            -g * d_n.y / (le.r_n_m + h),
            0.0,
        )
    } else {
        Vec3::zeros()
    };
    tilt + Vec3::new(0.0, 0.0, g2 - g) + w_ie.cross(&w_ie.cross(d_n))
}

/// Streaming truth generator (constant memory): an iterator of [`TruthSample`].
#[derive(Clone, Debug)]
pub struct TruthGenerator<'a> {
    traj: &'a Trajectory,
    cfg: TruthConfig,
    k: u64,
    n_samples: u64,
    dlat: f64,
    dlon: f64,
    h: f64,
    closed: Option<ClosedForm>,
    scheme: TruthScheme,
    /// segment and overlay boundaries (sorted): the Gauss panels never straddle one
    breaks: Vec<f64>,
    /// index of the first boundary after the current sample start
    bi: usize,
    /// overlay phases at `ph_base_t` (the current sample start; carried over from the
    /// previous sample's end evaluation)
    ph_base: OverlayPhases,
    ph_base_t: f64,
    /// scratch: the phases at the sample end
    ph_end: OverlayPhases,
    /// overlay phases of the node offsets of a sample without inner boundaries (panel `p`,
    /// node `i` at `3p + i`), the same for every such sample
    ph_nodes: Vec<OverlayPhases>,
    /// scratch for the node offsets of panels between inner boundaries
    ph_tmp: [OverlayPhases; 4],
    /// phases of offset 0
    ph_zero: OverlayPhases,
    /// phases of offset δt: the sample-to-sample rotation of the random-vibration
    /// components ([`Trajectory::phases_advance`])
    ph_step: OverlayPhases,
    /// `(L, sin L, cos L)` of the last latitude whose sin/cos was taken (the sample-end
    /// latitude is the next panel's start latitude)
    lat_sc: (f64, f64, f64),
    /// IMU lever arm and mounting ([`TruthGenerator::with_mount`])
    mount: Option<ImuMount>,
    /// `ω_ib^b` at the current sample start (the previous sample's end value)
    w_ib_prev: Option<Vec3>,
}

/// Where the IMU sits on the vehicle: a lever arm from the vehicle reference point and a
/// mounting rotation, both in the vehicle (body) frame.
///
/// The IMU senses `ω_is^s = C_b^s ω_ib^b` and `f^s = C_b^s (f_ref^b + ω̇_ib^b × l +
/// ω_ib^b × (ω_ib^b × l) − C_n^b Δγ)` (rigid body in inertial space, Groves 2nd ed.
/// §2.5; `Δγ` the model's gravitational attraction at the IMU minus that at the reference
/// point, ≈ 3e-6 s⁻² per m of lever arm, without which a navigation of the IMU point
/// drifts by ~1e-4 m/s per minute), so over a sample `Δθ^s = C_b^s Δθ^b` and
/// `Δv^s = C_b^s (Δv_ref^b + [ω_ib^b(t₁) − ω_ib^b(t₀)] × l + ∫ (ω_ib^b × (ω_ib^b × l) −
/// C_n^b Δγ) dt)`:
/// the angular-acceleration term integrates in closed form (a step in ω inside or at the
/// start of a sample, e.g. the start of a constant-rate turn, is the impulse it is), the
/// centripetal term by the same quadrature as `f`. The truth samples stay at the reference
/// point; [`ImuMount::imu_point`] gives the IMU's own position, velocity and attitude.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuMount {
    /// lever arm from the vehicle reference point to the IMU, vehicle frame \[m\]
    pub lever_arm_b_m: Vec3,
    /// rotation from the vehicle frame to the IMU (sensor) frame, `C_b^s`
    pub c_b_s: Mat3,
}

impl ImuMount {
    /// Lever arm `l` \[m\] and mounting Euler angles (roll, pitch, yaw of the IMU axes in the
    /// vehicle frame: `C_s^b = Rz Ry Rx`).
    pub fn new(lever_arm_b_m: Vec3, mount: sdins_core::math::Euler) -> Self {
        Self {
            lever_arm_b_m,
            c_b_s: sdins_core::math::c_b_n_from_euler(&mount).transpose(),
        }
    }

    /// The IMU's truth from a reference-point sample and the trajectory kinematics at the
    /// same instant, in the NED frame at the IMU (the frame a navigation of the IMU data
    /// keeps; it differs from the reference point's NED frame by `|l|/R ≈ 3e-7 rad` per
    /// 2 m of horizontal lever arm). Position `r^e + C_n^e C_b^n l` through ECEF
    /// ([`EarthModel::ecef_from_geodetic`] and back); earth-relative velocity
    /// `v + C_b^n (ω_eb^b × l)`, `ω_eb^b = ω_nb^b + C_n^b ω_en^n` (Groves 2nd ed. eq. 2.150
    /// form), and attitude `C_s^n = C_b^n C_s^b`, both rotated by `C_n^{n'} = C_e^{n'} C_n^e`.
    /// The flat model (no transport rate) has one NED frame: the offset is converted with
    /// the radii of curvature at the reference point. Returns
    /// `(lat_rad, lon_rad, h_m, v_n_mps, c_s_n)`.
    pub fn imu_point(
        &self,
        earth: &EarthModel,
        s: &TruthSample,
        kin: &Kinematics,
    ) -> (f64, f64, f64, Vec3, Mat3) {
        let l = self.lever_arm_b_m;
        let d_n = s.c_b_n * l;
        let w_en = earth.omega_en_n(s.lat_rad, s.h_m, &s.v_n_mps);
        let w_eb = kin.omega_nb_b_rps + s.c_b_n.transpose() * w_en;
        let v = s.v_n_mps + s.c_b_n * w_eb.cross(&l);
        let c_s_n = s.c_b_n * self.c_b_s.transpose();
        if !earth.transport {
            let r = earth.radii(s.lat_rad);
            let lat = s.lat_rad + d_n.x / (r.r_m_m + s.h_m);
            let lon = wrap_pi(s.lon_rad + d_n.y / ((r.r_n_m + s.h_m) * s.lat_rad.cos()));
            return (lat, lon, s.h_m - d_n.z, v, c_s_n);
        }
        let c_e_n = EarthModel::c_e_n(s.lat_rad, s.lon_rad);
        let r_e = earth.ecef_from_geodetic(s.lat_rad, s.lon_rad, s.h_m) + c_e_n.transpose() * d_n;
        let (lat, lon, h) = earth.geodetic_from_ecef(&r_e);
        let c_n_n2 = EarthModel::c_e_n(lat, lon) * c_e_n.transpose();
        (lat, lon, h, c_n_n2 * v, c_n_n2 * c_s_n)
    }
}

/// Gauss–Legendre 3-node nodes, Butcher `A` (collocation) matrix; weights 5/18, 4/9, 5/18
/// are applied as `y₂ + (5/18)((y₁ − y₂) + (y₃ − y₂))` (exact for constant integrands).
const GL3_C: [f64; 3] = [
    0.5 - 0.387_298_334_620_741_7, // ½ − √15/10
    0.5,
    0.5 + 0.387_298_334_620_741_7,
];
const SQ15: f64 = 3.872_983_346_207_417;
const GL3_A: [[f64; 3]; 3] = [
    [
        5.0 / 36.0,
        2.0 / 9.0 - SQ15 / 15.0,
        5.0 / 36.0 - SQ15 / 30.0,
    ],
    [
        5.0 / 36.0 + SQ15 / 24.0,
        2.0 / 9.0,
        5.0 / 36.0 - SQ15 / 24.0,
    ],
    [
        5.0 / 36.0 + SQ15 / 30.0,
        2.0 / 9.0 + SQ15 / 15.0,
        5.0 / 36.0,
    ],
];

/// The Gauss 3-node weighted mean `Σ b_i y_i` in the form exact for constant `y`.
#[inline]
fn gl3_mean(y: [f64; 3]) -> f64 {
    y[1] + (5.0 / 18.0) * ((y[0] - y[1]) + (y[2] - y[1]))
}

/// `Σ_j A_ij y_j` (collocation stage quadrature).
#[inline]
fn gl3_stage(y: [f64; 3]) -> [f64; 3] {
    let a = &GL3_A;
    [
        a[0][0] * y[0] + a[0][1] * y[1] + a[0][2] * y[2],
        a[1][0] * y[0] + a[1][1] * y[1] + a[1][2] * y[2],
        a[2][0] * y[0] + a[2][1] * y[1] + a[2][2] * y[2],
    ]
}

/// Gauss–Legendre 4-node nodes `½ ∓ ½√(3/7 ± (2/7)√(6/5))` and Butcher `A` matrix
/// (collocation, `A_ij = ∫₀^{c_i} ℓ_j`); weights `(18 ∓ √30)/72` (outer, inner) are applied
/// as `½(y₁ + y₂) + b_o((y₀ − y₁) + (y₃ − y₂))` (exact for constant integrands).
#[allow(clippy::excessive_precision)] // 20-digit values (mpmath)
const GL4_C: [f64; 4] = [
    0.069_431_844_202_973_712,
    0.330_009_478_207_571_87,
    0.669_990_521_792_428_13,
    0.930_568_155_797_026_29,
];
/// outer weight `(18 − √30)/72`
#[allow(clippy::excessive_precision)] // 20-digit values (mpmath)
const GL4_BO: f64 = 0.173_927_422_568_726_93;
#[allow(clippy::excessive_precision)] // 20-digit values (mpmath)
const GL4_A: [[f64; 4]; 4] = [
    [
        0.086_963_711_284_363_464,
        -0.026_604_180_084_998_793,
        0.012_627_462_689_404_725,
        -0.003_555_149_685_795_683_2,
    ],
    [
        0.188_118_117_499_868_07,
        0.163_036_288_715_636_54,
        -0.027_880_428_602_470_895,
        0.006_735_500_594_538_155_5,
    ],
    [
        0.167_191_921_974_188_77,
        0.353_953_006_033_743_97,
        0.163_036_288_715_636_54,
        -0.014_190_694_931_141_143,
    ],
    [
        0.177_482_572_254_522_61,
        0.313_445_114_741_868_35,
        0.352_676_757_516_271_86,
        0.086_963_711_284_363_464,
    ],
];

/// The Gauss 4-node weighted mean `Σ b_i y_i` in the form exact for constant `y`.
#[inline]
fn gl4_mean(y: [f64; 4]) -> f64 {
    0.5 * (y[1] + y[2]) + GL4_BO * ((y[0] - y[1]) + (y[3] - y[2]))
}

/// `Σ_j A_ij y_j` for the 4-node rule.
#[inline]
fn gl4_stage(y: [f64; 4]) -> [f64; 4] {
    let a = &GL4_A;
    std::array::from_fn(|i| a[i][0] * y[0] + a[i][1] * y[1] + a[i][2] * y[2] + a[i][3] * y[3])
}

/// One Gauss–Legendre rule: nodes, weighted mean, stage quadrature.
struct Rule<const N: usize> {
    c: [f64; N],
    mean: fn([f64; N]) -> f64,
    stage: fn([f64; N]) -> [f64; N],
}

const GL3: Rule<3> = Rule {
    c: GL3_C,
    mean: gl3_mean,
    stage: gl3_stage,
};
const GL4: Rule<4> = Rule {
    c: GL4_C,
    mean: gl4_mean,
    stage: gl4_stage,
};

/// The Gauss layout for `substeps`: `(nodes, panels per sample)`. Up to 16 substeps one
/// 3-node panel; above, 4-node panels of twice the length, `⌈substeps/32⌉` (more accurate
/// than 3-node panels of `⌈substeps/16⌉`, with fewer nodes: see [`TruthScheme::Gauss`]).
fn gauss_layout(substeps: usize) -> (usize, usize) {
    if substeps <= 16 {
        (3, 1)
    } else {
        (4, substeps.div_ceil(32))
    }
}

type State = [f64; 9];

impl<'a> TruthGenerator<'a> {
    /// New generator over the whole trajectory (⌊duration/δt⌉ samples).
    pub fn new(traj: &'a Trajectory, cfg: TruthConfig) -> Self {
        let n_samples = (traj.duration_s / cfg.dt_s).round().max(0.0) as u64;
        let mut g = Self {
            traj,
            cfg,
            k: 0,
            n_samples,
            dlat: 0.0,
            dlon: 0.0,
            h: cfg.h0_m,
            closed: None,
            scheme: TruthScheme::Gauss,
            breaks: Self::boundaries(traj),
            bi: 0,
            ph_base: OverlayPhases::default(),
            ph_base_t: f64::NAN,
            ph_end: OverlayPhases::default(),
            ph_nodes: Vec::new(),
            ph_tmp: Default::default(),
            ph_zero: OverlayPhases::default(),
            ph_step: OverlayPhases::default(),
            lat_sc: (f64::NAN, 0.0, 1.0),
            mount: None,
            w_ib_prev: None,
        };
        traj.phases_offset(0.0, &mut g.ph_zero);
        traj.phases_offset(cfg.dt_s, &mut g.ph_step);
        // node offsets of the regular panel layout, formed as in `sample_gauss`
        let (nodes, panels) = gauss_layout(cfg.substeps);
        let hp = cfg.dt_s / panels as f64;
        for p in 0..panels {
            let oa = 0.0 + p as f64 * hp;
            let c: &[f64] = if nodes == 3 { &GL3_C } else { &GL4_C };
            for &c in c {
                let mut ph = OverlayPhases::default();
                traj.phases_offset(oa + c * hp, &mut ph);
                g.ph_nodes.push(ph);
            }
        }
        if traj.is_constant_parallel() {
            g.closed = Some(g.closed_form());
        }
        g
    }

    /// IMU increments at a lever arm and mounting ([`ImuMount`]); the samples' position,
    /// velocity and attitude stay those of the vehicle reference point. Uses the general
    /// (integrated) path.
    pub fn with_mount(mut self, mount: ImuMount) -> Self {
        self.closed = None;
        self.mount = Some(mount);
        self
    }

    /// `ω_ib^b` at time `t` (branch `t_sel`) at the current position.
    fn omega_ib(&self, t: f64, t_sel: f64) -> Vec3 {
        let kin = self.traj.kinematics(t, t_sel);
        let e = &self.cfg.earth;
        let lat = self.cfg.lat0_rad + self.dlat;
        let w = e.omega_ie_n(lat) + e.omega_en_n(lat, self.h, &kin.v_n_mps);
        kin.omega_nb_b_rps + kin.c_b_n.transpose() * w
    }

    /// Force the general (integrated) path even where the closed form applies (for tests).
    pub fn without_closed_form(mut self) -> Self {
        self.closed = None;
        self
    }

    /// The classical RK4 reference with `substeps` steps per sample instead of the Gauss
    /// scheme, and never the closed form: the independent reference for tests.
    pub fn reference_rk4(mut self) -> Self {
        self.closed = None;
        self.scheme = TruthScheme::Rk4;
        self
    }

    /// The scheme of the general path.
    pub fn scheme(&self) -> TruthScheme {
        self.scheme
    }

    /// Start at sample `k` (time `k·δt`) from the configured start position instead of at
    /// t = 0, for comparing schemes on a window of a long scenario: the position is not
    /// propagated to `t_k`, and the closed-form path is not used.
    pub fn starting_at_sample(mut self, k: u64) -> Self {
        self.closed = None;
        self.w_ib_prev = None;
        self.k = k.min(self.n_samples);
        let t0 = self.k as f64 * self.cfg.dt_s;
        self.bi = self.breaks.partition_point(|&b| b <= t0);
        self
    }

    /// Position after the last sample as offsets from the start, `(L − L0 [rad], l − l0
    /// \[rad\], h \[m\])`: free of the rounding of the absolute coordinates of
    /// [`TruthSample`] (one ulp of a longitude near 2.2 rad is 2e-9 m), for comparing schemes.
    pub fn position_offsets(&self) -> (f64, f64, f64) {
        (self.dlat, self.dlon, self.h)
    }

    /// Interior segment starts and overlay window ends, sorted.
    fn boundaries(traj: &Trajectory) -> Vec<f64> {
        let mut b = traj.breakpoints();
        for o in traj.overlays() {
            b.push(o.start_s);
            b.push(o.end_s);
        }
        b.retain(|t| t.is_finite() && *t > 0.0 && *t < traj.duration_s);
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }

    /// Number of samples the generator will produce in total.
    pub fn len_samples(&self) -> u64 {
        self.n_samples
    }

    /// The navigation initial state at t = 0 (exact), at the IMU when a mount is set
    /// ([`TruthGenerator::with_mount`], [`ImuMount::imu_point`]).
    pub fn initial_state(&self) -> InitialState {
        let s = self.initial_truth();
        InitialState {
            lat_rad: s.lat_rad,
            lon_rad: s.lon_rad,
            h_m: s.h_m,
            v_n_mps: s.v_n_mps,
            c_b_n: s.c_b_n,
        }
    }

    /// The truth at t = 0 (zero increments), at the IMU when a mount is set: what the
    /// initial state of a navigation is compared with.
    pub fn initial_truth(&self) -> TruthSample {
        let k = self.traj.kinematics(0.0, 0.0);
        let s = TruthSample::new(
            0.0,
            Increment::new(Vec3::zeros(), Vec3::zeros()),
            self.cfg.lat0_rad,
            self.cfg.lon0_rad,
            self.cfg.h0_m,
            k.v_n_mps,
            k.c_b_n,
        );
        self.at_imu(&s)
    }

    /// A sample of this generator moved to the IMU ([`ImuMount::imu_point`]; unchanged
    /// without a mount): what a navigation of the IMU data is compared with.
    pub fn at_imu(&self, s: &TruthSample) -> TruthSample {
        let Some(m) = &self.mount else {
            return *s;
        };
        let t_sel = s.t_s - 0.25 * self.cfg.dt_s / self.cfg.substeps.max(1) as f64;
        let kin = self.traj.kinematics(s.t_s, t_sel.max(0.0));
        let (lat, lon, h, v, c) = m.imu_point(&self.cfg.earth, s, &kin);
        TruthSample::new(s.t_s, s.inc, lat, lon, h, v, c)
    }

    fn closed_form(&self) -> ClosedForm {
        let e = &self.cfg.earth;
        let k = self.traj.kinematics(0.0, 0.0);
        let (lat, h) = (self.cfg.lat0_rad, self.cfg.h0_m);
        let w_ie = e.omega_ie_n(lat);
        let w_en = e.omega_en_n(lat, h, &k.v_n_mps);
        let c_n_b = k.c_b_n.transpose();
        let dt = self.cfg.dt_s;
        let dtheta = c_n_b * (w_ie + w_en) * dt;
        let dv = c_n_b * ((2.0 * w_ie + w_en).cross(&k.v_n_mps) - e.gravity_n(lat, h)) * dt;
        let r = e.radii(lat);
        let lon_rate_rps = k.v_n_mps.y / ((r.r_n_m + h) * lat.cos());
        ClosedForm {
            inc: Increment::new(dtheta, dv),
            lon_rate_rps,
            v_n_mps: k.v_n_mps,
            c_b_n: k.c_b_n,
            sin_cos_lat: libm::sincos(lat),
        }
    }

    #[inline]
    fn deriv(&self, t_base: f64, off: f64, t_sel: f64, y: &State) -> State {
        let kin = self.traj.kinematics_split(t_base, off, t_sel);
        self.deriv_kin(&kin, y)
    }

    /// The state derivative given the trajectory kinematics at that time.
    #[inline]
    fn deriv_kin(&self, kin: &crate::truth::trajectory::Kinematics, y: &State) -> State {
        let e = &self.cfg.earth;
        let lat = self.cfg.lat0_rad + y[0];
        let h = y[2];
        let v = kin.v_n_mps;
        let r = e.radii(lat);
        let w_ie = e.omega_ie_n(lat);
        let w_en = e.omega_en_n(lat, h, &v);
        let c_n_b = kin.c_b_n.transpose();
        let w_ib = kin.omega_nb_b_rps + c_n_b * (w_ie + w_en);
        let mut f_b =
            c_n_b * (kin.v_dot_n_mps2 + (2.0 * w_ie + w_en).cross(&v) - e.gravity_n(lat, h));
        if let Some(m) = &self.mount {
            let d_n = kin.c_b_n * m.lever_arm_b_m;
            let le = e.local(lat, h);
            let g2 = e.gravity(lat + d_n.x / (le.r_m_m + h), h - d_n.z);
            let dg = gravity_difference(e, &le, h, &w_ie, &d_n, g2);
            f_b += w_ib.cross(&w_ib.cross(&m.lever_arm_b_m)) - c_n_b * dg;
        }
        let (lat_dot, lon_dot) = if e.transport {
            (v.x / (r.r_m_m + h), v.y / ((r.r_n_m + h) * lat.cos()))
        } else {
            // flat model: positions still advance over the ellipsoid at the start latitude
            let r0 = e.radii(self.cfg.lat0_rad);
            (
                v.x / (r0.r_m_m + h),
                v.y / ((r0.r_n_m + h) * self.cfg.lat0_rad.cos()),
            )
        };
        [
            lat_dot, lon_dot, -v.z, w_ib.x, w_ib.y, w_ib.z, f_b.x, f_b.y, f_b.z,
        ]
    }

    fn sample_rk4(&mut self, t0: f64) -> Increment {
        let n = self.cfg.substeps.max(1);
        let hs = self.cfg.dt_s / n as f64;
        let mut y: State = [self.dlat, self.dlon, self.h, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let add = |y: &State, k: &State, a: f64| -> State {
            let mut o = *y;
            for i in 0..9 {
                o[i] += a * k[i];
            }
            o
        };
        for j in 0..n {
            let oa = j as f64 * hs;
            let om = oa + 0.5 * hs;
            let ob = (j + 1) as f64 * hs;
            let tm = t0 + om;
            let k1 = self.deriv(t0, oa, tm, &y);
            // k2 and k3 share the midpoint kinematics: evaluate the trajectory once
            let kin_m = self.traj.kinematics_split(t0, om, tm);
            let k2 = self.deriv_kin(&kin_m, &add(&y, &k1, 0.5 * hs));
            let k3 = self.deriv_kin(&kin_m, &add(&y, &k2, 0.5 * hs));
            let k4 = self.deriv(t0, ob, tm, &add(&y, &k3, hs));
            for i in 0..9 {
                y[i] += hs / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        self.dlat = y[0];
        self.dlon = y[1];
        self.h = y[2];
        Increment::new(Vec3::new(y[3], y[4], y[5]), Vec3::new(y[6], y[7], y[8]))
    }
}

impl TruthGenerator<'_> {
    /// One sample `[t0, t0 + δt]` with the Gauss scheme ([`TruthScheme::Gauss`]).
    fn sample_gauss(&mut self, t0: f64) -> Increment {
        let dt = self.cfg.dt_s;
        let t1 = t0 + dt;
        // boundaries within a few ulp of the sample ends are at the ends (the sample grid
        // k·δt and the boundaries are both rounded): the panel midpoints select the branch
        let eps = 64.0 * f64::EPSILON * t1.abs().max(dt);
        while self.bi < self.breaks.len() && self.breaks[self.bi] <= t0 + eps {
            self.bi += 1;
        }
        let (nodes, panels) = gauss_layout(self.cfg.substeps);
        if self.ph_base_t.to_bits() != t0.to_bits() {
            self.traj.phases_at(t0, &mut self.ph_base);
            self.ph_base_t = t0;
        }
        let mut dth = Vec3::zeros();
        let mut dv = Vec3::zeros();
        // pieces [a, b] between the boundaries strictly inside the sample, P panels each
        let (mut a, mut j) = (0.0, self.bi);
        loop {
            let last = !(j < self.breaks.len() && self.breaks[j] < t1 - eps);
            let b = if last { dt } else { self.breaks[j] - t0 };
            let hp = (b - a) / panels as f64;
            // the whole sample in one piece: the node offsets of `ph_nodes`
            let regular = last && j == self.bi;
            for p in 0..panels {
                let reg = regular.then_some(p);
                let oa = a + p as f64 * hp;
                let (th, v) = if nodes == 3 {
                    self.panel_gauss(&GL3, t0, oa, hp, reg)
                } else {
                    self.panel_gauss(&GL4, t0, oa, hp, reg)
                };
                dth += th;
                dv += v;
            }
            if last {
                break;
            }
            a = b;
            j += 1;
        }
        Increment::new(dth, dv)
    }

    /// `(sin L, cos L)`, reusing the last result for the same `L`.
    #[inline]
    fn sin_cos_lat(&mut self, lat: f64) -> (f64, f64) {
        if self.lat_sc.0.to_bits() != lat.to_bits() {
            let (s, c) = libm::sincos(lat);
            self.lat_sc = (lat, s, c);
        }
        (self.lat_sc.1, self.lat_sc.2)
    }

    /// One Gauss panel `[t0 + oa, t0 + oa + hp]`: advances the position, returns the
    /// increments over the panel. `regular`: the panel index in a sample without inner
    /// boundaries, whose node phases are precomputed.
    fn panel_gauss<const N: usize>(
        &mut self,
        rule: &Rule<N>,
        t0: f64,
        oa: f64,
        hp: f64,
        regular: Option<usize>,
    ) -> (Vec3, Vec3) {
        let e = self.cfg.earth;
        let traj = self.traj;
        let t_sel = t0 + (oa + 0.5 * hp);
        let nodes: &[OverlayPhases] = match regular {
            Some(p) => &self.ph_nodes[N * p..N * p + N],
            None => {
                for (ph, c) in self.ph_tmp.iter_mut().zip(rule.c) {
                    traj.phases_offset(oa + c * hp, ph);
                }
                &self.ph_tmp[..N]
            }
        };
        let b = &self.ph_base;
        // filled in place (array::from_fn would copy each 144-byte value twice)
        let z = Vec3::zeros();
        let mut kin = [Kinematics {
            v_n_mps: z,
            v_dot_n_mps2: z,
            c_b_n: Mat3::zeros(),
            omega_nb_b_rps: z,
        }; N];
        for (i, k) in kin.iter_mut().enumerate() {
            *k = traj.kinematics_phased(t0, oa + rule.c[i] * hp, t_sel, b, &nodes[i]);
        }
        let lat_a = self.cfg.lat0_rad + self.dlat;
        let (s_a, c_a) = self.sin_cos_lat(lat_a);
        // height at the nodes: collocation quadrature of −v_D
        let vd: [f64; N] = std::array::from_fn(|i| -kin[i].v_n_mps.z);
        let hs = (rule.stage)(vd);
        let h_n: [f64; N] = std::array::from_fn(|i| self.h + hp * hs[i]);
        let h_b = self.h + hp * (rule.mean)(vd);
        // latitude and longitude rates; the flat model moves over the ellipsoid at the
        // start latitude (as the RK4 reference does)
        let flat = !e.transport;
        let (r0, cos0) = if flat {
            let l0 = self.cfg.lat0_rad;
            (e.radii(l0), libm::cos(l0))
        } else {
            (e.radii_sin(s_a), c_a)
        };
        // predictor: R_M at the panel start latitude
        let pred = (rule.stage)(std::array::from_fn(|i| {
            kin[i].v_n_mps.x / (r0.r_m_m + h_n[i])
        }));
        let mut th = [[0.0; N]; 3];
        let mut f = [[0.0; N]; 3];
        let mut lat_dot = [0.0; N];
        let mut lon_dot = [0.0; N];
        for i in 0..N {
            let (k, h) = (&kin[i], h_n[i]);
            let (s, c) = sin_cos_shift(s_a, c_a, hp * pred[i]);
            let le = e.local_sc(s, c, h);
            let v = k.v_n_mps;
            let w_ie = e.omega_ie_n_local(&le);
            let w_en = e.omega_en_n_local(&le, h, &v);
            let c_n_b = k.c_b_n.transpose();
            let th_i = k.omega_nb_b_rps + c_n_b * (w_ie + w_en);
            let mut f_i = c_n_b
                * (k.v_dot_n_mps2 + (2.0 * w_ie + w_en).cross(&v) - Vec3::new(0.0, 0.0, le.g_mps2));
            if let Some(m) = &self.mount {
                let d_n = k.c_b_n * m.lever_arm_b_m;
                let (s2, c2) = sin_cos_shift(s, c, d_n.x / (le.r_m_m + h));
                let g2 = e.local_sc(s2, c2, h - d_n.z).g_mps2;
                let dg = gravity_difference(&e, &le, h, &w_ie, &d_n, g2);
                f_i += th_i.cross(&th_i.cross(&m.lever_arm_b_m)) - c_n_b * dg;
            }
            for a in 0..3 {
                th[a][i] = th_i[a];
                f[a][i] = f_i[a];
            }
            if flat {
                lat_dot[i] = v.x / (r0.r_m_m + h);
                lon_dot[i] = v.y / ((r0.r_n_m + h) * cos0);
            } else {
                lat_dot[i] = v.x / (le.r_m_m + h);
                lon_dot[i] = v.y / ((le.r_n_m + h) * c);
            }
        }
        self.dlat += hp * (rule.mean)(lat_dot);
        self.dlon += hp * (rule.mean)(lon_dot);
        self.h = h_b;
        let mean3 =
            |y: [[f64; N]; 3]| Vec3::new((rule.mean)(y[0]), (rule.mean)(y[1]), (rule.mean)(y[2]));
        (mean3(th) * hp, mean3(f) * hp)
    }
}

impl Iterator for TruthGenerator<'_> {
    type Item = TruthSample;

    fn next(&mut self) -> Option<TruthSample> {
        if self.k >= self.n_samples {
            return None;
        }
        let dt = self.cfg.dt_s;
        let t0 = self.k as f64 * dt;
        self.k += 1;
        let t1 = self.k as f64 * dt;
        let (inc, v_n_mps, c_b_n, sin_cos_lat) = match &self.closed {
            Some(cf) => {
                self.dlon = cf.lon_rate_rps * t1;
                // constant state: velocity, attitude and latitude are those of t = 0
                (cf.inc, cf.v_n_mps, cf.c_b_n, cf.sin_cos_lat)
            }
            None => {
                let w0 = match (&self.mount, self.w_ib_prev) {
                    (None, _) => Vec3::zeros(),
                    (Some(_), Some(w)) => w,
                    (Some(_), None) => self.omega_ib(t0, t0),
                };
                let mut inc = match self.scheme {
                    TruthScheme::Gauss => self.sample_gauss(t0),
                    TruthScheme::Rk4 => self.sample_rk4(t0),
                };
                // attitude and velocity at the sample end are analytic (branch of the
                // last substep); its overlay phases are the next sample's base phases
                let t_sel = t1 - 0.25 * dt / self.cfg.substeps.max(1) as f64;
                // the random-vibration phases advance by one rotation per sample from
                // the sample start's (the same values the increments used), the others
                // are evaluated at t1
                if self.ph_base_t.to_bits() == t0.to_bits() {
                    self.traj
                        .phases_advance(&self.ph_base, &self.ph_step, t1, &mut self.ph_end);
                } else {
                    self.traj.phases_at(t1, &mut self.ph_end);
                }
                let kin = self
                    .traj
                    .kinematics_phased(t1, 0.0, t_sel, &self.ph_end, &self.ph_zero);
                std::mem::swap(&mut self.ph_base, &mut self.ph_end);
                self.ph_base_t = t1;
                if let Some(m) = self.mount {
                    let w1 = self.omega_ib(t1, t_sel);
                    self.w_ib_prev = Some(w1);
                    let dv = inc.dv_b_mps + (w1 - w0).cross(&m.lever_arm_b_m);
                    inc = Increment::new(m.c_b_s * inc.dtheta_b_rad, m.c_b_s * dv);
                }
                let lat_rad = self.cfg.lat0_rad + self.dlat;
                (inc, kin.v_n_mps, kin.c_b_n, self.sin_cos_lat(lat_rad))
            }
        };
        Some(TruthSample {
            t_s: t1,
            inc,
            // after the integration of this sample (the closed form keeps dlat = 0)
            lat_rad: self.cfg.lat0_rad + self.dlat,
            lon_rad: wrap_pi(self.cfg.lon0_rad + self.dlon),
            h_m: self.h,
            v_n_mps,
            c_b_n,
            sin_cos_lat,
        })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = (self.n_samples - self.k) as usize;
        (left, Some(left))
    }
}

/// RK4 substeps per sample for a trajectory: at least 16 (docs/theory/mechanizations.md
/// §"Truth generation"), and enough that
/// the fastest periodic motion advances at most 2e-3 rad per substep. RK4 on a pure
/// quadrature is Simpson's rule, whose error per sample is δt·h⁴·|ω⁗|/2880; for 1 Hz,
/// 0.5° coning at 100 Hz this is 4.5e-17 rad with 16 substeps and 2.8e-18 rad with 32.
/// A recorded trajectory ([`Trajectory::reference`]) also gets panels of at most 1/8 of its
/// shortest row step. Rounded up to a power of two. The default Gauss scheme uses one 3-node panel for 16 and
/// `substeps/32` 4-node panels above, i.e. at most 0.032 rad (3 nodes) or 0.064 rad (4 nodes)
/// of the fastest motion per panel ([`TruthScheme::Gauss`]). Random vibration, whose
/// components reach the Nyquist frequency with tiny amplitudes, is resolved instead by its
/// amplitude-weighted Gauss remainder ([`crate::truth::random_vibration::RandomVibration::gauss_panels`]:
/// at most 1e-17 m/s and 1e-19 rad per sample).
pub fn auto_substeps(dt_s: f64, traj: &Trajectory) -> usize {
    let w_max = traj.max_frequency_rps();
    let mut need = (dt_s * w_max / 2e-3).ceil().clamp(16.0, 4096.0) as usize;
    // random vibration: by the amplitude-weighted Gauss remainder of its components
    let panels = traj.random_vibration_panels(dt_s);
    if panels > 0 {
        need = need.max(32 * panels).min(4096);
    }
    // a recorded trajectory: panels of at most 1/8 of the shortest row step. Where the
    // rows step the angular rate, the C² interpolant turns it within one row h, and the
    // Gauss remainder grows with the interpolant's high derivatives (~Δω/hᵏ): on NaveGo's
    // 20°/s steps one 3-node panel per 5 ms sample leaves 1.6e-10 rad, 4-node panels of
    // h/2 4.6e-15 rad, h/4 1.8e-17 rad, h/8 8.7e-19 rad (the order-8 rate, 2⁸ per halving)
    if let Some(r) = traj.reference() {
        // panels are laid per piece between knots, so a sample holding several rows needs
        // 8 per piece, not per sample
        let p = (8.0 * (dt_s / r.min_step_s()).min(1.0) * (1.0 - 1e-9)).ceil();
        if p > 1.0 {
            need = need.max((32.0 * p).min(4096.0) as usize);
        }
    }
    need.next_power_of_two()
}

/// Longitude difference wrapped to (−π, π] (for error computation across ±180°).
#[inline]
pub fn lon_diff(a: f64, b: f64) -> f64 {
    // wrap_pi returns values already in range unchanged (no fmod rounding)
    wrap_pi(a - b)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An N-node Gauss rule: the weights integrate degree ≤ 2N − 1 exactly, the
    /// collocation stages degree ≤ N − 1, and degree 2N leaves the remainder
    /// `1/denominator` of its 2N-th derivative.
    fn check_rule<const N: usize>(rule: &Rule<N>, remainder_denominator: f64) {
        for d in 0..2 * N as i32 {
            let y = rule.c.map(|c| (d + 1) as f64 * c.powi(d));
            assert!(
                ((rule.mean)(y) - 1.0).abs() < 4.0 * f64::EPSILON,
                "N={N} degree {d}"
            );
            if d < N as i32 {
                for (i, (st, c)) in (rule.stage)(y).iter().zip(rule.c).enumerate() {
                    assert!(
                        (st - c.powi(d + 1)).abs() < 4.0 * f64::EPSILON,
                        "N={N} degree {d} stage {i}"
                    );
                }
            }
        }
        let d = 2 * N as i32;
        let y = rule.c.map(|c| (d + 1) as f64 * c.powi(d));
        let err = 1.0 - (rule.mean)(y);
        // the 2N-th derivative of (2N + 1) c^(2N) is (2N + 1)!
        let fact: f64 = (1..=d + 1).map(f64::from).product();
        assert!(
            (err - fact / remainder_denominator).abs() < 1e-14,
            "N={N}: {err:e}"
        );
    }

    #[test]
    fn gauss_weights_and_stages_are_exact_for_polynomials() {
        // remainders 1/2 016 000 (3 nodes) and 1/1 778 112 000 (4 nodes) of f^(2N)
        check_rule(&GL3, 2_016_000.0);
        check_rule(&GL4, 1_778_112_000.0);
        // the layout: 4-node panels only where they replace at least two 3-node panels
        assert_eq!(gauss_layout(16), (3, 1));
        assert_eq!(gauss_layout(32), (4, 1));
        assert_eq!(gauss_layout(64), (4, 2));
    }
}

//! The state layout of the error-state filter: one fixed capacity ([`MAX_STATES`]) and a
//! runtime list of blocks, each at an offset with its own process model. Every product of
//! the filter runs over the **active** dimension `n` only (the leading `n × n` block of the
//! fixed-capacity matrices), so the 15-state filter costs what a 15 × 15 filter costs.
//!
//! ## Blocks
//! The navigation and IMU-bias blocks are always first, at fixed offsets (the states of
//! [`super::error_model`]): position 0–2, velocity 3–5, attitude 6–8, accelerometer bias
//! 9–11, gyro bias 12–14. Optional blocks follow in the order they are added (the 21-state
//! filter of earlier versions is the layout with the two scale-factor blocks at 15–17 and
//! 18–20).
//!
//! Convention: navigation states are **estimate − truth**; every other block is the
//! residual error of a sensor parameter, **truth − estimate** (`b − b̂`, `s − ŝ`), so that
//! the closed-loop correction adds the estimate to the parameter (`b̂ += x̂_b`) and
//! subtracts it from the navigation state. Either way a correction `δ` leaves the error
//! state at `e − δ`.
//!
//! ## Process models ([`Process`], per component of a block)
//! * random constant: `ḃ = 0`;
//! * first-order Gauss–Markov, steady-state σ and correlation time τ:
//!   `ḃ = −b/τ + w`, `q = 2σ²/τ` (Groves 2nd ed. §14.2.6, eq. (14.80) family);
//! * random walk of density K: `ḃ = w`, `q = K²`;
//! * Gauss–Markov plus random walk (the IMU biases of the noise model): `q = K² + 2σ²/τ`;
//! * the two-state receiver clock (bias in m, drift in m/s; Brown & Hwang, *Introduction to
//!   Random Signals and Applied Kalman Filtering*, 4th ed., §9.3, with the Allan-variance
//!   coefficients h₀ (white frequency) and h₋₂ (random-walk frequency)): the exact discrete
//!   process noise over Δt is
//!   `q_bb = c²(h₀/2·Δt + 2π²h₋₂Δt³/3)`, `q_bd = c²π²h₋₂Δt²`, `q_dd = c²·2π²h₋₂Δt`, and
//!   `Φ = [[1, Δt], [0, 1]]`.
//!
//! The couplings of a block into the navigation-error dynamics are fixed by its kind: the
//! biases through `C_b^n` (Groves (14.64)–(14.70)), the scale factors through
//! `C_b^n diag(f^b)` and `C_b^n diag(ω_ib^b)` (Groves §14.2, "additional IMU error states");
//! the other sensor blocks enter only the measurement models.

use nalgebra::{SMatrix, SVector};

/// State capacity of the filter (fixed): 15 navigation and IMU-bias states, 6 IMU scale
/// factors and 11 more for sensor blocks (odometer scale factor, barometer bias and scale,
/// magnetometer hard iron or heading bias, vehicle-frame misalignment, receiver clock).
pub const MAX_STATES: usize = 32;
/// Largest number of blocks of a layout.
pub const MAX_BLOCKS: usize = 16;

/// Covariance, transition and system matrices at the fixed capacity (only the leading
/// `n × n` block is used).
pub type Cov = SMatrix<f64, MAX_STATES, MAX_STATES>;
/// A state vector at the fixed capacity (only the first `n` entries are used).
pub type XVec = SVector<f64, MAX_STATES>;

/// What a block of states is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum BlockKind {
    /// δL, δλ, δh \[rad, rad, m\]
    Position,
    /// δv^n \[m/s\]
    Velocity,
    /// ε, `Ĉ = (I + [ε×]) C` \[rad\]
    Attitude,
    /// accelerometer residual bias, body \[m/s²\]
    AccelBias,
    /// gyro residual bias, body \[rad/s\]
    GyroBias,
    /// accelerometer scale-factor error, body \[1\]
    AccelScale,
    /// gyro scale-factor error, body \[1\]
    GyroScale,
    /// odometer scale-factor error \[1\]
    OdometerScale,
    /// barometric altimeter bias \[m\]
    BaroBias,
    /// barometric altimeter scale-factor error \[1\]
    BaroScale,
    /// heading (magnetic or dual-antenna) bias \[rad\]
    HeadingBias,
    /// magnetometer hard iron, body \[µT\]
    MagHardIron,
    /// vehicle-frame misalignment (pitch, yaw) of the body frame \[rad\]
    VehicleMisalignment,
    /// receiver clock bias \[m\] and drift \[m/s\]
    Clock,
}

impl BlockKind {
    /// Short name (CSV columns, Monte Carlo statistics).
    pub fn name(self) -> &'static str {
        match self {
            BlockKind::Position => "position",
            BlockKind::Velocity => "velocity",
            BlockKind::Attitude => "attitude",
            BlockKind::AccelBias => "accel_bias",
            BlockKind::GyroBias => "gyro_bias",
            BlockKind::AccelScale => "accel_scale",
            BlockKind::GyroScale => "gyro_scale",
            BlockKind::OdometerScale => "odometer_scale",
            BlockKind::BaroBias => "baro_bias",
            BlockKind::BaroScale => "baro_scale",
            BlockKind::HeadingBias => "heading_bias",
            BlockKind::MagHardIron => "mag_hard_iron",
            BlockKind::VehicleMisalignment => "vehicle_misalignment",
            BlockKind::Clock => "clock",
        }
    }
    /// Whether the block is part of the navigation state (corrected by subtraction).
    pub fn is_navigation(self) -> bool {
        matches!(
            self,
            BlockKind::Position | BlockKind::Velocity | BlockKind::Attitude
        )
    }
}

/// Process model of one scalar state: `ḃ = −b/τ + w`, `E[w w] = q δ(t)`; `τ = ∞` is no decay.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Process {
    /// correlation time τ \[s\] (`f64::INFINITY`: random constant or random walk)
    pub tau_s: f64,
    /// white-noise density q \[unit²/s\]
    pub q: f64,
}

impl Process {
    /// A random constant.
    pub const CONSTANT: Process = Process {
        tau_s: f64::INFINITY,
        q: 0.0,
    };
    /// First-order Gauss–Markov of steady-state σ and correlation time τ: `q = 2σ²/τ`.
    pub fn gauss_markov(sigma: f64, tau_s: f64) -> Self {
        Self::gauss_markov_rw(sigma, tau_s, 0.0)
    }
    /// Random walk of density K \[unit/√s\]: `q = K²`.
    pub fn random_walk(k: f64) -> Self {
        Self::gauss_markov_rw(0.0, f64::INFINITY, k)
    }
    /// Gauss–Markov (σ, τ; ignored when τ is not finite and positive) plus a random walk K:
    /// `q = K² + 2σ²/τ`.
    pub fn gauss_markov_rw(sigma: f64, tau_s: f64, k: f64) -> Self {
        let mut q = k * k;
        let gm = tau_s.is_finite() && tau_s > 0.0;
        if gm {
            q += 2.0 * sigma * sigma / tau_s;
        }
        Self {
            tau_s: if gm { tau_s } else { f64::INFINITY },
            q,
        }
    }
    /// `−1/τ` (0 without decay): the diagonal entry of F.
    pub fn f_diag(&self) -> f64 {
        if self.tau_s.is_finite() {
            -1.0 / self.tau_s
        } else {
            0.0
        }
    }
}

/// Process model of a block.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum BlockProcess {
    /// driven by the navigation-error model (position, velocity, attitude)
    Navigation,
    /// one scalar process per component
    PerAxis([Process; 3]),
    /// receiver clock, components (bias \[m\], drift \[m/s\]); Allan-variance coefficients
    /// h₀ \[s\] and h₋₂ \[1/s\] of the fractional frequency
    Clock {
        /// white-frequency coefficient h₀
        h0: f64,
        /// random-walk-frequency coefficient h₋₂
        h_m2: f64,
    },
}

/// One block of states.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Block {
    /// what the block is
    pub kind: BlockKind,
    /// index of its first state
    pub offset: usize,
    /// number of states
    pub dim: usize,
    /// its process model
    pub process: BlockProcess,
}

/// Speed of light \[m/s\] (the clock block's unit conversion).
pub const C_LIGHT_MPS: f64 = 299_792_458.0;

/// Why a layout cannot be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum LayoutError {
    /// more than [`MAX_STATES`] states or [`MAX_BLOCKS`] blocks
    Capacity,
    /// the block kind is already present
    Duplicate(BlockKind),
    /// a process parameter is not finite or negative
    BadProcess(BlockKind),
}

impl core::fmt::Display for LayoutError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            LayoutError::Capacity => write!(
                f,
                "state layout: more than {MAX_STATES} states or {MAX_BLOCKS} blocks"
            ),
            LayoutError::Duplicate(k) => write!(f, "state layout: block `{}` twice", k.name()),
            LayoutError::BadProcess(k) => write!(
                f,
                "state layout: block `{}` has a non-finite or negative process parameter",
                k.name()
            ),
        }
    }
}

impl core::error::Error for LayoutError {}

/// The blocks of a filter and its active dimension.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StateLayout {
    blocks: [Block; MAX_BLOCKS],
    count: usize,
    n: usize,
}

impl StateLayout {
    /// The 15 navigation and IMU-bias states; the bias processes per axis (accelerometer,
    /// gyro).
    pub fn ins(accel_bias: [Process; 3], gyro_bias: [Process; 3]) -> Self {
        let nav = |kind, offset| Block {
            kind,
            offset,
            dim: 3,
            process: BlockProcess::Navigation,
        };
        let mut blocks = [nav(BlockKind::Position, 0); MAX_BLOCKS];
        blocks[1] = nav(BlockKind::Velocity, 3);
        blocks[2] = nav(BlockKind::Attitude, 6);
        blocks[3] = Block {
            kind: BlockKind::AccelBias,
            offset: 9,
            dim: 3,
            process: BlockProcess::PerAxis(accel_bias),
        };
        blocks[4] = Block {
            kind: BlockKind::GyroBias,
            offset: 12,
            dim: 3,
            process: BlockProcess::PerAxis(gyro_bias),
        };
        Self {
            blocks,
            count: 5,
            n: 15,
        }
    }

    /// Append a block of `dim` states (1–3; the clock is 2) with the given process.
    pub fn with(
        mut self,
        kind: BlockKind,
        dim: usize,
        process: BlockProcess,
    ) -> Result<Self, LayoutError> {
        if self.has(kind) {
            return Err(LayoutError::Duplicate(kind));
        }
        let ok = match process {
            BlockProcess::Navigation => false,
            BlockProcess::PerAxis(p) => p
                .iter()
                .all(|x| x.q.is_finite() && x.q >= 0.0 && x.tau_s > 0.0),
            BlockProcess::Clock { h0, h_m2 } => {
                dim == 2 && h0.is_finite() && h0 >= 0.0 && h_m2.is_finite() && h_m2 >= 0.0
            }
        };
        if !ok || dim == 0 || dim > 3 {
            return Err(LayoutError::BadProcess(kind));
        }
        if self.count >= MAX_BLOCKS || self.n + dim > MAX_STATES {
            return Err(LayoutError::Capacity);
        }
        self.blocks[self.count] = Block {
            kind,
            offset: self.n,
            dim,
            process,
        };
        self.count += 1;
        self.n += dim;
        Ok(self)
    }

    /// The 21-state layout of earlier versions: [`StateLayout::ins`] plus the accelerometer
    /// and gyro scale factors as random constants (states 15–17, 18–20).
    pub fn with_scale_factors(self) -> Result<Self, LayoutError> {
        let c = BlockProcess::PerAxis([Process::CONSTANT; 3]);
        self.with(BlockKind::AccelScale, 3, c)?
            .with(BlockKind::GyroScale, 3, c)
    }

    /// Active dimension n.
    pub fn n(&self) -> usize {
        self.n
    }
    /// The blocks, in state order.
    pub fn blocks(&self) -> &[Block] {
        &self.blocks[..self.count]
    }
    /// The block of a kind.
    pub fn block(&self, kind: BlockKind) -> Option<&Block> {
        self.blocks().iter().find(|b| b.kind == kind)
    }
    /// Offset of a block.
    pub fn offset(&self, kind: BlockKind) -> Option<usize> {
        self.block(kind).map(|b| b.offset)
    }
    /// Whether the layout has a block.
    pub fn has(&self, kind: BlockKind) -> bool {
        self.block(kind).is_some()
    }

    /// Add the process models to the system matrix `f` and the white-noise density `qc`
    /// (per component: `F_ii = −1/τ`, `Qc_ii = q`; the clock: `F = [[0, 1], [0, 0]]` and no
    /// `Qc`: its exact discrete noise is added by [`StateLayout::add_exact_q`]).
    pub fn add_processes(&self, f: &mut Cov, qc: &mut Cov) {
        for b in self.blocks() {
            match b.process {
                BlockProcess::Navigation => {}
                BlockProcess::PerAxis(p) => {
                    for (i, pi) in p.iter().enumerate().take(b.dim) {
                        let k = b.offset + i;
                        // the random constant / random walk leaves F_kk = 0 (not −0)
                        if pi.tau_s.is_finite() {
                            f[(k, k)] = pi.f_diag();
                        }
                        qc[(k, k)] = pi.q;
                    }
                }
                BlockProcess::Clock { .. } => {
                    f[(b.offset, b.offset + 1)] = 1.0;
                }
            }
        }
    }

    /// Add the exact discrete process noise of the blocks that declare one (the clock) to
    /// `q` over the interval `dt_s`.
    pub fn add_exact_q(&self, q: &mut Cov, dt_s: f64) {
        for b in self.blocks() {
            if let BlockProcess::Clock { h0, h_m2 } = b.process {
                let [bb, bd, dd] = clock_q(h0, h_m2, dt_s);
                let o = b.offset;
                q[(o, o)] += bb;
                q[(o, o + 1)] += bd;
                q[(o + 1, o)] += bd;
                q[(o + 1, o + 1)] += dd;
            }
        }
    }
}

/// Exact discrete process noise of the two-state clock over `dt_s` (Brown & Hwang §9.3):
/// `[q_bb, q_bd, q_dd]` in m², m²/s, m²/s².
pub fn clock_q(h0: f64, h_m2: f64, dt_s: f64) -> [f64; 3] {
    let c2 = C_LIGHT_MPS * C_LIGHT_MPS;
    let pi2 = core::f64::consts::PI * core::f64::consts::PI;
    let t = dt_s;
    [
        c2 * (h0 / 2.0 * t + 2.0 * pi2 * h_m2 * t * t * t / 3.0),
        c2 * pi2 * h_m2 * t * t,
        c2 * 2.0 * pi2 * h_m2 * t,
    ]
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn layouts_and_offsets() {
        let l = StateLayout::ins([Process::CONSTANT; 3], [Process::CONSTANT; 3]);
        assert_eq!(l.n(), 15);
        assert_eq!(l.offset(BlockKind::GyroBias), Some(12));
        let l = l.with_scale_factors().unwrap();
        assert_eq!(l.n(), 21);
        assert_eq!(l.offset(BlockKind::AccelScale), Some(15));
        assert_eq!(l.offset(BlockKind::GyroScale), Some(18));
        assert_eq!(
            l.with(
                BlockKind::AccelScale,
                3,
                BlockProcess::PerAxis([Process::CONSTANT; 3])
            ),
            Err(LayoutError::Duplicate(BlockKind::AccelScale))
        );
        let l = l
            .with(
                BlockKind::Clock,
                2,
                BlockProcess::Clock {
                    h0: 2e-19,
                    h_m2: 2e-20,
                },
            )
            .unwrap();
        assert_eq!(l.offset(BlockKind::Clock), Some(21));
        assert_eq!(l.n(), 23);
        // capacity: 32 states at most
        let big = l
            .with(
                BlockKind::MagHardIron,
                3,
                BlockProcess::PerAxis([Process::CONSTANT; 3]),
            )
            .unwrap()
            .with(
                BlockKind::VehicleMisalignment,
                2,
                BlockProcess::PerAxis([Process::CONSTANT; 3]),
            )
            .unwrap()
            .with(
                BlockKind::OdometerScale,
                1,
                BlockProcess::PerAxis([Process::CONSTANT; 3]),
            )
            .unwrap()
            .with(
                BlockKind::BaroBias,
                1,
                BlockProcess::PerAxis([Process::gauss_markov(1.0, 600.0); 3]),
            )
            .unwrap()
            .with(
                BlockKind::BaroScale,
                1,
                BlockProcess::PerAxis([Process::CONSTANT; 3]),
            )
            .unwrap()
            .with(
                BlockKind::HeadingBias,
                1,
                BlockProcess::PerAxis([Process::CONSTANT; 3]),
            )
            .unwrap();
        assert_eq!(big.n(), 32);
        assert_eq!(
            big.with(
                BlockKind::Position,
                1,
                BlockProcess::PerAxis([Process::CONSTANT; 3])
            ),
            Err(LayoutError::Duplicate(BlockKind::Position))
        );
        let bad = StateLayout::ins([Process::CONSTANT; 3], [Process::CONSTANT; 3]).with(
            BlockKind::BaroBias,
            1,
            BlockProcess::PerAxis(
                [Process {
                    tau_s: -1.0,
                    q: 1.0,
                }; 3],
            ),
        );
        assert_eq!(bad, Err(LayoutError::BadProcess(BlockKind::BaroBias)));
    }

    #[test]
    fn process_q() {
        let p = Process::gauss_markov(2.0, 100.0);
        assert_eq!(p.q, 2.0 * 4.0 / 100.0);
        assert_eq!(p.f_diag(), -0.01);
        let r = Process::random_walk(3.0);
        assert_eq!((r.q, r.f_diag()), (9.0, 0.0));
        let c = Process::gauss_markov(2.0, f64::INFINITY);
        assert_eq!(c, Process::CONSTANT);
    }

    /// The clock's exact discrete Q against the integral ∫ Φ(s) Qc Φ(s)ᵀ ds of the
    /// continuous model (`S_f = c²h₀/2`, `S_g = 2π²c²h₋₂`), by Simpson's rule (exact for
    /// this cubic integrand).
    #[test]
    fn clock_q_is_the_integral_of_the_continuous_model() {
        let (h0, hm2, t) = (9.4e-20, 3.8e-21, 1.7);
        let c2 = C_LIGHT_MPS * C_LIGHT_MPS;
        let (sf, sg) = (
            c2 * h0 / 2.0,
            2.0 * core::f64::consts::PI.powi(2) * c2 * hm2,
        );
        // Φ(s) = [[1, s], [0, 1]]: Φ Qc Φᵀ = [[S_f + S_g s², S_g s], [S_g s, S_g]]
        let f = |s: f64| [sf + sg * s * s, sg * s, sg];
        let (a, m, b) = (f(0.0), f(t / 2.0), f(t));
        let q = clock_q(h0, hm2, t);
        for i in 0..3 {
            let simpson = t / 6.0 * (a[i] + 4.0 * m[i] + b[i]);
            assert!((q[i] - simpson).abs() <= 1e-12 * simpson.abs(), "{i}");
        }
    }
}

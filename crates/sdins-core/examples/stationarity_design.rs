//! Prints the design tables of docs/theory/aiding-sensors.md §"Stationarity detection":
//! thresholds from the noise model, and the predicted probability of declaring a window
//! moving under vibration and steady offsets, for a tactical IMU at 200 Hz.
//!
//! `cargo run --release -p sdins-core --example stationarity_design`
use sdins_core::aiding::stationarity::{
    MotionModel, NoiseModel, StationarityDetector, StationarityError,
};

const D2R: f64 = core::f64::consts::PI / 180.0;
const DPH: f64 = D2R / 3600.0;
const G: f64 = 9.80665;
const DT: f64 = 0.005;

fn noise(sigma_ba: f64, sigma_bg: f64) -> Result<NoiseModel, StationarityError> {
    // ARW 0.003 °/√h, VRW 0.03 m/s/√h
    NoiseModel::from_random_walks(0.03 / 60.0, 0.003 * D2R / 60.0, DT, sigma_ba, sigma_bg)
}

fn row<const W: usize>(
    alpha: f64,
    n: NoiseModel,
) -> Result<StationarityDetector<W>, StationarityError> {
    let d = StationarityDetector::<W>::from_noise_model(n, DT, G, alpha)?;
    let (ka, kg) = n.kappas(W);
    println!(
        "| {W} | {alpha:e} | {:.3} | {:.3} | {:.4} | {:.4} |",
        ka,
        kg,
        d.threshold(),
        d.threshold() * W as f64
    );
    Ok(d)
}

fn main() -> Result<(), StationarityError> {
    let n0 = noise(0.0, 0.0)?;
    println!(
        "σ_a = {:.4e} m/s², σ_g = {:.4e} rad/s ({:.3} °/h)",
        n0.sigma_accel_mps2,
        n0.sigma_gyro_rps,
        n0.sigma_gyro_rps / DPH
    );
    println!("| W | α | κ_a | κ_g | γ | W·γ |");
    println!("|---|---|---|---|---|---|");
    for alpha in [1e-2, 1e-3, 1e-6] {
        row::<20>(alpha, n0)?;
        row::<200>(alpha, n0)?;
    }
    // residual biases 100 μg and 0.1 °/h, then 1 mg and 1 °/h
    for (ba, bg) in [(100e-6 * G, 0.1 * DPH), (1e-3 * G, 1.0 * DPH)] {
        row::<20>(1e-3, noise(ba, bg)?)?;
        row::<200>(1e-3, noise(ba, bg)?)?;
    }
    println!();
    println!("P(declared moving), W = 200, α = 1e-3, residual 100 μg / 0.1 °/h:");
    let d =
        StationarityDetector::<200>::from_noise_model(noise(100e-6 * G, 0.1 * DPH)?, DT, G, 1e-3)?;
    let sa = n0.sigma_accel_mps2;
    println!("| a_v/σ_a | a_v [m/s²] | P(moving) |");
    println!("|---|---|---|");
    for r in [0.0, 0.2, 0.3, 0.4, 0.5, 0.6, 0.8, 1.0] {
        let m = MotionModel {
            vibration_accel_mps2: r * sa,
            ..MotionModel::default()
        };
        let p = d.probability_declared_moving(&m)?;
        println!("| {r} | {:.2e} | {p:.4} |", r * sa);
    }
    println!("| δω [°/h] | P(moving) |");
    println!("|---|---|");
    for w in [0.5, 1.0, 2.0, 3.0, 5.0, 10.0] {
        let m = MotionModel {
            mean_rate_offset_rps: w * DPH,
            ..MotionModel::default()
        };
        let p = d.probability_declared_moving(&m)?;
        println!("| {w} | {p:.4} |");
    }
    println!("| horizontal a [m/s²] | ‖f̄‖ − g [m/s²] | P(moving) |");
    println!("|---|---|---|");
    for a in [0.05, 0.1, 0.2, 0.3, 0.5, 1.0] {
        let off = (G * G + a * a).sqrt() - G;
        let m = MotionModel {
            mean_accel_offset_mps2: off,
            ..MotionModel::default()
        };
        let p = d.probability_declared_moving(&m)?;
        println!("| {a} | {off:.2e} | {p:.4} |");
    }
    Ok(())
}

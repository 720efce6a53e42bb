//! The navigation core as it would run on a flight computer: no allocation, one
//! `update` per N IMU samples. Here the samples are those of a vehicle at rest at 45°N
//! (constant increments), and the example prints the state after one hour.
//!
//! `cargo run --release -p sdins-core --example flight_loop`
use sdins_core::coning::Increment;
use sdins_core::earth::EarthModel;
use sdins_core::math::{c_b_n_from_euler, Euler, Vec3};
use sdins_core::nav::{
    AlgorithmKind, AlgorithmSpec, AnyMechanization, InitialState, Mechanization,
};

fn main() {
    let earth = EarthModel::WGS84;
    let lat = 45f64.to_radians();
    let dt = 0.01; // 100 Hz IMU
    let c_b_n = c_b_n_from_euler(&Euler::new(0.0, 0.0, 0.0));
    // stationary increments: Δθ = C_n^b ω_ie^n δt, Δv = −C_n^b g^n δt
    let inc = Increment::new(
        c_b_n.transpose() * earth.omega_ie_n(lat) * dt,
        -(c_b_n.transpose() * earth.gravity_n(lat, 0.0)) * dt,
    );
    let init = InitialState {
        lat_rad: lat,
        lon_rad: 0.0,
        h_m: 0.0,
        v_n_mps: Vec3::zeros(),
        c_b_n,
    };
    let spec = AlgorithmSpec::new(AlgorithmKind::SongLeeComplete, 2);
    let mut nav = AnyMechanization::new(&spec, earth, dt, &init);
    let samples = [inc; 2];
    for _ in 0..180_000 {
        nav.update(&samples); // 2 samples per update, 1 hour
    }
    let s = nav.state();
    println!(
        "after {:.0} s at rest: lat {:.12}°, lon {:.3e}°, h {:.3e} m, |v| {:.3e} m/s",
        s.t_s,
        s.lat_rad.to_degrees(),
        s.lon_rad.to_degrees(),
        s.h_m,
        s.v_n_mps.norm()
    );
}

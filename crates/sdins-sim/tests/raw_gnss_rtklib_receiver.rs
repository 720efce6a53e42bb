//! RTKLIB as an outside receiver: a RINEX 3.04 observation/navigation pair written from
//! geometry computed here (nominal 24-slot constellation, light time with Earth rotation,
//! satellite clocks, white pseudorange noise only) is solved by RTKLIB's `rnx2rtkp`, which
//! must recover the static antenna position within the DOP-predicted σ. Skips visibly when
//! `rnx2rtkp` is not installed.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{Matrix4, Vector4};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use sdins_core::earth::EarthModel;
use sdins_core::gnss::{elevation_azimuth, nominal_constellation, transit, GpsTime, C_MPS};
use sdins_core::math::Vec3;
use sdins_sim::io::rinex::{
    nav_to_rinex3, obs_to_rinex3, NavFile, ObsCode, ObsEpoch, ObsFile, ObsHeader, ObsValue, SatObs,
};
use std::process::Command;

#[test]
fn rnx2rtkp_recovers_a_static_position_from_our_rinex() {
    if Command::new("rnx2rtkp").arg("-?").output().is_err() {
        let msg = "SKIPPED: rnx2rtkp (RTKLIB) is not installed: apt-get install rtklib";
        eprintln!("{msg}");
        println!("{msg}");
        return;
    }
    let earth = EarthModel::WGS84;
    let (lat, lon, h) = (45.2_f64.to_radians(), 7.6_f64.to_radians(), 310.0);
    let r = earth.ecef_from_geodetic(lat, lon, h);
    let c_e_n = EarthModel::c_e_n(lat, lon);
    let t0 = GpsTime::from_calendar(2024, 3, 5, 10, 0, 0.0);
    let mut ephs = nominal_constellation(t0).to_vec();
    for (k, e) in ephs.iter_mut().enumerate() {
        e.af0_s = 2e-5 * (k as f64 - 11.5); // up to ±70 km: RTKLIB must apply the clocks
        e.af1_sps = 1e-11;
    }
    let sigma = 1.0; // white pseudorange noise [m]
    let dt_rx_s = 2.5e-4; // receiver clock bias: the epoch tags are receiver time
    let mask = 10f64.to_radians();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(20240305);
    let noise = Normal::new(0.0, sigma).unwrap();
    let n_epochs = 120;
    let mut epochs = Vec::new();
    let mut q_pred = Vec::new(); // predicted NED covariance per epoch, σ² (GᵀG)⁻¹ of the masked set
    for k in 0..n_epochs {
        let t = t0.add_s(10.0 * k as f64);
        let mut sats = Vec::new();
        let mut g = Matrix4::<f64>::zeros();
        for e in &ephs {
            let tr = transit(e, &t, &r).unwrap();
            let u = (tr.r_sat_rx_e_m - r) / tr.range_m;
            let (el, _) = elevation_azimuth(&c_e_n, &u);
            if el < 5f64.to_radians() {
                continue; // below the horizon (RTKLIB's 10° mask removes the rest)
            }
            if el >= mask {
                let un = c_e_n * u;
                let row = Vector4::new(-un.x, -un.y, -un.z, 1.0);
                g += row * row.transpose();
            }
            let p = tr.range_m + C_MPS * (dt_rx_s - tr.sat.clock_bias_s) + noise.sample(&mut rng);
            let p = (p * 1e3).round() / 1e3; // what F14.3 holds
            sats.push(SatObs {
                prn: e.prn,
                values: vec![Some(ObsValue {
                    value: p,
                    lli: None,
                    ssi: Some(8),
                })],
            });
        }
        let q = g.try_inverse().unwrap() * (sigma * sigma);
        q_pred.push(q.fixed_view::<3, 3>(0, 0).into_owned());
        epochs.push(ObsEpoch {
            t: t.add_s(dt_rx_s),
            flag: 0,
            rx_clock_offset_s: None,
            sats,
        });
    }
    let obs = ObsFile {
        header: ObsHeader {
            version: 3.04,
            marker_name: "SDINS-STATIC".into(),
            receiver_type: "SDINS".into(),
            approx_position_e_m: Some([r.x, r.y, r.z]),
            antenna_delta_hen_m: [0.0; 3],
            gps_types: vec![ObsCode::new("C1C").unwrap()],
            interval_s: Some(10.0),
            first_obs: None,
        },
        epochs,
    };
    let nav = NavFile {
        version: 3.04,
        klobuchar: None,
        ephemerides: ephs,
        skipped_records: 0,
    };
    let dir = std::env::temp_dir().join(format!("sdins-rtklib-rx-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (po, pn, pc, pp) = (
        dir.join("s.obs"),
        dir.join("s.nav"),
        dir.join("s.conf"),
        dir.join("s.pos"),
    );
    std::fs::write(&po, obs_to_rinex3(&obs)).unwrap();
    std::fs::write(&pn, nav_to_rinex3(&nav)).unwrap();
    // single point, L1, 10° mask, no atmosphere (none was simulated)
    let conf = "pos1-posmode =single\npos1-frequency =l1\npos1-elmask =10\npos1-ionoopt =off\npos1-tropopt =off\npos1-navsys =1\nout-solformat =xyz\n";
    std::fs::write(&pc, conf).unwrap();
    let st = Command::new("rnx2rtkp")
        .arg("-k")
        .arg(&pc)
        .arg("-o")
        .arg(&pp)
        .arg(&po)
        .arg(&pn)
        .stderr(std::process::Stdio::null())
        .status()
        .unwrap();
    assert!(st.success());
    let sols: Vec<Vec3> = std::fs::read_to_string(&pp)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('%'))
        .map(|l| {
            let f: Vec<f64> = l
                .split_whitespace()
                .skip(2)
                .take(3)
                .map(|s| s.parse().unwrap())
                .collect();
            Vec3::new(f[0], f[1], f[2])
        })
        .collect();
    assert_eq!(sols.len(), n_epochs, "RTKLIB solved every epoch");
    // normalised errors: eᵀ P⁻¹ e is χ²(3) per epoch when the DOP-predicted covariance holds
    let (mut chi2, mut sum) = (0.0, Vec3::zeros());
    for (s, q) in sols.iter().zip(&q_pred) {
        let e = c_e_n * (s - r);
        chi2 += (e.transpose() * q.try_inverse().unwrap() * e)[(0, 0)];
        sum += e;
    }
    let mean_chi2 = chi2 / n_epochs as f64;
    let mean = sum / n_epochs as f64;
    println!("rnx2rtkp on {n_epochs} simulated epochs: mean eᵀP⁻¹e = {mean_chi2:.2} (3 expected), mean error NED [{:.3}, {:.3}, {:.3}] m", mean.x, mean.y, mean.z);
    // E = 3, sd of the mean of 120 χ²(3) = √(6/120) = 0.22: ±4 sd; RTKLIB's near-equal
    // weights (URA, iono and tropo variances dominate its model) cost little efficiency
    assert!((2.1..=3.9).contains(&mean_chi2), "{mean_chi2}");
    // the mean error: each axis within 4 σ/√n of zero (σ ≤ 2.5 m for PDOP ≤ 2.5)
    for k in 0..3 {
        let s_k = (q_pred.iter().map(|q| q[(k, k)]).sum::<f64>() / n_epochs as f64).sqrt();
        assert!(
            mean[k].abs() <= 4.0 * s_k / (n_epochs as f64).sqrt(),
            "axis {k}: {} vs σ {s_k}",
            mean[k]
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

//! One fusion loop, two front ends: a scenario fused in memory (the stream generated from
//! the exact truth) and the same scenario's IMU record and GNSS fixes written to files
//! (shortest round-trip decimals, Rust's `{}` for f64) and fused through the readers give
//! bit-identical estimates, covariances, innovations and smoothed states.
#![allow(clippy::unwrap_used)]

use sdins_core::aiding::ekf::UpdateReport;
use sdins_core::nav::NavState;
use sdins_sim::cancel::CancelToken;
use sdins_sim::fusion::files::{fuse_files, FilesInput, InitSource, SensorModelSource};
use sdins_sim::fusion::records::{record_from_scenario_with_aiding, RecordEvent, RecordOptions};
use sdins_sim::fusion::simulated::{
    fuse_scenario, FuseEvent, FuseOptions, InitSigma, ScaleFactorPrior,
};
use sdins_sim::io::gnss_file::{GnssFormat, GnssReadOptions, ImuClock};
use sdins_sim::io::imu_file::ImuFormat;
use sdins_sim::scenario::Scenario;
use sdins_sim::sensors::gnss::GnssConfig;
use std::fmt::Write as _;

/// The aiding sensors of the two-path test: dyadic rates, so that every time of validity
/// is exact in binary and in the file's decimals (the odometer without NHC rows: their
/// simulated violation has no place in a record, where the constraint is zero).
const AIDING: &str = "[baro]\nrate_hz = 1.0\n[odometer]\nrate_hz = 8.0\n[magnetometer]\nrate_hz = 4.0\n[dual_antenna]\nrate_hz = 2.0\nbaseline_b_m = [0.5, 1.5, 0.0]\n[body_velocity]\nrate_hz = 8.0\nlever_arm_b_m = [1.0, 0.0, 0.5]\n";

/// The sensors' settings as an aiding TOML for the records written by [`write_aiding`].
const AIDING_FILES: &str = "[baro]\nfile = \"baro.csv\"\n[odometer]\nfile = \"odo.csv\"\n[magnetometer]\nfile = \"mag.csv\"\n[dual_antenna]\nfile = \"dual.csv\"\ncolumns = \"t_s=t_s,az_rad=az_rad,el_rad=el_rad\"\nbaseline_b_m = [0.5, 1.5, 0.0]\n[body_velocity]\nfile = \"dvl.csv\"\nlever_arm_b_m = [1.0, 0.0, 0.5]\ncolumns = \"t_ms=time,v_x_mps=vx,v_y_mps=vy,v_z_mps=vz\"\n";

/// Each aiding sensor's record in `dir` (the body-velocity record in milliseconds under
/// its own header, read through a column map).
fn write_aiding(dir: &std::path::Path, meas: &[sdins_core::aiding::sensors::AidingMeas]) {
    use sdins_core::aiding::sensors::AidingMeas as A;
    let mut f: [String; 5] = [
        "t_s,h_m\n".into(),
        "t_s,speed_mps\n".into(),
        "t_s,m_x_ut,m_y_ut,m_z_ut\n".into(),
        "t_s,az_rad,el_rad\n".into(),
        "time,vx,vy,vz\n".into(),
    ];
    for m in meas {
        match m {
            A::Baro(b) => writeln!(f[0], "{},{}", b.t_s, b.h_baro_m),
            A::Odometer(o) => writeln!(f[1], "{},{}", o.t_s, o.speed_mps),
            A::Magnetometer(g) => {
                let v = g.m_b_ut;
                writeln!(f[2], "{},{},{},{}", g.t_s, v.x, v.y, v.z)
            }
            A::DualAntenna(d) => writeln!(f[3], "{},{},{}", d.t_s, d.az_rad, d.el_rad),
            A::BodyVelocity(b) => {
                let v = b.v_v_mps;
                writeln!(f[4], "{},{},{},{}", b.t_s * 1e3, v.x, v.y, v.z)
            }
            _ => Ok(()),
        }
        .unwrap();
    }
    for (name, text) in ["baro", "odo", "mag", "dual", "dvl"].iter().zip(&f) {
        std::fs::write(dir.join(format!("{name}.csv")), text).unwrap();
    }
    std::fs::write(dir.join("aiding.toml"), AIDING_FILES).unwrap();
}

/// A manoeuvring drive at 128 Hz (a dyadic sample period: the file's sample times are
/// exact, so the reader's mean interval is the scenario's `1/128 s` to the bit), with the
/// sensor tables `aiding`.
fn scenario_with(aiding: &str) -> Scenario {
    let mut segs = String::new();
    for (kind, extra) in [
        ("accelerate", "accel_mps2 = 1.0"),
        ("turn", "rate_dps = 9.0"),
        ("cruise", ""),
        ("accelerate", "accel_mps2 = -0.5"),
        ("turn", "rate_dps = -9.0"),
        ("sturn", "amplitude_dps = 5.0"),
    ] {
        write!(
            segs,
            "[[segment]]\ntype = \"{kind}\"\nduration_s = 10.0\n{extra}\n"
        )
        .unwrap();
    }
    let toml = format!(
        "name = \"two-paths\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\nh_m = 100.0\nspeed_mps = 10.0\nyaw_deg = 30.0\n[imu]\nrate_hz = 128.0\nseed = 11\ngrade = \"tactical\"\n[nav]\nsamples = 2\n{aiding}{segs}{segs}"
    );
    Scenario::from_toml(&toml, "two-paths.toml").unwrap()
}

#[derive(Debug, PartialEq)]
struct Out {
    rows: Vec<(f64, NavState, [f64; 6], [f64; 6])>,
    smoothed: Vec<(f64, NavState, [f64; 6])>,
    updates: Vec<UpdateReport>,
}

fn bits(s: &NavState) -> Vec<u64> {
    let mut v = vec![
        s.t_s.to_bits(),
        s.lat_rad.to_bits(),
        s.lon_rad.to_bits(),
        s.h_m.to_bits(),
    ];
    v.extend(s.v_n_mps.iter().map(|x| x.to_bits()));
    v.extend(s.c_b_n.iter().map(|x| x.to_bits()));
    v
}

#[test]
fn scenario_in_memory_and_through_files_give_bit_identical_estimates() {
    let gnss = GnssConfig::default();
    let run = 4;
    let dir = std::env::temp_dir().join(format!("sdins-two-paths-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (sf, aiding) in [
        (None, false),
        (Some(ScaleFactorPrior::uniform(300.0, 300.0)), false),
        (None, true),
    ] {
        let scn = scenario_with(if aiding { AIDING } else { "" });
        let every = 0.25;
        // in memory
        let opts = FuseOptions {
            draw_initial_errors: false,
            smooth: true,
            nhc_sigma_mps: Some(0.1),
            scale_factors: sf,
            every_s: Some(every),
            ..Default::default()
        };
        let mut a = Out {
            rows: Vec::new(),
            smoothed: Vec::new(),
            updates: Vec::new(),
        };
        let sa = fuse_scenario(
            &scn,
            &gnss,
            &opts,
            run,
            &CancelToken::new(),
            |ev| match ev {
                FuseEvent::Epoch(e) => {
                    let sig = std::array::from_fn(|i| e.p[(3 + i, 3 + i)].max(0.0).sqrt());
                    let b = std::array::from_fn(|i| e.est[9 + i]);
                    a.rows.push((e.t_s, e.state, b, sig));
                }
                FuseEvent::Smoothed(e) => {
                    a.smoothed
                        .push((e.t_s, e.state, std::array::from_fn(|i| e.est[9 + i])))
                }
                FuseEvent::Update(u) => a.updates.push(*u),
                _ => {}
            },
        )
        .unwrap();
        // to files: the same run's IMU record and fixes (and the aiding sensors' records)
        let (imu, fixes, rec) = record_from_scenario_with_aiding(&scn, &gnss, run).unwrap();
        if aiding {
            write_aiding(&dir, &rec.meas);
        }
        let mut text =
            String::from("t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n");
        for (k, i) in imu.increments.iter().enumerate() {
            let (th, dv) = (i.dtheta_b_rad, i.dv_b_mps);
            writeln!(
                text,
                "{},{},{},{},{},{},{}",
                imu.dt_s * (k + 1) as f64,
                th.x,
                th.y,
                th.z,
                dv.x,
                dv.y,
                dv.z
            )
            .unwrap();
        }
        std::fs::write(dir.join("imu.csv"), &text).unwrap();
        let mut g = String::from("t_s,lat_rad,lon_rad,h_m,v_n_mps,v_e_mps,v_d_mps\n");
        for f in &fixes {
            let v = f.vel.unwrap().0;
            writeln!(
                g,
                "{},{},{},{},{},{},{}",
                f.t_s, f.lat_rad, f.lon_rad, f.h_m, v.x, v.y, v.z
            )
            .unwrap();
        }
        std::fs::write(dir.join("gnss.csv"), &g).unwrap();
        let (sp, sv) = (gnss.sigma_pos_ned_m, gnss.sigma_vel_ned_mps);
        std::fs::write(
            dir.join("gnss_params.txt"),
            format!(
                "stdm = [{}, {}, {}]\nstdv = [{}, {}, {}]\nlarm = [0, 0, 0]\nfreq = [{}]\n",
                sp[0], sp[1], sp[2], sv[0], sv[1], sv[2], gnss.rate_hz
            ),
        )
        .unwrap();
        let state = sdins_sim::truth::TruthGenerator::new(&scn.trajectory, scn.truth_config())
            .initial_state();
        let input = FilesInput {
            imu: (dir.join("imu.csv"), ImuFormat::Sdins),
            gnss: (dir.join("gnss.csv"), GnssFormat::NaveGo),
            gnss_options: GnssReadOptions::default(),
            clock: ImuClock::SameAsGnss,
            sensor: SensorModelSource::Model(Box::new(scn.imu.model.clone())),
            init: InitSource::Given(state, InitSigma::default()),
            truth: None,
            check_after_s: 30.0,
            columns: Default::default(),
            aiding: aiding.then(|| dir.join("aiding.toml")),
        };
        let ropts = RecordOptions {
            algo: opts.algo,
            cov_rate_hz: opts.cov_rate_hz,
            nhc_sigma_mps: opts.nhc_sigma_mps,
            smooth: true,
            scale_factors: sf,
            every_s: Some(every),
            ..Default::default()
        };
        let mut b = Out {
            rows: Vec::new(),
            smoothed: Vec::new(),
            updates: Vec::new(),
        };
        let sb = fuse_files(&input, &ropts, &CancelToken::new(), |ev, _| match ev {
            RecordEvent::Forward(p) => {
                let (ba, bg) = p.bias;
                let sig = std::array::from_fn(|i| p.sigma_nav[3 + i]);
                b.rows
                    .push((p.t_s, p.state, [ba.x, ba.y, ba.z, bg.x, bg.y, bg.z], sig));
            }
            RecordEvent::Smoothed(p) => {
                let (ba, bg) = p.bias;
                b.smoothed
                    .push((p.t_s, p.state, [ba.x, ba.y, ba.z, bg.x, bg.y, bg.z]));
            }
            RecordEvent::Update(u) => b.updates.push(*u),
            _ => {}
        })
        .unwrap();
        assert_eq!(imu.dt_s, 1.0 / 128.0);
        assert_eq!(sb.imu_dt_s, imu.dt_s);
        assert_eq!(sb.summary.fixes_used, sa.fixes);
        assert!(
            a.rows.len() == 481 && a.updates.len() > 1300,
            "{}",
            a.rows.len()
        );
        if aiding {
            // every aiding kind took part
            for k in [
                "baro",
                "odometer",
                "magnetometer",
                "dual_antenna",
                "body_velocity",
            ] {
                assert!(b.updates.iter().any(|u| u.kind.name() == k), "{k}");
            }
        }
        println!(
            "scale factors {}: {} rows, {} smoothed rows, {} updates ({} fixes)",
            sf.is_some(),
            a.rows.len(),
            a.smoothed.len(),
            a.updates.len(),
            sa.fixes
        );
        assert_eq!(a.rows.len(), b.rows.len());
        for (x, y) in a.rows.iter().zip(&b.rows) {
            assert_eq!(x.0.to_bits(), y.0.to_bits());
            assert_eq!(bits(&x.1), bits(&y.1), "t = {}", x.0);
            assert_eq!(x.2.map(f64::to_bits), y.2.map(f64::to_bits), "t = {}", x.0);
            assert_eq!(x.3.map(f64::to_bits), y.3.map(f64::to_bits), "t = {}", x.0);
        }
        assert_eq!(a.smoothed.len(), b.smoothed.len());
        for (x, y) in a.smoothed.iter().zip(&b.smoothed) {
            assert_eq!(bits(&x.1), bits(&y.1), "smoothed t = {}", x.0);
            assert_eq!(x.2.map(f64::to_bits), y.2.map(f64::to_bits));
        }
        assert_eq!(a.updates.len(), b.updates.len());
        for (x, y) in a.updates.iter().zip(&b.updates) {
            assert_eq!(x.nis.to_bits(), y.nis.to_bits(), "{x:?} {y:?}");
            assert_eq!(
                x.innovation.map(f64::to_bits),
                y.innovation.map(f64::to_bits)
            );
            assert_eq!(x.t_s.to_bits(), y.t_s.to_bits());
        }
        assert_eq!(
            (sa.est_bias, sa.est_scale),
            (sb.summary.final_bias, sb.summary.final_scale)
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

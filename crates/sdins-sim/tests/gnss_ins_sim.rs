//! gnss-ins-sim motion files: import, round trip, runs, analytic checks on the truth,
//! truth refinement, located errors
//! (docs/scenarios.md §"Importing gnss-ins-sim motion files").
#![allow(clippy::unwrap_used)]
use sdins_core::math::{euler_from_c_b_n, Vec3};
use sdins_core::nav::{AlgorithmKind, AlgorithmSpec};
use sdins_sim::io::gnss_ins_sim::{
    outages, parse_motion_def, read_motion_def, to_scenario_toml, ImportOptions, MotionFile,
};
use sdins_sim::nav::pipeline::{run, RunOptions};
use sdins_sim::scenario::Scenario;
use sdins_sim::truth::body_motion::{BodyCommand, BodyMotion, CommandKind, MotionLimits};
use sdins_sim::truth::{TruthConfig, TruthGenerator};
use std::path::{Path, PathBuf};

const DIR: &str = "../../../shared/data/gnss_ins_sim";

fn data_dir() -> Option<PathBuf> {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join(DIR);
    if d.is_dir() {
        Some(d)
    } else {
        eprintln!("skipped: {} is absent", d.display());
        None
    }
}

fn files() -> Vec<PathBuf> {
    let Some(d) = data_dir() else {
        return Vec::new();
    };
    let mut v: Vec<PathBuf> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let n = p.file_name().unwrap().to_string_lossy().into_owned();
            n.starts_with("motion_def") && n.ends_with(".csv")
        })
        .collect();
    v.sort();
    v
}

/// The lowest of 10, 20, 50, 100 Hz at which every command is whole samples.
fn rate_for(mf: &MotionFile) -> f64 {
    for r in [10.0, 20.0, 50.0, 100.0] {
        if mf.commands.iter().all(|c| {
            let n = c.duration_s * r;
            (n - n.round()).abs() < 1e-6 * n.max(1.0)
        }) {
            return r;
        }
    }
    panic!("no rate");
}

fn cfg(scn: &Scenario, substeps: usize) -> TruthConfig {
    TruthConfig {
        substeps,
        ..scn.truth_config()
    }
}

fn import(path: &Path, rate_hz: f64) -> (MotionFile, Scenario, String) {
    let mf = read_motion_def(path).unwrap();
    let opts = ImportOptions {
        limits: MotionLimits::DEFAULT,
        rate_hz,
    };
    let name = path.file_stem().unwrap().to_string_lossy().into_owned();
    let toml = to_scenario_toml(&mf, &name, "f.csv", &opts).unwrap();
    let scn = Scenario::from_toml(&toml, "f.toml").unwrap();
    (mf, scn, toml)
}

/// The motion compiled straight from the file's commands (durations as whole samples).
fn direct(mf: &MotionFile, dt: f64) -> BodyMotion {
    let cmds: Vec<BodyCommand> = mf
        .commands
        .iter()
        .map(|c| BodyCommand {
            duration_s: (c.duration_s / dt).round() * dt,
            ..*c
        })
        .collect();
    BodyMotion::compile(mf.start, &cmds, MotionLimits::DEFAULT, dt)
}

fn check_file(path: &Path) {
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    let mf = read_motion_def(path).unwrap();
    let rate = rate_for(&mf);
    let (mf, scn, _) = import(path, rate);
    let dt = 1.0 / rate;
    // round trip: the TOML gives the motion compiled straight from the file, bit for bit
    let want = direct(&mf, dt);
    assert_eq!(scn.trajectory.body_motion(), Some(&want), "{name}");
    assert_eq!(scn.trajectory.duration_s, want.duration_s);
    let g = scn.gnss.as_ref().unwrap();
    assert_eq!(g.outages_s, outages(&want, &mf.gps_visible), "{name}");
    // the CSV is accepted wherever a scenario is, as the same scenario
    let via_load = Scenario::from_file(path).unwrap();
    if rate == 100.0 {
        assert_eq!(via_load.trajectory, scn.trajectory, "{name}");
    }
    // truth + error-free IMU + navigation completes with finite errors
    let opts = RunOptions {
        algos: vec![AlgorithmSpec::new(AlgorithmKind::SongLeeComplete, 2)],
        vertical_hold: false,
        every_s: None,
        until_s: None,
        sensor_run: None,
    };
    let mut finite = true;
    let mut max_pos = 0.0_f64;
    let t0 = std::time::Instant::now();
    let summ = run(
        &scn,
        &opts,
        |_, _, _, e| {
            finite &= e
                .pos_err_ned_m
                .iter()
                .chain(&e.att_err_rad)
                .all(|v| v.is_finite());
            max_pos = max_pos.max(Vec3::from(e.pos_err_ned_m).norm());
        },
        |_, _| {},
    )
    .unwrap();
    assert!(finite, "{name}");
    eprintln!(
        "{name}: {} commands ({} extended), {:.1} s at {rate} Hz, nav updates {}, max |pos err| {max_pos:.3e} m, {:.2} s",
        mf.commands.len(),
        want.extended.len(),
        want.duration_s,
        summ[0].nav_updates,
        t0.elapsed().as_secs_f64()
    );
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn every_motion_file_imports_round_trips_and_runs() {
    // all eleven, the 2234 s long drive included (0.2 s of work at 10 Hz)
    let f = files();
    for p in &f {
        check_file(p);
    }
    if data_dir().is_some() {
        assert!(f.len() >= 11, "{f:?}");
    }
}

fn load(name: &str, rate_hz: f64) -> Option<(MotionFile, Scenario)> {
    let d = data_dir()?;
    let (mf, scn, _) = import(&d.join(name), rate_hz);
    Some((mf, scn))
}

fn wrap(x: f64) -> f64 {
    sdins_core::nav::wrap_pi(x)
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn constant_euler_rates_integrate_exactly() {
    // motion_def-90deg_turn: 1 s straight, 15 deg/s of yaw for 6 s, 3 s straight, from
    // yaw 315 deg: yaw = 315 + 15·(t − 1) deg during the turn and 45 deg after, to rounding
    // (|ψ| ≤ 7.1 rad: a few ulp, 1e-13 rad).
    let Some((_, scn)) = load("motion_def-90deg_turn.csv", 100.0) else {
        return;
    };
    let c = cfg(&scn, scn.nav.substeps);
    let mut worst = 0.0_f64;
    for s in TruthGenerator::new(&scn.trajectory, c) {
        let t = s.t_s;
        let want = 315f64.to_radians() + 15f64.to_radians() * (t - 1.0).clamp(0.0, 6.0);
        let yaw = euler_from_c_b_n(&s.c_b_n).yaw_rad;
        worst = worst.max(wrap(yaw - want).abs());
    }
    eprintln!("90deg_turn: max |yaw − (ψ0 + rT)| {worst:e} rad");
    assert!(worst <= 1e-13, "{worst:e}");
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn absolute_commands_reach_and_hold_and_keep_the_limits() {
    // motion_def.csv, command 2 (type 5, pitch +45 deg, vx 10 m/s, 250 s from t = 10 s):
    // pitch is rate-limited, T_c = max(2·45/2, √(2π·45/0.5)) = 45 s, vx needs 2·10/1 = 20 s;
    // from t = 55 s to 260 s pitch = 45 deg and v^b = (10, 0, 0) to rounding.
    let Some((mf, scn)) = load("motion_def.csv", 100.0) else {
        return;
    };
    assert_eq!(mf.commands[1].kind, CommandKind::RelAttAbsVel);
    let c = cfg(&scn, scn.nav.substeps);
    let (mut dp, mut dv) = (0.0_f64, 0.0_f64);
    for s in TruthGenerator::new(&scn.trajectory, c) {
        if s.t_s >= 55.0 && s.t_s <= 260.0 {
            let e = euler_from_c_b_n(&s.c_b_n);
            dp = dp.max((e.pitch_rad - 45f64.to_radians()).abs());
            let vb = s.c_b_n.transpose() * s.v_n_mps;
            dv = dv.max((vb - Vec3::new(10.0, 0.0, 0.0)).norm());
        }
    }
    eprintln!("hold: |Δpitch| {dp:e} rad, |Δv^b| {dv:e} m/s");
    assert!(dp <= 1e-13, "{dp:e}");
    assert!(dv <= 1e-13, "{dv:e}");
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn limits_are_honoured_and_zero_lateral_body_velocity_is_exact() {
    // At every sample instant of every file: the Euler-angle rates, their second
    // derivatives and the body-velocity rates of the commands of types 2–5 stay within the
    // mode limits (+1e-12 relative rounding); the smooth step reaches its peak rate 2Δ/T_c
    // at mid-step, so a rate-limited 90 deg turn must reach the limit to 1e-6 (sampling).
    // Files whose commands all have vy = vz = 0 (and start so) keep the body-frame lateral
    // and vertical velocity C_n^b v^n at 0 to 1e-12 m/s.
    let lim = MotionLimits::DEFAULT;
    let mut peak_rate = 0.0_f64;
    for p in files() {
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        let mf = read_motion_def(&p).unwrap();
        let rate = rate_for(&mf);
        let (mf, scn, _) = import(&p, rate);
        let bm = scn.trajectory.body_motion().unwrap();
        let dt = 1.0 / rate;
        let n = (bm.duration_s / dt).round() as u64;
        for k in 0..=n {
            let t = k as f64 * dt;
            let i = bm.piece_at(t);
            if mf.commands[i].kind == CommandKind::Rates {
                continue;
            }
            let st = bm.state(t, t);
            for j in 0..3 {
                let (r, a) = (st.euler_rate_ypr[j].abs(), st.euler_accel_ypr[j].abs());
                peak_rate = peak_rate.max(r);
                assert!(
                    r <= lim.max_angular_rate_rps * (1.0 + 1e-12),
                    "{name} t {t}: rate {r}"
                );
                assert!(
                    a <= lim.max_angular_accel_rps2 * (1.0 + 1e-12),
                    "{name} t {t}: {a}"
                );
                let vd = st.vel_dot_b[j].abs();
                assert!(
                    vd <= lim.max_accel_mps2 * (1.0 + 1e-12),
                    "{name} t {t}: {vd}"
                );
            }
        }
        let planar = mf.start.vel_b[1] == 0.0
            && mf.start.vel_b[2] == 0.0
            && mf
                .commands
                .iter()
                .all(|c| c.vel_b[1] == 0.0 && c.vel_b[2] == 0.0);
        if planar {
            let c = cfg(&scn, scn.nav.substeps);
            let mut lat = 0.0_f64;
            for s in TruthGenerator::new(&scn.trajectory, c) {
                let vb = s.c_b_n.transpose() * s.v_n_mps;
                lat = lat.max(vb.y.abs()).max(vb.z.abs());
            }
            eprintln!("{name}: max |v_y^b|, |v_z^b| {lat:e} m/s");
            assert!(lat <= 1e-12, "{name}: {lat:e}");
        }
    }
    if !files().is_empty() {
        assert!(
            (peak_rate - lim.max_angular_rate_rps).abs() <= 1e-6 * lim.max_angular_rate_rps,
            "peak {peak_rate}"
        );
    }
}

/// Gauss (scenario substeps) vs RK4 (or Gauss if `!rk4`) at `mult` times as many substeps
/// over windows `(start_s, len_s)`, each started at its sample from the start position:
/// max |Δθ| rad, |Δv| m/s, position m.
fn gauss_vs_rk4(scn: &Scenario, mult: usize, rk4: bool, windows: &[(f64, f64)]) -> (f64, f64, f64) {
    let base = scn.nav.substeps;
    let (c1, c2) = (cfg(scn, base), cfg(scn, mult * base));
    let e = c1.earth;
    let (mut dth, mut dv, mut dpos) = (0.0_f64, 0.0_f64, 0.0_f64);
    for &(start, len) in windows {
        let k = (start / c1.dt_s).round() as u64;
        let n = (len / c1.dt_s).round() as usize;
        let mut a = TruthGenerator::new(&scn.trajectory, c1)
            .without_closed_form()
            .starting_at_sample(k);
        let b = TruthGenerator::new(&scn.trajectory, c2).without_closed_form();
        let mut b = if rk4 { b.reference_rk4() } else { b }.starting_at_sample(k);
        for _ in 0..n {
            let (Some(x), Some(y)) = (a.next(), b.next()) else {
                break;
            };
            assert_eq!(x.t_s, y.t_s);
            dth = dth.max((x.inc.dtheta_b_rad - y.inc.dtheta_b_rad).norm());
            dv = dv.max((x.inc.dv_b_mps - y.inc.dv_b_mps).norm());
            let (pa, pb) = (a.position_offsets(), b.position_offsets());
            let r = e.radii(y.lat_rad);
            let p = Vec3::new(
                (pa.0 - pb.0) * (r.r_m_m + y.h_m),
                (pa.1 - pb.1) * (r.r_n_m + y.h_m) * y.lat_rad.cos(),
                pa.2 - pb.2,
            );
            dpos = dpos.max(p.norm());
        }
    }
    (dth, dv, dpos)
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn gauss_matches_rk4_at_smooth_step_ends_inside_samples() {
    // Holland tunnel: the smooth-step ends t0 + T_c of the attitude channels fall inside
    // samples, where the Gauss panels are split; 1.5 s around each of the first eight such
    // ends, the bounds of the test below. The RK4 reference does not split its substeps
    // there (it takes the branch of the substep midpoint), and at T_c the Euler angles'
    // third derivative, i.e. ω̈, jumps: its local error is O(jump·h³) instead of O(h⁵)
    // (measured: RK4 at 2× vs 8× the substeps differ by 3.6e-16 rad there, the Gauss
    // scheme at 1× vs 8× by 4e-19). So the reference here runs at 8× the substeps, where
    // its Δv carries the rounding of 128 summed substeps (√128 · ulp(0.1 m/s) ≈ 1.6e-16
    // m/s typical): the Δv bound against it is 1e-15 m/s, as for turn-90dps in
    // tests/truth.rs. The Gauss scheme against itself at 8× keeps the scenario bounds.
    let Some((_, scn)) = load("motion_def-Holland_tunnel.csv", 100.0) else {
        return;
    };
    let bm = scn.trajectory.body_motion().unwrap();
    let inside: Vec<f64> = bm
        .breaks()
        .into_iter()
        .filter(|b| {
            let x = b * 100.0;
            (x - x.round()).abs() > 1e-3
        })
        .take(8)
        .collect();
    assert_eq!(inside.len(), 8);
    let w: Vec<(f64, f64)> = inside
        .iter()
        .map(|b| (b.floor() - 0.5, 1.0 + 0.5))
        .collect();
    let (gth, gv, gpos) = gauss_vs_rk4(&scn, 8, false, &w);
    let (dth, dv, dpos) = gauss_vs_rk4(&scn, 8, true, &w);
    eprintln!("Holland tunnel T_c ends {inside:?}: Gauss 1× vs 8×: dθ {gth:e} rad, dv {gv:e} m/s, pos {gpos:e} m; vs RK4 8×: dθ {dth:e} rad, dv {dv:e} m/s, pos {dpos:e} m");
    assert!(gth <= 2e-17, "{gth:e}");
    assert!(gv <= 2e-16, "{gv:e}");
    assert!(gpos <= 1e-9, "{gpos:e}");
    // the reference's own kink error at 8×: RK4 8× vs 32× differ by 1.6e-17 rad there
    assert!(dth <= 5e-17, "{dth:e}");
    assert!(dv <= 1e-15, "{dv:e}");
    assert!(dpos <= 1e-9, "{dpos:e}");
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn gauss_matches_rk4_reference_on_imported_3d_motion() {
    // The Gauss truth against the RK4 reference at twice the substeps over the whole 3-D
    // motion (130 s at 100 Hz): the bounds of the scenario tests of tests/truth.rs
    // (dq-paper: 2e-17 rad, 2e-16 m/s, 1e-9 m), whose floor is the rounding of the
    // increments (|Δv| ≈ 0.1 m/s, ulp 1.4e-17).
    let Some((_, scn)) = load("motion_def-3d.csv", 100.0) else {
        return;
    };
    let base = scn.nav.substeps;
    let (c1, c2) = (cfg(&scn, base), cfg(&scn, 2 * base));
    let e = c1.earth;
    let a = TruthGenerator::new(&scn.trajectory, c1).without_closed_form();
    assert_eq!(a.scheme(), sdins_sim::truth::TruthScheme::Gauss);
    let b = TruthGenerator::new(&scn.trajectory, c2).reference_rk4();
    let (mut dth, mut dv, mut dpos) = (0.0_f64, 0.0_f64, 0.0_f64);
    let (mut a, mut b) = (a, b);
    while let (Some(x), Some(y)) = (a.next(), b.next()) {
        assert_eq!(x.t_s, y.t_s);
        dth = dth.max((x.inc.dtheta_b_rad - y.inc.dtheta_b_rad).norm());
        dv = dv.max((x.inc.dv_b_mps - y.inc.dv_b_mps).norm());
        let (pa, pb) = (a.position_offsets(), b.position_offsets());
        let r = e.radii(y.lat_rad);
        let p = Vec3::new(
            (pa.0 - pb.0) * (r.r_m_m + y.h_m),
            (pa.1 - pb.1) * (r.r_n_m + y.h_m) * y.lat_rad.cos(),
            pa.2 - pb.2,
        );
        dpos = dpos.max(p.norm());
    }
    eprintln!(
        "3d: Gauss ({base}) vs RK4 ({}): dθ {dth:e} rad, dv {dv:e} m/s, pos {dpos:e} m",
        2 * base
    );
    assert!(dth <= 2e-17, "{dth:e}");
    assert!(dv <= 2e-16, "{dv:e}");
    assert!(dpos <= 1e-9, "{dpos:e}");
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn scenario_command_errors_are_located() {
    let Some(d) = data_dir() else {
        return;
    };
    let (_, _, toml) = import(&d.join("motion_def-3d.csv"), 100.0);
    let err = |t: &str| Scenario::from_toml(t, "f.toml").unwrap_err().to_string();
    let line_of = |pat: &str| toml.lines().position(|l| l.contains(pat)).unwrap() + 1;
    let e = err(&toml.replacen("type = 2", "type = 7", 1));
    assert!(
        e.starts_with(&format!("f.toml:{}: command.type:", line_of("type = 2"))),
        "{e}"
    );
    let e = err(&toml.replacen("duration_s = 20.0", "duration_s = -1.0", 1));
    assert!(
        e.contains("command.duration_s") && e.contains("must be > 0"),
        "{e}"
    );
    let e = err(&toml.replacen("duration_s = 20.0", "duration_s = 20.005", 1));
    assert!(e.contains("whole number of IMU samples"), "{e}");
    let e = err(&toml.replacen("max_accel_mps2 = 1.0", "max_accel_mps2 = 0.0", 1));
    assert!(e.contains("body_motion.max_accel_mps2"), "{e}");
    let e = err(&toml.replacen("yaw_rate_dps = 0.0", "yaw_deg = 0.0", 1));
    assert!(
        e.contains("command.yaw_deg") && e.contains("not a key of command type 1"),
        "{e}"
    );
    let e = err(&toml.replacen("vehicle = \"free\"", "vehicle = \"car\"", 1));
    assert!(
        e.contains("vehicle = \\\"free\\\"") || e.contains("free"),
        "{e}"
    );
    let e = err(&toml.replacen("[start]", "[start]\nspeed_mps = 3.0", 1));
    assert!(e.contains("start.speed_mps"), "{e}");
}

#[test]
fn motion_file_errors_are_located() {
    let good = "ini lat (deg),a,b,c,d,e,f,g,h\n32,120,0,0,0,0,0,0,0\nh,a,b,c,d,e,f,g,h\n2,90,0,0,10,0,0,20,1\n";
    let e = |t: &str| parse_motion_def(t, "m.csv").unwrap_err().to_string();
    assert!(
        e(&good.replace("2,90,0,0,10,0,0,20,1", "2,90,0,0,10,0,0,20"))
            .starts_with("m.csv:4:1: expected 9")
    );
    assert!(e(&good.replace(",10,0,0,20", ",ten,0,0,20"))
        .starts_with("m.csv:4:5: `ten` is not a number"));
    assert!(e(&good.replace("32,120,0,", "32,nan,0,")).starts_with("m.csv:2:2:"));
    assert!(e(&good.replace("2,90,", "6,90,")).starts_with("m.csv:4:1: command type"));
    assert!(e(&good.replace(",20,1", ",0,1")).starts_with("m.csv:4:8:"));
    let dir = std::env::temp_dir().join(format!("sdins-gis-{}", std::process::id()));
    let missing = dir.join("none.csv");
    assert!(read_motion_def(&missing)
        .unwrap_err()
        .to_string()
        .contains("cannot read"));
    // a passed-in CSV goes through the scenario path with its location
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("bad.csv");
    std::fs::write(&f, good.replace(",20,1", ",-2,1")).unwrap();
    let e = Scenario::from_file(&f).unwrap_err().to_string();
    assert!(e.contains("bad.csv:4: column 8:"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

//! `sdins demo`: the papers' headline comparisons on built-in scenarios, with the
//! papers' reference numbers (docs/validation.md) printed beside ours, and one self-contained HTML
//! report.

use super::run::{
    error_figure, execute_full, print_table, summary_rows, Args as RunArgs, Outcome, SUMMARY_HEADER,
};
use crate::error::CliError;
use crate::plot::Bars;
use crate::report::Report;
use sdins_sim::analysis::error_analysis::schuler_share::schuler_share_table_p2;
use std::path::PathBuf;

/// Arguments of `sdins demo`.
#[derive(clap::Args, Debug)]
#[command(after_help = "Example:\n  sdins demo --out sdins-out/demo")]
pub struct Args {
    /// output folder (default ./sdins-out/demo)
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// no progress bars
    #[arg(long)]
    pub quiet: bool,
}

/// The `run` arguments the demo uses for one scenario (also used by the tests that
/// compare the demo's numbers with `sdins run`).
pub fn run_args(scenario: &str, algo: &str, out: PathBuf, quiet: bool) -> RunArgs {
    RunArgs {
        scenario: scenario.into(),
        algo: Some(algo.into()),
        samples: None,
        coning: None,
        attitude: None,
        rot3: false,
        rotvec: None,
        vertical: None,
        out: Some(out),
        until_s: None,
        every_s: 1.0,
        ideal: false,
        grade: None,
        run: 0,
        plot_scale: crate::plot::PlotScale::Log,
        json: false,
        quiet,
    }
}

const ALL: &str = "savage,songlee,songlee-complete,dualquat";

fn find<'a>(o: &'a Outcome, algo: &str) -> Option<&'a sdins_sim::nav::pipeline::RunSummary> {
    o.sums.iter().find(|s| s.algo == algo)
}

fn section(
    r: &mut Report,
    title: &str,
    o: &Outcome,
    paper_header: &[&str],
    paper_rows: &[Vec<String>],
    note: &str,
) -> Result<(), CliError> {
    r.heading(title);
    r.para(&o.scn.description);
    r.table(&SUMMARY_HEADER, &summary_rows(&o.sums));
    if !paper_rows.is_empty() {
        r.para("The papers' numbers (reconstructed, docs/validation.md) for comparison:");
        r.table(paper_header, paper_rows);
    }
    r.para(note);
    r.figure(
        &error_figure(o),
        &format!(
            "{}: error norms against the exact truth (log scale).",
            o.scn.name
        ),
    )?;
    let bars = Bars {
        title: format!("{}: navigation time per update", o.scn.name),
        y_label: "time [ns/update]".into(),
        bars: o
            .sums
            .iter()
            .map(|s| (s.algo.clone(), s.wall_s / s.nav_updates.max(1) as f64 * 1e9))
            .collect(),
        size: (900, 360),
    };
    r.bars(
        &bars,
        "Execution time of each navigation loop on this machine (truth generation excluded).",
    )
}

fn v(xs: &[&str]) -> Vec<String> {
    xs.iter().map(|s| s.to_string()).collect()
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    let out = args.out.unwrap_or_else(|| PathBuf::from("sdins-out/demo"));
    crate::output::claim(&out)?;
    let mut r = Report::new("sdins demo: the papers' comparisons reproduced against exact truth");
    song_lee_table1(&mut r, &out, args.quiet)?;
    turn_90dps(&mut r, &out, args.quiet)?;
    dq_paper(&mut r, &out, args.quiet)?;
    alignment(&mut r)?;
    schuler_share(&mut r)?;
    let dest = out.join("report.html");
    r.write(&dest)?;
    outln!("\nreport: {}", dest.display());
    Ok(())
}

/// Section 1: Song–Lee Table 1 (Mach 1 due east, 90 min).
fn song_lee_table1(r: &mut Report, out: &std::path::Path, quiet: bool) -> Result<(), CliError> {
    outln!("== 1. Song-Lee Table 1: Mach 1 due east, 90 min, 2 ms samples, 6 ms updates (docs/validation.md) ==");
    let a1 = execute_full(&run_args("mach1-east", ALL, out.join("mach1-east"), quiet))?;
    print_table(&a1.scn, &a1.sums);
    outln!("paper (S1 Table 1, reconstructed magnitudes):");
    outln!("  Savage    pos 3.0, 47.1, 557.2 m   vel 3.1, 52.5, 971 mm/s   att 7.1, 0.5, 5.5 urad");
    outln!(
        "  Proposed  pos 0.01, 0.7, 7.8 m     vel 0.05, 0.7, 13.7 mm/s  att 0.1, 0.01, 0.08 urad"
    );
    let mut ratio_text = String::new();
    if let (Some(sav), Some(sl)) = (find(&a1, "savage"), find(&a1, "songlee")) {
        let ratio = |a: [f64; 3], b: [f64; 3]| {
            (0..3)
                .map(|i| a[i].abs() / b[i].abs().max(1e-300))
                .fold(f64::INFINITY, f64::min)
        };
        let q = ratio(sav.final_err.pos_err_ned_m, sl.final_err.pos_err_ned_m)
            .min(ratio(
                sav.final_err.vel_err_ned_mps,
                sl.final_err.vel_err_ned_mps,
            ))
            .min(ratio(sav.final_err.att_err_rad, sl.final_err.att_err_rad));
        ratio_text = format!("Smallest Savage/Song-Lee ratio over all nine components: {q:.1} (the paper claims > 50). East and down agree with the paper within 2 %; the north error does not: the paper prints 0.01 m, we and an independent reconstruction get 0.044 m. The paper states neither its latitude, constants nor exact evaluation time, and the north error of this due-east flight is the small residue of a Schuler oscillation, the component most sensitive to them; we report the difference rather than claim a reproduction.");
        outln!("  {ratio_text}");
    }
    let t1_header = [
        "row",
        "pos N,E,D [m]",
        "vel N,E,D [mm/s]",
        "att N,E,D [μrad]",
    ];
    let t1_rows = vec![
        v(&[
            "Savage, S1 Table 1 (reconstructed)",
            "3.0, 47.1, 557.2",
            "3.1, 52.5, 971",
            "7.1, 0.5, 5.5",
        ]),
        v(&[
            "Savage, paper reference",
            "3.065, −47.58, −566.7",
            "3.476, −52.88, −991.6",
            "7.451, 0.482, −5.718",
        ]),
        v(&[
            "Song–Lee, S1 Table 1",
            "0.01, 0.7, 7.8",
            "0.05, 0.7, 13.7",
            "0.1, 0.01, 0.08",
        ]),
        v(&[
            "Song–Lee, paper reference",
            "0.0438, −0.681, −8.109",
            "0.0497, −0.757, −14.19",
            "0.107, 0.0069, −0.082",
        ]),
        v(&[
            "Song–Lee complete, reference bars",
            "≤ 1e−2 (horizontal), ≤ 0.2 (D)",
            "≤ 1e−2, ≤ 0.3 (D)",
            "≤ 2e−3",
        ]),
        v(&[
            "dual quaternion, reference bars",
            "≤ 0.5 (horizontal), ≤ 5 (D)",
            "",
            "≤ 0.05",
        ]),
    ];
    section(
        r,
        "1. Song–Lee Table 1: Mach 1 due east for 90 minutes",
        &a1,
        &t1_header,
        &t1_rows,
        &ratio_text,
    )?;
    Ok(())
}

/// Section 2: the 90°/s turn at Mach 1.
fn turn_90dps(r: &mut Report, out: &std::path::Path, quiet: bool) -> Result<(), CliError> {
    outln!("\n== 2. 90 deg/s turn from east to south at Mach 1 (docs/validation.md) ==");
    // every update is an output epoch here, so that the end of the turn (the update
    // nearest t = 8 s; 8 s is not a multiple of ΔT = 6 ms) is in the series
    let mut a2_args = run_args("turn-90dps", ALL, out.join("turn-90dps"), quiet);
    a2_args.every_s = 0.006;
    let a2 = execute_full(&a2_args)?;
    print_table(&a2.scn, &a2.sums);
    let mut five = run_args("turn-90dps", "songlee", out.join("turn-90dps-five"), quiet);
    five.attitude = Some("five".into());
    five.every_s = 0.006;
    let a2five = execute_full(&five)?;
    let at8 = |o: &Outcome, algo: &str| -> f64 {
        o.sums
            .iter()
            .position(|s| s.algo == algo)
            .and_then(|i| o.series.get(i))
            .and_then(|s| s.iter().find(|p| (p.0 - 8.0).abs() <= 0.003))
            .map_or(f64::NAN, |p| p.4 * 1e6) // μrad
    };
    let att_rows = vec![
        vec![
            "Song–Lee, transport attitude (S1 eq. 6)".into(),
            format!("{:.3e}", at8(&a2, "songlee")),
            "8.30e−4".into(),
            "≈ 1e−4".into(),
        ],
        vec![
            "Song–Lee velocity + (5)-method attitude".into(),
            format!("{:.3e}", at8(&a2five, "songlee")),
            "0.299".into(),
            "0.3".into(),
        ],
        vec![
            "Song–Lee complete".into(),
            format!("{:.3e}", at8(&a2, "songlee-complete")),
            "6.7e−6 (SL + rot3)".into(),
            "".into(),
        ],
        vec![
            "dual quaternion".into(),
            format!("{:.3e}", at8(&a2, "dualquat")),
            "6.5e−8".into(),
            "".into(),
        ],
        vec![
            "Savage".into(),
            format!("{:.3e}", at8(&a2, "savage")),
            "".into(),
            "".into(),
        ],
    ];
    outln!("attitude error |ε| at the end of the turn (t = 8 s):");
    for row in &att_rows {
        outln!(
            "  {:<42} {:>10}  ref {:>20}  S1 {}",
            row[0],
            row[1],
            row[2],
            row[3]
        );
    }
    section(
        r,
        "2. 90°/s turn from east to south at Mach 1",
        &a2,
        &["attitude option", "|ε| at 8 s [μrad] (sdins)", "reference", "S1"],
        &att_rows,
        "The transport-matrix attitude (S1 eq. 6) keeps the attitude error at the end of the turn near 1e-3 μrad; the (5)-method reproduces S1's 0.3 μrad. Position errors during the turn are the trapezoid rule's transient (ΔT²/12)(a(t) − a(t0)), which vanishes when the turn ends.",
    )?;
    Ok(())
}

/// Section 3: the dual-quaternion paper's case.
fn dq_paper(r: &mut Report, out: &std::path::Path, quiet: bool) -> Result<(), CliError> {
    outln!("\n== 3. Dual-quaternion paper case: stationary, accelerate, S-turn, 1 Hz coning, 100 Hz IMU, 2 samples (docs/validation.md) ==");
    let b = execute_full(&run_args("dq-paper", ALL, out.join("dq-paper"), quiet))?;
    print_table(&b.scn, &b.sums);
    let mut timing = String::new();
    if let (Some(sav), Some(dq)) = (find(&b, "savage"), find(&b, "dualquat")) {
        timing = format!(
            "Execution time dual quaternion / Savage: {:.2} here (S2: 2.7 in MATLAB; reference prototype 2.2).",
            dq.wall_s / sav.wall_s.max(1e-12)
        );
        outln!("  {timing}");
    }
    let hrow = |name: &str,
                s: Option<&sdins_sim::nav::pipeline::RunSummary>,
                spec_h: &str,
                spec_vd: &str|
     -> Vec<String> {
        vec![
            name.into(),
            s.map_or("-".into(), |s| format!("{:.3e}", s.final_err.height_err_m)),
            spec_h.into(),
            s.map_or("-".into(), |s| {
                format!("{:.3e}", s.final_err.vel_err_ned_mps[2])
            }),
            spec_vd.into(),
        ]
    };
    let b_rows = vec![
        hrow("Savage 2-sample", find(&b, "savage"), "7.94e−2", "−4.95e−4"),
        hrow(
            "Song–Lee 2-sample",
            find(&b, "songlee"),
            "8.96e−2 (Δθ rotation term)",
            "−4.44e−4",
        ),
        hrow(
            "Song–Lee complete",
            find(&b, "songlee-complete"),
            "−8.6e−4 (SL + rot3)",
            "6.4e−6",
        ),
        hrow(
            "dual quaternion 2-sample",
            find(&b, "dualquat"),
            "7.7e−6",
            "2.66e−6",
        ),
    ];
    outln!("height and down-velocity errors at 420 s (S2: DQ better in height and v_D):");
    for row in &b_rows {
        outln!(
            "  {:<26} h {:>11} (ref {:>26})  vD {:>11} (ref {})",
            row[0],
            row[1],
            row[2],
            row[3],
            row[4]
        );
    }
    section(
        r,
        "3. The dual-quaternion paper's case (accuracy and execution time, its Figures 1–4)",
        &b,
        &["algorithm", "height error [m] (sdins)", "reference", "v_D error [m/s] (sdins)", "reference"],
        &b_rows,
        &format!("S2 found the dual-quaternion algorithm better in north/down velocity and height: reproduced. {timing}"),
    )?;
    Ok(())
}

/// Section 4: initial alignment on the built-in `alignment` scenario.
fn alignment(r: &mut Report) -> Result<(), CliError> {
    outln!("\n== 4. Initial alignment: 37.5N, roll/pitch/yaw 2/-3/40 deg, aviation-grade IMU (docs/theory/alignment.md) ==");
    let align_rows = alignment_summary()?;
    for row in &align_rows {
        outln!(
            "  {:<34} φ N/E/D {:>9} {:>9} {:>10} μrad  {}",
            row[0],
            row[1],
            row[2],
            row[3],
            row[4]
        );
    }
    r.heading("4. Initial alignment");
    r.para("Built-in scenario `alignment` (37.5°N, roll/pitch/yaw 2/−3/40°, aviation-grade IMU, run 0): attitude error φ (convention G, NED) of coarse 1-step and 2-step alignment over the first 60 s and of the 12-state fine Kalman alignment after 300 s and 1800 s. Tilt is limited by the accelerometer biases and heading by the east gyro bias, as the first-order error table (docs/theory/alignment.md) predicts; `sdins align` gives the biases and the ±3σ plots.");
    r.table(
        &["method", "φ N [μrad]", "φ E [μrad]", "φ D [μrad]", "note"],
        &align_rows,
    );
    Ok(())
}

/// Section 5: the Schuler share by sensor grade.
fn schuler_share(r: &mut Report) -> Result<(), CliError> {
    // 5. Schuler share (docs/theory/error-analysis.md §"The Schuler share")
    outln!(
        "\n== 5. Schuler share of the position error by sensor grade ([P2] Table 1, docs/theory/error-analysis.md) =="
    );
    let share = schuler_share_table_p2();
    let share_rows: Vec<Vec<String>> = share
        .iter()
        .map(|s| {
            vec![
                s.grade.clone(),
                format!("{}", s.accel_bias_ug),
                format!("{}", s.gyro_bias_dph),
                format!("{:.2}", s.share_pct),
            ]
        })
        .collect();
    for row in &share_rows {
        outln!(
            "  {:<14} accel {:>6} ug  gyro {:>6} deg/h  share {:>6} %",
            row[0],
            row[1],
            row[2],
            row[3]
        );
    }
    r.heading("5. Schuler share of the position error by sensor grade");
    r.para("The share of the Schuler oscillation in the bias-driven position error at the paper's evaluation time (our reconstruction of [P2] Table 1, docs/theory/error-analysis.md).");
    r.table(
        &[
            "grade",
            "accel bias [μg]",
            "gyro bias [°/h]",
            "Schuler share [%]",
        ],
        &share_rows,
    );
    Ok(())
}

/// Coarse and fine alignment on the built-in `alignment` scenario (aviation grade, run 0).
fn alignment_summary() -> Result<Vec<Vec<String>>, CliError> {
    use sdins_core::align::coarse::CoarseMethod;
    use sdins_core::align::fine::{reference_config, FineAlign};
    use sdins_core::math::attitude_error;
    use sdins_sim::align::experiment::{coarse_window, corrupt, truth_record};
    use sdins_sim::sensors::imu_error::{DPSH, UG};
    let scn = sdins_sim::scenario::Scenario::load("alignment")?;
    let dt = scn.imu.dt_s();
    let tr = truth_record(
        &scn.trajectory,
        scn.nav.earth.model(),
        dt,
        scn.start.lat_rad,
        scn.start.lon_rad,
        scn.start.h_m,
    );
    let incs = corrupt(&tr.increments, dt, &scn.imu.model, scn.imu.seed, 0)
        .map_err(|e| CliError::Other(e.to_string()))?;
    let n60 = (60.0 / dt).round() as usize;
    let fmt = |v: sdins_core::Vec3| {
        [
            format!("{:.1}", v.x / 1e-6),
            format!("{:.1}", v.y / 1e-6),
            format!("{:.1}", v.z / 1e-6),
        ]
    };
    let mut rows = Vec::new();
    for (name, m) in [
        ("coarse 1-step (60 s)", CoarseMethod::OneStep),
        ("coarse 2-step (60 s)", CoarseMethod::TwoStep),
    ] {
        let c = coarse_window(&incs, dt, 0, n60, &tr.site, m)
            .map_err(|e| CliError::Other(e.to_string()))?;
        let [a, b, d] = fmt(attitude_error(&c, &tr.c_b_n0));
        rows.push(vec![name.to_string(), a, b, d, String::new()]);
    }
    let c0 = coarse_window(&incs, dt, 0, n60, &tr.site, CoarseMethod::TwoStep)
        .map_err(|e| CliError::Other(e.to_string()))?;
    let model = &scn.imu.model;
    let cfg = reference_config(
        tr.site,
        model.accel_vrw_ugpsqrthz[0].max(1e-3) * UG,
        model.gyro_arw_dpsh[0].max(1e-6) * DPSH,
    );
    let mut fa = FineAlign::new(cfg, &c0);
    for (j, inc) in incs.iter().enumerate() {
        fa.step(inc, dt);
        let t = (j + 1) as f64 * dt;
        if (t - 300.0).abs() < 0.5 * dt || (t - 1800.0).abs() < 0.5 * dt {
            let truth = tr.c_b_n.get(j).copied().unwrap_or(tr.c_b_n0);
            let [a, b, d] = fmt(attitude_error(&fa.c_b_n(), &truth));
            let s = fa.attitude_sigma();
            rows.push(vec![
                format!("fine Kalman ({t:.0} s)"),
                a,
                b,
                d,
                format!(
                    "1σ {:.0}/{:.0}/{:.0} μrad (incl. unobservable part)",
                    s.x / 1e-6,
                    s.y / 1e-6,
                    s.z / 1e-6
                ),
            ]);
        }
    }
    Ok(rows)
}

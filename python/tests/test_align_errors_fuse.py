"""sdins.align, sdins.errors and sdins.fuse give the CLI's numbers to the last bit (the
CLI's JSON floats are shortest round-trip decimals, so every comparison is `==`), and
bad input raises SdinsError with the CLI's located message."""

import json

import numpy as np
import pytest

import sdins

ALIGN_KEYS = (
    "method", "roll_deg", "pitch_deg", "yaw_deg", "accel_bias_ug", "accel_bias_sigma_ug",
    "gyro_bias_dph", "gyro_bias_sigma_dph", "attitude_sigma_urad", "phi_urad",
    "true_accel_bias_ug", "true_gyro_bias_dph",
)


@pytest.mark.parametrize(
    "args,kw",
    [
        (["alignment", "--method", "coarse2", "--duration-s", "300"],
         dict(scenario="alignment", method="coarse2", duration_s=300.0)),
        (["alignment", "--method", "fine", "--duration-s", "300", "--run", "2"],
         dict(scenario="alignment", method="fine", duration_s=300.0, run=2)),
        (["moored-ship", "--method", "i0", "--window-s", "300"],
         dict(scenario="moored-ship", method="i0", window_s=300.0)),
    ],
)
def test_align_equals_cli_json(cli, args, kw):
    code, out, err = cli(*["align", *args, "--json"])
    assert code == 0, err
    js = json.loads(out)
    r = sdins.align(**kw)
    d = r.as_dict()
    for k in ALIGN_KEYS:
        if k in js:
            assert d[k] == js[k], k
        else:
            assert d[k] is None, k
    if kw["method"] == "fine":
        h = r.history
        assert h["t_s"].shape[0] == h["euler_deg"].shape[0] > 10
        assert h["phi_urad"].shape == h["euler_deg"].shape


def test_align_refuses_motion_and_names_the_option(cli):
    with pytest.raises(sdins.SdinsError, match=r"truth speed is 340\.\d+ m/s at t = 0\.\d+ s.*--method i0"):
        sdins.align("mach1-east", method="coarse2")
    code, _, err = cli(*["align", "mach1-east", "--method", "coarse2"])
    assert code == 2
    with pytest.raises(sdins.SdinsError) as e:
        sdins.align("alignment", sigma_z_mps=-1.0)
    assert "--sigma-z -1: expected a positive velocity σ in m/s" in str(e.value)
    code, _, err = cli(*["align", "alignment", "--sigma-z=-1"])
    assert code == 2 and "--sigma-z -1: expected a positive velocity σ in m/s" in err
    with pytest.raises(sdins.SdinsError, match="method"):
        sdins.align("alignment", method="nope")


def test_errors_equals_cli_json(cli, tmp_path):
    args = ["errors", "--gyro-bias-dph", "0,0.01,0", "--accel-bias-ug", "30,0,0",
            "--hours", "3", "--json", "--out", str(tmp_path / "e")]
    code, out, err = cli(*args)
    assert code == 0, err
    js = json.loads(out)
    r = sdins.errors(gyro_bias_dph=[0, 0.01, 0], accel_bias_ug=[30, 0, 0], hours=3.0)
    assert r.report == js
    assert r.t_s.shape == (3 * 360 + 1,) and r.dp_n_m.shape == (r.t_s.shape[0], 3)
    # the linear model at an epoch is the report's
    k = int(round(js["epochs"][-1]["t_h"] * 3600 / 10))
    assert list(r.dp_n_m[k]) == js["epochs"][-1]["linear"]["dp_n_m"]
    assert len(r.budget) == 2


def test_errors_bad_input(cli):
    with pytest.raises(sdins.SdinsError, match=r"--hours: must be in \(0, 240\], got -1"):
        sdins.errors(grade="aviation", hours=-1.0)
    with pytest.raises(sdins.SdinsError, match="unknown grade"):
        sdins.errors(grade="nope")
    code, _, err = cli(*["errors", "--grade", "nope"])
    assert code == 2 and "unknown grade" in err


def test_schuler_share_equals_cli(cli):
    code, out, _ = cli(*["errors", "--schuler-share", "--json"])
    assert code == 0
    assert sdins.schuler_share() == json.loads(out)


def test_fuse_equals_cli_json(cli, tmp_path):
    code, out, err = cli(*["fuse", "dq-paper", "--json", "--out", str(tmp_path / "f")])
    assert code == 0, err
    js = json.loads(out)
    r = sdins.fuse("dq-paper")
    assert r.fixes == js["fixes"] and r.rejected == js["rejected"]
    for k in ("accel_bias_est_mps2", "accel_bias_true_mps2", "gyro_bias_est_rps", "gyro_bias_true_rps"):
        assert r.__dict__[k] == js[k], k
    rms = r.rms()
    for k in ("rms_pos_ned_m", "rms_vel_ned_mps", "rms_att_ned_rad"):
        assert rms[k] == js[k], k
    n = r.t_s.shape[0]
    assert r.error.shape == (n, 15) and r.sigma.shape == (n, 15) and r.nees.shape == (n, 3)
    assert np.all(r.sigma[:, :3] > 0) and np.all(np.isfinite(r.nees))
    # nav.csv of the CLI: position error and its σ in metres, to the last bit
    with open(tmp_path / "f" / "nav.csv") as f:
        rows = [l.strip().split(",") for l in f][1:]
    assert len(rows) == n
    for k in (0, n // 2, n - 1):
        row = [float(x) for x in rows[k]]
        assert row[0] == r.t_s[k]
        assert row[1:4] == list(r.pos_error_ned_m[k])
        assert row[4:7] == list(r.sigma[k, 0:3])
    # the health verdict: the same checks and words as the CLI's
    assert r.health == js["health"] and r.health["ok"]
    assert [c["name"] for c in r.health["checks"]] == [
        "nis_windows", "rejected_share", "forced_updates", "sigma_h", "bias"]
    inn = r.innovations
    assert (inn["kind"] == "gnss").sum() == js["fixes"]
    assert (~inn["accepted"]).sum() == js["rejected"]


def test_fuse_bad_input():
    with pytest.raises(sdins.SdinsError, match="cov_rate_hz"):
        sdins.fuse("dq-paper", cov_rate_hz=-1.0)
    with pytest.raises(sdins.SdinsError, match="algo"):
        sdins.fuse("dq-paper", algo="nope")


def test_fuse_smooth_equals_cli_smoothed_csv(cli, tmp_path):
    out = tmp_path / "f"
    code, _, err = cli("fuse", "dq-paper", "--smooth", "--out", str(out), "--json")
    assert code == 0, err
    rows = np.loadtxt(out / "smoothed.csv", delimiter=",", skiprows=1, ndmin=2)
    r = sdins.fuse("dq-paper", smooth=True)
    s = r.smoothed
    assert s is not None and len(s["t_s"]) == rows.shape[0]
    # the CSV prints shortest round-trip decimals ({:e}): equal to the last bit
    assert np.array_equal(s["pos_error_ned_m"][:, 0], rows[:, 1])
    assert np.array_equal(s["sigma"][:, 0], rows[:, 4])
    # smoothed rows at the forward rows' epochs (the epoch rule, initial row included);
    # the smoother never has a larger σ than the forward filter at the same epoch
    assert np.array_equal(s["t_s"], r.t_s)
    assert np.all(s["sigma"][:, :9] <= r.sigma[:, :9] * (1 + 1e-12))


def test_fuse_files_navego_equals_cli(cli, tmp_path):
    import pathlib

    d = pathlib.Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "csv" / "navego"
    if not d.is_dir():
        pytest.skip(f"{d} not found")
    args = dict(
        imu=str(d / "imu2.csv"), gnss=str(d / "gnss.csv"),
        navego_params=str(d / "imu2_params.txt"), truth=str(d / "ref.csv"), smooth=True,
    )
    code, out, err = cli(
        "fuse", "--imu", args["imu"], "--gnss", args["gnss"], "--navego-params",
        args["navego_params"], "--truth", args["truth"], "--smooth", "--json",
        "--out", str(tmp_path / "n"),
    )
    assert code == 0, err
    js = json.loads(out)
    r = sdins.fuse_files(**args)
    assert r["fixes_used"] == js["fixes_used"] and r["rejected"] == js["rejected"]
    assert r["health"] == js["health"] and r["health"]["ok"]
    names = ["roll", "pitch", "yaw", "v_N", "v_E", "v_D", "N", "E", "D"]
    for i, n in enumerate(names):
        want = js["smoothed_vs_truth"][n]["rmse"]
        got = r["smoothed_rmse"][i]
        assert (np.degrees(got) if i < 3 else got) == want, n
        assert r["smoothed_rmse"][i] <= r["forward_rmse"][i], n
    assert len(r["smoothed"]["t_s"]) == len(r["forward"]["t_s"])


def test_fuse_files_bad_input_raises_located_error(tmp_path):
    g = tmp_path / "g.csv"
    g.write_text("t_s,lat_deg,lon_deg,h_m,sigma_n_m,sigma_e_m,sigma_d_m\n1,95,127,0,1,1,2\n")
    imu = tmp_path / "i.csv"
    imu.write_text("t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n"
                   + "".join(f"{0.01 * (k + 1)},0,0,0,0,0,-0.098\n" for k in range(300)))
    with pytest.raises(sdins.SdinsError, match="g.csv:2"):
        sdins.fuse_files(str(imu), str(g), gnss_format="sdins", grade="tactical",
                         init="37.5,127,0,0,0,0,0,0,0")
    with pytest.raises(sdins.SdinsError, match="--grade"):
        sdins.fuse_files(str(imu), str(g), init="37.5,127,0,0,0,0,0,0,0")


def test_fuse_scale_factors_equal_cli(cli, tmp_path):
    code, out, err = cli(
        "fuse", "dq-paper", "--json", "--scale-factors-ppm", "300,500", "--out", str(tmp_path / "f")
    )
    assert code == 0, err
    js = json.loads(out)
    r = sdins.fuse("dq-paper", scale_factors_ppm=(300.0, 500.0))
    n = r.t_s.shape[0]
    assert r.scale_factor_error.shape == (n, 6) and r.scale_factor_sigma.shape == (n, 6)
    # the prior σ at the first epoch (the scale factors barely move in one epoch)
    assert abs(r.scale_factor_sigma[0, 0] - 300e-6) < 30e-6
    assert abs(r.scale_factor_sigma[0, 3] - 500e-6) < 50e-6
    assert [x * 1e6 for x in r.gyro_scale_est] == js["gyro_scale_est_ppm"]
    assert [x * 1e6 for x in r.accel_scale_true] == js["accel_scale_true_ppm"]
    # without the option: no scale-factor states
    assert sdins.fuse("dq-paper", until_s=5.0).scale_factor_error is None


def test_fuse_grade_equals_cli(cli, tmp_path):
    # --grade on a scenario: the simulated IMU errors and the filter's model
    code, out, err = cli(
        "fuse", "dq-paper", "--grade", "consumer", "--json", "--until-s", "20",
        "--out", str(tmp_path / "g"),
    )
    assert code == 0, err
    js = json.loads(out)
    r = sdins.fuse("dq-paper", grade="consumer", until_s=20.0)
    assert js["grade"] == "consumer"
    for k in ("accel_bias_est_mps2", "accel_bias_true_mps2", "gyro_bias_true_rps"):
        assert r.__dict__[k] == js[k], k
    assert r.rms()["rms_pos_ned_m"] == js["rms_pos_ned_m"]
    # and it changes the run: the consumer grade's biases are 10x the default's
    plain = sdins.fuse("dq-paper", until_s=20.0)
    assert plain.accel_bias_true_mps2 != r.accel_bias_true_mps2
    with pytest.raises(sdins.SdinsError, match="grade"):
        sdins.fuse("dq-paper", grade="nope")


def test_fuse_montecarlo_equals_cli(cli, tmp_path):
    # two CLI shards merged by the CLI against Python shards merged in Python
    kw = ["--grade", "tactical", "--no-gate", "--until-s", "15", "--runs", "6", "--seed", "3",
          "--block", "2", "--quiet"]
    for i in range(2):
        code, _, err = cli("fuse", "dq-paper", *kw, "--shard", f"{i}/2",
                           "--out", str(tmp_path / f"s{i}"))
        assert code == 0, err
    code, out, err = cli("fuse", "--merge", str(tmp_path / "s1"), str(tmp_path / "s0"),
                         "--out", str(tmp_path / "m"), "--json")
    assert code == 0, err
    js = json.loads(out)
    py = [
        sdins.fuse_montecarlo("dq-paper", 6, seed=3, shard=(i, 2), block=2, grade="tactical",
                              gate=False, until_s=15.0)
        for i in (1, 0)
    ]
    merged = sdins.fuse_merge(py)
    cli_state = sdins.FuseMcState.from_file(tmp_path / "m")
    assert merged == cli_state
    st = merged.statistics()
    assert st["runs"] == 6 and st["complete"] and js["runs"] == 6
    assert st["columns"][0] == "nees_position" and st["mean"].shape[1] == len(st["columns"])
    c = merged.consistency("nees_position", after_s=5.0)
    assert c["epochs"] > 0 and c["dof"] == 3
    with pytest.raises(sdins.SdinsError, match="missing"):
        sdins.fuse_merge(py[:1])


def _rate_logger(cli, tmp_path):
    """A rate logger's files (deg/s and g on right-forward-up axes, GPS seconds of week;
    fixes without σ) written from an `sdins truth` record, as in own_data_cli.rs."""
    scn = tmp_path / "s.toml"
    scn.write_text(
        'name = "own-data"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\nspeed_mps = 10.0\n'
        '[imu]\nrate_hz = 100.0\ngrade = "tactical"\n[nav]\nsamples = 2\n'
        '[[segment]]\ntype = "turn"\nrate_dps = 3.0\nduration_s = 30.0\n'
    )
    code, _, err = cli("truth", str(scn), "--out", str(tmp_path / "rec"))
    assert code == 0, err
    rows = [list(map(float, l.split(","))) for l in (tmp_path / "rec" / "imu.csv").read_text().splitlines()[1:]]
    dt, sow0, g0 = rows[0][0], 345600.0, 9.80665
    out = ["time,gx,gy,gz,ax,ay,az"]
    for t, r in [(0.0, rows[0])] + [(r[0], r) for r in rows]:
        w = [np.degrees(x / dt) for x in (r[2], r[1], -r[3])]
        a = [x / dt / g0 for x in (r[5], r[4], -r[6])]
        out.append(",".join(repr(float(x)) for x in [sow0 + t] + w + a))
    imu = tmp_path / "rates.csv"
    imu.write_text("\n".join(out) + "\n")
    fixes = ["time,lat,lon,alt"]
    for l in (tmp_path / "rec" / "truth.csv").read_text().splitlines()[1:]:
        v = l.split(",")
        t = float(v[0])
        if t > 0 and abs(t * 2 - round(t * 2)) < 1e-9:
            fixes.append(f"{sow0 + t!r},{v[1]},{v[2]},{v[3]}")
    gnss = tmp_path / "fixes.csv"
    gnss.write_text("\n".join(fixes) + "\n")
    return imu, gnss, tmp_path / "rec" / "truth.csv"


RATE_MAP = ("t_s=time,gyro_x_dps=gx,gyro_y_dps=gy,gyro_z_dps=gz,accel_x_g=ax,accel_y_g=ay,"
            "accel_z_g=az,axes=x:+y,y:+x,z:-z,time=gps-sow")
FIX_MAP = "t_s=time,lat_deg=lat,lon_deg=lon,h_m=alt,time=gps-sow"


def test_fuse_files_column_maps_equal_cli(cli, tmp_path):
    imu, gnss, truth = _rate_logger(cli, tmp_path)
    init = "37.5,127,0,10,0,0,0,0,0"
    code, out, err = cli(
        "fuse", "--imu", str(imu), "--gnss", str(gnss), "--imu-columns", RATE_MAP,
        "--gnss-columns", FIX_MAP, "--gnss-sigma", "1,1,2", "--grade", "tactical",
        "--init", init, "--truth", str(truth), "--json", "--health", "warn",
        "--out", str(tmp_path / "o"),
    )
    assert code == 0, err
    js = json.loads(out)
    r = sdins.fuse_files(str(imu), str(gnss), imu_columns=RATE_MAP, gnss_columns=FIX_MAP,
                         gnss_sigma="1,1,2", grade="tactical", init=init, truth=str(truth))
    assert r["fixes_used"] == js["fixes_used"]
    assert r["inputs"]["imu"].startswith("imu: 3001 rows, time gps-sow")
    names = ["roll", "pitch", "yaw", "v_N", "v_E", "v_D", "N", "E", "D"]
    for i, n in enumerate(names):
        got = r["forward_rmse"][i]
        assert (np.degrees(got) if i < 3 else got) == js["forward_vs_truth"][n]["rmse"], n
    rec = sdins.read_imu(str(imu), columns=RATE_MAP)
    assert len(rec) == 3000 and rec.input is not None
    with pytest.raises(sdins.SdinsError, match="imu_columns.*reflection"):
        sdins.fuse_files(str(imu), str(gnss), imu_columns=RATE_MAP.replace("z:-z", "z:+z"),
                         gnss_columns=FIX_MAP, gnss_sigma="1,1,2", grade="tactical", init=init)


def test_fuse_files_sensor_model(cli, tmp_path):
    """``sensor_model=``: your own sensor-model TOML (docs/own-data.md "Your sensor
    model"); a bad key is an error naming it and its line; on NaveGo's data the result
    equals the CLI's ``--sensor-model`` run."""
    import os
    import pathlib

    bad = tmp_path / "bad.toml"
    bad.write_text("[imu]\ngyro_arw_dpsh = [0.1, 0.1, 0.1]\ngyro_arw = [1, 1, 1]\n")
    with pytest.raises(sdins.SdinsError, match=r"bad\.toml:3:.*gyro_arw"):
        sdins.fuse_files(str(tmp_path / "imu.csv"), str(tmp_path / "gnss.csv"),
                         sensor_model=str(bad), attitude_deg=[0, 0, 0])
    base = os.environ.get("SDINS_SHARED_DATA")
    d = (pathlib.Path(base) if base else
         pathlib.Path(__file__).resolve().parents[2] / ".." / "shared" / "data") / "csv" / "navego"
    if not d.is_dir():
        pytest.skip(f"{d} not found")
    model = tmp_path / "adis.toml"
    model.write_text(
        "[imu]\ngyro_arw_dpsh = [2, 2, 2]\naccel_vrw_mpsph = [0.2, 0.2, 0.2]\n"
        "gyro_bias_dph = [10800, 10800, 10800]\naccel_bias_ug = [50000, 50000, 50000]\n"
        "gyro_bias_turn_on_dph = [624, 624, 624]\naccel_bias_turn_on_ug = [2900, 2900, 2900]\n"
        "gyro_bias_instability_dph = [23.3, 23.3, 23.3]\ngyro_bias_instability_tau_s = [189, 189, 189]\n"
        "[initial]\nattitude_deg = [0, 0, -15]\nattitude_sigma_deg = [1, 1, 2]\n"
    )
    args = dict(imu=str(d / "imu1.csv"), gnss=str(d / "gnss.csv"), truth=str(d / "ref.csv"),
                sensor_model=str(model), samples=1)
    code, out, err = cli(
        "fuse", "--imu", args["imu"], "--gnss", args["gnss"], "--truth", args["truth"],
        "--sensor-model", str(model), "--samples", "1", "--health", "warn", "--json",
        "--out", str(tmp_path / "n"),
    )
    assert code == 0, err
    js = json.loads(out)
    r = sdins.fuse_files(**args)
    assert r["fixes_used"] == js["fixes_used"] and r["rejected"] == js["rejected"]
    names = ["roll", "pitch", "yaw", "v_N", "v_E", "v_D", "N", "E", "D"]
    for i, n in enumerate(names):
        want = js["forward_vs_truth"][n]["rmse"]
        got = r["forward_rmse"][i]
        assert (np.degrees(got) if i < 3 else got) == want, n


def test_fuse_files_aiding_and_zupt_detector(cli, tmp_path):
    """``aiding=`` (docs/own-data.md "Aiding sensors") and the ZUPT detector on recorded
    data equal the CLI's ``--aiding --zupt-detector`` run; a bad aiding table is an error
    naming it."""
    imu, gnss, _ = _rate_logger(cli, tmp_path)
    init = "37.5,127,0,10,0,0,0,0,0"
    # an odometer on the IMU's clock (GPS seconds of week): the drive's 10 m/s at 10 Hz
    sow0 = 345600.0
    rows = ["time,v"] + [f"{sow0 + k / 10.0!r},10.0" for k in range(1, 300)]
    (tmp_path / "odo.csv").write_text("\n".join(rows) + "\n")
    aid = tmp_path / "aiding.toml"
    aid.write_text('[odometer]\nfile = "odo.csv"\ncolumns = "t_s=time,speed_mps=v,time=gps-sow"\n'
                   "sigma_mps = 0.1\n")
    code, out, err = cli(
        "fuse", "--imu", str(imu), "--gnss", str(gnss), "--imu-columns", RATE_MAP,
        "--gnss-columns", FIX_MAP, "--gnss-sigma", "1,1,2", "--grade", "tactical",
        "--init", init, "--json", "--health", "warn", "--aiding", str(aid),
        "--zupt-detector", "--zupt-sigma-mps", "0.01", "--out", str(tmp_path / "o"))
    assert code == 0, err
    js = json.loads(out)
    r = sdins.fuse_files(str(imu), str(gnss), imu_columns=RATE_MAP, gnss_columns=FIX_MAP,
                         gnss_sigma="1,1,2", grade="tactical", init=init, aiding=str(aid),
                         zupt_sigma_mps=0.01)
    assert r["fixes_used"] == js["fixes_used"]
    assert js["measurements"]["odometer"]["applied"] > 250
    # the innovations carry the odometer updates too
    assert sum(1 for k in r["innovations"]["kind"] if k == "odometer") == \
        sum(js["measurements"]["odometer"][k] for k in ("applied", "rejected", "late"))
    bad = tmp_path / "bad.toml"
    bad.write_text('[wheel]\nfile = "odo.csv"\n')
    with pytest.raises(sdins.SdinsError, match=r"unknown table `\[wheel\]`"):
        sdins.fuse_files(str(imu), str(gnss), imu_columns=RATE_MAP, gnss_columns=FIX_MAP,
                         gnss_sigma="1,1,2", grade="tactical", init=init, aiding=str(bad))


def test_fuse_scenario_aiding_sensors_and_zupt_detector():
    """A scenario's aiding sensors are fused from Python as from the CLI; the ZUPT from the
    stationarity detector needs its σ."""
    scn = sdins.Scenario.builtin("car-odometer")
    r = sdins.fuse(scn, zupt_sigma_mps=0.01, zupt_detector=True, until_s=60.0)
    kinds = set(r.innovations["kind"])
    assert {"gnss", "odometer", "zupt"} <= kinds, kinds
    assert r.health["ok"], r.health
    with pytest.raises(sdins.SdinsError, match="zupt_detector needs zupt_sigma_mps"):
        sdins.fuse(scn, zupt_detector=True, until_s=10.0)

"""The Python API gives the CLI's numbers to the last bit (same library functions).

Exactness: the CLI writes floats as shortest round-trip decimals (`{}`, `{:e}`, serde_json),
which Python parses back to the same IEEE-754 doubles, so every comparison is `==`.
"""

import csv
import json
import math

import numpy as np
import pytest

import sdins

D = 180.0 / math.pi  # as the CLI: value_rad * (180 / π)


def read_csv(path):
    with open(path) as f:
        rows = [r for r in csv.reader(l for l in f if not l.startswith("#"))]
    return rows[0], rows[1:]


def same_error_dict(py, js):
    for k in ("t_s", "height_err_m"):
        assert py[k] == js[k], k
    for k in ("pos_err_ned_m", "vel_err_ned_mps", "att_err_rad", "euler_err_rad"):
        assert list(py[k]) == js[k], k


@pytest.mark.parametrize(
    "name,algos",
    [
        ("turn-90dps", "savage,songlee,songlee-complete,dualquat"),
        ("dq-paper", "savage,songlee,songlee-complete,dualquat"),
        ("mach1-east", "savage,songlee"),  # Song–Lee Table 1
    ],
)
def test_run_json_and_csv_bit_identical(cli, tmp_path, name, algos):
    code, out, err = cli("run", name, "--algo", algos, "--json", "--quiet", "--out", tmp_path)
    assert code == 0, err
    js = json.loads(out)
    py = sdins.run(name, algos=algos)
    assert list(py) == algos.split(",")
    for r in js["results"]:
        a = py[r["algo"]]
        assert a.nav_updates == r["nav_updates"] and a.samples == r["samples"]
        same_error_dict(a.final, r["final"])
        same_error_dict(a.max_abs, r["max_abs"])
        head, rows = read_csv(tmp_path / f"err_{a.algo}.csv")
        got = np.column_stack(
            [a.errors.t_s, a.errors.pos_err_ned_m, a.errors.vel_err_ned_mps,
             a.errors.att_err_rad, a.errors.height_err_m, a.errors.euler_err_rad]
        )
        want = np.array(rows, dtype=float)
        assert got.shape == want.shape
        assert np.array_equal(got, want), f"{a.algo}: err CSV differs"
        head, rows = read_csv(tmp_path / f"nav_{a.algo}.csv")
        n = a.nav
        got = np.column_stack(
            [n.t_s, n.lat_rad * D, n.lon_rad * D, n.h_m, n.v_ned_mps, n.euler_rad * D]
        )
        assert np.array_equal(got, np.array(rows, dtype=float)), f"{a.algo}: nav CSV differs"


def test_truth_csv_bit_identical(cli, tmp_path):
    code, _, err = cli("truth", "turn-90dps", "--every", "7", "--quiet", "--out", tmp_path)
    assert code == 0, err
    t = sdins.truth("turn-90dps", every=7)
    _, rows = read_csv(tmp_path / "imu.csv")
    imu = np.array(rows, dtype=float)
    assert np.array_equal(imu[:, 0], t.imu_t_s)
    assert np.array_equal(imu[:, 1:4], t.dtheta_rad)
    assert np.array_equal(imu[:, 4:7], t.dv_mps)
    _, rows = read_csv(tmp_path / "truth.csv")
    assert len(rows) == len(t)
    # truth.csv holds shortest round-trip decimals (csv crate): the same doubles, every row
    tr = np.array(rows, dtype=float)
    got = np.column_stack(
        [t.t_s, t.lat_rad * D, t.lon_rad * D, t.h_m, t.v_ned_mps, t.euler_rad * D, t.q_b_n]
    )
    assert np.array_equal(tr, got)


def test_nav_over_imu_file_bit_identical(cli, tmp_path):
    code, _, err = cli("truth", "turn-90dps", "--quiet", "--out", tmp_path)
    assert code == 0, err
    init = "37.5,127,0,0,340.29,0,0,0,90"
    code, out, err = cli(
        "nav", "--imu", tmp_path / "imu.csv", "--init", init, "--algo", "songlee",
        "--samples", "3", "--json", "--out", tmp_path / "n",
    )
    assert code == 0, err
    js = json.loads(out)
    rec = sdins.read_imu(tmp_path / "imu.csv")
    nav = sdins.navigate(rec.dtheta_rad, rec.dv_mps, rec.dt_s, init, algo="songlee",
                         samples=3, t0_s=rec.t0_s - rec.dt_s)
    assert nav.updates == js["imu_samples"] // 3
    _, rows = read_csv(tmp_path / "n" / "nav_songlee.csv")
    # `sdins nav` writes value_rad · (180/π), shortest round-trip decimals
    got = np.column_stack(
        [nav.t_s, nav.lat_rad * D, nav.lon_rad * D, nav.h_m, nav.v_ned_mps, nav.euler_rad * D]
    )
    assert np.array_equal(got, np.array(rows, dtype=float))


def test_montecarlo_state_equals_cli(cli, tmp_path):
    code, out, err = cli(
        "montecarlo", "turn-90dps", "--runs", "6", "--seed", "5", "--grade", "tactical",
        "--block", "2", "--every-s", "0.5", "--quiet", "--json", "--out", tmp_path,
    )
    assert code == 0, err
    st = sdins.montecarlo("turn-90dps", 6, 5, grade="tactical", block=2, every_s=0.5)
    assert st == sdins.McState.from_file(tmp_path)
    stats = sdins.merge([st])
    js = json.loads(out)
    for k, c in enumerate(stats.channels):
        f = js["final"][c]
        assert stats.mean[-1, k] == f["mean"] and stats.sigma[-1, k] == f["sigma"]
        assert stats.p95[-1, k] == f["p95"]


# the unit constants of sdins_sim::sensors::imu_error, formed as there
DEG = math.pi / 180.0
DPH = DEG / 3600.0
DPSH = DEG / 60.0
UG = 1e-6 * 9.80665


def test_allan_equals_cli_json_and_csv(cli, tmp_path):
    """`sdins allan --json` and allan.csv against `sdins.read_imu` + `sdins.allan`."""
    code, _, err = cli("truth", "turn-90dps", "--out", tmp_path / "t", "--quiet")
    assert code == 0, err
    code, out, err = cli("allan", "--imu", tmp_path / "t" / "imu.csv", "--json", "--out", tmp_path / "a")
    assert code == 0, err
    rec = sdins.read_imu(tmp_path / "t" / "imu.csv")
    res = sdins.allan(rec.dtheta_rad, rec.dv_mps, rec.dt_s)
    header, rows = read_csv(tmp_path / "a" / "allan.csv")
    got = np.array(rows, dtype=float)
    assert np.array_equal(got[:, 0], res.tau_s)
    units = [DPH] * 3 + [UG] * 3
    for k in range(6):
        assert np.array_equal(got[:, 1 + k], res.adev[:, k] / units[k]), header[1 + k]
    js = json.loads(out)
    for k, ch in enumerate(js["channels"]):
        white = res.fits[k]["white"]
        if k < 3:
            want = None if white is None else white / DPSH
            assert ch["arw_dpsh"] == want, ch["name"]
        else:
            want = None if white is None else white / UG
            assert ch["vrw_ugpsqrthz"] == want, ch["name"]


def test_calibrate_equals_cli_json(cli):
    code, out, err = cli("calibrate", "calibration", "--runs", "3", "--json")
    assert code == 0, err
    assert sdins.calibrate("calibration", runs=3) == json.loads(out)
    code, out, err = cli("calibrate", "calibration", "--no-draw", "--run", "2", "--json")
    assert code == 0, err
    assert sdins.calibrate("calibration", draw=False, run=2) == json.loads(out)
    with pytest.raises(sdins.SdinsError, match="draw_scale_ppm"):
        sdins.calibrate("calibration", draw_scale_ppm=(10.0, 2e5))


def test_merge_equals_cli_json(cli, tmp_path):
    kw = dict(grade="tactical", block=2, every_s=0.5)
    for i in range(2):
        code, _, err = cli(
            "montecarlo", "turn-90dps", "--runs", "6", "--seed", "5", "--grade", "tactical",
            "--block", "2", "--every-s", "0.5", "--shard", f"{i}/2", "--quiet",
            "--out", tmp_path / f"s{i}",
        )
        assert code == 0, err
    code, out, err = cli("merge", tmp_path / "s0", tmp_path / "s1", "--json", "--quiet", "--out", tmp_path / "m")
    assert code == 0, err
    states = [sdins.montecarlo("turn-90dps", 6, 5, shard=(i, 2), **kw) for i in range(2)]
    stats = sdins.merge(states)
    js = json.loads(out)
    for k, c in enumerate(stats.channels):
        f = js["final"][c]
        assert stats.mean[-1, k] == f["mean"] and stats.sigma[-1, k] == f["sigma"], c

"""Every API function, with checks that can fail (closed forms, identities, theory)."""

import math
import pickle

import numpy as np
import pytest

import sdins

DPH = math.pi / 180.0 / 3600.0  # rad/s per deg/h


def test_scenarios_and_scenario_roundtrip(tmp_path):
    names = [n for n, _ in sdins.scenarios()]
    assert {"stationary", "mach1-east", "turn-90dps", "dq-paper"} <= set(names)
    s = sdins.Scenario.builtin("turn-90dps")
    assert s.name == "turn-90dps" and s.duration_s == 30.0 and s.samples == 3
    assert s.dt_s == 1.0 / 500.0
    t = sdins.Scenario.from_toml(s.to_toml())
    p = tmp_path / "s.toml"
    p.write_text(s.to_toml())
    f = sdins.Scenario.from_file(p)
    for x in (t, f, pickle.loads(pickle.dumps(s))):
        assert x.to_toml() == s.to_toml() and x.duration_s == s.duration_s


def test_truth_shapes_decimation_and_until():
    t = sdins.truth("turn-90dps")
    n = round(30.0 * 500)
    assert t.dtheta_rad.shape == (n, 3) and t.dv_mps.shape == (n, 3)
    assert len(t) == n + 1 and t.q_b_n.shape == (n + 1, 4)
    assert all(a.dtype == np.float64 for a in (t.t_s, t.dtheta_rad, t.q_b_n))
    # unit quaternions, and q_b_n agrees with the Euler angles' yaw (level flight)
    assert np.max(np.abs(np.linalg.norm(t.q_b_n, axis=1) - 1.0)) < 4e-16
    # the first 6 s are a straight run east at 340.29 m/s
    assert t.v_ned_mps[0, 1] == pytest.approx(340.29, abs=1e-9)
    d = sdins.truth("turn-90dps", every=10, until_s=1.0)
    assert len(d.dtheta_rad) == 500 and len(d) == 51
    assert np.array_equal(d.dtheta_rad, t.dtheta_rad[:500])
    assert np.array_equal(d.lat_rad[1:], t.lat_rad[10:501:10])
    assert len(sdins.truth("turn-90dps", imu=False).dtheta_rad) == 0


def test_corrupt_constant_bias_is_exact_and_runs_are_deterministic():
    t = sdins.truth("turn-90dps", until_s=1.0)
    b_dph = [0.5, -1.0, 2.0]
    a, v = sdins.corrupt(t.dtheta_rad, t.dv_mps, t.dt_s, errors={"gyro_bias_dph": b_dph})
    # a constant bias adds b·δt to every Δθ (rounding of one addition: ≤ 1 ulp of Δθ)
    want = np.array(b_dph) * DPH * t.dt_s
    diff = a - t.dtheta_rad
    assert np.max(np.abs(diff - want)) <= 4 * np.finfo(float).eps * np.max(np.abs(t.dtheta_rad))
    assert np.array_equal(v, t.dv_mps)
    g1 = sdins.corrupt(t.dtheta_rad, t.dv_mps, t.dt_s, grade="tactical", seed=3, run=1)
    g2 = sdins.corrupt(t.dtheta_rad, t.dv_mps, t.dt_s, grade="tactical", seed=3, run=1)
    g3 = sdins.corrupt(t.dtheta_rad, t.dv_mps, t.dt_s, grade="tactical", seed=3, run=2)
    assert np.array_equal(g1[0], g2[0]) and not np.array_equal(g1[0], g3[0])


def test_navigate_equals_run_state_for_state():
    # the same increments through the same algorithm: navigate == run at every update
    scn = sdins.Scenario.builtin("turn-90dps")
    t = sdins.truth(scn)
    lat, lon = math.degrees(t.lat_rad[0]), math.degrees(t.lon_rad[0])
    v = t.v_ned_mps[0]
    r, p, y = np.degrees(t.euler_rad[0])
    init = [lat, lon, t.h_m[0], v[0], v[1], v[2], r, p, y]
    nav = sdins.navigate(t.dtheta_rad, t.dv_mps, t.dt_s, init, algo="songlee-complete", samples=3)
    run = sdins.run(scn, algos=["songlee-complete"], every_s=3 * t.dt_s, vertical="free", ideal=True)
    rn = run["songlee-complete"].nav
    # run keeps the initial state as its first row (the epoch rule), navigate returns
    # the state after every update
    assert len(nav) == 5000 and len(rn) == 5001
    assert rn.t_s[0] == 0.0
    assert np.array_equal(nav.t_s, rn.t_s[1:])
    # init through degrees costs ≤ 1 ulp of the angles; the algorithm is the same
    assert np.max(np.abs(nav.lat_rad - rn.lat_rad[1:])) < 1e-15
    assert np.max(np.abs(nav.v_ned_mps - rn.v_ned_mps[1:])) < 1e-9
    # and the complete algorithm is exact to ~1e-10 rad on this case (README table)
    e = run["songlee-complete"].errors
    assert np.max(np.abs(e.att_err_rad)) < 1e-9


def test_run_defaults_are_the_scenarios():
    r = sdins.run("turn-90dps")
    assert list(r) == sdins.Scenario.builtin("turn-90dps").algos
    a = next(iter(r.values()))
    assert a.nav_updates == 5000 and len(a.errors) == 31  # 0, 1, …, 30 s
    assert a.errors.t_s[-1] == pytest.approx(30.0)


def test_read_imu_psins(shared_data):
    files = sorted((shared_data / "psins").glob("*.imu"))
    if not files:
        pytest.skip("no PSINS .imu file in the shared data")
    rec = sdins.read_imu(files[0], "psins")
    assert rec.format == "psins" and rec.dtheta_rad.shape[1] == 3 and len(rec) > 0
    assert rec.psins_header is not None


def test_allan_white_noise_recovers_the_arw():
    # pure angle random walk N: σ(τ) = N/√τ; the fit must return N within the Allan
    # estimate's statistical error (~1/√(2·clusters) ≈ 2 % at τ = 1 s here; tolerance 10 %)
    n, dt = 200_000, 0.01
    z = np.zeros((n, 3))
    arw_dpsh = 0.1
    a, v = sdins.corrupt(z, z, dt, errors={"gyro_arw_dpsh": [arw_dpsh] * 3}, seed=7)
    res = sdins.allan(a, v, dt)
    want = arw_dpsh * math.pi / 180.0 / 60.0  # deg/√h → rad/√s
    for k in range(3):
        assert res.fits[k]["white"] == pytest.approx(want, rel=0.10)
    assert res.adev.shape == (len(res.tau_s), 6)


def test_to_pandas():
    pd = pytest.importorskip("pandas")
    r = sdins.run("turn-90dps", algos="songlee")
    df = r["songlee"].errors.to_pandas()
    assert isinstance(df, pd.DataFrame) and df.index.name == "t_s"
    assert list(df.columns[:3]) == ["pos_err_n_m", "pos_err_e_m", "pos_err_d_m"]
    assert np.array_equal(df["att_err_d_rad"].to_numpy(), r["songlee"].errors.att_err_rad[:, 2])
    assert sdins.truth("turn-90dps", until_s=0.1).to_pandas().shape[0] == 51
    st = sdins.merge([sdins.montecarlo("turn-90dps", 4, 1, grade="tactical", block=2, until_s=1.0)])
    assert st.to_pandas().shape == (len(st.times_s), 45)


def test_montecarlo_shards_merge_exactly_in_process():
    kw = dict(grade="tactical", block=2, until_s=2.0, every_s=0.5)
    whole = sdins.merge([sdins.montecarlo("turn-90dps", 10, 9, **kw)])
    shards = [sdins.montecarlo("turn-90dps", 10, 9, shard=(i, 3), **kw) for i in (2, 0, 1)]
    part = sdins.merge(shards)
    for k in ("times_s", "mean", "sigma", "p05", "p50", "p95"):
        assert np.array_equal(getattr(part, k), getattr(whole, k)), k
    assert part.runs == 10 and part.complete
    with pytest.raises(sdins.SdinsError, match="blocks missing"):
        sdins.merge(shards[:2])
    assert sdins.merge(shards[:2], allow_partial=True).runs < 10


def test_scenario_from_reference(tmp_path):
    # a gentle 4 s turn at 10 Hz rows from reference time 100 s, in a CSV of its own
    rows = ["time,lat,lon,alt,r,p,y"]
    for i in range(41):
        t = 0.1 * i
        rows.append(f"{100 + t!r},{45 + 1e-5 * t!r},{7 + 1e-5 * t * (1 + 0.01 * t)!r},100,0.5,1.0,{30 + 2 * t!r}")
    f = tmp_path / "log.csv"
    f.write_text("\n".join(rows) + "\n")
    cols = "t_s=time,lat_deg=lat,lon_deg=lon,h_m=alt,roll_deg=r,pitch_deg=p,yaw_deg=y"
    s = sdins.Scenario.from_reference(f, rate_hz=50.0, columns=cols)
    assert s.duration_s == pytest.approx(4.0) and s.dt_s == 1.0 / 50.0
    t = sdins.truth(s)
    assert t.dtheta_rad.shape == (200, 3)
    # the interpolant passes through the rows: at truth time 2 s (row 20) yaw is 34 deg
    k = int(np.argmin(np.abs(t.t_s - 2.0)))
    assert t.t_s[k] == pytest.approx(2.0)
    assert math.degrees(t.euler_rad[k, 2]) == pytest.approx(34.0, abs=1e-9)
    assert math.degrees(t.lat_rad[k]) == pytest.approx(45 + 2e-5, abs=1e-12)
    # picklable (Dask): the same truth again
    u = sdins.truth(pickle.loads(pickle.dumps(s)))
    assert np.array_equal(u.dv_mps, t.dv_mps)
    rows[6] = rows[5]
    f.write_text("\n".join(rows) + "\n")
    with pytest.raises(sdins.SdinsError, match=r"log\.csv:7: t_s: .* does not increase"):
        sdins.Scenario.from_reference(f, columns=cols)
    with pytest.raises(sdins.SdinsError, match="--columns: missing `lat_UNIT=COLUMN`"):
        sdins.Scenario.from_reference(f, columns="t_s=time")
    with pytest.raises(sdins.SdinsError, match="earth: `flat`"):
        sdins.Scenario.from_reference(f, columns=cols, earth="flat")


def test_gnss_ins_sim_motion_file_as_scenario(shared_data):
    f = shared_data / "gnss_ins_sim" / "motion_def-3d.csv"
    s = sdins.Scenario.from_file(f)
    assert s.duration_s == pytest.approx(140.0)
    # the imported TOML is the scenario's text, so it pickles and parses back
    u = pickle.loads(pickle.dumps(s))
    assert u.to_toml() == s.to_toml() and "[[command]]" in s.to_toml()
    a = sdins.truth(s, until_s=2.0)
    b = sdins.truth(u, until_s=2.0)
    assert np.array_equal(a.dv_mps, b.dv_mps)


def test_docs_list_every_builtin_scenario():
    """docs/python.md names every built-in scenario (a new one must be documented)."""
    import pathlib
    import re

    doc = (pathlib.Path(__file__).parents[2] / "docs" / "python.md").read_text()
    line = next(l for l in doc.splitlines() if l.startswith("| `sdins.Scenario.builtin(name)`"))
    listed = set(re.findall(r"`([a-z0-9-]+)`", line.split("|")[2]))
    names = {n for n, _ in sdins.scenarios()}
    assert names <= listed, names - listed


def test_dir_shows_only_the_public_api():
    public = set(sdins.__all__) | {"__version__"}
    assert set(dir(sdins)) == public
    for hidden in ("Any", "Dict", "np", "Optional"):
        assert hidden not in dir(sdins)


def test_statistics_and_merge_return_one_type():
    st = sdins.montecarlo("turn-90dps", 2, 1, grade="tactical", until_s=1.0, every_s=0.5)
    a = st.statistics()
    b = sdins.merge([st])
    assert type(a) is type(b) is sdins.McStatistics
    assert a.sigma.tobytes() == b.sigma.tobytes()


@pytest.mark.parametrize(
    "call,arg",
    [
        (lambda: sdins.montecarlo("turn-90dps", -1), "runs = -1"),
        (lambda: sdins.montecarlo("turn-90dps", 2, seed=-5, until_s=1.0), "seed = -5"),
        (lambda: sdins.run("turn-90dps", run=2**64, until_s=1.0), "run = 18446744073709551616"),
        (lambda: sdins.truth("turn-90dps", every=-2), "every = -2"),
    ],
)
def test_out_of_range_integers_raise_sdins_error_naming_the_argument(call, arg):
    # PyO3 raises OverflowError for a negative u64; the front end says which argument
    with pytest.raises(sdins.SdinsError, match=arg.replace("+", r"\+")):
        call()

"""Bad input raises sdins.SdinsError (a ValueError) with the CLI's located message."""

import numpy as np
import pytest

import sdins

GOOD = "[start]\nlat_deg = 37.5\nlon_deg = 127.0\n[imu]\nrate_hz = 100.0\n[[segment]]\ntype = \"static\"\nduration_s = 1.0\n"


def cli_message(stderr):
    assert stderr.startswith("sdins: error: "), stderr
    return stderr[len("sdins: error: "):].strip()


@pytest.mark.parametrize(
    "text",
    [
        GOOD.replace("lon_deg = 127.0", "lon_deg = 127.0\nheigth_m = 3.0"),
        GOOD.replace("duration_s = 1.0", "duration_s = -5.0"),
        GOOD.replace("lat_deg = 37.5", "lat_deg = 95.0"),
        GOOD.replace("[imu]", "[imu"),
    ],
)
def test_bad_scenario_file_same_message_as_cli(cli, tmp_path, text):
    p = tmp_path / "bad.toml"
    p.write_text(text)
    code, _, err = cli("run", p, "--quiet")
    assert code == 2
    with pytest.raises(sdins.SdinsError) as e:
        sdins.Scenario.from_file(p)
    assert isinstance(e.value, ValueError)
    assert str(e.value) == cli_message(err)
    assert str(p) in str(e.value)  # located: the file (and line/column or key)


@pytest.mark.parametrize(
    "kwargs,cli_args",
    [
        (dict(algos="warp"), ["--algo", "warp"]),
        (dict(samples=7), ["--samples", "7"]),
        (dict(coning="four_poly", samples=3), ["--coning", "four_poly", "--samples", "3"]),
        (dict(vertical="up"), ["--vertical", "up"]),
        (dict(every_s=-1.0), ["--every-s=-1"]),
    ],
)
def test_bad_run_options_same_message_as_cli(cli, tmp_path, kwargs, cli_args):
    code, _, err = cli("run", "turn-90dps", *cli_args, "--quiet", "--out", tmp_path)
    assert code == 2
    with pytest.raises(sdins.SdinsError) as e:
        sdins.run("turn-90dps", **kwargs)
    assert str(e.value) == cli_message(err)


def test_other_bad_inputs_raise():
    z = np.zeros((10, 3))
    with pytest.raises(sdins.SdinsError, match="unknown"):
        sdins.Scenario.builtin("mach2")
    with pytest.raises(sdins.SdinsError, match=r"\(n, 3\)"):
        sdins.navigate(np.zeros((10, 2)), z, 0.01, [0] * 9)
    with pytest.raises(sdins.SdinsError, match="dt"):
        sdins.navigate(z, z, -0.01, [0] * 9)
    with pytest.raises(sdins.SdinsError, match="not finite"):
        bad = z.copy()
        bad[3, 1] = np.nan
        sdins.navigate(bad, z, 0.01, [0] * 9)
    with pytest.raises(sdins.SdinsError, match="--earth mars"):
        sdins.navigate(z, z, 0.01, [0] * 9, earth="mars")
    with pytest.raises(sdins.SdinsError, match="grade"):
        sdins.corrupt(z, z, 0.01, grade="mil-spec")
    with pytest.raises(sdins.SdinsError, match="gyro_bias_dph|unknown"):
        sdins.corrupt(z, z, 0.01, errors={"gyro_bias_dpx": [1.0, 1.0, 1.0]})
    with pytest.raises(sdins.SdinsError, match="every"):
        sdins.truth("turn-90dps", every=0)
    with pytest.raises(sdins.SdinsError, match="shard"):
        sdins.montecarlo("turn-90dps", 4, 1, shard=(3, 2), grade="tactical")
    with pytest.raises(sdins.SdinsError, match="cannot read|No such"):
        sdins.read_imu("/nonexistent/imu.csv")
    with pytest.raises(sdins.SdinsError, match="Monte Carlo state"):
        sdins.McState("{}")


def test_keyboard_interrupt_stops_a_long_call():
    import _thread
    import threading
    import time

    threading.Timer(0.3, _thread.interrupt_main).start()
    t0 = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        # about a minute of work uninterrupted (256 runs of the 90-minute case), so the
        # interrupt always lands inside the call whatever the machine's speed
        sdins.montecarlo("mach1-east", runs=256, seed=1)
    assert time.perf_counter() - t0 < 2.0

"""Monte Carlo shards as Dask tasks on a multi-process LocalCluster merge exactly: the
statistics equal a single in-process run bit for bit (docs/montecarlo.md)."""

import random

import numpy as np
import pytest

import sdins

distributed = pytest.importorskip("dask.distributed")


def test_shards_on_a_local_cluster_merge_bit_for_bit():
    scn = sdins.Scenario.builtin("turn-90dps")
    kw = dict(grade="tactical", block=2, every_s=0.5, threads=1)
    runs, seed, n = 12, 4, 4
    whole = sdins.merge([sdins.montecarlo(scn, runs, seed, **kw)])
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        futures = [
            client.submit(sdins.montecarlo, scn, runs, seed, shard=(i, n), pure=False, **kw)
            for i in range(n)
        ]
        states = client.gather(futures)
        # the shards really ran in other processes
        assert len(client.scheduler_info()["workers"]) == 2
    order = list(range(n))
    random.Random(1).shuffle(order)
    assert order != sorted(order)
    merged = sdins.merge([states[i] for i in order])
    assert merged.runs == runs and merged.complete
    for k in ("times_s", "mean", "sigma", "p05", "p50", "p95"):
        a, b = getattr(merged, k), getattr(whole, k)
        assert a.tobytes() == b.tobytes(), k
    assert merged.state == whole.state
    # and the statistics are not trivial: the sensors are noisy (the held vertical
    # channel, pos D and vel D, has no spread)
    horizontal = [0, 1, 3, 4, 6, 7, 8]
    assert np.all(merged.sigma[-1, horizontal] > 0)


def test_fuse_montecarlo_shards_on_a_local_cluster_merge_bit_for_bit():
    scn = sdins.Scenario.builtin("dq-paper")
    kw = dict(grade="tactical", gate=False, until_s=10.0, block=2, threads=1)
    runs, seed, n = 8, 2, 4
    whole = sdins.fuse_montecarlo(scn, runs, seed, **kw)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        futures = [
            client.submit(sdins.fuse_montecarlo, scn, runs, seed, shard=(i, n), pure=False, **kw)
            for i in range(n)
        ]
        states = client.gather(futures)
    order = list(range(n))
    random.Random(2).shuffle(order)
    merged = sdins.fuse_merge([states[i] for i in order])
    assert merged == whole
    a, b = merged.statistics(), whole.statistics()
    assert a["mean"].tobytes() == b["mean"].tobytes()
    assert np.all(a["mean"][1:, 0] > 0)


def test_the_documented_dask_example_runs_as_a_script(tmp_path):
    """docs/montecarlo.md's Dask block, saved as a file and run as `python file.py`
    (smaller: 16 runs of 60 s in blocks of 2), finishes: the `__main__` guard is there."""
    import pathlib
    import re
    import subprocess
    import sys

    doc = (pathlib.Path(__file__).parents[2] / "docs" / "montecarlo.md").read_text()
    section = doc[doc.index("## The same job from Python, on Dask"):]
    block = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    assert 'if __name__ == "__main__":' in block
    # 16 runs in blocks of 2: every one of the 8 shards gets a block
    small = {"1000, 1, shard": "16, 1, shard", "until_s=600.0": "until_s=60.0", "threads=1)": "threads=1, block=2)"}
    script = block
    for a, b in small.items():
        assert a in script, a
        script = script.replace(a, b)
    f = tmp_path / "mc_dask.py"
    f.write_text(script)
    r = subprocess.run([sys.executable, str(f)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    assert "t_s" in r.stdout

"""Python-side benchmarks of the `sdins` package (docs/performance.md, "From Python").

1. `sdins.navigate` on 360 000 samples (mach1-east, first 720 s at 500 Hz, N = 3,
   songlee-complete) from Python, against the same navigation in Rust alone: the
   navigation-loop time the library measures inside the same call (`wall_s`) and
   `sdins nav --json` (`wall_s`) on the same samples written as imu.csv.
2. Peak memory of `sdins.truth` on mach1-east (2.7 M samples), measured in a fresh
   subprocess as the growth of the peak RSS (VmHWM) over the imported baseline.

    python bench/python_bench.py [--sdins target/release/sdins] [--repeat 5]
"""

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]

MEM_SNIPPET = r"""
import sys, sdins
def kib(key):
    for line in open("/proc/self/status"):
        if line.startswith(key):
            return int(line.split()[1])
base = kib("VmHWM:")
kw = eval(sys.argv[1])
t = sdins.truth("mach1-east", **kw)
peak = kib("VmHWM:")
arrays = sum(getattr(t, k).nbytes for k in vars(t) if hasattr(getattr(t, k), "nbytes"))
print(peak - base, arrays, len(t.imu_t_s), len(t), kib("VmRSS:") - base)
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--sdins", default=str(ROOT / "target" / "release" / "sdins"))
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    import numpy as np

    import sdins

    t = sdins.truth("mach1-east", until_s=720.0, every=10**9)
    n = len(t.dtheta_rad)
    assert n == 360_000, n
    init = [37.5, 127.0, 0.0, 0.0, 340.29, 0.0, 0.0, 0.0, 90.0]
    py, rust = [], []
    for _ in range(a.repeat):
        t0 = time.perf_counter()
        nav = sdins.navigate(t.dtheta_rad, t.dv_mps, t.dt_s, init, samples=3)
        py.append(time.perf_counter() - t0)
        rust.append(nav.wall_s)
    # the same work in Rust alone (arrays in, state columns with Euler angles and q_b_n
    # out): examples/navigate_arrays, run alternately with the Python calls so that both
    # see the same load
    ex = ROOT / "target" / "release" / "examples" / "navigate_arrays"
    ref, py_alt = [], []
    if ex.exists():
        for _ in range(a.repeat):
            out = subprocess.run([str(ex)], capture_output=True, text=True, check=True).stdout
            ref.append(float(out.split(":")[1].split("ms")[0]) / 1e3)
            t0 = time.perf_counter()
            sdins.navigate(t.dtheta_rad, t.dv_mps, t.dt_s, init, samples=3)
            py_alt.append(time.perf_counter() - t0)
    cli = []
    if os.path.exists(a.sdins):
        with tempfile.TemporaryDirectory() as d:
            p = pathlib.Path(d) / "imu.csv"
            rows = np.column_stack([t.imu_t_s, t.dtheta_rad, t.dv_mps])
            with open(p, "w") as f:
                f.write("t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n")
                for r in rows:
                    f.write(",".join(repr(float(x)) for x in r) + "\n")
            for _ in range(a.repeat):
                out = subprocess.run(
                    [a.sdins, "nav", "--imu", str(p), "--init", ",".join(map(str, init)),
                     "--samples", "3", "--json", "--out", str(pathlib.Path(d) / "n")],
                    capture_output=True, text=True, check=True,
                ).stdout
                cli.append(json.loads(out)["wall_s"])
    med = statistics.median
    print(f"navigate, {n} samples, {nav.updates} updates (songlee-complete, N = 3), median of {a.repeat}:")
    print(f"  Python call sdins.navigate        {med(py) * 1e3:8.1f} ms")
    print(f"  Rust loop inside that call        {med(rust) * 1e3:8.1f} ms   ratio {med(py) / med(rust):.2f}")
    if ref:
        print(f"  Rust alone, examples/navigate_arrays {med(ref) * 1e3:5.1f} ms   "
              f"Python call alternating with it {med(py_alt) * 1e3:.1f} ms: ratio {med(py_alt) / med(ref):.2f}")
    else:
        print(f"  (build the reference: cargo build --release -p sdins-sim --example navigate_arrays)")
    if cli:
        print(f"  Rust alone, sdins nav --json      {med(cli) * 1e3:8.1f} ms   ratio {med(py) / med(cli):.2f}")
    print("peak memory of sdins.truth('mach1-east', ...), fresh process:")
    for kw in ("{}", "{'every': 500}", "{'every': 500, 'imu': False}", "{'until_s': 600.0}"):
        r = subprocess.run([sys.executable, "-c", MEM_SNIPPET, kw], capture_output=True, text=True, check=True)
        grow_kib, arrays, n_imu, rows, rss_kib = map(int, r.stdout.split())
        print(f"  {kw:32} {n_imu:8d} IMU samples {rows:8d} rows: arrays {arrays / 2**20:7.1f} MiB, "
              f"peak RSS (VmHWM) growth {grow_kib / 1024:7.1f} MiB, RSS after {rss_kib / 1024:7.1f} MiB")


if __name__ == "__main__":
    main()

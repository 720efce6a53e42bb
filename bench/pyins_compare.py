#!/usr/bin/env python3
"""Side-by-side with pyins (PyPI `python-ins`): same IMU increments, same machine.

Run through bench/compare.sh (it makes the throwaway venv and builds sdins).

The case is the one pyins checks its strapdown integration with in its own tests,
pyins/tests/test_strapdown.py::test_integrate_sine_velocity (increment sensors):
``sim.generate_sine_velocity_motion(1e-2, 3600, [55, 37, 1500], [5, -3, 0.2],
velocity_change_amplitude=1, sensor_type='increment')`` -- 100 Hz, 1 h, NED velocity
(5, -3, 0.2) m/s plus 1 m/s sines of period 60 s, roll 0, pitch/heading along the
velocity. pyins's simulator generates the increments; both packages navigate the same
numbers.

Frames (converted here, at the edge): pyins resolves velocity in NED and its body
axes are x forward, y right, z down, with mat_nb = Rz(heading) Ry(pitch) Rx(roll) --
the same as sdins's NED/FRD and c_b_n = Rz(yaw) Ry(pitch) Rx(roll), so the vectors pass
unchanged. pyins's angles and lat/lon are degrees (so is `sdins nav --init`). pyins
prepends a duplicate "before" sample to increment data; the sdins file holds the real
samples only, each stamped with its end time.

Gravity: pyins simulates and navigates with g = gamma(L)(1 - 2h/a) (Somigliana with the
linear free-air factor); sdins's default WGS-84 model uses the TR8350.2 height series,
~9e-6 m/s^2 weaker at 1.5 km. The free vertical channel turns that into ~760 m of
height error in the hour, which leaks into the horizontal through Coriolis, so sdins
runs with `--earth wgs84-linear`, the same gravity formula (the other constants are
identical: a, e^2, earth rate).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np

from pyins import earth, sim, strapdown
from pyins._numba_integrate import integrate as pyins_kernel


def horizontal_m(lat1, lon1, lat2, lon2, alt):
    """North/east distance [m] between two lat/lon points (degrees) near each other."""
    rn, _, rp = earth.principal_radii(lat1, alt)
    dn = np.deg2rad(lat2 - lat1) * rn
    de = np.deg2rad(lon2 - lon1) * rp
    return float(np.hypot(dn, de))


def stats(xs):
    return {"median": statistics.median(xs), "min": min(xs), "max": max(xs), "runs": len(xs)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sdins", required=True, help="path of the sdins binary")
    ap.add_argument("--out", required=True, help="output folder (generated files)")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--algos", default="savage,songlee,songlee-complete,dualquat")
    ap.add_argument("--samples", default="1,3", help="N values for sdins")
    ap.add_argument("--tolerance-m", type=float, default=0.5)
    ap.add_argument("--check", default="songlee-complete:3,dualquat:3",
                    help="algo:N rows that must agree with pyins within the tolerance "
                         "(savage is the deliberately first-order baseline and N = 1 has "
                         "no coning/sculling correction: reported, not checked)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)

    t0 = time.perf_counter()
    ref, imu = sim.generate_sine_velocity_motion(
        1e-2, 3600, [55, 37, 1500], [5, -3, 0.2], velocity_change_amplitude=1,
        sensor_type="increment")
    print(f"pyins simulator: {len(imu) - 1} increments in {time.perf_counter() - t0:.1f} s")

    # --- the sdins increment file (row 0 is pyins's duplicated "before" sample)
    t = imu.index.values[1:]
    data = np.column_stack([t, imu[["gyro_x", "gyro_y", "gyro_z"]].values[1:],
                            imu[["accel_x", "accel_y", "accel_z"]].values[1:]])
    imu_file = os.path.join(a.out, "sine_velocity_imu.csv")
    np.savetxt(imu_file, data, delimiter=",", fmt="%.17g", comments="",
               header="t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps")
    p0 = ref.iloc[0]
    init = ",".join(repr(float(p0[c])) for c in
                    ["lat", "lon", "alt", "VN", "VE", "VD", "roll", "pitch", "heading"])

    # --- pyins: the public API (coning/sculling increments + Integrator) and the kernel
    def pyins_api(imu_df):
        inc = strapdown.compute_increments_from_imu(imu_df, "increment")
        integ = strapdown.Integrator(ref.iloc[0], True)
        return integ.integrate(inc)

    def pyins_kernel_only(inc):
        n = len(inc)
        lla = np.empty((n + 1, 3))
        vel = np.empty((n + 1, 3))
        mat = np.empty((n + 1, 3, 3))
        integ = strapdown.Integrator(ref.iloc[0], True)
        lla[0], vel[0], mat[0] = integ.lla[0], integ.velocity_n[0], integ.mat_nb[0]
        theta = np.ascontiguousarray(inc[["theta_x", "theta_y", "theta_z"]])
        dv = np.ascontiguousarray(inc[["dv_x", "dv_y", "dv_z"]])
        dt = np.asarray(inc.dt)
        t0 = time.perf_counter()
        pyins_kernel(dt, lla, vel, mat, theta, dv, 0, True)
        return time.perf_counter() - t0

    pyins_api(imu.iloc[:100])  # numba compiles here, outside the timing
    api_t, kern_t = [], []
    for _ in range(a.repeat):
        t0 = time.perf_counter()
        res = pyins_api(imu)
        api_t.append(time.perf_counter() - t0)
    inc = strapdown.compute_increments_from_imu(imu, "increment")
    for _ in range(a.repeat):
        kern_t.append(pyins_kernel_only(inc))
    n_samples = len(t)
    last = res.iloc[-1]
    py_vs_ref = horizontal_m(ref.lat.iloc[-1], ref.lon.iloc[-1], last.lat, last.lon,
                             ref.alt.iloc[-1])
    print(f"pyins: Integrator API median {statistics.median(api_t):.4f} s, numba kernel "
          f"median {statistics.median(kern_t):.4f} s for {n_samples} samples; final "
          f"horizontal error vs reference {py_vs_ref:.4f} m")

    out = {"case": "pyins test_integrate_sine_velocity (increment)", "samples": n_samples,
           "pyins": {"api_s": stats(api_t), "kernel_s": stats(kern_t),
                     "final_horizontal_vs_reference_m": py_vs_ref},
           "sdins": []}
    ok = True
    print(f"{'algo':18} {'N':>2} {'nav s (med)':>11} {'min':>8} {'max':>8} {'Msamp/s':>8} "
          f"{'vs API':>7} {'vs kernel':>9} {'|sdins-pyins| m':>15} {'sdins-ref m':>11}")
    for algo in a.algos.split(","):
        for n in (int(x) for x in a.samples.split(",")):
            walls = []
            d = os.path.join(a.out, f"{algo}_N{n}")
            for _ in range(a.repeat):
                r = subprocess.run(
                    [a.sdins, "nav", "--imu", imu_file, "--format", "sdins", "--init", init,
                     "--algo", algo, "--samples", str(n), "--earth", "wgs84-linear", "--out", d, "--json"],
                    check=True, capture_output=True, text=True)
                walls.append(json.loads(r.stdout)["wall_s"])
            nav = np.loadtxt(os.path.join(d, f"nav_{algo}.csv"), delimiter=",", skiprows=1)
            t_end, lat, lon, alt = nav[-1, 0], nav[-1, 1], nav[-1, 2], nav[-1, 3]
            k = int(np.argmin(np.abs(res.index.values - t_end)))
            assert abs(res.index.values[k] - t_end) < 1e-6, (t_end, res.index.values[k])
            vs_py = horizontal_m(res.lat.iloc[k], res.lon.iloc[k], lat, lon, alt)
            kr = int(np.argmin(np.abs(ref.index.values - t_end)))
            vs_ref = horizontal_m(ref.lat.iloc[kr], ref.lon.iloc[kr], lat, lon, alt)
            med = statistics.median(walls)
            r_api = statistics.median(api_t) / med
            r_kern = statistics.median(kern_t) / med
            checked = f"{algo}:{n}" in a.check.split(",")
            if checked:
                ok &= vs_py < a.tolerance_m
            print(f"{algo:18} {n:>2} {med:>11.4f} {min(walls):>8.4f} {max(walls):>8.4f} "
                  f"{n_samples / med / 1e6:>8.2f} {r_api:>6.1f}x {r_kern:>8.2f}x "
                  f"{vs_py:>15.4f} {vs_ref:>11.4f}"
                  + (f"  {'ok' if vs_py < a.tolerance_m else 'DISAGREE'}" if checked else ""))
            out["sdins"].append({"algo": algo, "samples": n, "nav_s": stats(walls),
                                 "t_end_s": t_end, "ratio_vs_pyins_api": r_api,
                                 "ratio_vs_pyins_kernel": r_kern,
                                 "final_horizontal_vs_pyins_m": vs_py, "checked": checked,
                                 "final_horizontal_vs_reference_m": vs_ref})
    with open(os.path.join(a.out, "compare.json"), "w") as f:
        json.dump(out, f, indent=1)
    print(f"agreement of {a.check} (horizontal, after 1 h, tolerance {a.tolerance_m} m): "
          f"{'PASS' if ok else 'FAIL'}; results in {a.out}/compare.json")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())

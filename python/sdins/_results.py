"""Result classes: float64 numpy attributes and ``.to_pandas()`` (pandas imported there only)."""

from __future__ import annotations

from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

_AXES = ("n", "e", "d")


def _pandas():
    try:
        import pandas as pd
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("to_pandas() needs pandas: pip install pandas") from e
    return pd


def _frame(t_s: np.ndarray, columns: Sequence[Tuple[str, np.ndarray, Sequence[str]]]):
    """A DataFrame indexed by ``t_s``; 2-D arrays become one column per component."""
    pd = _pandas()
    data: Dict[str, np.ndarray] = {}
    for name, arr, parts in columns:
        if arr.ndim == 1:
            data[name] = arr
        else:
            for k, p in enumerate(parts):
                data[f"{name}_{p}" if p else name] = arr[:, k]
    return pd.DataFrame(data, index=pd.Index(t_s, name="t_s"))


class Truth:
    """Exact truth of a scenario (``sdins.truth``).

    Trajectory rows (row 0 is the initial state at t = 0, then every ``every`` samples):
    ``t_s`` (m,) [s]; ``lat_rad``, ``lon_rad`` (m,) geodetic [rad]; ``h_m`` (m,) [m];
    ``v_ned_mps`` (m, 3) velocity over the earth, NED [m/s]; ``euler_rad`` (m, 3)
    roll, pitch, yaw [rad]; ``q_b_n`` (m, 4) Hamilton scalar-first body-to-NED quaternion.
    IMU samples (every sample): ``imu_t_s`` (n,) end time of each sample [s];
    ``dtheta_rad`` (n, 3) Δθ = ∫ω_ib^b dt, body FRD [rad]; ``dv_mps`` (n, 3)
    Δv = ∫f^b dt, body FRD [m/s]; ``dt_s`` the sample interval [s].
    """

    def __init__(self, d: Dict[str, Any]):
        self.dt_s: float = d["dt_s"]
        self.t_s: np.ndarray = d["t_s"]
        self.lat_rad: np.ndarray = d["lat_rad"]
        self.lon_rad: np.ndarray = d["lon_rad"]
        self.h_m: np.ndarray = d["h_m"]
        self.v_ned_mps: np.ndarray = d["v_ned_mps"]
        self.euler_rad: np.ndarray = d["euler_rad"]
        self.q_b_n: np.ndarray = d["q_b_n"]
        self.imu_t_s: np.ndarray = d["imu_t_s"]
        self.dtheta_rad: np.ndarray = d["dtheta_rad"]
        self.dv_mps: np.ndarray = d["dv_mps"]

    def __len__(self) -> int:
        return len(self.t_s)

    def __repr__(self) -> str:
        return f"Truth({len(self.t_s)} rows, {len(self.imu_t_s)} IMU samples at {self.dt_s} s)"

    def to_pandas(self):
        """Trajectory rows as a DataFrame indexed by ``t_s``."""
        return _frame(
            self.t_s,
            [
                ("lat_rad", self.lat_rad, ()),
                ("lon_rad", self.lon_rad, ()),
                ("h_m", self.h_m, ()),
                ("v_mps", self.v_ned_mps, _AXES),
                ("euler_rad", self.euler_rad, ("roll", "pitch", "yaw")),
                ("q_b_n", self.q_b_n, ("w", "x", "y", "z")),
            ],
        )

    def imu_to_pandas(self):
        """IMU increments as a DataFrame indexed by ``imu_t_s``."""
        return _frame(
            self.imu_t_s,
            [("dtheta_rad", self.dtheta_rad, "xyz"), ("dv_mps", self.dv_mps, "xyz")],
        )


class Navigation:
    """Navigation states after every update (``sdins.navigate``) or at output epochs
    (``sdins.run``): ``t_s`` (m,) [s]; ``lat_rad``, ``lon_rad``, ``h_m`` (m,);
    ``v_ned_mps`` (m, 3) NED [m/s]; ``euler_rad`` (m, 3) roll, pitch, yaw [rad];
    ``q_b_n`` (m, 4) scalar-first. ``algo``, ``samples`` (N), ``updates`` and ``wall_s``
    (time in the navigation updates only [s]) where known."""

    def __init__(self, d: Dict[str, Any]):
        self.algo: Optional[str] = d.get("algo")
        self.samples: Optional[int] = d.get("samples")
        self.updates: Optional[int] = d.get("updates")
        self.wall_s: Optional[float] = d.get("wall_s")
        self.t_s: np.ndarray = d["t_s"]
        self.lat_rad: np.ndarray = d["lat_rad"]
        self.lon_rad: np.ndarray = d["lon_rad"]
        self.h_m: np.ndarray = d["h_m"]
        self.v_ned_mps: np.ndarray = d["v_ned_mps"]
        self.euler_rad: np.ndarray = d["euler_rad"]
        self.q_b_n: np.ndarray = d["q_b_n"]

    def __len__(self) -> int:
        return len(self.t_s)

    def __repr__(self) -> str:
        return f"Navigation({self.algo}, {len(self.t_s)} states)"

    def to_pandas(self):
        """States as a DataFrame indexed by ``t_s``."""
        return _frame(
            self.t_s,
            [
                ("lat_rad", self.lat_rad, ()),
                ("lon_rad", self.lon_rad, ()),
                ("h_m", self.h_m, ()),
                ("v_mps", self.v_ned_mps, _AXES),
                ("euler_rad", self.euler_rad, ("roll", "pitch", "yaw")),
                ("q_b_n", self.q_b_n, ("w", "x", "y", "z")),
            ],
        )


class Errors:
    """Navigation errors against the truth (docs/conventions.md §"Errors"):
    ``t_s`` (m,); ``pos_err_ned_m`` (m, 3) δN = δL(R_M+h), δE = δλ(R_N+h)cos L,
    δD = −δh [m]; ``vel_err_ned_mps`` (m, 3) v_alg − v_true [m/s]; ``att_err_rad``
    (m, 3) ε with C_alg C_trueᵀ = I + [ε×] [rad]; ``height_err_m`` (m,);
    ``euler_err_rad`` (m, 3) roll, pitch, yaw differences wrapped to (−π, π]."""

    def __init__(self, d: Dict[str, Any]):
        self.t_s: np.ndarray = d["t_s"]
        self.pos_err_ned_m: np.ndarray = d["pos_err_ned_m"]
        self.vel_err_ned_mps: np.ndarray = d["vel_err_ned_mps"]
        self.att_err_rad: np.ndarray = d["att_err_rad"]
        self.height_err_m: np.ndarray = d["height_err_m"]
        self.euler_err_rad: np.ndarray = d["euler_err_rad"]

    def __len__(self) -> int:
        return len(self.t_s)

    def to_pandas(self):
        """Errors as a DataFrame indexed by ``t_s`` (column names as the CLI's err_*.csv)."""
        return _frame(
            self.t_s,
            [
                ("pos_err", self.pos_err_ned_m, ("n_m", "e_m", "d_m")),
                ("vel_err", self.vel_err_ned_mps, ("n_mps", "e_mps", "d_mps")),
                ("att_err", self.att_err_rad, ("n_rad", "e_rad", "d_rad")),
                ("height_err_m", self.height_err_m, ()),
                ("euler_err", self.euler_err_rad, ("roll_rad", "pitch_rad", "yaw_rad")),
            ],
        )


class AlgorithmRun:
    """One algorithm of ``sdins.run``: ``nav`` (Navigation at the output epochs),
    ``errors`` (Errors at the same epochs), ``final`` and ``max_abs`` (dicts of the errors
    at the last update and their maximum absolute values, as ``sdins run --json``),
    ``nav_updates``, ``samples``, ``wall_s``."""

    def __init__(self, d: Dict[str, Any]):
        self.algo: str = d["algo"]
        self.samples: int = d["samples"]
        self.nav_updates: int = d["nav_updates"]
        self.wall_s: float = d["wall_s"]
        self.final: Dict[str, Any] = d["final"]
        self.max_abs: Dict[str, Any] = d["max_abs"]
        n = dict(d["nav"])
        n["algo"], n["samples"] = self.algo, self.samples
        self.nav = Navigation(n)
        self.errors = Errors(d["errors"])

    def __repr__(self) -> str:
        p = self.final["pos_err_ned_m"]
        return f"AlgorithmRun({self.algo}, final pos err N,E,D = {p[0]:.4e} {p[1]:.4e} {p[2]:.4e} m)"

    def to_pandas(self):
        """Errors and states side by side, indexed by ``t_s``."""
        pd = _pandas()
        return pd.concat([self.errors.to_pandas(), self.nav.to_pandas()], axis=1)


class RunResult(dict):
    """``sdins.run``: a dict algorithm name → AlgorithmRun, in the order run."""

    def __repr__(self) -> str:
        return "RunResult(" + ", ".join(repr(v) for v in self.values()) + ")"

    def to_pandas(self):
        """All algorithms' errors, columns prefixed ``<algo>.``, indexed by ``t_s``."""
        pd = _pandas()
        return pd.concat(
            [v.errors.to_pandas().add_prefix(f"{k}.") for k, v in self.items()], axis=1
        )


class McStatistics:
    """Monte Carlo statistics: ``times_s`` (m,) [s]; ``mean``, ``sigma``, ``p05``,
    ``p50``, ``p95`` (m, 9) in ``channels`` order (pos N/E/D m, vel N/E/D m/s,
    att N/E/D rad); ``runs`` included; ``complete``; ``state`` (the merged McState)."""

    def __init__(self, d: Dict[str, Any], state: Any = None):
        self.runs: int = d["runs"]
        self.complete: bool = d["complete"]
        self.channels: List[str] = list(d["channels"])
        self.times_s: np.ndarray = d["times_s"]
        self.mean: np.ndarray = d["mean"]
        self.sigma: np.ndarray = d["sigma"]
        self.p05: np.ndarray = d["p05"]
        self.p50: np.ndarray = d["p50"]
        self.p95: np.ndarray = d["p95"]
        self.state = state

    def __repr__(self) -> str:
        return f"McStatistics({self.runs} runs, {len(self.times_s)} epochs, complete={self.complete})"

    def to_pandas(self):
        """One column per channel and statistic (``pos_n_m.mean`` …), indexed by ``t_s``."""
        pd = _pandas()
        data = {}
        for k, c in enumerate(self.channels):
            for s in ("mean", "sigma", "p05", "p50", "p95"):
                data[f"{c}.{s}"] = getattr(self, s)[:, k]
        return pd.DataFrame(data, index=pd.Index(self.times_s, name="t_s"))


class ImuRecord:
    """An IMU file (``sdins.read_imu``): ``t_s`` (n,) sample time stamps [s] (t0_s + k δt);
    ``dtheta_rad``, ``dv_mps`` (n, 3) body FRD increments; ``dt_s``; ``t0_s``; ``format``
    (the format read); ``psins_header`` (dict or None: lat_deg, lon_deg, h_m,
    vel0_enu_mps, att0_deg); ``input`` (str or None: what a column map did, its time base,
    clock origin and offset)."""

    def __init__(self, d: Dict[str, Any]):
        self.format: str = d["format"]
        self.dt_s: float = d["dt_s"]
        self.t0_s: float = d["t0_s"]
        self.t_s: np.ndarray = d["t_s"]
        self.dtheta_rad: np.ndarray = d["dtheta_rad"]
        self.dv_mps: np.ndarray = d["dv_mps"]
        self.psins_header: Optional[Dict[str, Any]] = d.get("psins_header")
        self.input: Optional[str] = d.get("input")

    def __len__(self) -> int:
        return len(self.t_s)

    def __repr__(self) -> str:
        return f"ImuRecord({self.format}, {len(self.t_s)} samples at {self.dt_s} s)"

    def to_pandas(self):
        """Increments as a DataFrame indexed by ``t_s``."""
        return _frame(
            self.t_s,
            [("dtheta_rad", self.dtheta_rad, "xyz"), ("dv_mps", self.dv_mps, "xyz")],
        )


class AllanResult:
    """Allan deviation (``sdins.allan``): ``tau_s`` (m,) cluster times [s]; ``adev``
    (m, 6) overlapping Allan deviation of gyro x, y, z [rad/s] and accelerometer x, y, z
    [m/s²]; ``fits`` six dicts (IEEE Std 952, SI): ``white`` (N: rad/√s or m/s/√s),
    ``bias_instability`` (B: rad/s or m/s²), ``quantization``, ``rate_random_walk``
    (K), with the τ ranges used; absent terms are None."""

    CHANNELS = ("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z")

    def __init__(self, d: Dict[str, Any]):
        self.tau_s: np.ndarray = d["tau_s"]
        self.adev: np.ndarray = d["adev"]
        self.fits: List[Dict[str, Any]] = list(d["fits"])

    def to_pandas(self):
        """Deviations as a DataFrame indexed by ``tau_s``."""
        pd = _pandas()
        return pd.DataFrame(
            {c: self.adev[:, k] for k, c in enumerate(self.CHANNELS)},
            index=pd.Index(self.tau_s, name="tau_s"),
        )


class AlignResult:
    """Alignment result (``sdins.align``). Attributes as ``sdins align --json``:
    ``method``; ``roll_deg``, ``pitch_deg``, ``yaw_deg`` (NED, yaw clockwise from north);
    ``c_b_n`` (3, 3); for the filters ``accel_bias_ug``/``accel_bias_sigma_ug`` (body
    FRD, μg), ``gyro_bias_dph``/``gyro_bias_sigma_dph`` (°/h); fine:
    ``attitude_sigma_urad`` (1σ φ N/E/D, μrad); scenarios: ``phi_urad`` (attitude error
    against the truth, convention G, μrad), ``true_accel_bias_ug``,
    ``true_gyro_bias_dph``; absent values are None. Also ``samples``, ``dt_s``,
    ``lat_deg``, ``h_m``, ``g_mps2``, ``sigma_z_used_mps``, ``warnings`` and ``history``
    (filters: a dict of arrays per Kalman update: ``t_s`` (n,), ``euler_deg``,
    ``attitude_sigma_urad``, ``accel_bias_ug``, ``accel_bias_sigma_ug``,
    ``gyro_bias_dph``, ``gyro_bias_sigma_dph``, ``phi_urad`` (n, 3) or None)."""

    def __init__(self, d: Dict[str, Any]):
        self._d = d
        for k, v in d.items():
            setattr(self, k, v)

    def as_dict(self) -> Dict[str, Any]:
        """The fields of ``sdins align --json`` (same keys, None for absent ones)."""
        keys = (
            "method", "roll_deg", "pitch_deg", "yaw_deg", "accel_bias_ug",
            "accel_bias_sigma_ug", "gyro_bias_dph", "gyro_bias_sigma_dph",
            "attitude_sigma_urad", "phi_urad", "true_accel_bias_ug", "true_gyro_bias_dph",
        )
        return {k: self._d[k] for k in keys}

    def to_pandas(self):
        """The filter history as a DataFrame indexed by ``t_s`` (None for coarse/i0)."""
        h = self._d.get("history")
        if h is None:
            return None
        cols = [
            ("euler_deg", h["euler_deg"], ("roll", "pitch", "yaw")),
            ("sigma_phi_urad", h["attitude_sigma_urad"], "ned"),
            ("ba_ug", h["accel_bias_ug"], "xyz"),
            ("sigma_ba_ug", h["accel_bias_sigma_ug"], "xyz"),
            ("bg_dph", h["gyro_bias_dph"], "xyz"),
            ("sigma_bg_dph", h["gyro_bias_sigma_dph"], "xyz"),
        ]
        if h["phi_urad"] is not None:
            cols.append(("phi_urad", h["phi_urad"], "ned"))
        return _frame(h["t_s"], cols)


class ErrorAnalysis:
    """Stationary error analysis (``sdins.errors``): ``report`` (the ``sdins errors
    --json`` object as a dict: lat_deg, hours, grade, biases, params, epochs with
    closed_form / linear / nonlinear), ``t_s`` (n,) and the linear model's ``dp_n_m``
    (n, 3) position error N, E, D [m] and ``sigma_p_m`` (n, 3) 1σ [m] every 10 s,
    ``budget`` (list of (source, value, (δN, δE) [m]) at the final time)."""

    def __init__(self, d: Dict[str, Any]):
        import json

        self.report: Dict[str, Any] = json.loads(d["report_json"])
        self.t_s: np.ndarray = d["t_s"]
        self.dp_n_m: np.ndarray = d["dp_n_m"]
        self.sigma_p_m: np.ndarray = d["sigma_p_m"]
        self.budget: List[Tuple[str, str, Tuple[float, float]]] = [
            (a, b, (c[0], c[1])) for a, b, c in d["budget"]
        ]

    def to_pandas(self):
        """The linear model's time history as a DataFrame indexed by ``t_s``."""
        return _frame(self.t_s, [("dp_m", self.dp_n_m, "ned"), ("sigma_p_m", self.sigma_p_m, "ned")])


class FuseResult:
    """INS/GNSS filter run (``sdins.fuse``). Per output row (by default every covariance
    epoch, the initial state first): ``t_s`` (n,);
    ``error`` (n, 15) true error in state coordinates (δL, δλ [rad], δh [m], δv NED
    [m/s], φ NED [rad], accelerometer bias [m/s²], gyro bias [rad/s]); ``pos_error_ned_m``
    (n, 3) position error in metres NED, ``vel_error_ned_mps`` (n, 3) [m/s] and
    ``att_error_rad`` (n, 3) attitude error φ NED (convention G) [rad] in user units
    (the CLI's nav.csv); ``sigma`` (n, 15) filter 1σ in user units
    (position in metres NED, the rest as ``error``); ``nees`` (n, 3) NEES of the
    position, velocity and attitude blocks (3 dof each). ``innovations``: dict of arrays
    per measurement update: ``t_s``, ``t_valid_s``, ``kind`` (gnss, zupt, nhc), ``dof``,
    ``nis``, ``accepted``, ``forced``, ``late``, ``innovation`` (m, 12; first ``dof`` used).
    Summary: ``fixes``, ``rejected``, ``late``, ``nav_updates``, ``accel_bias_est_mps2``,
    ``accel_bias_true_mps2``, ``gyro_bias_est_rps``, ``gyro_bias_true_rps``, ``samples``,
    ``run``; ``health``: the verdict (``{"ok": bool, "checks": [{"name", "passed",
    "detail"}]}``, docs/user-guide.md "Health verdict"; never raised). With
    ``scale_factors_ppm`` (the 21-state filter) also
    ``scale_factor_error`` / ``scale_factor_sigma`` (n, 6; true error ``s − ŝ`` and 1σ,
    dimensionless, accelerometer x y z then gyro x y z) and ``accel_scale_est``,
    ``accel_scale_true``, ``gyro_scale_est``, ``gyro_scale_true``; otherwise those are
    None."""

    def __init__(self, d: Dict[str, Any]):
        self.t_s: np.ndarray = d["t_s"]
        self.error: np.ndarray = d["error"]
        self.pos_error_ned_m: np.ndarray = d["pos_error_ned_m"]
        self.vel_error_ned_mps: np.ndarray = d["vel_error_ned_mps"]
        self.att_error_rad: np.ndarray = d["att_error_rad"]
        self.sigma: np.ndarray = d["sigma"]
        self.nees: np.ndarray = d["nees"]
        inn = d["innovations"]
        self.innovations: Dict[str, Any] = {
            "t_s": inn["t_s"],
            "t_valid_s": inn["t_valid_s"],
            "kind": np.array(inn["kind"]),
            "dof": np.asarray(inn["dof"], dtype=np.int64),
            "nis": inn["nis"],
            "accepted": np.asarray(inn["accepted"], dtype=bool),
            "forced": np.asarray(inn["forced"], dtype=bool),
            "late": np.asarray(inn["late"], dtype=bool),
            "innovation": inn["innovation"],
        }
        self.smoothed: Optional[Dict[str, Any]] = d.get("smoothed")
        self.scale_factor_error: Optional[np.ndarray] = d.get("scale_factor_error")
        self.scale_factor_sigma: Optional[np.ndarray] = d.get("scale_factor_sigma")
        for k in ("accel_scale_est", "accel_scale_true", "gyro_scale_est", "gyro_scale_true"):
            setattr(self, k, d.get(k))
        for k in (
            "fixes", "rejected", "late", "nav_updates", "accel_bias_est_mps2", "accel_bias_true_mps2",
            "gyro_bias_est_rps", "gyro_bias_true_rps", "samples", "run",
        ):
            setattr(self, k, d[k])
        self.health: Dict[str, Any] = d["health"]

    def rms(self) -> Dict[str, List[float]]:
        """RMS over the epochs of the position [m], velocity [m/s] and attitude [rad]
        errors, N, E, D (``sdins fuse --json``: rms_pos_ned_m, rms_vel_ned_mps,
        rms_att_ned_rad)."""
        sq = np.zeros(9)
        blocks = np.concatenate(
            [self.pos_error_ned_m, self.vel_error_ned_mps, self.att_error_rad], axis=1
        )
        n = max(len(self.t_s), 1)
        for row in blocks:
            sq += row * row
        r = [float(np.sqrt(x / n)) for x in sq]
        return {"rms_pos_ned_m": r[0:3], "rms_vel_ned_mps": r[3:6], "rms_att_ned_rad": r[6:9]}

    def to_pandas(self):
        """Errors and 1σ per epoch as a DataFrame indexed by ``t_s``."""
        return _frame(
            self.t_s,
            [
                ("err_pos_m", self.pos_error_ned_m, "ned"),
                ("err_vel_mps", self.vel_error_ned_mps, "ned"),
                ("err_att_rad", self.att_error_rad, "ned"),
                ("sigma_pos_m", self.sigma[:, 0:3], "ned"),
                ("sigma_vel_mps", self.sigma[:, 3:6], "ned"),
                ("sigma_att_rad", self.sigma[:, 6:9], "ned"),
            ],
        )

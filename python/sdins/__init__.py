"""sdins: exact strapdown inertial navigation simulation and navigation algorithms.

Every function calls the same Rust library function as the ``sdins`` command of the
same name, so numbers are identical to the CLI's ``--json``/CSV output. Arrays are
float64 numpy arrays (no per-sample Python objects). Frames: NED navigation frame,
FRD body frame, Hamilton scalar-first quaternions ``q_b_n`` (docs/conventions.md).
Every optional parameter defaults to ``None`` = the library's default. Bad input raises
:class:`SdinsError` (a ``ValueError``) with the CLI's located message; long calls
release the GIL and stop on KeyboardInterrupt.
"""

from __future__ import annotations

from typing import Any, Dict, Iterable, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _sdins as _raw
from ._results import (
    AlgorithmRun,
    AlignResult,
    ErrorAnalysis,
    FuseResult,
    AllanResult,
    Errors,
    ImuRecord,
    McStatistics,
    Navigation,
    RunResult,
    Truth,
)
from ._sdins import FuseMcState, McState, Scenario, SdinsError

__version__: str = _raw.__version__

_U64_MAX = 2**64 - 1


def _overflow_message(f: Any, name: str, args: tuple, kwargs: dict) -> str:
    """Name the integer argument PyO3 could not convert (negative, or above u64)."""
    import inspect

    try:
        bound = inspect.signature(f).bind(*args, **kwargs).arguments
    except (TypeError, ValueError):
        bound = {}
    for arg, v in bound.items():
        for x in v if isinstance(v, tuple) else (v,):
            if isinstance(x, int) and not isinstance(x, bool) and not 0 <= x <= _U64_MAX:
                return f"{arg} = {x}: expected a whole number in 0..={_U64_MAX}"
    return f"{name}: an integer argument is negative or too large"


class _Checked:
    """``_sdins`` with PyO3's OverflowError (a negative ``seed``, ``runs``, …) raised as
    :class:`SdinsError` naming the argument, like every other bad value."""

    def __init__(self, mod: Any) -> None:
        self._mod = mod

    def __getattr__(self, name: str) -> Any:
        f = getattr(self._mod, name)
        if isinstance(f, type) or not callable(f):
            return f

        def call(*args: Any, **kwargs: Any) -> Any:
            try:
                return f(*args, **kwargs)
            except OverflowError:
                raise SdinsError(_overflow_message(f, name, args, kwargs)) from None

        return call


_sdins = _Checked(_raw)


def __dir__() -> List[str]:
    """The public names only (PEP 562): ``dir(sdins)`` lists what ``__all__`` exports."""
    return sorted(__all__ + ["__version__"])

__all__ = [
    "fuse_files",
    "fuse_montecarlo",
    "fuse_merge",
    "FuseMcState",
    "SdinsError",
    "Scenario",
    "McState",
    "Truth",
    "Navigation",
    "Errors",
    "AlgorithmRun",
    "RunResult",
    "McStatistics",
    "ImuRecord",
    "AllanResult",
    "scenarios",
    "truth",
    "corrupt",
    "navigate",
    "run",
    "read_imu",
    "allan",
    "montecarlo",
    "merge",
    "AlignResult",
    "ErrorAnalysis",
    "FuseResult",
    "align",
    "calibrate",
    "errors",
    "fuse",
    "schuler_share",
]


def _f64x3(name: str, a: Any) -> np.ndarray:
    arr = np.ascontiguousarray(a, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise SdinsError(f"{name}: expected an (n, 3) array, got shape {arr.shape}")
    return arr


def _scenario(s: Union[Scenario, str]) -> Scenario:
    if isinstance(s, Scenario):
        return s
    if isinstance(s, str):
        return Scenario.builtin(s)
    raise SdinsError(f"scenario: expected sdins.Scenario or a built-in name, got {type(s).__name__}")


def scenarios() -> List[Tuple[str, str]]:
    """The built-in scenarios (the papers' cases): a list of ``(name, summary)``."""
    return list(_sdins.scenarios())


def truth(
    scenario: Union[Scenario, str],
    until_s: Optional[float] = None,
    every: Optional[int] = None,
    imu: Optional[bool] = None,
) -> Truth:
    """Exact truth trajectory and IMU increments of ``scenario``.

    ``until_s``: stop after this time [s] (default: the whole scenario). ``every``: keep
    every N-th trajectory row (default 1; row 0, the initial state, is always kept; the
    IMU increments are never decimated). ``imu``: also return the increments (default
    True; ``False`` saves 48 bytes per sample). Same numbers as ``sdins truth``.
    """
    return Truth(_sdins.truth(_scenario(scenario), until_s, every, imu))


def corrupt(
    dtheta: Any,
    dv: Any,
    dt: float,
    grade: Optional[str] = None,
    errors: Optional[Dict[str, Any]] = None,
    seed: Optional[int] = None,
    run: Optional[int] = None,
) -> Tuple[np.ndarray, np.ndarray]:
    """Corrupt exact increments ``dtheta`` [rad] and ``dv`` [m/s] ((n, 3), body FRD,
    sample interval ``dt`` [s]) with realisation ``run`` (default 0) of an IMU error model.

    ``grade``: a preset (marine, aviation, intermediate, tactical, consumer); ``errors``:
    keys of a scenario's ``[imu.errors]`` table with units in the names (e.g.
    ``{"gyro_bias_dph": [0.01]*3}``, docs/scenarios.md), applied over ``grade`` if both are
    given. ``seed`` defaults to the scenario default 1. Returns ``(dtheta, dv)``.
    """
    return _sdins.corrupt(_f64x3("dtheta", dtheta), _f64x3("dv", dv), float(dt), grade, errors, seed, run)


def navigate(
    dtheta: Any,
    dv: Any,
    dt: float,
    init: Union[str, Sequence[float]],
    algo: Optional[str] = None,
    samples: Optional[int] = None,
    coning: Optional[str] = None,
    earth: Optional[str] = None,
    vertical: Optional[str] = None,
    t0_s: Optional[float] = None,
) -> Navigation:
    """Navigate recorded increments with one algorithm (``sdins nav``).

    ``dtheta`` [rad], ``dv`` [m/s]: (n, 3) body FRD increments at interval ``dt`` [s].
    ``init``: ``lat_deg, lon_deg, h_m, v_n_mps, v_e_mps, v_d_mps, roll_deg, pitch_deg,
    yaw_deg`` as 9 numbers or the CLI's comma-separated string. ``algo``: savage,
    songlee, songlee-complete (default) or dualquat; ``samples``: IMU samples per update
    N (1..4, default 1; a trailing partial update is dropped); ``coning``: coning/sculling
    set (default: 1prev for N = 1, else the polynomial set of N); ``earth``: wgs84 (default), wgs84-linear, psins,
    flat; ``vertical``: free (default; a held channel needs a reference, see ``run``);
    ``t0_s``: time of ``init`` [s] (default 0). Returns the state after every update.
    """
    return Navigation(
        _sdins.navigate(
            _f64x3("dtheta", dtheta), _f64x3("dv", dv), float(dt), init,
            algo, samples, coning, earth, vertical, t0_s,
        )
    )


def run(
    scenario: Union[Scenario, str],
    algos: Optional[Union[str, Sequence[str]]] = None,
    samples: Optional[int] = None,
    coning: Optional[str] = None,
    attitude: Optional[str] = None,
    rotvec: Optional[str] = None,
    rot3: Optional[bool] = None,
    vertical: Optional[str] = None,
    every_s: Optional[float] = None,
    until_s: Optional[float] = None,
    ideal: Optional[bool] = None,
    run: Optional[int] = None,
    grade: Optional[str] = None,
) -> RunResult:
    """Run the scenario's exact truth through algorithms side by side (``sdins run``).

    ``algos``: names (list or comma-separated; default: the scenario's); ``samples``
    (default: the scenario's N), ``coning``, ``attitude`` (transport, five, savage),
    ``rotvec`` (theta, phi), ``rot3``: as the CLI options; ``vertical``: free or hold
    (default: the scenario's); ``every_s``: output epoch spacing [s] (default 1);
    ``until_s``: stop time [s]; ``ideal``: ignore the scenario's IMU error model;
    ``run``: sensor-error realisation (default 0); ``grade``: an IMU grade preset
    replacing the scenario's error model (marine, aviation, intermediate, tactical,
    consumer). Output rows are the updates nearest to 0, every_s, 2·every_s, … s (with
    their own times) and the last update. Returns a dict algo → AlgorithmRun
    with the errors against the truth at the output epochs (the CLI's err_*.csv) and
    the final and maximum errors (its ``--json``).
    """
    d = _sdins.run(
        _scenario(scenario), algos, samples, coning, attitude, rotvec, rot3,
        vertical, every_s, until_s, ideal, run, grade,
    )
    return RunResult((k, AlgorithmRun(v)) for k, v in d.items())


def _imu_format(imu_format: Optional[str], format: Optional[str]) -> Optional[str]:
    """``imu_format``, the one name of the option (``--imu-format``); ``format`` is its
    deprecated alias."""
    if format is not None:
        import warnings

        warnings.warn("format= is deprecated; use imu_format=", DeprecationWarning, stacklevel=3)
        if imu_format is not None and imu_format != format:
            raise SdinsError(f"imu_format={imu_format!r} and format={format!r} disagree: give imu_format only")
        return format
    return imu_format


def read_imu(
    path: Any,
    imu_format: Optional[str] = "auto",
    format: Optional[str] = None,
    columns: Optional[str] = None,
    profile: Optional[Any] = None,
) -> ImuRecord:
    """Read an IMU file: sdins CSV, PSINS ``.imu`` (psins) or trj CSV (psins-csv),
    KF-GINS text (kfgins), NaveGo CSV (navego); ``imu_format="auto"`` detects it
    (docs/imu-files.md; ``format=`` is a deprecated alias). Any other delimited text is
    read through ``columns``, a column map (the CLI's ``--imu-columns``, docs/own-data.md),
    or a TOML ``profile``'s ``[imu]`` map; rates become increments by the trapezoid rule.
    Increments are converted to body FRD."""
    return ImuRecord(
        _sdins.read_imu(
            str(path), _imu_format(imu_format, format), columns, None if profile is None else str(profile)
        )
    )


def allan(dtheta: Any, dv: Any, dt: float) -> AllanResult:
    """Overlapping Allan deviation of the six channels (rates Δθ/δt, Δv/δt) and the
    IEEE Std 952 noise fits, SI units (``sdins allan``)."""
    return AllanResult(_sdins.allan(_f64x3("dtheta", dtheta), _f64x3("dv", dv), float(dt)))


def montecarlo(
    scenario: Union[Scenario, str],
    runs: int,
    seed: Optional[int] = None,
    shard: Optional[Tuple[int, int]] = None,
    algo: Optional[str] = None,
    samples: Optional[int] = None,
    grade: Optional[str] = None,
    every_s: Optional[float] = None,
    until_s: Optional[float] = None,
    vertical: Optional[str] = None,
    block: Optional[int] = None,
    threads: Optional[int] = None,
) -> McState:
    """Compute shard ``shard = (i, n)`` (default: the whole job) of a Monte Carlo job of
    ``runs`` runs with sensor-error ``seed`` (default: the scenario's ``[imu] seed``)
    (``sdins montecarlo --shard i/n``).

    ``algo`` (default songlee-complete), ``samples`` (default the scenario's N),
    ``grade`` (replaces the scenario's error model), ``every_s`` (epoch spacing, default
    10 s), ``until_s``, ``vertical`` (hold (default) or free), ``block`` (runs per block,
    default 16; every shard must use the same), ``threads`` (default: rayon's pool, all
    cores). Returns a picklable :class:`McState`; merge shards with :func:`merge` in any
    order: the statistics equal a single run's bit for bit.
    """
    return _sdins.montecarlo(
        _scenario(scenario), runs, seed,
        None if shard is None else (int(shard[0]), int(shard[1])),
        algo, samples, grade, every_s, until_s, vertical, block, threads,
    )


def merge(states: Iterable[McState], allow_partial: Optional[bool] = None) -> McStatistics:
    """Merge Monte Carlo shard states exactly (any order) and return the statistics
    (``sdins merge``). Missing blocks are an error unless ``allow_partial=True``."""
    merged, stats = _sdins.merge(list(states), allow_partial)
    return McStatistics(stats, merged)


def align(
    scenario: Optional[Union[Scenario, str]] = None,
    imu: Optional[Any] = None,
    imu_format: Optional[str] = None,
    method: Optional[str] = None,
    alg: Optional[str] = None,
    start: Optional[str] = None,
    lat_deg: Optional[float] = None,
    h_m: Optional[float] = None,
    window_s: Optional[float] = None,
    duration_s: Optional[float] = None,
    run: Optional[int] = None,
    sigma_z_mps: Optional[float] = None,
    vrw_ug_per_sqrt_hz: Optional[float] = None,
    arw_deg_per_sqrt_h: Optional[float] = None,
    format: Optional[str] = None,
) -> AlignResult:
    """Initial alignment (``sdins align``) of a scenario (with run ``run`` of its IMU
    error model, default 0) or an IMU file ``imu`` (``imu_format``: auto (default), sdins,
    psins, psins-csv, kfgins, navego; ``format=`` is a deprecated alias).

    ``method``: coarse1, coarse2, i0, fine (default) or multiheading; ``alg``: a
    (default) or b (multi-heading); ``start``: i0 (default) or coarse2 (fine filter
    start); ``lat_deg`` [deg] / ``h_m`` [m]: site (files without a PSINS header need
    ``lat_deg``; for scenarios it overrides the start latitude); ``window_s``: coarse/i0
    window [s] (default 60); ``duration_s``: use only the first seconds; ``sigma_z_mps``:
    zero-velocity σ [m/s] (default 1e-3, a floor with start=i0); ``vrw_ug_per_sqrt_hz``,
    ``arw_deg_per_sqrt_h``: filter noise (default: the scenario's, else aviation grade).

    Stationary-only methods (all but i0) raise :class:`SdinsError` on a scenario whose
    truth speed exceeds 0.5 m/s in the alignment window, and add a warning to
    ``warnings`` for a file that seems to move. Attitude errors in convention G
    (Ĉ = (I + [φ×]) C, NED); biases in body axes (FRD), μg and °/h.
    """
    scn = None if scenario is None else _scenario(scenario)
    return AlignResult(
        _sdins.align(
            scn, None if imu is None else str(imu), _imu_format(imu_format, format), method, alg, start, lat_deg,
            h_m, window_s, duration_s, run, sigma_z_mps, vrw_ug_per_sqrt_hz,
            arw_deg_per_sqrt_h,
        )
    )


def errors(
    grade: Optional[str] = None,
    gyro_bias_dph: Optional[Sequence[float]] = None,
    accel_bias_ug: Optional[Sequence[float]] = None,
    hours: Optional[float] = None,
    lat_deg: Optional[float] = None,
    nonlinear: Optional[bool] = None,
) -> ErrorAnalysis:
    """Stationary free-inertial error analysis (``sdins errors``): closed form, 15-state
    linear model with 1σ envelope, nonlinear INS column, error budget.

    ``grade`` (marine, aviation, intermediate, tactical, consumer: its turn-on bias σ on
    every NED axis and its ARW/VRW), or ``gyro_bias_dph`` [°/h] and/or ``accel_bias_ug``
    [μg] as N, E, D; ``hours`` (default 24, ≤ 240); ``lat_deg`` (default 37.5);
    ``nonlinear``: run the nonlinear column (default True).
    """
    g = None if gyro_bias_dph is None else [float(x) for x in gyro_bias_dph]
    a = None if accel_bias_ug is None else [float(x) for x in accel_bias_ug]
    return ErrorAnalysis(_sdins.errors(grade, g, a, hours, lat_deg, nonlinear))


def calibrate(
    scenario: Union[Scenario, str],
    imu: Optional[Any] = None,
    imu_format: Optional[str] = None,
    run: Optional[int] = None,
    runs: Optional[int] = None,
    draw_scale_ppm: Optional[Tuple[float, float]] = None,
    draw_misalignment_mrad: Optional[Tuple[float, float]] = None,
    draw: Optional[bool] = None,
) -> Dict[str, Any]:
    """Turntable calibration (``sdins calibrate``) of the scenario's schedule: on its
    simulated IMU (run ``run``, default 0; ``runs`` > 1: a Monte Carlo over runs 0..runs)
    or on a recorded IMU file ``imu`` (``imu_format``: auto (default), sdins, psins, …).

    ``draw_scale_ppm`` / ``draw_misalignment_mrad``: the (lo, hi) magnitudes of the drawn
    scale factors and misalignments (default (100, 1000) ppm, (0.1, 1) mrad); ``draw=False``
    keeps the scenario's own. Returns the ``sdins calibrate --json`` summary as a dict
    (parameters with estimate, 1σ and truth; NEES; the Monte Carlo summary).
    """
    import json

    t = _sdins.calibrate(
        _scenario(scenario), None if imu is None else str(imu), imu_format, run, runs,
        None if draw_scale_ppm is None else (float(draw_scale_ppm[0]), float(draw_scale_ppm[1])),
        None if draw_misalignment_mrad is None else (float(draw_misalignment_mrad[0]), float(draw_misalignment_mrad[1])),
        draw,
    )
    return json.loads(t)


def schuler_share() -> List[Dict[str, Any]]:
    """The Schuler-share table (``sdins errors --schuler-share``, reconstruction of
    [P2] Table 1) as a list of dicts (grade, accel_bias_ug, gyro_bias_dph, share_pct)."""
    import json

    return json.loads(_sdins.schuler_share_json())


def fuse(
    scenario: Union[Scenario, str],
    algo: Optional[str] = None,
    samples: Optional[int] = None,
    run: Optional[int] = None,
    cov_rate_hz: Optional[float] = None,
    gate: Optional[bool] = None,
    exact_start: Optional[bool] = None,
    zupt_sigma_mps: Optional[float] = None,
    nhc_sigma_mps: Optional[float] = None,
    until_s: Optional[float] = None,
    smooth: Optional[bool] = None,
    in_motion: Optional[bool] = None,
    scale_factors_ppm: Optional[Tuple[float, float]] = None,
    grade: Optional[str] = None,
    every_s: Optional[float] = None,
    max_latency_s: Optional[float] = None,
    zupt_detector: Optional[bool] = None,
) -> FuseResult:
    """Loosely coupled INS/GNSS filter on a scenario (``sdins fuse``, the same library
    call); the scenario's ``[gnss]`` table sets the receiver, its aiding-sensor tables
    (``[baro]``, ``[odometer]``, …) the other sensors. ``zupt_detector`` True applies the
    ``zupt_sigma_mps`` ZUPTs when the IMU's stationarity detector declares rest instead of
    when the truth is at rest (``--zupt-detector``).

    Every parameter defaults to the library's: ``algo`` songlee-complete, ``samples`` the
    scenario's N (as the CLI), ``run`` 0 (IMU/GNSS/initial-error streams), ``cov_rate_hz``
    10, ``gate`` True (χ² 99.9 % NIS gate), ``exact_start`` False (initial errors drawn
    from P0), ``zupt_sigma_mps`` / ``nhc_sigma_mps`` None (off), ``until_s`` None (whole
    scenario), ``smooth`` False (True: the Rauch–Tung–Striebel smoother; ``result.smoothed``
    then holds the smoothed rows with the same fields as the forward ones), ``in_motion``
    False (True: in-motion alignment from an unknown heading, started at the first fix at
    ≥ 5 m/s), ``scale_factors_ppm`` None (15 states; ``(accel_ppm, gyro_ppm)``: the
    layout with the accelerometer and gyro scale factors, prior σ per axis; the result
    then has ``scale_factor_error`` / ``scale_factor_sigma`` (n × 6, dimensionless, accel
    x y z then gyro x y z) and the ``accel_scale_est`` / ``accel_scale_true`` /
    ``gyro_scale_est`` / ``gyro_scale_true`` summaries), ``grade`` None (an IMU grade
    preset replacing the scenario's error model: the simulated IMU errors and the
    filter's model), ``every_s`` None (output rows at the updates nearest to k·every_s;
    default the covariance interval), ``max_latency_s`` None (1 s: older measurements are
    refused and counted in ``late``).
    """
    return FuseResult(
        _sdins.fuse(
            _scenario(scenario), algo, samples, run, cov_rate_hz, gate, exact_start,
            zupt_sigma_mps, nhc_sigma_mps, until_s, smooth, in_motion, scale_factors_ppm,
            grade, every_s, max_latency_s, zupt_detector,
        )
    )


def fuse_montecarlo(
    scenario: Union[Scenario, str],
    runs: int,
    seed: Optional[int] = None,
    shard: Optional[Tuple[int, int]] = None,
    block: Optional[int] = None,
    threads: Optional[int] = None,
    draw_scale_factors: Optional[bool] = None,
    algo: Optional[str] = None,
    samples: Optional[int] = None,
    cov_rate_hz: Optional[float] = None,
    gate: Optional[bool] = None,
    exact_start: Optional[bool] = None,
    zupt_sigma_mps: Optional[float] = None,
    nhc_sigma_mps: Optional[float] = None,
    until_s: Optional[float] = None,
    scale_factors_ppm: Optional[Tuple[float, float]] = None,
    grade: Optional[str] = None,
    every_s: Optional[float] = None,
    max_latency_s: Optional[float] = None,
) -> FuseMcState:
    """Shard ``shard = (i, n)`` (default: the whole job) of the Monte Carlo of the filter on
    a scenario (``sdins fuse SCENARIO --runs N --seed S --shard i/n``): per output epoch the
    mergeable moments of the NEES of every state block with a known truth and of the NIS
    of every measurement kind. ``seed`` (default the scenario's ``[imu] seed``) replaces
    the IMU and GNSS seeds; ``block`` runs per block (default 16, equal in every shard);
    ``threads`` (default: rayon's pool); ``draw_scale_factors`` draws each run's true
    scale factors from the prior of ``scale_factors_ppm``; the filter options as in
    :func:`fuse` (use ``gate=False`` for consistency). Returns a picklable
    :class:`FuseMcState` (``.statistics()``, ``.consistency(column, after_s=30)``); merge
    shards with :func:`fuse_merge` in any order: the statistics equal a single run's bit
    for bit, for any thread count.
    """
    return _sdins.fuse_montecarlo(
        _scenario(scenario), runs, seed,
        None if shard is None else (int(shard[0]), int(shard[1])),
        block, threads, draw_scale_factors, algo, samples, cov_rate_hz, gate, exact_start,
        zupt_sigma_mps, nhc_sigma_mps, until_s, scale_factors_ppm, grade, every_s,
        max_latency_s,
    )


def fuse_merge(states: Iterable[FuseMcState], allow_partial: Optional[bool] = None) -> FuseMcState:
    """Merge fusion Monte Carlo shard states exactly, in any order (``sdins fuse --merge``).
    Missing blocks are an error unless ``allow_partial=True``."""
    return _sdins.fuse_merge(list(states), allow_partial)


def fuse_files(
    imu: str,
    gnss: str,
    imu_format: Optional[str] = None,
    gnss_format: Optional[str] = None,
    grade: Optional[str] = None,
    navego_params: Optional[str] = None,
    init: Optional[str] = None,
    attitude_deg: Optional[Sequence[float]] = None,
    attitude_sigma_deg: Optional[Sequence[float]] = None,
    static_s: Optional[float] = None,
    lever_arm_m: Optional[Sequence[float]] = None,
    truth: Optional[str] = None,
    smooth: Optional[bool] = None,
    algo: Optional[str] = None,
    samples: Optional[int] = None,
    cov_rate_hz: Optional[float] = None,
    gate: Optional[bool] = None,
    nhc_sigma_mps: Optional[float] = None,
    gnss_offset_s: Optional[float] = None,
    scale_factors_ppm: Optional[Tuple[float, float]] = None,
    every_s: Optional[float] = None,
    max_latency_s: Optional[float] = None,
    imu_columns: Optional[str] = None,
    gnss_columns: Optional[str] = None,
    truth_columns: Optional[str] = None,
    profile: Optional[str] = None,
    gps_week: Optional[int] = None,
    gnss_sigma: Optional[str] = None,
    undulation_m: Optional[float] = None,
    sensor_model: Optional[str] = None,
    aiding: Optional[str] = None,
    zupt_sigma_mps: Optional[float] = None,
    zupt_window_s: Optional[float] = None,
    zupt_false_alarm: Optional[float] = None,
) -> Dict[str, Any]:
    """INS/GNSS filter (and smoother) on recorded files (``sdins fuse --imu --gnss``).

    ``aiding`` names the aiding sensors' TOML (barometer, odometer, magnetometer, dual
    antenna, body velocity records and settings; docs/own-data.md "Aiding sensors", the
    CLI's ``--aiding``). ``zupt_sigma_mps`` applies zero-velocity updates whenever the IMU's
    stationarity detector declares rest (``--zupt-detector``; window ``zupt_window_s``,
    default 0.5 s, false-alarm rate ``zupt_false_alarm``, default 1e-3).

    One's own files are read through column maps (docs/own-data.md), the strings of the
    CLI's ``--imu-columns``/``--gnss-columns``/``--truth-columns`` (e.g. ``imu_columns=
    "t_s=time,gyro_x_dps=gx,...,accel_z_g=az,axes=x:+y,y:+x,z:-z,time=gps-sow"``), or a
    TOML ``profile``; ``gps_week``, ``gnss_sigma`` (``"N,E,D[,vN,vE,vD]"``) and
    ``undulation_m`` supply what such files lack. The result's ``inputs`` maps ``imu``,
    ``gnss``, ``reference`` to what each map did (time base, clock origin, offset).

    The IMU's error model comes from ``grade`` (a preset), ``navego_params`` (a NaveGo
    ``imuN_params.txt``) or ``sensor_model`` (your own sensor-model TOML, or a KF-GINS
    ``kf-gins.yaml`` by its extension ``.yaml``/``.yml``; docs/own-data.md "Your sensor
    model": it may also give the lever arm, the scale-factor σ and the initial attitude
    and σ); exactly one of the three. The initial state from ``init`` (``"lat_deg,lon_deg,h_m,v_n,v_e,
    v_d,roll_deg,pitch_deg,yaw_deg"``), ``attitude_deg`` (roll, pitch, yaw with the first
    fix's position and velocity; σ ``attitude_sigma_deg``, default 1, 1, 2°), ``static_s``
    (coarse alignment at rest), or, with NaveGo parameters, their ``ini_align`` (with a
    sensor model, its initial attitude). Defaults
    are the library's (``RecordOptions::default()``: songlee-complete N = 2, covariance
    10 Hz, χ² 99.9 % gate). Returns a dict: ``forward`` (and with ``smooth`` ``smoothed``)
    with per navigation update ``t_s`` (IMU clock) [s], ``lat_rad``, ``lon_rad``, ``h_m``,
    ``v_ned_mps`` (n, 3), ``euler_rad`` (n, 3: roll, pitch, yaw), ``sigma_nav`` (n, 9:
    N, E, D [m], v N, E, D [m/s], ε N, E, D [rad]), ``sigma_euler_rad`` (n, 3), ``bias``
    (n, 6: accelerometer [m/s²], gyro [rad/s]), ``scale_factor`` and
    ``sigma_scale_factor`` (n, 6: accelerometer then gyro, dimensionless; zero unless
    ``scale_factors_ppm = (accel_ppm, gyro_ppm)`` selects the 21-state filter with that
    prior σ); ``innovations`` (t_s, t_valid_s, kind, dof, nis, accepted, forced, late,
    innovation (m, 12)); ``fixes_used``, ``rejected``, ``late``, ``fixes_outside`` (before, after),
    ``imu_samples``; with ``truth``: ``forward_rmse`` / ``smoothed_rmse`` (roll, pitch,
    yaw [rad], v N, E, D [m/s], N, E, D [m]) and their ``*_inside_3sigma`` fractions;
    ``health``: the verdict (``{"ok": bool, "checks": [...]}``; never raised: check
    ``result["health"]["ok"]``).
    """
    return _sdins.fuse_files(
        imu, gnss, imu_format, gnss_format, grade, navego_params, init,
        None if attitude_deg is None else [float(x) for x in attitude_deg],
        None if attitude_sigma_deg is None else [float(x) for x in attitude_sigma_deg],
        static_s,
        None if lever_arm_m is None else [float(x) for x in lever_arm_m],
        truth, smooth, algo, samples, cov_rate_hz, gate, nhc_sigma_mps, gnss_offset_s,
        scale_factors_ppm, every_s, max_latency_s, imu_columns, gnss_columns, truth_columns,
        None if profile is None else str(profile), gps_week, gnss_sigma, undulation_m,
        None if sensor_model is None else str(sensor_model),
        None if aiding is None else str(aiding),
        zupt_sigma_mps, zupt_window_s, zupt_false_alarm,
    )

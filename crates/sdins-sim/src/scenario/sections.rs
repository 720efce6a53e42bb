//! Validation of the optional sections: `[[waypoint]]`/`[route]`, `[calibration]`,
//! rotation and random-vibration overlays, `[mounting]`, `vehicle` and `[nav]`.

use super::*;

/// `[[waypoint]]` and `[route]`: the route, compiled ([`crate::truth::route::compile`]); its
/// errors located at the waypoint they name.
pub(super) fn parse_route(
    cx: &Ctx<'_>,
    doc: &FileDoc,
    earth: EarthModel,
    dt: f64,
) -> Result<crate::truth::route::CompiledRoute, ScenarioError> {
    use crate::truth::route::{LegKind, Route, RouteError, RouteLimits, TurnLimit, Waypoint};
    let route_span = doc.route.as_ref().map_or(0..0, |r| r.span());
    if doc.waypoint.len() < 2 {
        let span = doc.waypoint.first().map_or(route_span, |w| w.span());
        return cx.err(
            span,
            "waypoint",
            format!(
                "a route needs at least two [[waypoint]] tables (got {})",
                doc.waypoint.len()
            ),
        );
    }
    if let Some(w) = doc.waypoint.get(crate::truth::route::MAX_WAYPOINTS) {
        return cx.err(
            w.span(),
            "waypoint",
            format!(
                "more than {} [[waypoint]] tables (the limit of one route): split the route",
                crate::truth::route::MAX_WAYPOINTS
            ),
        );
    }
    let mut wps = Vec::with_capacity(doc.waypoint.len());
    for w in &doc.waypoint {
        let wd = w.get_ref();
        let lat = cx.range(
            &wd.lat_deg,
            "waypoint.lat_deg",
            -89.5,
            89.5,
            "latitude in [-89.5, 89.5] deg",
        )?;
        let lon = cx.range(
            &wd.lon_deg,
            "waypoint.lon_deg",
            -180.0,
            360.0,
            "longitude in [-180, 360] deg",
        )?;
        let h = match &wd.h_m {
            Some(v) => cx.range(
                v,
                "waypoint.h_m",
                -1000.0,
                100_000.0,
                "height in [-1000, 100000] m",
            )?,
            None => 0.0,
        };
        let v = cx.range(
            &wd.speed_mps,
            "waypoint.speed_mps",
            0.0,
            3000.0,
            "speed in (0, 3000] m/s",
        )?;
        if v <= 0.0 {
            return cx.err(
                wd.speed_mps.span(),
                "waypoint.speed_mps",
                "a route's speed must be > 0 (use hold_s for time at rest)",
            );
        }
        let hold = match &wd.hold_s {
            Some(x) => cx.range(
                x,
                "waypoint.hold_s",
                0.0,
                MAX_SEGMENT_S,
                "a time at rest in [0, 1e7] s",
            )?,
            None => 0.0,
        };
        wps.push(Waypoint {
            lat_rad: lat * D2R,
            lon_rad: lon * D2R,
            h_m: h,
            speed_mps: v,
            hold_s: hold,
        });
    }
    let mut limits = RouteLimits::default();
    let mut legs = LegKind::GreatCircle;
    if let Some(r) = &doc.route {
        let rd = r.get_ref();
        if let Some(l) = &rd.legs {
            legs = match l.get_ref().as_str() {
                "great_circle" => LegKind::GreatCircle,
                "rhumb" => LegKind::Rhumb,
                other => {
                    return cx.err(
                        l.span(),
                        "route.legs",
                        format!("unknown leg kind `{other}`: expected great_circle or rhumb"),
                    )
                }
            };
        }
        match (&rd.turn_rate_limit_dps, &rd.bank_limit_deg) {
            (Some(a), Some(_)) => {
                return cx.err(
                    a.span(),
                    "route.turn_rate_limit_dps",
                    "give either turn_rate_limit_dps or bank_limit_deg, not both",
                )
            }
            (Some(a), None) => {
                limits.turn = TurnLimit::Rate(
                    cx.range(
                        a,
                        "route.turn_rate_limit_dps",
                        1e-3,
                        360.0,
                        "a turn-rate limit in [0.001, 360] deg/s",
                    )? * D2R,
                )
            }
            (None, Some(b)) => {
                limits.turn = TurnLimit::Bank(
                    cx.range(
                        b,
                        "route.bank_limit_deg",
                        0.1,
                        80.0,
                        "a bank limit in [0.1, 80] deg",
                    )? * D2R,
                )
            }
            (None, None) => {}
        }
        if let Some(x) = &rd.roll_rate_limit_dps {
            limits.roll_rate_rps = cx.range(
                x,
                "route.roll_rate_limit_dps",
                0.01,
                360.0,
                "a roll-rate limit in [0.01, 360] deg/s",
            )? * D2R;
        }
        if let Some(x) = &rd.climb_rate_limit_mps {
            limits.climb_rate_mps = cx.range(
                x,
                "route.climb_rate_limit_mps",
                1e-3,
                500.0,
                "a climb-rate limit in [0.001, 500] m/s",
            )?;
        }
        if let Some(x) = &rd.accel_limit_mps2 {
            limits.accel_mps2 = cx.range(
                x,
                "route.accel_limit_mps2",
                1e-3,
                100.0,
                "an acceleration limit in [0.001, 100] m/s²",
            )?;
        }
    }
    let route = Route {
        waypoints: wps,
        legs,
        limits,
    };
    crate::truth::route::compile_with(&route, earth, dt, cx.cancel).map_err(|e| {
        if let RouteError::Cancelled(_) = e {
            return ScenarioError::Cancelled;
        }
        let wp = match &e {
            RouteError::Value { waypoint, .. }
            | RouteError::Coincident { waypoint, .. }
            | RouteError::Ambiguous { waypoint, .. }
            | RouteError::Pole { waypoint, .. }
            | RouteError::TooShort { waypoint, .. }
            | RouteError::Turn { waypoint, .. }
            | RouteError::Solve { waypoint, .. } => Some(*waypoint),
            _ => None,
        };
        let span = match wp.and_then(|i| doc.waypoint.get(i.saturating_sub(1))) {
            Some(w) => w.span(),
            None => route_span.clone(),
        };
        let key = if wp.is_some() { "waypoint" } else { "route" };
        ScenarioError::Invalid {
            file: cx.file.to_string(),
            line: cx.line_of(span.start),
            key: key.to_string(),
            message: format!("[[waypoint]] route: {e}"),
        }
    })
}

/// `[calibration]`: a standard turntable schedule (crate::truth::schedule) in
/// place of `[[segment]]` and `[[overlay]]`, at rest (zero speed and climb rate, free
/// vehicle).
pub(super) fn parse_calibration(
    cx: &Ctx<'_>,
    doc: &FileDoc,
    speed: f64,
    climb: f64,
    vehicle: Vehicle,
    dt: f64,
) -> Result<Option<crate::truth::schedule::Schedule>, ScenarioError> {
    use crate::truth::schedule::{
        Schedule, ScheduleError, Standard, DEFAULT_DWELL_S, DEFAULT_ROTATION_S,
    };
    let Some(c) = &doc.calibration else {
        return Ok(None);
    };
    let span = c.span();
    if let Some(s) = doc.segment.first() {
        return cx.err(s.span(), "segment", "a [calibration] scenario builds its own static segment and rotations: remove the [[segment]] tables");
    }
    if let Some(o) = doc.overlay.first() {
        return cx.err(
            o.span(),
            "overlay",
            "a [calibration] scenario builds its own rotations: remove the [[overlay]] tables",
        );
    }
    if speed != 0.0 || climb != 0.0 || vehicle != Vehicle::Free {
        return cx.err(span, "calibration", "a calibration schedule is at rest on the table: start.speed_mps and start.climb_rate_mps must be 0 and vehicle left out");
    }
    let cd = c.get_ref();
    let Some(kind) = Standard::from_name(cd.schedule.get_ref()) else {
        return cx.err(
            cd.schedule.span(),
            "calibration.schedule",
            format!(
                "unknown schedule `{}`: expected 6-position or 12-position",
                cd.schedule.get_ref()
            ),
        );
    };
    let dwell = match &cd.dwell_s {
        Some(v) => cx.positive(v, "calibration.dwell_s")?,
        None => DEFAULT_DWELL_S,
    };
    let rot = match &cd.rotation_s {
        Some(v) => cx.positive(v, "calibration.rotation_s")?,
        None => DEFAULT_ROTATION_S,
    };
    if dwell > MAX_SEGMENT_S / 16.0 || rot > MAX_SEGMENT_S / 16.0 {
        return cx.err(
            span,
            "calibration",
            format!(
                "dwell_s and rotation_s must be at most {:e} s",
                MAX_SEGMENT_S / 16.0
            ),
        );
    }
    match Schedule::standard(kind, dwell, rot, dt) {
        Ok(s) => Ok(Some(s)),
        Err(ScheduleError::Duration { key, what }) => {
            let v = if key == "dwell_s" {
                &cd.dwell_s
            } else {
                &cd.rotation_s
            };
            cx.err(
                v.as_ref().map_or(span, |v| v.span()),
                &format!("calibration.{key}"),
                what,
            )
        }
        Err(e) => cx.err(span, "calibration", e.to_string()),
    }
}

/// `[[overlay]] type = "rotation"`: `axis`, `angle_deg`, `start_s` and `end_s` required,
/// no `freq_hz` (the raised-cosine rate follows from the angle and the window).
pub(super) fn parse_rotation(
    cx: &Ctx<'_>,
    o: &S<OverlayDoc>,
    total: f64,
) -> Result<Overlay, ScenarioError> {
    let od = o.get_ref();
    for (k, present) in [
        ("freq_hz", od.freq_hz.is_some()),
        ("half_angle_deg", od.half_angle_deg.is_some()),
        ("angle_amp_deg", od.angle_amp_deg.is_some()),
        ("accel_amp_mps2", od.accel_amp_mps2.is_some()),
        ("phase_deg", od.phase_deg.is_some()),
    ] {
        if present {
            return cx.err(
                o.span(),
                &format!("overlay.{k}"),
                "not a key of overlay type `rotation` (its keys: axis, angle_deg, start_s, end_s)",
            );
        }
    }
    let axis = match &od.axis {
        None => {
            return cx.err(
                o.span(),
                "overlay.axis",
                "missing required key for overlay type `rotation`",
            )
        }
        Some(a) => match a.get_ref().as_str() {
            "x" => Axis::X,
            "y" => Axis::Y,
            "z" => Axis::Z,
            other => {
                return cx.err(
                    a.span(),
                    "overlay.axis",
                    format!("unknown axis `{other}`: expected x, y or z"),
                )
            }
        },
    };
    let Some(a) = &od.angle_deg else {
        return cx.err(
            o.span(),
            "overlay.angle_deg",
            "missing required key for overlay type `rotation`",
        );
    };
    let angle = cx.range(
        a,
        "overlay.angle_deg",
        -3600.0,
        3600.0,
        "an angle within ±3600 deg",
    )?;
    if angle == 0.0 {
        return cx.err(
            a.span(),
            "overlay.angle_deg",
            "a rotation needs a non-zero angle",
        );
    }
    let (Some(s0), Some(s1)) = (&od.start_s, &od.end_s) else {
        return cx.err(
            o.span(),
            "overlay.end_s",
            "overlay type `rotation` needs both start_s and end_s",
        );
    };
    let start_s = cx.range(
        s0,
        "overlay.start_s",
        0.0,
        total,
        "a time within the scenario",
    )?;
    let end_s = cx.range(
        s1,
        "overlay.end_s",
        start_s,
        total,
        "a time after start_s within the scenario",
    )?;
    if end_s <= start_s {
        return cx.err(
            s1.span(),
            "overlay.end_s",
            "a rotation needs end_s > start_s",
        );
    }
    Ok(OverlayKind::rotation(axis, angle * D2R, start_s, end_s))
}

/// `start_s`/`end_s` of an overlay (defaults 0 and ∞).
pub(super) fn overlay_window(
    cx: &Ctx<'_>,
    od: &OverlayDoc,
    total: f64,
) -> Result<(f64, f64), ScenarioError> {
    let start_s = match &od.start_s {
        Some(v) => cx.range(
            v,
            "overlay.start_s",
            0.0,
            total,
            "a time within the scenario",
        )?,
        None => 0.0,
    };
    let end_s = match &od.end_s {
        Some(v) => cx.range(
            v,
            "overlay.end_s",
            start_s,
            f64::INFINITY,
            "a time after start_s",
        )?,
        None => f64::INFINITY,
    };
    Ok((start_s, end_s))
}

/// A `random_vibration` overlay: its PSD tables (files relative to the scenario file),
/// realised over its window ([`crate::truth::random_vibration`]).
pub(super) fn parse_random_vibration(
    cx: &Ctx<'_>,
    o: &S<OverlayDoc>,
    file: &str,
    rate_hz: f64,
    imu_seed: u64,
    window_s: f64,
    index: u64,
) -> Result<
    (
        crate::truth::random_vibration::RandomVibration,
        crate::truth::random_vibration::VibrationReport,
    ),
    ScenarioError,
> {
    use crate::truth::random_vibration::{PsdTable, RandomVibration, RandomVibrationSpec};
    let od = o.get_ref();
    for (k, v) in [
        ("overlay.axis", od.axis.as_ref().map(|v| v.span())),
        ("overlay.freq_hz", od.freq_hz.as_ref().map(|v| v.span())),
        (
            "overlay.half_angle_deg",
            od.half_angle_deg.as_ref().map(|v| v.span()),
        ),
        (
            "overlay.angle_amp_deg",
            od.angle_amp_deg.as_ref().map(|v| v.span()),
        ),
        (
            "overlay.accel_amp_mps2",
            od.accel_amp_mps2.as_ref().map(|v| v.span()),
        ),
        ("overlay.phase_deg", od.phase_deg.as_ref().map(|v| v.span())),
    ] {
        if let Some(span) = v {
            return cx.err(
                span,
                k,
                "not a key of overlay type `random_vibration` (its spectrum comes from the PSD keys)",
            );
        }
    }
    let base = Path::new(file).parent().unwrap_or(Path::new(""));
    let table = |path: &Option<S<String>>,
                 bp: &Option<S<Vec<Vec<f64>>>>,
                 what: &str|
     -> Result<Option<PsdTable>, ScenarioError> {
        let fkey = format!("overlay.{what}_psd_file");
        let bkey = format!("overlay.{what}_psd_breakpoints");
        match (path, bp) {
            (Some(p), Some(_)) => cx.err(
                p.span(),
                &fkey,
                format!("give either {fkey} or {bkey}, not both"),
            ),
            (Some(p), None) => {
                let full = base.join(p.get_ref());
                PsdTable::read_csv(&full)
                    .map(Some)
                    .or_else(|e| cx.err(p.span(), &fkey, e.to_string()))
            }
            (None, Some(b)) => PsdTable::from_breakpoints(b.get_ref(), &bkey)
                .map(Some)
                .or_else(|e| {
                    let msg = match e {
                        crate::truth::random_vibration::PsdError::Invalid {
                            line,
                            column,
                            message,
                            ..
                        } => format!("breakpoint {line}, entry {column}: {message}"),
                        other => other.to_string(),
                    };
                    cx.err(b.span(), &bkey, msg)
                }),
            (None, None) => Ok(None),
        }
    };
    let accel = table(&od.accel_psd_file, &od.accel_psd_breakpoints, "accel")?;
    let gyro = table(&od.gyro_psd_file, &od.gyro_psd_breakpoints, "gyro")?;
    if accel.is_none() && gyro.is_none() {
        return cx.err(
            o.span(),
            "overlay",
            "a random_vibration overlay needs accel_psd_file, accel_psd_breakpoints, gyro_psd_file or gyro_psd_breakpoints",
        );
    }
    let spec = RandomVibrationSpec {
        accel,
        gyro,
        seed: od.seed.as_ref().map_or(imu_seed, |s| *s.get_ref()),
    };
    RandomVibration::realise(&spec, window_s, 0.5 * rate_hz, index)
        .or_else(|m| cx.err(o.span(), "overlay", m))
}

pub(super) fn parse_mounting(
    cx: &Ctx<'_>,
    m: Option<&S<MountingDoc>>,
) -> Result<Mounting, ScenarioError> {
    let Some(m) = m else {
        return Ok(Mounting::default());
    };
    let vec3 = |v: &Option<S<Vec<f64>>>, key: &str, lim: f64, unit: &str| {
        let Some(v) = v else {
            return Ok(None);
        };
        let x = v.get_ref();
        if x.len() != 3 || x.iter().any(|c| !c.is_finite() || c.abs() > lim) {
            return cx.err(
                v.span(),
                key,
                format!("expected three finite numbers [x, y, z] within ±{lim} {unit}, got {x:?}"),
            );
        }
        Ok(Some(sdins_core::math::Vec3::new(x[0], x[1], x[2])))
    };
    let m = m.get_ref();
    let arm = vec3(&m.imu_lever_arm_m, "mounting.imu_lever_arm_m", 100.0, "m")?;
    let ang = vec3(&m.imu_mount_deg, "mounting.imu_mount_deg", 180.0, "deg")?;
    let gnss = vec3(&m.gnss_lever_arm_m, "mounting.gnss_lever_arm_m", 100.0, "m")?;
    let imu = if arm.is_some() || ang.is_some() {
        let a = ang.unwrap_or_default() * D2R;
        Some(crate::truth::ImuMount::new(
            arm.unwrap_or_default(),
            Euler::new(a.x, a.y, a.z),
        ))
    } else {
        None
    };
    Ok(Mounting {
        imu,
        gnss_lever_arm_b_m: gnss,
    })
}

pub(super) fn parse_vehicle(cx: &Ctx<'_>, doc: &FileDoc) -> Result<Vehicle, ScenarioError> {
    let alpha = match &doc.angle_of_attack_deg {
        Some(a) => Some((
            cx.range(
                a,
                "angle_of_attack_deg",
                -30.0,
                30.0,
                "an angle of attack in [-30, 30] deg",
            )? * D2R,
            a.span(),
        )),
        None => None,
    };
    let v = match doc
        .vehicle
        .as_ref()
        .map(|v| (v.get_ref().as_str(), v.span()))
    {
        None | Some(("free", _)) => Vehicle::Free,
        Some(("car", _)) => Vehicle::Car,
        Some(("aircraft", _)) => Vehicle::Aircraft {
            angle_of_attack_rad: alpha.as_ref().map_or(0.0, |a| a.0),
        },
        Some((other, span)) => {
            return cx.err(
                span,
                "vehicle",
                format!("unknown vehicle `{other}`: expected free, aircraft or car"),
            );
        }
    };
    if let (Some((_, span)), false) = (alpha, matches!(v, Vehicle::Aircraft { .. })) {
        return cx.err(
            span,
            "angle_of_attack_deg",
            "only an aircraft has an angle of attack (set vehicle = \"aircraft\")",
        );
    }
    Ok(v)
}

pub(super) fn parse_nav(cx: &Ctx<'_>, nav: Option<&NavDoc>) -> Result<NavConfig, ScenarioError> {
    let mut cfg = NavConfig::default();
    let Some(n) = nav else { return Ok(cfg) };
    if let Some(s) = &n.samples {
        let v = *s.get_ref();
        if !(1..=4).contains(&v) {
            return cx.err(
                s.span(),
                "nav.samples",
                format!("{v}: expected 1, 2, 3 or 4 samples per update"),
            );
        }
        cfg.samples = v as usize;
    }
    if let Some(s) = &n.substeps {
        let v = *s.get_ref();
        if !(1..=1024).contains(&v) {
            return cx.err(s.span(), "nav.substeps", format!("{v}: expected 1..=1024"));
        }
        cfg.substeps = v as usize;
    }
    if let Some(a) = &n.algos {
        for name in a.get_ref() {
            if sdins_core::nav::AlgorithmKind::from_name(name).is_none() {
                let names: Vec<&str> = sdins_core::nav::AlgorithmKind::ALL
                    .iter()
                    .map(|k| k.name())
                    .collect();
                let hint = suggest_from(name, &names)
                    .map(|s| format!(" (did you mean `{s}`?)"))
                    .unwrap_or_default();
                return cx.err(
                    a.span(),
                    "nav.algos",
                    format!(
                        "unknown algorithm `{name}`{hint}: expected {}",
                        names.join(", ")
                    ),
                );
            }
        }
        cfg.algos = a.get_ref().clone();
    }
    if let Some(c) = &n.coning {
        let name = c.get_ref();
        match sdins_core::coning::ConingSet::parse(name, cfg.samples) {
            Some(set) if set.accepts(cfg.samples) => {}
            Some(set) => {
                return cx.err(
                    c.span(),
                    "nav.coning",
                    format!(
                        "`{name}` is the set for {} samples per update, but nav.samples is {}",
                        set.samples(),
                        cfg.samples
                    ),
                )
            }
            None => {
                return cx.err(
                    c.span(),
                    "nav.coning",
                    format!("unknown coning set `{name}`: expected none, 1prev, two, three_poly, three_opt, four_poly, four_opt, polynomial or optimal"),
                )
            }
        }
        cfg.coning = Some(name.clone());
    }
    if let Some(e) = &n.earth {
        cfg.earth = match e.get_ref().as_str() {
            "wgs84" => EarthChoice::Wgs84,
            "psins" => EarthChoice::Psins,
            "flat" => EarthChoice::Flat,
            other => {
                return cx.err(
                    e.span(),
                    "nav.earth",
                    format!("unknown earth model `{other}`: expected wgs84, psins or flat"),
                )
            }
        };
    }
    if let Some(v) = &n.vertical {
        cfg.vertical_hold = match v.get_ref().as_str() {
            "free" => false,
            "hold" => true,
            other => {
                return cx.err(
                    v.span(),
                    "nav.vertical",
                    format!("unknown vertical mode `{other}`: expected free or hold"),
                )
            }
        };
    }
    Ok(cfg)
}

//! Scenario validation: the located-error context and [`Scenario::from_toml`].

use super::*;

pub(super) struct Ctx<'a> {
    pub(super) file: &'a str,
    pub(super) text: &'a str,
    pub(super) cancel: &'a crate::cancel::CancelToken,
}

impl Ctx<'_> {
    pub(super) fn line_of(&self, pos: usize) -> usize {
        self.text
            .get(..pos.min(self.text.len()))
            .map_or(1, |s| s.bytes().filter(|&b| b == b'\n').count() + 1)
    }
    pub(super) fn err<T>(
        &self,
        span: std::ops::Range<usize>,
        key: &str,
        message: impl Into<String>,
    ) -> Result<T, ScenarioError> {
        Err(ScenarioError::Invalid {
            file: self.file.to_string(),
            line: self.line_of(span.start),
            key: key.to_string(),
            message: message.into(),
        })
    }
    pub(super) fn finite(&self, v: &S<f64>, key: &str) -> Result<f64, ScenarioError> {
        let x = *v.get_ref();
        if !x.is_finite() {
            return self.err(v.span(), key, "must be a finite number");
        }
        Ok(x)
    }
    pub(super) fn range(
        &self,
        v: &S<f64>,
        key: &str,
        lo: f64,
        hi: f64,
        what: &str,
    ) -> Result<f64, ScenarioError> {
        let x = self.finite(v, key)?;
        if !(lo..=hi).contains(&x) {
            return self.err(
                v.span(),
                key,
                format!("{x} is out of range: expected {what}"),
            );
        }
        Ok(x)
    }
    pub(super) fn positive(&self, v: &S<f64>, key: &str) -> Result<f64, ScenarioError> {
        let x = self.finite(v, key)?;
        if x <= 0.0 {
            return self.err(v.span(), key, format!("{x} must be > 0"));
        }
        Ok(x)
    }
}

pub(super) fn toml_error(file: &str, text: &str, e: &toml::de::Error) -> ScenarioError {
    let line = e.span().map_or(1, |s| {
        text.get(..s.start)
            .map_or(1, |p| p.matches('\n').count() + 1)
    });
    let msg = e.message().trim().to_string();
    let mut key = String::from("(syntax)");
    let mut message = msg.clone();
    if let Some(rest) = msg.strip_prefix("unknown field `") {
        if let Some(end) = rest.find('`') {
            let name = &rest[..end];
            key = name.to_string();
            // candidates: the keys the parser listed as expected here
            let expected: Vec<&str> = rest.split('`').skip(2).step_by(2).collect();
            let hint = if expected.is_empty() {
                suggest(name)
            } else {
                suggest_from(name, &expected)
            };
            message = format!(
                "unknown key{}",
                hint.map(|s| format!(" (did you mean `{s}`?)"))
                    .unwrap_or_default()
            );
            if let Some(exp) = rest.find("expected") {
                message.push_str(&format!("; {}", &rest[exp..]));
            }
        }
    } else if let Some(rest) = msg.strip_prefix("missing field `") {
        if let Some(end) = rest.find('`') {
            key = rest[..end].to_string();
            message = "missing required key".to_string();
        }
    }
    ScenarioError::Invalid {
        file: file.to_string(),
        line,
        key,
        message,
    }
}

impl Scenario {
    /// Parse and validate scenario text; `file` names it in error messages.
    pub fn from_toml(text: &str, file: &str) -> Result<Scenario, ScenarioError> {
        Scenario::from_toml_with(text, file, &crate::cancel::CancelToken::new())
    }

    /// [`Scenario::from_toml`] polling `cancel` ([`Scenario::from_file_with`]).
    pub fn from_toml_with(
        text: &str,
        file: &str,
        cancel: &crate::cancel::CancelToken,
    ) -> Result<Scenario, ScenarioError> {
        let doc: FileDoc = toml::from_str(text).map_err(|e| toml_error(file, text, &e))?;
        cancel.check().map_err(|_| ScenarioError::Cancelled)?;
        let cx = Ctx { file, text, cancel };
        let start_from_route;
        let start_doc: &S<StartDoc> = match (&doc.start, doc.waypoint.first()) {
            (Some(s), None) => s,
            (Some(s), Some(_)) => {
                return cx.err(s.span(), "start", "a route's first [[waypoint]] is its start position (and its heading and speed come from the route): leave [start] out");
            }
            (None, Some(w)) => {
                let wd = w.get_ref();
                start_from_route = S::new(
                    w.span(),
                    StartDoc {
                        lat_deg: wd.lat_deg.clone(),
                        lon_deg: wd.lon_deg.clone(),
                        h_m: wd.h_m.clone(),
                        speed_mps: None,
                        climb_rate_mps: None,
                        roll_deg: None,
                        pitch_deg: None,
                        yaw_deg: None,
                    },
                );
                &start_from_route
            }
            (None, None) => {
                return Err(ScenarioError::Invalid {
                    file: file.into(),
                    line: 1,
                    key: "start".into(),
                    message:
                        "missing required key (a [start] table, or a route of [[waypoint]] tables)"
                            .into(),
                });
            }
        };
        let st = start_doc.get_ref();
        let lat = cx.range(
            &st.lat_deg,
            "start.lat_deg",
            -90.0,
            90.0,
            "latitude in [-90, 90] deg",
        )?;
        if lat.abs() > 89.0 {
            // The local-level (NED) mechanization is singular at the poles: tan L and
            // 1/cos L in the transport rate and longitude rate. We accept up to ±89.99°.
            if lat.abs() > 89.99 {
                return cx.err(st.lat_deg.span(), "start.lat_deg", format!("{lat} is too close to a pole: the local-level NED mechanization needs |lat| ≤ 89.99 deg"));
            }
        }
        let lon = cx.range(
            &st.lon_deg,
            "start.lon_deg",
            -180.0,
            360.0,
            "longitude in [-180, 360] deg",
        )?;
        let h = match &st.h_m {
            Some(v) => cx.range(
                v,
                "start.h_m",
                -1000.0,
                100_000.0,
                "height in [-1000, 100000] m",
            )?,
            None => 0.0,
        };
        let speed = match &st.speed_mps {
            Some(v) => cx.range(v, "start.speed_mps", 0.0, 3000.0, "speed in [0, 3000] m/s")?,
            None => 0.0,
        };
        let climb = match &st.climb_rate_mps {
            Some(v) => cx.range(
                v,
                "start.climb_rate_mps",
                -500.0,
                500.0,
                "climb rate in [-500, 500] m/s",
            )?,
            None => 0.0,
        };
        let ang = |v: &Option<S<f64>>, key: &str, lim: f64| -> Result<f64, ScenarioError> {
            match v {
                Some(v) => {
                    Ok(
                        cx.range(v, key, -lim, lim, &format!("angle in [-{lim}, {lim}] deg"))?
                            * D2R,
                    )
                }
                None => Ok(0.0),
            }
        };
        let euler = Euler::new(
            ang(&st.roll_deg, "start.roll_deg", 180.0)?,
            ang(&st.pitch_deg, "start.pitch_deg", 89.9)?,
            ang(&st.yaw_deg, "start.yaw_deg", 360.0)?,
        );
        let start = Start {
            lat_rad: lat * D2R,
            lon_rad: lon * D2R,
            h_m: h,
            speed_mps: speed,
            climb_rate_mps: climb,
            euler,
        };
        // the one initial-state validator every source uses (the ranges above name the key)
        if let Err(e) = crate::io::initial::validate_initial_state(&sdins_core::nav::InitialState {
            lat_rad: start.lat_rad,
            lon_rad: start.lon_rad,
            h_m: start.h_m,
            v_n_mps: sdins_core::math::Vec3::new(speed, 0.0, -climb),
            c_b_n: sdins_core::math::c_b_n_from_euler(&euler),
        }) {
            return cx.err(start_doc.span(), "start", e.to_string());
        }

        let im = doc.imu.get_ref();
        let rate_hz = cx.positive(&im.rate_hz, "imu.rate_hz")?;
        if rate_hz > 100_000.0 {
            return cx.err(
                im.rate_hz.span(),
                "imu.rate_hz",
                format!("{rate_hz} Hz is beyond 100 kHz"),
            );
        }
        let grade = im.grade.as_ref().map(|g| g.get_ref().clone());
        let base = match &im.grade {
            None => crate::sensors::imu_error::ImuErrorModel::ideal(),
            Some(g) => match crate::sensors::imu_error::ImuErrorModel::preset(g.get_ref()) {
                Ok(m) => m,
                Err(e) => return cx.err(g.span(), "imu.grade", e.to_string()),
            },
        };
        let model = match &im.errors {
            None => base,
            Some(t) => {
                let r = if t.contains_key("preset") {
                    crate::sensors::imu_error::ImuErrorModel::from_table(t)
                } else {
                    base.with_overrides(t)
                };
                match r {
                    Ok(m) => m,
                    Err(e) => return cx.err(doc.imu.span(), "imu.errors", e.to_string()),
                }
            }
        };
        let imu = ImuConfig {
            rate_hz,
            seed: im.seed.unwrap_or(1),
            grade,
            errors: im.errors.clone(),
            model,
        };

        let nav = parse_nav(&cx, doc.nav.as_ref())?;

        let dt = 1.0 / rate_hz;
        let vehicle = parse_vehicle(&cx, &doc)?;
        if vehicle != Vehicle::Free {
            for (v, key) in [
                (&st.roll_deg, "start.roll_deg"),
                (&st.pitch_deg, "start.pitch_deg"),
            ] {
                if let Some(v) = v {
                    if *v.get_ref() != 0.0 {
                        return cx.err(v.span(), key, format!("with vehicle = \"{}\" roll and pitch follow the motion (bank, flight-path angle, road grade): leave this key out", vehicle.name()));
                    }
                }
            }
        }
        let calibration = parse_calibration(&cx, &doc, speed, climb, vehicle, 1.0 / rate_hz)?;
        let body = parse_body_motion(&cx, &doc, start_doc.get_ref(), euler, vehicle, dt)?;
        let mut motions = Vec::new();
        // the [[segment]] of each motion (a coordinated turn is three motions)
        let mut seg_of_motion: Vec<std::ops::Range<usize>> = Vec::new();
        let mut speed_now = speed;
        for s in &doc.segment {
            let sd = s.get_ref();
            let kind = sd.kind.get_ref().as_str();
            let profile = sd.profile.as_ref().map(|p| p.get_ref().as_str());
            let coordinated = kind == "turn" && profile == Some("coordinated");
            let dur = match (&sd.duration_s, coordinated) {
                (Some(d), false) => cx.positive(d, "segment.duration_s")?,
                (Some(d), true) => {
                    return cx.err(d.span(), "segment.duration_s", "a coordinated turn takes its duration from angle_deg, bank_deg and roll_rate_dps: leave duration_s out");
                }
                (None, true) => 1.0,
                (None, false) => {
                    return cx.err(s.span(), "segment.duration_s", "missing required key");
                }
            };
            if dur > MAX_SEGMENT_S {
                let span = sd.duration_s.as_ref().map_or(s.span(), |d| d.span());
                return cx.err(
                    span,
                    "segment.duration_s",
                    format!("{dur} s is too long: expected at most {MAX_SEGMENT_S:e} s (116 days)"),
                );
            }
            let n = dur / dt;
            let dspan = sd.duration_s.as_ref().map_or(s.span(), |d| d.span());
            if !coordinated && n.round() < 1.0 {
                return cx.err(
                    dspan,
                    "segment.duration_s",
                    format!("{dur} s is shorter than one IMU sample ({dt} s at {rate_hz} Hz)"),
                );
            }
            if !coordinated && (n - n.round()).abs() > 1e-6 * n.max(1.0) {
                return cx.err(dspan, "segment.duration_s", format!("{dur} s is not a whole number of IMU samples at {rate_hz} Hz (segment boundaries must fall on sample boundaries)"));
            }
            // keys allowed per type
            let allowed: &[&str] = match kind {
                "static" | "cruise" => &[],
                "accelerate" => &["accel_mps2", "profile"],
                "turn" if coordinated => &["angle_deg", "profile", "bank_deg", "roll_rate_dps"],
                "turn" => &["rate_dps", "angle_deg", "profile"],
                "sturn" => &["amplitude_dps"],
                "climb" => &["to_climb_rate_mps", "profile"],
                other => {
                    return cx.err(sd.kind.span(), "segment.type", format!("unknown segment type `{other}`: expected one of static, cruise, accelerate, turn, sturn, climb"));
                }
            };
            let present: [(&str, Option<std::ops::Range<usize>>); 8] = [
                ("bank_deg", sd.bank_deg.as_ref().map(|v| v.span())),
                ("roll_rate_dps", sd.roll_rate_dps.as_ref().map(|v| v.span())),
                ("accel_mps2", sd.accel_mps2.as_ref().map(|v| v.span())),
                ("rate_dps", sd.rate_dps.as_ref().map(|v| v.span())),
                ("angle_deg", sd.angle_deg.as_ref().map(|v| v.span())),
                ("profile", sd.profile.as_ref().map(|v| v.span())),
                ("amplitude_dps", sd.amplitude_dps.as_ref().map(|v| v.span())),
                (
                    "to_climb_rate_mps",
                    sd.to_climb_rate_mps.as_ref().map(|v| v.span()),
                ),
            ];
            for (k, span) in present {
                if let Some(span) = span {
                    if !allowed.contains(&k) {
                        return cx.err(
                            span,
                            &format!("segment.{k}"),
                            format!(
                                "not a key of segment type `{kind}` (it takes: {})",
                                if allowed.is_empty() {
                                    "duration_s only".to_string()
                                } else {
                                    allowed.join(", ")
                                }
                            ),
                        );
                    }
                }
            }
            let need = |v: &Option<S<f64>>, key: &str| -> Result<f64, ScenarioError> {
                match v {
                    Some(v) => cx.finite(v, key),
                    None => cx.err(
                        s.span(),
                        key,
                        format!("missing required key for segment type `{kind}`"),
                    ),
                }
            };
            let motion = match kind {
                "static" => {
                    if speed_now != 0.0 {
                        return cx.err(sd.kind.span(), "segment.type", format!("a static segment needs zero speed, but the vehicle moves at {speed_now} m/s here (use `cruise`)"));
                    }
                    Motion::Static
                }
                "cruise" => Motion::Cruise,
                "turn" if coordinated => {
                    let angle = need(&sd.angle_deg, "segment.angle_deg")?;
                    let bank = need(&sd.bank_deg, "segment.bank_deg")?;
                    let roll = need(&sd.roll_rate_dps, "segment.roll_rate_dps")?;
                    if !(bank > 0.0 && bank < 90.0) {
                        let span = sd.bank_deg.as_ref().map_or(s.span(), |v| v.span());
                        return cx.err(
                            span,
                            "segment.bank_deg",
                            format!("{bank} deg: expected a bank limit in (0, 90) deg"),
                        );
                    }
                    if !(roll > 0.0 && roll <= 360.0) {
                        let span = sd.roll_rate_dps.as_ref().map_or(s.span(), |v| v.span());
                        return cx.err(
                            span,
                            "segment.roll_rate_dps",
                            format!("{roll} deg/s: expected a roll-rate limit in (0, 360] deg/s"),
                        );
                    }
                    if angle == 0.0 || speed_now <= 0.0 {
                        return cx.err(s.span(), "segment.angle_deg", format!("a coordinated turn needs a non-zero angle and a moving vehicle (speed here {speed_now} m/s)"));
                    }
                    match crate::truth::vehicle::coordinated_turn(
                        speed_now,
                        angle * D2R,
                        bank * D2R,
                        roll * D2R,
                        dt,
                    ) {
                        Ok(parts) => {
                            for p in parts {
                                motions.push(p);
                                seg_of_motion.push(s.span());
                            }
                        }
                        Err(e) => return cx.err(s.span(), "segment.type", e.to_string()),
                    }
                    continue;
                }
                "accelerate" => {
                    let a = need(&sd.accel_mps2, "segment.accel_mps2")?;
                    if a.abs() > 1000.0 * 9.80665 {
                        return cx.err(
                            s.span(),
                            "segment.accel_mps2",
                            format!("{a} m/s² exceeds 1000 g"),
                        );
                    }
                    speed_now = crate::truth::trajectory::accelerated_speed(speed_now, a, dur);
                    if speed_now < 0.0 {
                        return cx.err(s.span(), "segment.accel_mps2", format!("the speed would become negative ({speed_now} m/s) by the end of this segment"));
                    }
                    match profile {
                        None | Some("linear") => Motion::Accelerate { accel_mps2: a },
                        Some("smooth") => Motion::AccelerateSmooth {
                            delta_speed_mps: a * dur,
                        },
                        Some(other) => {
                            let span = sd.profile.as_ref().map_or(s.span(), |p| p.span());
                            return cx.err(span, "segment.profile", format!("unknown profile `{other}` for accelerate: expected linear or smooth"));
                        }
                    }
                }
                "turn" => {
                    let profile = sd
                        .profile
                        .as_ref()
                        .map_or("constant", |p| p.get_ref().as_str());
                    match (profile, &sd.rate_dps, &sd.angle_deg) {
                        ("constant", Some(r), None) => Motion::TurnRate {
                            rate_rps: cx.finite(r, "segment.rate_dps")? * D2R,
                        },
                        ("constant", None, Some(a)) => Motion::TurnRate {
                            rate_rps: cx.finite(a, "segment.angle_deg")? * D2R / dur,
                        },
                        ("smooth", None, Some(a)) => Motion::TurnSmooth {
                            angle_rad: cx.finite(a, "segment.angle_deg")? * D2R,
                        },
                        ("smooth", Some(r), None) => Motion::TurnSmooth {
                            angle_rad: cx.finite(r, "segment.rate_dps")? * D2R * dur,
                        },
                        ("constant" | "smooth", Some(_), Some(_)) => {
                            return cx.err(
                                s.span(),
                                "segment.rate_dps",
                                "give either rate_dps or angle_deg, not both",
                            );
                        }
                        ("constant" | "smooth", None, None) => {
                            return cx.err(
                                s.span(),
                                "segment.angle_deg",
                                "a turn needs rate_dps or angle_deg",
                            );
                        }
                        (other, _, _) => {
                            let span = sd.profile.as_ref().map_or(s.span(), |p| p.span());
                            return cx.err(
                                span,
                                "segment.profile",
                                format!("unknown profile `{other}`: expected constant or smooth"),
                            );
                        }
                    }
                }
                "sturn" => Motion::STurn {
                    amplitude_rps: need(&sd.amplitude_dps, "segment.amplitude_dps")? * D2R,
                },
                _ => {
                    let to = need(&sd.to_climb_rate_mps, "segment.to_climb_rate_mps")?;
                    match profile {
                        None | Some("linear") => Motion::Climb {
                            to_climb_rate_mps: to,
                        },
                        Some("smooth") => Motion::ClimbSmooth {
                            to_climb_rate_mps: to,
                        },
                        Some(other) => {
                            let span = sd.profile.as_ref().map_or(s.span(), |p| p.span());
                            return cx.err(span, "segment.profile", format!("unknown profile `{other}` for climb: expected linear or smooth"));
                        }
                    }
                }
            };
            motions.push((motion, (n.round()) * dt));
            seg_of_motion.push(s.span());
        }
        let mut route_report = None;
        let (mut speed, mut euler, mut start) = (speed, euler, start);
        if !doc.waypoint.is_empty() || doc.route.is_some() {
            if let Some(sg) = doc.segment.first() {
                return cx.err(sg.span(), "segment", "a scenario takes either [[segment]] tables or a route of [[waypoint]] tables, not both");
            }
            if let Some(c) = &doc.calibration {
                return cx.err(c.span(), "calibration", "a [calibration] schedule cannot be combined with a route of [[waypoint]] tables");
            }
            let compiled = parse_route(&cx, &doc, nav.earth.model(), dt)?;
            for &w in &compiled.motion_waypoint {
                seg_of_motion.push(doc.waypoint.get(w).map_or(0..0, |x| x.span()));
            }
            motions = compiled.motions.clone();
            speed = compiled.start_speed_mps;
            euler.yaw_rad = compiled.start_heading_rad;
            start.speed_mps = speed;
            start.euler = euler;
            route_report = Some(compiled);
        }
        if let Some(sched) = &calibration {
            motions.push((Motion::Static, sched.duration_s));
            seg_of_motion.push(doc.calibration.as_ref().map_or(0..0, |c| c.span()));
        }
        if let Some((_, spans)) = &body {
            seg_of_motion = spans.clone();
        }
        if motions.is_empty() && body.is_none() {
            return Err(ScenarioError::Invalid {
                file: file.into(),
                line: 1,
                key: "segment".into(),
                message: "a scenario needs at least one [[segment]] (or a [calibration] table)"
                    .into(),
            });
        }
        let total: f64 = match &body {
            Some((b, _)) => b.duration_s,
            None => motions.iter().map(|m| m.1).sum(),
        };

        let mut overlays = Vec::new();
        let mut vib_list = Vec::new();
        let mut vib_reports = Vec::new();
        for (oi, o) in doc.overlay.iter().enumerate() {
            let od = o.get_ref();
            let kind = od.kind.get_ref().as_str();
            let rv_keys = [
                od.accel_psd_file.as_ref().map(|v| v.span()),
                od.gyro_psd_file.as_ref().map(|v| v.span()),
                od.accel_psd_breakpoints.as_ref().map(|v| v.span()),
                od.gyro_psd_breakpoints.as_ref().map(|v| v.span()),
                od.seed.as_ref().map(|v| v.span()),
            ];
            if kind != "random_vibration" {
                if let Some(span) = rv_keys.iter().flatten().next() {
                    return cx.err(
                        span.clone(),
                        "overlay",
                        format!("a PSD or seed key belongs to overlay type `random_vibration`, not `{kind}`"),
                    );
                }
            }
            let need_pos = |v: &Option<S<f64>>, key: &str| -> Result<f64, ScenarioError> {
                match v {
                    Some(v) => cx.positive(v, key),
                    None => cx.err(
                        o.span(),
                        key,
                        format!("missing required key for overlay type `{kind}`"),
                    ),
                }
            };
            let axis = |default: Axis| -> Result<Axis, ScenarioError> {
                match &od.axis {
                    None => Ok(default),
                    Some(a) => match a.get_ref().as_str() {
                        "x" => Ok(Axis::X),
                        "y" => Ok(Axis::Y),
                        "z" => Ok(Axis::Z),
                        other => cx.err(
                            a.span(),
                            "overlay.axis",
                            format!("unknown axis `{other}`: expected x, y or z"),
                        ),
                    },
                }
            };
            if kind == "rotation" {
                overlays.push(parse_rotation(&cx, o, total)?);
                continue;
            }
            if let Some(a) = &od.angle_deg {
                return cx.err(
                    a.span(),
                    "overlay.angle_deg",
                    format!("angle_deg belongs to overlay type `rotation`, not `{kind}`"),
                );
            }
            let (start_s, end_s) = overlay_window(&cx, od, total)?;
            if kind == "random_vibration" {
                let (rv, rep) = parse_random_vibration(
                    &cx,
                    o,
                    file,
                    rate_hz,
                    im.seed.unwrap_or(1),
                    end_s.min(total) - start_s,
                    oi as u64,
                )?;
                overlays.push(Overlay {
                    kind: OverlayKind::RandomVibration { id: vib_list.len() },
                    start_s,
                    end_s,
                });
                vib_list.push(rv);
                vib_reports.push(rep);
                continue;
            }
            let freq = need_pos(&od.freq_hz, "overlay.freq_hz")?;
            if freq > 0.5 * rate_hz {
                return cx.err(
                    o.span(),
                    "overlay.freq_hz",
                    format!(
                        "{freq} Hz is above the Nyquist frequency {} Hz of the IMU",
                        0.5 * rate_hz
                    ),
                );
            }
            let omega = 2.0 * std::f64::consts::PI * freq;
            let k = match kind {
                "coning" => {
                    let a = need_pos(&od.half_angle_deg, "overlay.half_angle_deg")?;
                    if a >= 90.0 {
                        return cx.err(
                            o.span(),
                            "overlay.half_angle_deg",
                            "half-angle must be below 90 deg",
                        );
                    }
                    OverlayKind::Coning {
                        axis: axis(Axis::Z)?,
                        half_angle_rad: a * D2R,
                        omega_rps: omega,
                    }
                }
                "sculling" => OverlayKind::Sculling {
                    angle_amp_rad: need_pos(&od.angle_amp_deg, "overlay.angle_amp_deg")? * D2R,
                    accel_amp_mps2: need_pos(&od.accel_amp_mps2, "overlay.accel_amp_mps2")?,
                    omega_rps: omega,
                },
                "vibration" => OverlayKind::Vibration {
                    axis: axis(Axis::Z)?,
                    accel_amp_mps2: need_pos(&od.accel_amp_mps2, "overlay.accel_amp_mps2")?,
                    omega_rps: omega,
                },
                "sway" => {
                    let a = need_pos(&od.angle_amp_deg, "overlay.angle_amp_deg")?;
                    if a >= 90.0 {
                        return cx.err(
                            o.span(),
                            "overlay.angle_amp_deg",
                            "sway amplitude must be below 90 deg",
                        );
                    }
                    let phase = match &od.phase_deg {
                        Some(v) => cx.range(
                            v,
                            "overlay.phase_deg",
                            -360.0,
                            360.0,
                            "a phase in degrees within ±360",
                        )?,
                        None => 0.0,
                    };
                    OverlayKind::Sway {
                        axis: axis(Axis::X)?,
                        amp_rad: a * D2R,
                        omega_rps: omega,
                        phase_rad: phase * D2R,
                    }
                }
                other => {
                    return cx.err(od.kind.span(), "overlay.type", format!("unknown overlay type `{other}`: expected coning, sculling, vibration, sway, random_vibration or rotation"));
                }
            };
            overlays.push(Overlay {
                kind: k,
                start_s,
                end_s,
            });
        }

        if let Some(sched) = &calibration {
            overlays.extend(sched.overlays());
        }
        let trajectory = match body {
            Some((b, _)) => Trajectory::from_body_motion(b, overlays),
            None => Trajectory::new(speed, -climb, euler, &motions, overlays),
        }
        .with_random_vibration(vib_list);
        let trajectory = match trajectory.with_vehicle(vehicle, nav.earth.model(), lat * D2R, h) {
            Ok(t) => t,
            Err(e) => {
                let i = match &e {
                    VehicleError::Joint { index, .. } | VehicleError::Vertical { index, .. } => {
                        *index
                    }
                };
                let span = seg_of_motion
                    .get(i.saturating_sub(1))
                    .cloned()
                    .unwrap_or(0..0);
                let which = doc
                    .segment
                    .iter()
                    .position(|d| d.span() == span)
                    .map_or(i, |p| p + 1);
                let what = match &route_report {
                    // a route's motion i belongs to a waypoint's turn or leg
                    Some(r) => format!(
                        "route motion {i} (the turn or leg of [[waypoint]] number {})",
                        r.motion_waypoint
                            .get(i.saturating_sub(1))
                            .map_or(0, |w| w + 1)
                    ),
                    None => format!("[[segment]] number {which}"),
                };
                let msg = e
                    .to_string()
                    .replacen(&format!("segment {i} (1-based)"), &what, 1);
                return cx.err(span, "segment", msg);
            }
        };
        if let Err(e) = crate::truth::envelope::check_trajectory_with(
            &trajectory,
            crate::truth::envelope::StartPosition {
                lat_rad: start.lat_rad,
                h_m: start.h_m,
            },
            dt,
            &crate::truth::envelope::Envelope::DEFAULT,
            cancel,
        ) {
            if let crate::truth::envelope::EnvelopeError::Cancelled(_) = e {
                return Err(ScenarioError::Cancelled);
            }
            // the trajectory's segment k comes from a [[segment]] (a coordinated turn
            // gives three)
            let span = match e.segment().and_then(|k| seg_of_motion.get(k)) {
                Some(span) => span.clone(),
                None => start_doc.span(),
            };
            return cx.err(span, "segment", e.to_string());
        }
        let mounting = parse_mounting(&cx, doc.mounting.as_ref())?;
        let mut nav = nav;
        if nav.substeps == 0 {
            nav.substeps = crate::truth::auto_substeps(dt, &trajectory);
        }
        // [gnss] section
        let gnss = match &doc.gnss {
            None => None,
            Some(g) => {
                let cfg = g.get_ref().clone();
                if let Err(crate::sensors::gnss::GnssConfigError::Invalid { key, what }) =
                    cfg.validate()
                {
                    return cx.err(g.span(), &format!("gnss.{key}"), what);
                }
                Some(cfg)
            }
        };
        // aiding-sensor tables
        let aiding = parse_aiding(&cx, &doc)?;
        // [raw_gnss]: validated, satellites loaded (nav_file relative to the scenario)
        let raw_gnss = match &doc.raw_gnss {
            None => None,
            Some(t) => {
                let nav = match &t.get_ref().nav_file {
                    None => None,
                    Some(f) => {
                        let base = Path::new(file).parent().unwrap_or(Path::new(""));
                        match crate::io::rinex::read_nav(&base.join(f)) {
                            Ok(n) => Some((n.ephemerides, n.klobuchar)),
                            Err(e) => return cx.err(t.span(), "raw_gnss.nav_file", e.to_string()),
                        }
                    }
                };
                match crate::sensors::raw_gnss::RawGnssConfig::resolve(
                    t.get_ref(),
                    nav,
                    trajectory.duration_s,
                ) {
                    Ok(c) => Some(c),
                    Err(crate::sensors::raw_gnss::RawGnssConfigError::Invalid { key, what }) => {
                        return cx.err(t.span(), &format!("raw_gnss.{key}"), what);
                    }
                }
            }
        };
        Ok(Scenario {
            name: doc.name.unwrap_or_else(|| {
                Path::new(file)
                    .file_stem()
                    .map_or_else(|| "scenario".into(), |s| s.to_string_lossy().into_owned())
            }),
            description: doc.description.unwrap_or_default(),
            start,
            imu,
            nav,
            trajectory,
            gnss,
            aiding,
            raw_gnss,
            source_toml: text.to_string(),
            mounting,
            vibration: vib_reports,
            route: route_report,
        })
    }
}

/// The aiding-sensor tables, each validated with its located error.
fn parse_aiding(
    cx: &Ctx<'_>,
    doc: &FileDoc,
) -> Result<crate::sensors::aiding::AidingConfig, ScenarioError> {
    use crate::sensors::aiding::{AidingConfig, AidingConfigError};
    fn take<T: Clone>(
        cx: &Ctx<'_>,
        v: &Option<S<T>>,
        check: impl Fn(&T) -> Result<(), AidingConfigError>,
    ) -> Result<Option<T>, ScenarioError> {
        let Some(v) = v else { return Ok(None) };
        match check(v.get_ref()) {
            Ok(()) => Ok(Some(v.get_ref().clone())),
            Err(AidingConfigError::Invalid { table, key, what }) => {
                cx.err(v.span(), &format!("{table}.{key}"), what)
            }
        }
    }
    Ok(AidingConfig {
        baro: take(cx, &doc.baro, |c| c.validate())?,
        odometer: take(cx, &doc.odometer, |c| c.validate())?,
        magnetometer: take(cx, &doc.magnetometer, |c| c.validate())?,
        dual_antenna: take(cx, &doc.dual_antenna, |c| c.validate())?,
        body_velocity: take(cx, &doc.body_velocity, |c| c.validate())?,
    })
}

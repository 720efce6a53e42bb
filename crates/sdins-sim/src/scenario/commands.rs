//! Validation of `[body_motion]` and `[[command]]` (gnss-ins-sim motion commands).

use super::*;

/// The compiled `[[command]]` motion and each command's span.
pub(super) type CompiledCommands = (
    crate::truth::body_motion::BodyMotion,
    Vec<std::ops::Range<usize>>,
);

/// The six channel keys of a command, with their values.
pub(super) type ChannelKeys<'a> = [(&'a Option<S<f64>>, &'static str); 6];

/// `[[command]]` and `[body_motion]`: gnss-ins-sim motion commands on the "Euler angles +
/// body velocity" base ([`crate::truth::body_motion`]), in place of `[[segment]]`; free vehicle,
/// start attitude from `[start]`, start body velocity from `[body_motion]`. Returns the
/// compiled motion and the span of each command.
pub(super) fn parse_body_motion(
    cx: &Ctx<'_>,
    doc: &FileDoc,
    st: &StartDoc,
    euler: Euler,
    vehicle: Vehicle,
    dt: f64,
) -> Result<Option<CompiledCommands>, ScenarioError> {
    use crate::truth::body_motion::{
        BodyCommand, BodyMotion, BodyStart, CommandKind, MotionLimits,
    };
    if let Some(c) = doc.command.get(crate::truth::body_motion::MAX_COMMANDS) {
        return cx.err(
            c.span(),
            "command",
            format!(
                "more than {} [[command]] tables (the limit of one motion): split the motion",
                crate::truth::body_motion::MAX_COMMANDS
            ),
        );
    }
    if doc.command.is_empty() {
        if let Some(b) = &doc.body_motion {
            return cx.err(
                b.span(),
                "body_motion",
                "[body_motion] goes with [[command]] tables: add commands or remove it",
            );
        }
        return Ok(None);
    }
    let first = doc.command[0].span();
    if let Some(s) = doc.segment.first() {
        return cx.err(
            s.span(),
            "segment",
            "[[command]] tables replace [[segment]]: use one or the other",
        );
    }
    if let Some(c) = &doc.calibration {
        return cx.err(
            c.span(),
            "calibration",
            "[[command]] tables and [calibration] exclude each other",
        );
    }
    if vehicle != Vehicle::Free {
        return cx.err(
            first,
            "vehicle",
            "[[command]] motion sets the body velocity directly: it needs vehicle = \"free\"",
        );
    }
    if let Some(w) = doc.waypoint.first() {
        return cx.err(
            w.span(),
            "waypoint",
            "[[command]] tables and [[waypoint]] routes exclude each other: use one or the other",
        );
    }
    for (v, key) in [
        (&st.speed_mps, "start.speed_mps"),
        (&st.climb_rate_mps, "start.climb_rate_mps"),
    ] {
        if let Some(v) = v {
            return cx.err(
                v.span(),
                key,
                "with [[command]] tables the start velocity is [body_motion] vx_mps, vy_mps, vz_mps: leave this key out",
            );
        }
    }
    let bm = doc.body_motion.as_ref().map(|b| b.get_ref());
    let opt = |v: Option<&S<f64>>, key: &str, lim: f64, def: f64| -> Result<f64, ScenarioError> {
        match v {
            Some(v) => cx.range(v, key, -lim, lim, &format!("a value in [-{lim}, {lim}]")),
            None => Ok(def),
        }
    };
    let pos = |v: Option<&S<f64>>, key: &str, def: f64| -> Result<f64, ScenarioError> {
        match v {
            Some(v) => cx.positive(v, key),
            None => Ok(def),
        }
    };
    let vel_b = [
        opt(
            bm.and_then(|b| b.vx_mps.as_ref()),
            "body_motion.vx_mps",
            3000.0,
            0.0,
        )?,
        opt(
            bm.and_then(|b| b.vy_mps.as_ref()),
            "body_motion.vy_mps",
            3000.0,
            0.0,
        )?,
        opt(
            bm.and_then(|b| b.vz_mps.as_ref()),
            "body_motion.vz_mps",
            3000.0,
            0.0,
        )?,
    ];
    let d = MotionLimits::DEFAULT.to_mode();
    let limits = MotionLimits::from_mode([
        pos(
            bm.and_then(|b| b.max_accel_mps2.as_ref()),
            "body_motion.max_accel_mps2",
            d[0],
        )?,
        pos(
            bm.and_then(|b| b.max_angular_accel_dps2.as_ref()),
            "body_motion.max_angular_accel_dps2",
            d[1],
        )?,
        pos(
            bm.and_then(|b| b.max_angular_rate_dps.as_ref()),
            "body_motion.max_angular_rate_dps",
            d[2],
        )?,
    ]);
    let mut commands = Vec::with_capacity(doc.command.len());
    let mut spans = Vec::with_capacity(doc.command.len());
    for c in &doc.command {
        let cd = c.get_ref();
        let Some(kind) = CommandKind::from_number(*cd.kind.get_ref()) else {
            return cx.err(
                cd.kind.span(),
                "command.type",
                format!(
                    "{} is not a command type: expected 1, 2, 3, 4 or 5",
                    cd.kind.get_ref()
                ),
            );
        };
        let rates = kind == CommandKind::Rates;
        let (given, other): (ChannelKeys<'_>, ChannelKeys<'_>) = {
            let a = [
                (&cd.yaw_deg, "yaw_deg"),
                (&cd.pitch_deg, "pitch_deg"),
                (&cd.roll_deg, "roll_deg"),
                (&cd.vx_mps, "vx_mps"),
                (&cd.vy_mps, "vy_mps"),
                (&cd.vz_mps, "vz_mps"),
            ];
            let r = [
                (&cd.yaw_rate_dps, "yaw_rate_dps"),
                (&cd.pitch_rate_dps, "pitch_rate_dps"),
                (&cd.roll_rate_dps, "roll_rate_dps"),
                (&cd.ax_mps2, "ax_mps2"),
                (&cd.ay_mps2, "ay_mps2"),
                (&cd.az_mps2, "az_mps2"),
            ];
            if rates {
                (r, a)
            } else {
                (a, r)
            }
        };
        for (v, k) in other {
            if let Some(v) = v {
                let takes = given.map(|g| g.1).join(", ");
                return cx.err(
                    v.span(),
                    &format!("command.{k}"),
                    format!(
                        "not a key of command type {} (it takes: {takes}, duration_s)",
                        kind.number()
                    ),
                );
            }
        }
        let mut x = [0.0; 6];
        for (i, (v, k)) in given.iter().enumerate() {
            if let Some(v) = v {
                x[i] = cx.range(v, &format!("command.{k}"), -1e6, 1e6, "a value within ±1e6")?;
            }
        }
        let dur = cx.positive(&cd.duration_s, "command.duration_s")?;
        if dur > MAX_SEGMENT_S {
            return cx.err(
                cd.duration_s.span(),
                "command.duration_s",
                format!("{dur} s is too long: expected at most {MAX_SEGMENT_S:e} s"),
            );
        }
        let n = dur / dt;
        if n.round() < 1.0 || (n - n.round()).abs() > 1e-6 * n.max(1.0) {
            return cx.err(
                cd.duration_s.span(),
                "command.duration_s",
                format!("{dur} s is not a whole number of IMU samples ({dt} s) (command boundaries must fall on sample boundaries)"),
            );
        }
        commands.push(BodyCommand {
            kind,
            euler_ypr: [x[0] * D2R, x[1] * D2R, x[2] * D2R],
            vel_b: [x[3], x[4], x[5]],
            duration_s: n.round() * dt,
        });
        spans.push(c.span());
    }
    let start = BodyStart {
        euler_ypr: [euler.yaw_rad, euler.pitch_rad, euler.roll_rad],
        vel_b,
    };
    let body = BodyMotion::compile_with(start, &commands, limits, dt, cx.cancel)
        .map_err(|_| ScenarioError::Cancelled)?;
    Ok(Some((body, spans)))
}

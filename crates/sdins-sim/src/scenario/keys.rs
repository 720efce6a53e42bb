//! The keys a scenario file accepts ([`ACCEPTED_KEYS`], the list docs/scenarios.md must
//! match) and the "did you mean" suggestions for misspelt keys.

/// Every key the parser accepts, by table (the documentation test compares with
/// `docs/scenarios.md`).
pub const ACCEPTED_KEYS: &[(&str, &[&str])] = &[
    (
        "",
        &[
            "name",
            "description",
            "start",
            "imu",
            "nav",
            "segment",
            "overlay",
            "vehicle",
            "angle_of_attack_deg",
            "mounting",
            "gnss",
            "baro",
            "odometer",
            "magnetometer",
            "dual_antenna",
            "body_velocity",
            "raw_gnss",
            "calibration",
            "body_motion",
            "command",
            "waypoint",
            "route",
        ],
    ),
    (
        "waypoint",
        &["lat_deg", "lon_deg", "h_m", "speed_mps", "hold_s"],
    ),
    (
        "route",
        &[
            "legs",
            "turn_rate_limit_dps",
            "bank_limit_deg",
            "roll_rate_limit_dps",
            "climb_rate_limit_mps",
            "accel_limit_mps2",
        ],
    ),
    BODY_MOTION_KEYS,
    COMMAND_KEYS,
    ("calibration", &["schedule", "dwell_s", "rotation_s"]),
    (
        "mounting",
        &["imu_lever_arm_m", "imu_mount_deg", "gnss_lever_arm_m"],
    ),
    (
        "start",
        &[
            "lat_deg",
            "lon_deg",
            "h_m",
            "speed_mps",
            "climb_rate_mps",
            "roll_deg",
            "pitch_deg",
            "yaw_deg",
        ],
    ),
    ("imu", &["rate_hz", "seed", "grade", "errors"]),
    (
        "nav",
        &[
            "samples", "algos", "coning", "earth", "vertical", "substeps",
        ],
    ),
    (
        "segment",
        &[
            "type",
            "duration_s",
            "accel_mps2",
            "rate_dps",
            "angle_deg",
            "profile",
            "amplitude_dps",
            "to_climb_rate_mps",
            "bank_deg",
            "roll_rate_dps",
        ],
    ),
    (
        "overlay",
        &[
            "type",
            "axis",
            "half_angle_deg",
            "freq_hz",
            "angle_amp_deg",
            "accel_amp_mps2",
            "phase_deg",
            "angle_deg",
            "start_s",
            "end_s",
            "accel_psd_file",
            "gyro_psd_file",
            "accel_psd_breakpoints",
            "gyro_psd_breakpoints",
            "seed",
        ],
    ),
    GNSS_KEYS,
    RAW_GNSS_KEYS,
    (
        "baro",
        &[
            "rate_hz",
            "sigma_m",
            "bias_sigma_m",
            "bias_tau_s",
            "outages_s",
            "seed",
        ],
    ),
    (
        "odometer",
        &[
            "rate_hz",
            "sigma_mps",
            "resolution_mps",
            "scale_sigma",
            "lever_arm_b_m",
            "mount_deg",
            "nhc_sigma_mps",
            "outages_s",
            "seed",
        ],
    ),
    (
        "magnetometer",
        &[
            "rate_hz",
            "sigma_ut",
            "declination_deg",
            "inclination_deg",
            "intensity_ut",
            "hard_iron_sigma_ut",
            "outages_s",
            "seed",
        ],
    ),
    (
        "dual_antenna",
        &[
            "rate_hz",
            "baseline_b_m",
            "sigma_rel_m",
            "heading_only",
            "outages_s",
            "seed",
        ],
    ),
    (
        "body_velocity",
        &[
            "rate_hz",
            "sigma_mps",
            "lever_arm_b_m",
            "mount_deg",
            "outages_s",
            "seed",
        ],
    ),
];

// ---- [body_motion] and [[command]] (gnss-ins-sim motion commands) ----
/// Keys of `[body_motion]` (start body velocity and the motion limits).
pub(super) const BODY_MOTION_KEYS: (&str, &[&str]) = (
    "body_motion",
    &[
        "vx_mps",
        "vy_mps",
        "vz_mps",
        "max_accel_mps2",
        "max_angular_accel_dps2",
        "max_angular_rate_dps",
    ],
);

/// Keys of `[[command]]` ([`crate::truth::body_motion::BodyCommand`]).
pub(super) const COMMAND_KEYS: (&str, &[&str]) = (
    "command",
    &[
        "type",
        "yaw_deg",
        "pitch_deg",
        "roll_deg",
        "vx_mps",
        "vy_mps",
        "vz_mps",
        "yaw_rate_dps",
        "pitch_rate_dps",
        "roll_rate_dps",
        "ax_mps2",
        "ay_mps2",
        "az_mps2",
        "duration_s",
    ],
);

// ---- [gnss] section (INS/GNSS fusion) ----
/// Keys of the `[gnss]` table (`crate::sensors::gnss::GnssConfig`).
pub(super) const GNSS_KEYS: (&str, &[&str]) = (
    "gnss",
    &[
        "rate_hz",
        "offset_s",
        "sigma_pos_ned_m",
        "sigma_vel_ned_mps",
        "gm_sigma_ned_m",
        "gm_tau_s",
        "lever_arm_b_m",
        "outages_s",
        "dropout_prob",
        "outliers_t_s_ned_m",
        "latency_s",
        "latency_modelled",
        "seed",
    ],
);

// ---- [raw_gnss] (raw GNSS measurement simulation) ----
/// Keys of the `[raw_gnss]` table (`crate::sensors::raw_gnss::RawGnssTable`).
pub(super) const RAW_GNSS_KEYS: (&str, &[&str]) = (
    "raw_gnss",
    &[
        "rate_hz",
        "start_gpst",
        "nav_file",
        "klobuchar_alpha",
        "klobuchar_beta",
        "mask_deg",
        "sky_mask_az_el_deg",
        "prns",
        "sigma_pr_m",
        "sigma_rr_mps",
        "h0_s",
        "h_m2_per_s",
        "iono_scale",
        "iono_resid_frac",
        "iono_resid_tau_s",
        "tropo_resid_zenith_m",
        "tropo_resid_tau_s",
        "sis_ura_scale",
        "lever_arm_b_m",
        "clock_jump_t_s_ms",
        "outliers_t_s_prn_m",
        "outages_s",
        "seed",
    ],
);

pub(super) fn levenshtein(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur.push(sub.min(prev[j + 1] + 1).min(cur[j] + 1));
        }
        prev = cur;
    }
    prev[b.len()]
}

pub(super) fn is_subsequence(short: &str, long: &str) -> bool {
    let mut it = long.chars();
    short.chars().all(|c| it.any(|x| x == c))
}

/// Closest of `candidates` to an unknown key (for "did you mean" hints): the smallest
/// edit distance within half the key's length, or a key whose letters appear in order in
/// the unknown one (`heigth_m` → `h_m`).
pub fn suggest_from<'a>(unknown: &str, candidates: &[&'a str]) -> Option<&'a str> {
    let best = candidates
        .iter()
        .copied()
        .map(|k| (levenshtein(unknown, k), k))
        .min_by_key(|(d, _)| *d);
    if let Some((d, k)) = best {
        if d <= 3.max(unknown.len() / 2) {
            return Some(k);
        }
    }
    candidates
        .iter()
        .copied()
        .filter(|k| k.len() >= 3 && is_subsequence(k, unknown))
        .max_by_key(|k| k.len())
}

/// Closest accepted key (of any table) to an unknown one.
pub fn suggest(unknown: &str) -> Option<&'static str> {
    let all: Vec<&'static str> = ACCEPTED_KEYS
        .iter()
        .flat_map(|(_, keys)| keys.iter().copied())
        .collect();
    suggest_from(unknown, &all)
}

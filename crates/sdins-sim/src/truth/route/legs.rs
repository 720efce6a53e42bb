//! The building blocks of route compilation: geodesic and rhumb legs cut into pieces,
//! the shooting of a leg onto its end waypoint, and fly-by turn motions.

use super::*;

/// Position and heading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct P {
    pub(super) lat: f64,
    pub(super) lon: f64,
    pub(super) h: f64,
    pub(super) psi: f64,
}

impl P {
    pub(super) fn add(&self, k: &[f64; 4], s: f64) -> P {
        P {
            lat: self.lat + s * k[0],
            lon: self.lon + s * k[1],
            h: self.h + s * k[2],
            psi: self.psi + s * k[3],
        }
    }
}

pub(super) fn wrap(a: f64) -> f64 {
    let mut a = a % (2.0 * PI);
    if a > PI {
        a -= 2.0 * PI;
    }
    if a < -PI {
        a += 2.0 * PI;
    }
    a
}

impl Ctx<'_> {
    /// `[L̇, λ̇, ḣ, ψ̇]` for speed `s`, down velocity `v_d` (Groves eq. 2.111) and the
    /// geodesic heading rate `ψ̇ = v_E tan L/(R_N + h)` (zero on rhumb legs).
    pub(super) fn rates(&self, p: &P, s: f64, v_d: f64) -> [f64; 4] {
        let r = self.earth.radii(p.lat);
        let (sp, cp) = p.psi.sin_cos();
        let (v_n, v_e) = (s * cp, s * sp);
        let rn = r.r_n_m + p.h;
        let psi_dot = match self.legs {
            LegKind::GreatCircle => v_e * p.lat.tan() / rn,
            LegKind::Rhumb => 0.0,
        };
        [
            v_n / (r.r_m_m + p.h),
            v_e / (rn * p.lat.cos()),
            -v_d,
            psi_dot,
        ]
    }

    pub(super) fn ecef(&self, p: &P) -> Vec3 {
        self.earth.ecef_from_geodetic(p.lat, p.lon, p.h)
    }

    /// NED offset of `q` from `p` at `p` \[m\].
    pub(super) fn ned(&self, p: &P, q: &P) -> Vec3 {
        EarthModel::c_e_n(p.lat, p.lon) * (self.ecef(q) - self.ecef(p))
    }

    /// RK4 from `p` over `[t0, t1]` of segment `seg`; the heading from the ODE
    /// (`ode = true`) or from the segment (turns). Calls `visit(t, p)` after each step.
    pub(super) fn fly(
        &self,
        seg: &Segment,
        p0: P,
        (t0, t1): (f64, f64),
        max_step: f64,
        ode: bool,
        mut visit: impl FnMut(f64, &P),
    ) -> P {
        let n = (((t1 - t0) / max_step).ceil() as usize).max(1);
        let h = (t1 - t0) / n as f64;
        let f = |t: f64, p: &P| -> [f64; 4] {
            let nm = seg.eval(t);
            let mut q = *p;
            if !ode {
                q.psi = nm.heading;
            }
            let mut k = self.rates(&q, nm.speed, nm.v_d);
            if !ode {
                k[3] = 0.0;
            }
            k
        };
        let mut p = p0;
        for i in 0..n {
            let t = t0 + i as f64 * h;
            let k1 = f(t, &p);
            let k2 = f(t + 0.5 * h, &p.add(&k1, 0.5 * h));
            let k3 = f(t + 0.5 * h, &p.add(&k2, 0.5 * h));
            let k4 = f(t + h, &p.add(&k3, h));
            let mut k = [0.0; 4];
            for j in 0..4 {
                k[j] = (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]) / 6.0;
            }
            p = p.add(&k, h);
            if !ode {
                p.psi = seg.eval(t + h).heading;
            }
            visit(t + h, &p);
        }
        p
    }

    /// Along an ideal leg by arc length `len` (unit speed, level): the geodesic or rhumb
    /// line from `p` with heading `p.psi`. Returns the end and the largest |L| reached.
    pub(super) fn arc(&self, p: P, len: f64) -> (P, f64) {
        let seg = Segment::with_start(Motion::Cruise, 0.0, len, (1.0, p.psi, 0.0));
        let mut max_lat = p.lat.abs();
        let q = self.fly(&seg, p, (0.0, len), 500.0, true, |_, q| {
            max_lat = max_lat.max(q.lat.abs());
        });
        (q, max_lat)
    }

    /// The ideal leg from `a` to `b` at height `h`: start heading, end heading, length,
    /// largest |L| (Newton on start heading and length).
    pub(super) fn ideal_leg(
        &self,
        a: &Waypoint,
        b: &Waypoint,
        wp: usize,
    ) -> Result<(f64, f64, f64, f64), RouteError> {
        let h = 0.5 * (a.h_m + b.h_m);
        let pa = P {
            lat: a.lat_rad,
            lon: a.lon_rad,
            h,
            psi: 0.0,
        };
        let pb = P {
            lat: b.lat_rad,
            lon: b.lon_rad,
            h,
            psi: 0.0,
        };
        // the start azimuth and length in closed form (Karney's inverse problem, or the
        // rhumb line's formula): the start of the Newton iteration, and the checks
        let way = match self.legs {
            LegKind::GreatCircle => geodesic_way(&self.earth, a, b),
            LegKind::Rhumb => rhumb_way(&self.earth, a, b),
        };
        if way.len_m < 1.0 {
            return Err(RouteError::Coincident {
                waypoint: wp,
                distance_m: way.len_m,
            });
        }
        if way.margin_m < AMBIGUOUS_M {
            let [lat_deg, lon_deg] = intermediate(&self.earth, a, way.len_m);
            return Err(RouteError::Ambiguous {
                from: wp - 1,
                waypoint: wp,
                kind: self.legs,
                length_m: way.len_m,
                margin_m: way.margin_m,
                suggest_deg: [lat_deg, lon_deg],
            });
        }
        let mut psi = way.azi1;
        let mut len = way.len_m * (1.0 + h / self.earth.a_m);
        let miss = |psi: f64, len: f64| -> Vec3 {
            let (q, _) = self.arc(P { psi, ..pa }, len);
            self.ned(&pb, &q)
        };
        for _ in 0..30 {
            self.cancel.check()?;
            let m = miss(psi, len);
            if m.x.hypot(m.y) < 1e-7 {
                let (q, max_lat) = self.arc(P { psi, ..pa }, len);
                // the horizontal NED components vanish at the antipode too: the end must
                // be the waypoint itself
                let d = (self.ecef(&q) - self.ecef(&pb)).norm();
                if d > 1e-3 {
                    return Err(RouteError::Solve {
                        waypoint: wp,
                        why: format!("the ideal leg ends {d:.3} m from the waypoint"),
                    });
                }
                return Ok((psi, q.psi, len, max_lat));
            }
            let (dp, dl) = (1e-7, 1e-3);
            let mp = (miss(psi + dp, len) - m) / dp;
            let ml = (miss(psi, len + dl) - m) / dl;
            let det = mp.x * ml.y - mp.y * ml.x;
            if det.abs() < 1e-30 || !det.is_finite() {
                break;
            }
            let step_p = (m.x * ml.y - m.y * ml.x) / det;
            let step_l = (mp.x * m.y - mp.y * m.x) / det;
            psi -= step_p.clamp(-0.5, 0.5);
            len = (len - step_l).max(0.5 * len);
            let (_, max_lat) = self.arc(P { psi, ..pa }, len);
            if max_lat > MAX_LAT_RAD {
                return Err(RouteError::Pole {
                    waypoint: wp,
                    lat_deg: max_lat.to_degrees(),
                });
            }
        }
        Err(RouteError::Solve {
            waypoint: wp,
            why: "the ideal leg did not converge".into(),
        })
    }

    pub(super) fn round_dt(&self, t: f64) -> f64 {
        (t / self.dt - 1e-9).ceil().max(1.0) * self.dt
    }
}

/// A leg piece: speed change, down-velocity change, duration.
#[derive(Clone, Copy, Debug)]
pub(super) struct Piece {
    pub(super) d_speed: f64,
    pub(super) d_vd: f64,
    pub(super) dur: f64,
}

/// The leg pieces before the cruise (speed change, climb) and after it (stop), and their
/// along-track length.
pub(super) fn leg_pieces(
    ctx: &Ctx<'_>,
    lim: &RouteLimits,
    v0: f64,
    v1: f64,
    dh: f64,
    stop: bool,
) -> (Vec<Piece>, Vec<Piece>, f64) {
    let a = lim.accel_mps2;
    let mut pre = Vec::new();
    let mut len = 0.0;
    if v1 != v0 {
        // smooth step: peak acceleration 2Δ/T
        let dur = ctx.round_dt(2.0 * (v1 - v0).abs() / a);
        pre.push(Piece {
            d_speed: v1 - v0,
            d_vd: 0.0,
            dur,
        });
        len += 0.5 * (v0 + v1) * dur;
    }
    if dh != 0.0 {
        let c_lim = lim.climb_rate_mps;
        // ramp in and out (each of length T_r = 2c/a, height c·T_r/2), hold at c
        let mut c = c_lim;
        let mut t_r = ctx.round_dt(2.0 * c / a);
        let mut t_h = (dh.abs() / c - t_r).max(0.0);
        if dh.abs() < c * t_r {
            c = (dh.abs() * a / 2.0).sqrt();
            t_r = ctx.round_dt(2.0 * c / a);
            t_h = 0.0;
        }
        let t_h = if t_h > 0.0 { ctx.round_dt(t_h) } else { 0.0 };
        // the exact rate so the height change is dh: c (T_r + T_h) = |dh|
        let c = dh.abs() / (t_r + t_h);
        let vd = -c * dh.signum();
        pre.push(Piece {
            d_speed: 0.0,
            d_vd: vd,
            dur: t_r,
        });
        if t_h > 0.0 {
            pre.push(Piece {
                d_speed: 0.0,
                d_vd: 0.0,
                dur: t_h,
            });
        }
        pre.push(Piece {
            d_speed: 0.0,
            d_vd: -vd,
            dur: t_r,
        });
        len += v1 * (2.0 * t_r + t_h);
    }
    let mut post = Vec::new();
    if stop {
        let dur = ctx.round_dt(2.0 * v1 / a);
        post.push(Piece {
            d_speed: -v1,
            d_vd: 0.0,
            dur,
        });
        len += 0.5 * v1 * dur;
    }
    (pre, post, len)
}

/// A flown leg: pieces with durations (the cruise inserted), start heading.
pub(super) struct Leg {
    pub(super) pieces: Vec<Piece>,
    pub(super) speed0: f64,
}

impl Leg {
    pub(super) fn segs(&self, psi0: f64, t0: f64) -> Vec<(Segment, f64)> {
        let mut out = Vec::new();
        let (mut t, mut s, mut vd) = (t0, self.speed0, 0.0);
        for pc in &self.pieces {
            let m = Motion::Geodesic {
                heading_cheb: [0.0; GEO_CHEB_N],
                delta_speed_mps: pc.d_speed,
                delta_v_d_mps: pc.d_vd,
            };
            out.push((Segment::with_start(m, t, pc.dur, (s, psi0, vd)), t));
            t += pc.dur;
            s += pc.d_speed;
            vd += pc.d_vd;
            if vd.abs() < 1e-12 {
                vd = 0.0;
            }
        }
        out
    }
}

pub(super) fn piece_step(dur: f64) -> f64 {
    (dur / 100.0).clamp(1e-3, 1.0)
}

impl Ctx<'_> {
    /// Fly a leg from `p` with start heading `p.psi`: the end state.
    pub(super) fn fly_leg(&self, leg: &Leg, p: P) -> P {
        let mut q = p;
        for (seg, t) in leg.segs(p.psi, 0.0) {
            q = self.fly(
                &seg,
                q,
                (t, t + seg.duration_s),
                piece_step(seg.duration_s),
                true,
                |_, _| {},
            );
        }
        q
    }

    /// Shoot a leg from `p` to `target`: start heading and cruise time (continuous),
    /// then the cruise rounded to samples and the heading re-solved for zero cross-track
    /// miss. Returns the start heading and the leg.
    pub(super) fn shoot(
        &self,
        (pre, post): (&[Piece], &[Piece]),
        (speed0, cruise_speed): (f64, f64),
        p: P,
        target: &P,
        t_cruise0: f64,
        wp: usize,
    ) -> Result<(f64, Leg), RouteError> {
        let build = |t_c: f64| -> Leg {
            let mut pieces = pre.to_vec();
            let mut left = t_c;
            while left > 0.0 {
                let d = left.min(MAX_PIECE_S);
                pieces.push(Piece {
                    d_speed: 0.0,
                    d_vd: 0.0,
                    dur: d,
                });
                left -= d;
                if left < 1e-9 {
                    break;
                }
            }
            pieces.extend_from_slice(post);
            Leg { pieces, speed0 }
        };
        let miss = |psi: f64, t_c: f64| -> Vec3 {
            let q = self.fly_leg(&build(t_c), P { psi, ..p });
            self.ned(target, &q)
        };
        let d0 = self.ned(&p, target);
        let mut psi = p.psi;
        let mut t_c = t_cruise0.max(0.0);
        let fail = |why: &str| RouteError::Solve {
            waypoint: wp,
            why: why.into(),
        };
        let mut ok = false;
        for _ in 0..30 {
            self.cancel.check()?;
            let m = miss(psi, t_c);
            if m.x.hypot(m.y) < 1e-6 {
                ok = true;
                break;
            }
            let (dp, dtc) = (1e-7, 1e-3);
            let mp = (miss(psi + dp, t_c) - m) / dp;
            let mt = (miss(psi, t_c + dtc) - m) / dtc;
            let det = mp.x * mt.y - mp.y * mt.x;
            if det.abs() < 1e-30 || !det.is_finite() {
                return Err(fail("singular shooting Jacobian"));
            }
            psi -= ((m.x * mt.y - m.y * mt.x) / det).clamp(-0.3, 0.3);
            t_c -= (mp.x * m.y - mp.y * m.x) / det;
            if t_c < 0.0 {
                let need = d0.x.hypot(d0.y) - t_c * cruise_speed;
                return Err(RouteError::TooShort {
                    waypoint: wp,
                    what: "speed change, climb and turn leads".into(),
                    need_m: need,
                    have_m: d0.x.hypot(d0.y),
                });
            }
        }
        if !ok {
            return Err(fail("the shooting did not converge"));
        }
        let end = self.fly_leg(&build(t_c), P { psi, ..p });
        let d = (self.ecef(&end) - self.ecef(target)).norm();
        if d > 1.0 {
            return Err(fail(&format!("the shot leg ends {d:.3} m from its target")));
        }
        // whole samples, then zero cross-track miss (normal to the arrival heading)
        let t_r = if t_c < 0.5 * self.dt {
            0.0
        } else {
            (t_c / self.dt).round() * self.dt
        };
        let cross = |psi: f64| -> f64 {
            let q = self.fly_leg(&build(t_r), P { psi, ..p });
            let m = self.ned(target, &q);
            let (s, c) = q.psi.sin_cos();
            -m.x * s + m.y * c
        };
        for _ in 0..20 {
            self.cancel.check()?;
            let c0 = cross(psi);
            if c0.abs() < 1e-7 {
                break;
            }
            let d = (cross(psi + 1e-7) - c0) / 1e-7;
            if !(d.is_finite() && d != 0.0) {
                return Err(fail("singular cross-track derivative"));
            }
            psi -= c0 / d;
        }
        Ok((psi, build(t_r)))
    }

    /// Chebyshev interpolant of the leg's heading on each piece: the motions.
    pub(super) fn leg_motions(&self, leg: &Leg, p: P) -> (Vec<(Motion, f64)>, P) {
        let mut out = Vec::new();
        let mut q = p;
        for (seg, t0) in leg.segs(p.psi, 0.0) {
            let dur = seg.duration_s;
            let mut cheb = [0.0; GEO_CHEB_N];
            let pc = match seg.motion {
                Motion::Geodesic {
                    delta_speed_mps,
                    delta_v_d_mps,
                    ..
                } => (delta_speed_mps, delta_v_d_mps),
                _ => (0.0, 0.0),
            };
            if self.legs == LegKind::GreatCircle {
                let n = GEO_CHEB_N;
                // nodes of the first kind, ascending in x
                let mut nodes: Vec<(usize, f64)> = (0..n)
                    .map(|j| (j, 0.5 * (1.0 + (PI * (j as f64 + 0.5) / n as f64).cos())))
                    .collect();
                nodes.sort_by(|a, b| a.1.total_cmp(&b.1));
                let mut f = vec![0.0; n];
                let (mut tc, mut pp) = (t0, q);
                for &(j, x) in &nodes {
                    let tn = t0 + x * dur;
                    pp = self.fly(&seg, pp, (tc, tn), piece_step(dur), true, |_, _| {});
                    tc = tn;
                    f[j] = pp.psi - q.psi;
                }
                for (k, ck) in cheb.iter_mut().enumerate() {
                    let s: f64 = (0..n)
                        .map(|j| f[j] * (PI * k as f64 * (j as f64 + 0.5) / n as f64).cos())
                        .sum();
                    *ck = 2.0 * s / n as f64 * if k == 0 { 0.5 } else { 1.0 };
                }
            }
            q = self.fly(&seg, q, (t0, t0 + dur), piece_step(dur), true, |_, _| {});
            out.push((
                Motion::Geodesic {
                    heading_cheb: cheb,
                    delta_speed_mps: pc.0,
                    delta_v_d_mps: pc.1,
                },
                dur,
            ));
        }
        (out, q)
    }

    /// The geodesic heading rate at `p` for speed `s`.
    pub(super) fn geo_rate(&self, p: &P, s: f64) -> f64 {
        self.rates(p, s, 0.0)[3]
    }
}

/// The turn at a waypoint: its motions at speed `v` for heading change `dpsi` with the
/// rate ramps from `a` to the limit rate and back to `b`, durations from
/// [`crate::truth::vehicle::coordinated_turn`] (kept fixed, `timing`), the hold rate solved
/// for `dpsi`.
pub(super) fn turn_motions(timing: (f64, f64), dpsi: f64, a: f64, b: f64) -> Vec<(Motion, f64)> {
    let (t_r, t_h) = timing;
    let r = (dpsi - 0.5 * t_r * (a + b)) / (t_r + t_h);
    let mut m = vec![(
        Motion::TurnRamp {
            from_rps: a,
            to_rps: r,
        },
        t_r,
    )];
    if t_h > 0.0 {
        m.push((Motion::TurnRate { rate_rps: r }, t_h));
    }
    m.push((
        Motion::TurnRamp {
            from_rps: r,
            to_rps: b,
        },
        t_r,
    ));
    m
}

/// Flat-plane displacement of a turn `(along the entry heading, to its right)` \[m\].
pub(super) fn turn_displacement(motions: &[(Motion, f64)], v: f64) -> (f64, f64) {
    let (mut x, mut y, mut t, mut psi) = (0.0, 0.0, 0.0, 0.0);
    for &(m, d) in motions {
        let seg = Segment::with_start(m, t, d, (v, psi, 0.0));
        let n = ((d / 0.01).ceil() as usize).max(2) * 2;
        let h = d / n as f64;
        for i in 0..=n {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let ps = seg.eval(t + i as f64 * h).heading;
            x += w * h / 3.0 * v * ps.cos();
            y += w * h / 3.0 * v * ps.sin();
        }
        psi = seg.end().1;
        t += d;
    }
    (x, y)
}

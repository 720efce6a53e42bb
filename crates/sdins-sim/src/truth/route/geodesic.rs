//! The inverse problem between two waypoints, solved in closed form before any leg is
//! flown: the geodesic's start azimuth and length by Karney's algorithm (C. F. F. Karney,
//! "Algorithms for geodesics", J. Geod. 87:43–55, 2013, through `geographiclib-rs`), the
//! rhumb line's by the isometric latitude; and the check that the leg is not ambiguous
//! (docs/theory/routes.md §"Nearly antipodal waypoints").

use super::*;
use geographiclib_rs::{DirectGeodesic, Geodesic, InverseGeodesic};

/// Two ways from one waypoint to the next whose lengths differ by less than this are
/// ambiguous \[m\].
pub const AMBIGUOUS_M: f64 = 1e-3;

/// The shortest way on the ellipsoid (height 0) from `a` to `b`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Way {
    /// start azimuth \[rad\]
    pub(super) azi1: f64,
    /// length \[m\]
    pub(super) len_m: f64,
    /// the other way (the geodesic on the other side of the antipode, or the rhumb line
    /// the other way round) is longer by this much \[m\]; infinite when there is none
    pub(super) margin_m: f64,
}

fn geodesic_of(earth: &EarthModel) -> Geodesic {
    Geodesic::new(earth.a_m, earth.f)
}

/// The geodesic from `a` to `b` (Karney's inverse problem) and its margin over the
/// geodesic on the other side of `a`'s cut locus.
///
/// On an oblate ellipsoid the cut locus of `a` is a segment of the parallel at `−L_a`
/// centred on the antipodal meridian. Project `b` onto that parallel, `b* = (−L_a, λ_b)`:
/// if the inverse problem at `b*` has two solutions (GeographicLib's rule for
/// `lat1 = −lat2`: the start and end azimuths `α₁ ≠ α₂`, the second geodesic having them
/// swapped), `b*` is on the cut locus and the two geodesics reach `b`, a distance `δ`
/// north of `b*`, with lengths `s* + δ cos α₂` and `s* + δ cos α₁` to first order: the margin
/// is `|δ (cos α₂ − cos α₁)|`. Otherwise `b*` is off the cut locus and no second geodesic
/// of nearly equal length exists near `b`.
pub(super) fn geodesic_way(earth: &EarthModel, a: &Waypoint, b: &Waypoint) -> Way {
    let g = geodesic_of(earth);
    let (la, oa) = (a.lat_rad.to_degrees(), a.lon_rad.to_degrees());
    let (lb, ob) = (b.lat_rad.to_degrees(), b.lon_rad.to_degrees());
    let (s12, azi1, _azi2, _a12): (f64, f64, f64, f64) = g.inverse(la, oa, lb, ob);
    let (_, c1, c2, _): (f64, f64, f64, f64) = g.inverse(la, oa, -la, ob);
    let margin_m = if (c1 - c2).abs() > 1e-9 {
        let delta = (b.lat_rad + a.lat_rad) * earth.radii(-a.lat_rad).r_m_m;
        (delta * (c2.to_radians().cos() - c1.to_radians().cos())).abs()
    } else {
        f64::INFINITY
    };
    Way {
        azi1: azi1.to_radians(),
        len_m: s12,
        margin_m,
    }
}

/// A waypoint that resolves an ambiguous leg: halfway along the geodesic that leaves `a`
/// due east (its latitude stays within `|L_a|`, so it keeps clear of the poles)
/// `[lat, lon]` \[deg\].
pub(super) fn intermediate(earth: &EarthModel, a: &Waypoint, len_m: f64) -> [f64; 2] {
    let g = geodesic_of(earth);
    let (lat, lon): (f64, f64) = g.direct(
        a.lat_rad.to_degrees(),
        a.lon_rad.to_degrees(),
        90.0,
        0.5 * len_m,
    );
    [lat, lon]
}

/// Isometric latitude `q = atanh(sin L) − e atanh(e sin L)`.
fn isometric(earth: &EarthModel, lat: f64) -> f64 {
    let e = earth.e2.sqrt();
    let s = lat.sin();
    s.atanh() - e * (e * s).atanh()
}

/// Meridian arc from `l1` to `l2` (Simpson, 64 panels: relative error ~1e-12).
fn meridian_arc(earth: &EarthModel, l1: f64, l2: f64) -> f64 {
    let n = 64;
    let h = (l2 - l1) / n as f64;
    let mut s = 0.0;
    for i in 0..=n {
        let w = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        s += w * earth.radii(l1 + i as f64 * h).r_m_m;
    }
    s * h / 3.0
}

/// The rhumb line from `a` to `b` the short way in longitude (`ψ = atan2(Δλ, Δq)`, length
/// `Δμ/cos ψ`, or `|Δλ| R_N cos L` along a parallel) and its margin over the rhumb line the
/// other way round (equal lengths when `|Δλ| = 180°`).
pub(super) fn rhumb_way(earth: &EarthModel, a: &Waypoint, b: &Waypoint) -> Way {
    let dq = isometric(earth, b.lat_rad) - isometric(earth, a.lat_rad);
    let dmu = meridian_arc(earth, a.lat_rad, b.lat_rad).abs();
    let dl = wrap(b.lon_rad - a.lon_rad);
    let len = |dl: f64| -> f64 {
        if dq.abs() < 1e-15 {
            dl.abs() * earth.radii(a.lat_rad).r_n_m * a.lat_rad.cos()
        } else {
            dmu * (1.0 + (dl / dq).powi(2)).sqrt()
        }
    };
    let other = dl - 2.0 * PI * if dl >= 0.0 { 1.0 } else { -1.0 };
    let len_m = len(dl);
    Way {
        azi1: dl.atan2(dq),
        len_m,
        margin_m: len(other) - len_m,
    }
}

//! Clipping to a panel's rectangle: polylines are cut where they leave it (Liang–Barsky)
//! and polygons are cut along its edges (Sutherland–Hodgman), so that nothing is drawn
//! outside a panel whatever the backend, and data beyond the axis range leave the frame
//! instead of being flattened along its edge. Coordinates are linear in the panel (the
//! caller takes logarithms of log axes first).

/// A point.
pub type P = (f64, f64);

/// An axis-aligned rectangle `[x0, x1] × [y0, y1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    /// left
    pub x0: f64,
    /// right
    pub x1: f64,
    /// bottom
    pub y0: f64,
    /// top
    pub y1: f64,
}

impl Rect {
    /// Whether `p` lies in the rectangle (edges included).
    pub fn contains(&self, p: P) -> bool {
        p.0 >= self.x0 && p.0 <= self.x1 && p.1 >= self.y0 && p.1 <= self.y1
    }
}

/// The part of segment `a`–`b` inside `r` (Liang–Barsky); an end inside `r` is returned
/// unchanged (bit for bit).
pub fn segment(a: P, b: P, r: Rect) -> Option<(P, P)> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
    for (p, q) in [
        (-dx, a.0 - r.x0),
        (dx, r.x1 - a.0),
        (-dy, a.1 - r.y0),
        (dy, r.y1 - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    if t0.is_nan() || t1.is_nan() || t0 > t1 {
        return None;
    }
    let at = |t: f64| {
        if t == 0.0 {
            a
        } else if t == 1.0 {
            b
        } else {
            // on the edge exactly: no rounding outside the rectangle
            (
                (a.0 + t * dx).clamp(r.x0, r.x1),
                (a.1 + t * dy).clamp(r.y0, r.y1),
            )
        }
    };
    Some((at(t0), at(t1)))
}

/// The visible pieces of a polyline: where it leaves `r` it is cut, where it comes back
/// a new piece starts. Pieces have at least two points.
pub fn polyline(pts: &[P], r: Rect) -> Vec<Vec<P>> {
    let mut out: Vec<Vec<P>> = Vec::new();
    let mut cur: Vec<P> = Vec::new();
    if pts.len() == 1 && r.contains(pts[0]) {
        return vec![vec![pts[0], pts[0]]];
    }
    for w in pts.windows(2) {
        match segment(w[0], w[1], r) {
            Some((a, b)) => {
                if cur.last() != Some(&a) {
                    if cur.len() >= 2 {
                        out.push(std::mem::take(&mut cur));
                    }
                    cur.clear();
                    cur.push(a);
                }
                cur.push(b);
            }
            None => {
                if cur.len() >= 2 {
                    out.push(std::mem::take(&mut cur));
                }
                cur.clear();
            }
        }
    }
    if cur.len() >= 2 {
        out.push(cur);
    }
    out
}

/// A polygon cut to `r` (Sutherland–Hodgman); empty when nothing is inside.
pub fn polygon(pts: &[P], r: Rect) -> Vec<P> {
    type Edge = (fn(P, Rect) -> bool, fn(P, P, Rect) -> P);
    let edges: [Edge; 4] = [
        (
            |p, r| p.0 >= r.x0,
            |a, b, r| (r.x0, a.1 + (b.1 - a.1) * (r.x0 - a.0) / (b.0 - a.0)),
        ),
        (
            |p, r| p.0 <= r.x1,
            |a, b, r| (r.x1, a.1 + (b.1 - a.1) * (r.x1 - a.0) / (b.0 - a.0)),
        ),
        (
            |p, r| p.1 >= r.y0,
            |a, b, r| (a.0 + (b.0 - a.0) * (r.y0 - a.1) / (b.1 - a.1), r.y0),
        ),
        (
            |p, r| p.1 <= r.y1,
            |a, b, r| (a.0 + (b.0 - a.0) * (r.y1 - a.1) / (b.1 - a.1), r.y1),
        ),
    ];
    let mut poly: Vec<P> = pts.to_vec();
    for (inside, cross) in edges {
        if poly.is_empty() {
            break;
        }
        let mut next = Vec::with_capacity(poly.len() + 4);
        for i in 0..poly.len() {
            let cur = poly[i];
            let prev = poly[(i + poly.len() - 1) % poly.len()];
            match (inside(prev, r), inside(cur, r)) {
                (true, true) => next.push(cur),
                (true, false) => next.push(cross(prev, cur, r)),
                (false, true) => {
                    next.push(cross(prev, cur, r));
                    next.push(cur);
                }
                (false, false) => {}
            }
        }
        poly = next;
    }
    // clamp rounding of the intersections onto the rectangle
    poly.iter()
        .map(|p| (p.0.clamp(r.x0, r.x1), p.1.clamp(r.y0, r.y1)))
        .collect()
}

/// A filled disc of radius `r` px around pixel `c`, cut to the pixel rectangle `rect`
/// (x range, y range, ends exclusive), as a polygon in pixels relative to `base`.
pub fn disc(
    c: (i32, i32),
    r: i32,
    rect: &(std::ops::Range<i32>, std::ops::Range<i32>),
    base: (i32, i32),
) -> Vec<(i32, i32)> {
    let frame = Rect {
        x0: f64::from(rect.0.start),
        x1: f64::from(rect.0.end - 1),
        y0: f64::from(rect.1.start),
        y1: f64::from(rect.1.end - 1),
    };
    let ring: Vec<P> = (0..16)
        .map(|k| {
            let a = f64::from(k) * std::f64::consts::PI / 8.0;
            let rad = f64::from(r) + 0.5;
            (
                f64::from(c.0) + rad * a.cos(),
                f64::from(c.1) + rad * a.sin(),
            )
        })
        .collect();
    polygon(&ring, frame)
        .into_iter()
        .map(|(x, y)| (x.round() as i32 - base.0, y.round() as i32 - base.1))
        .collect()
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    const R: Rect = Rect {
        x0: 0.0,
        x1: 10.0,
        y0: -1.0,
        y1: 1.0,
    };

    #[test]
    fn polylines_are_cut_not_flattened() {
        // inside: unchanged, one piece
        let p = vec![(0.0, 0.0), (5.0, 0.5), (10.0, -0.5)];
        assert_eq!(polyline(&p, R), vec![p.clone()]);
        // leaves through the top and comes back: two pieces ending on the edge
        let p = vec![(0.0, 0.0), (2.0, 3.0), (4.0, 0.0), (6.0, 0.0)];
        let pieces = polyline(&p, R);
        assert_eq!(pieces.len(), 2);
        let close = |a: &[P], b: &[P]| {
            a.len() == b.len()
                && a.iter()
                    .zip(b)
                    .all(|(p, q)| (p.0 - q.0).abs() < 1e-12 && (p.1 - q.1).abs() < 1e-12)
        };
        assert!(close(&pieces[0], &[(0.0, 0.0), (2.0 / 3.0, 1.0)]));
        assert!(close(
            &pieces[1],
            &[(4.0 - 2.0 / 3.0, 1.0), (4.0, 0.0), (6.0, 0.0)]
        ));
        // entirely outside: nothing; crossing the whole panel: one segment
        assert!(polyline(&[(0.0, 5.0), (10.0, 6.0)], R).is_empty());
        let s = polyline(&[(-10.0, -10.0), (20.0, 20.0)], R);
        assert_eq!(s.len(), 1);
        assert!(s[0].iter().all(|p| R.contains(*p)));
        // degenerate segments and single points
        assert_eq!(polyline(&[(1.0, 0.0), (1.0, 0.0)], R).len(), 1);
        assert_eq!(polyline(&[(1.0, 0.0)], R).len(), 1);
        assert!(polyline(&[(1.0, 9.0)], R).is_empty());
    }

    #[test]
    fn polygons_are_cut_along_the_edges() {
        // a band from -5 to 5 over x in [-2, 12]
        let band = vec![(-2.0, -5.0), (12.0, -5.0), (12.0, 5.0), (-2.0, 5.0)];
        let c = polygon(&band, R);
        assert!(c.iter().all(|p| R.contains(*p)));
        let area = |q: &[P]| {
            (0..q.len())
                .map(|i| {
                    let (a, b) = (q[i], q[(i + 1) % q.len()]);
                    a.0 * b.1 - b.0 * a.1
                })
                .sum::<f64>()
                .abs()
                / 2.0
        };
        assert!((area(&c) - 20.0).abs() < 1e-9);
        assert!(polygon(&[(20.0, 0.0), (30.0, 0.0), (25.0, 1.0)], R).is_empty());
        let inside = vec![(1.0, 0.0), (2.0, 0.5), (3.0, 0.0)];
        assert_eq!(polygon(&inside, R), inside);
    }
}

//! Axis ticks: where the labelled grid lines go and how their labels are written.
//!
//! One notation per axis, chosen from the range ([`Ticks::label`]):
//! * linear axes whose largest label lies in [0.01, 10⁵): plain decimals, all with the
//!   same number of decimals (`-0.02`, `-0.01`, `0.00`, `0.01`); other linear axes:
//!   plain mantissas with a shared power of ten that the axis description states
//!   (`-3.0` … `1.0` and "(×1e-7)"), never a mix of `0.02` and `-1e-2`;
//! * logarithmic axes: every decade labelled, top one included (every m-th decade counted
//!   down from the top one when the panel is too short for all, the others drawn as grid
//!   lines), plain (`0.01`, `1`, `100`) when every label lies in [0.01, 10⁵), otherwise all
//!   in `1eK` form (`1e-9`, `1e0`, `1e3`).

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use std::ops::Range;

/// Tick count that fits `len_px` pixels of axis with `px_per_label` per label (2 … 10).
pub fn label_count(len_px: u32, px_per_label: u32) -> usize {
    ((len_px / px_per_label.max(1)) as usize).clamp(2, 10)
}

/// The step between "nice" ticks (1, 2, 5 × 10ᵏ) for at most about `n` labels over
/// `span`.
pub fn nice_step(span: f64, n: usize) -> f64 {
    let raw = span.abs() / n.max(1) as f64;
    if !(raw > 0.0 && raw.is_finite()) {
        return 1.0;
    }
    let p = 10f64.powf(raw.log10().floor());
    let m = raw / p;
    let k = if m <= 1.0 {
        1.0
    } else if m <= 2.0 {
        2.0
    } else if m <= 5.0 {
        5.0
    } else {
        10.0
    };
    k * p
}

/// The next smaller nice step (5 → 2 → 1 → 0.5 …).
fn smaller_step(step: f64) -> f64 {
    let p = 10f64.powf(step.log10().floor());
    let m = (step / p).round();
    if m >= 5.0 {
        2.0 * p
    } else if m >= 2.0 {
        p
    } else {
        0.5 * p
    }
}

/// Remove trailing zeros of a decimal fraction (`"2.500"` → `"2.5"`, `"3.000"` → `"3"`).
fn trim_fraction(s: &str) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s.to_string()
    }
}

/// Decimals that write multiples of `step` exactly (`0.5` → 1, `0.02` → 2, `50` → 0).
fn decimals_of(step: f64) -> usize {
    if !(step > 0.0 && step.is_finite()) {
        return 0;
    }
    (-(step.log10() + 1e-9).floor()).clamp(0.0, 15.0) as usize
}

/// How the labels of one axis are written.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Notation {
    /// fixed decimals (linear)
    Plain(usize),
    /// value / 10^exp with fixed decimals; the axis states "×1e{exp}" (linear)
    Scaled { exp: i32, decimals: usize },
    /// shortest plain form (logarithmic, labels in [0.01, 10⁵))
    LogPlain,
    /// `1e-3`, `2e-3`, `1e0` (logarithmic)
    LogSci,
}

/// The ticks of one axis: labelled values (bold grid lines), unlabelled grid values
/// (light lines) and the label notation.
#[derive(Clone, Debug, PartialEq)]
pub struct Ticks {
    /// labelled values, ascending
    pub major: Vec<f64>,
    /// unlabelled grid values, ascending
    pub minor: Vec<f64>,
    notation: Notation,
}

/// Multiples `k step` with `lo ≤ k step ≤ hi` (a hair of tolerance at both ends).
fn multiples(lo: f64, hi: f64, step: f64) -> Vec<f64> {
    if !(step > 0.0 && lo.is_finite() && hi.is_finite()) || hi < lo {
        return Vec::new();
    }
    let tol = 1e-9 * step;
    let k0 = ((lo - tol) / step).ceil();
    let k1 = ((hi + tol) / step).floor();
    if !(k0.is_finite() && k1.is_finite()) || k1 - k0 > 10_000.0 {
        return Vec::new();
    }
    (k0 as i64..=k1 as i64)
        .map(|k| {
            let v = k as f64 * step;
            if v.abs() < tol {
                0.0
            } else {
                v
            }
        })
        .collect()
}

impl Ticks {
    /// Ticks of a linear axis over `[lo, hi]` with at most about `max_labels` labels (at
    /// least two when the range allows).
    pub fn linear(lo: f64, hi: f64, max_labels: usize) -> Self {
        let span = hi - lo;
        let mut step = nice_step(span, max_labels.max(2) + 1);
        let mut major = multiples(lo, hi, step);
        for _ in 0..4 {
            if major.len() >= 2 {
                break;
            }
            step = smaller_step(step);
            major = multiples(lo, hi, step);
        }
        let p = 10f64.powf(step.log10().floor());
        let sub = if (step / p).round() == 2.0 {
            step / 4.0
        } else {
            step / 5.0
        };
        let minor = multiples(lo, hi, sub)
            .into_iter()
            .filter(|v| !major.iter().any(|m| (m - v).abs() < 1e-6 * sub))
            .collect();
        let biggest = major.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        let notation = if biggest == 0.0 || (1e-2..1e5).contains(&biggest) {
            Notation::Plain(decimals_of(step))
        } else {
            let exp = biggest.log10().floor() as i32;
            Notation::Scaled {
                exp,
                decimals: decimals_of(step / 10f64.powi(exp)),
            }
        };
        Ticks {
            major,
            minor,
            notation,
        }
    }

    /// Ticks of a logarithmic axis over `[lo, hi]` (`0 < lo < hi`) with at most about
    /// `max_labels` labels: every decade, top one included, or every m-th decade counted
    /// down from the top one; 1-2-5 values when at most two decades are in range; linear
    /// ticks within less than a factor of 2.5.
    pub fn log(lo: f64, hi: f64, max_labels: usize) -> Self {
        let max_labels = max_labels.max(2);
        let k_lo = (lo.log10() - 1e-9).ceil() as i32;
        let k_hi = (hi.log10() + 1e-9).floor() as i32;
        let decades = k_hi - k_lo + 1;
        let in_range = |v: &f64| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9);
        let (major, minor) = if decades >= 3 {
            let m = (decades as usize).div_ceil(max_labels).max(1) as i32;
            let mut major = Vec::new();
            let mut minor = Vec::new();
            for k in k_lo..=k_hi {
                if (k_hi - k) % m == 0 {
                    major.push(10f64.powi(k));
                } else {
                    minor.push(10f64.powi(k));
                }
            }
            if decades <= 6 {
                for k in (k_lo - 1)..=k_hi {
                    for c in 2..=9 {
                        minor.push(f64::from(c) * 10f64.powi(k));
                    }
                }
            }
            minor.retain(in_range);
            minor.sort_by(f64::total_cmp);
            (major, minor)
        } else {
            let mut major = Vec::new();
            let mut minor = Vec::new();
            for k in (k_lo - 1)..=k_hi.max(k_lo) {
                for c in 1..=9 {
                    let v = f64::from(c) * 10f64.powi(k);
                    if [1, 2, 5].contains(&c) {
                        major.push(v);
                    } else {
                        minor.push(v);
                    }
                }
            }
            major.retain(in_range);
            minor.retain(in_range);
            if major.len() > max_labels && decades == 2 {
                // too tall for 1-2-5: the two decades only
                let (d, rest): (Vec<f64>, Vec<f64>) = major
                    .iter()
                    .partition(|v| (v.log10() - v.log10().round()).abs() < 1e-9);
                minor.extend(rest);
                minor.sort_by(f64::total_cmp);
                major = d;
            }
            if major.len() < 2 {
                // less than a factor 2.5: linear ticks in the positive range
                let t = Ticks::linear(lo, hi, max_labels);
                return Ticks {
                    major: t.major.into_iter().filter(|v| *v > 0.0).collect(),
                    minor: t.minor.into_iter().filter(|v| *v > 0.0).collect(),
                    notation: t.notation,
                };
            }
            (major, minor)
        };
        let plain = major.iter().all(|v| (1e-2..1e5).contains(v));
        Ticks {
            major,
            minor,
            notation: if plain {
                Notation::LogPlain
            } else {
                Notation::LogSci
            },
        }
    }

    /// The label of the tick value `v` in the axis notation.
    pub fn label(&self, v: f64) -> String {
        if !v.is_finite() {
            return String::new();
        }
        let fixed = |x: f64, d: usize| {
            let s = format!("{x:.d$}");
            // no "-0.00"
            if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
                s[1..].to_string()
            } else {
                s
            }
        };
        match self.notation {
            Notation::Plain(d) => fixed(v, d),
            Notation::Scaled { exp, decimals } => fixed(v / 10f64.powi(exp), decimals),
            Notation::LogPlain => trim_fraction(&format!("{:.*}", decimals_of(v), v)),
            Notation::LogSci => {
                let s = format!("{v:.0e}");
                match s.split_once('e') {
                    Some((m, e)) => format!("{}e{e}", trim_fraction(m)),
                    None => s,
                }
            }
        }
    }

    /// The shared power of ten of a scaled linear axis, for its description
    /// (`"×1e-7"`); `None` when the labels are the values.
    pub fn multiplier(&self) -> Option<String> {
        match self.notation {
            Notation::Scaled { exp, .. } => Some(format!("×1e{exp}")),
            _ => None,
        }
    }

    /// The axis description with the shared power of ten appended when there is one.
    pub fn describe(&self, desc: &str) -> String {
        match self.multiplier() {
            Some(m) if !desc.is_empty() => format!("{desc} ({m})"),
            Some(m) => m,
            None => desc.to_string(),
        }
    }
}

/// A plotters axis (linear or logarithmic) whose grid lines and labels are our
/// [`Ticks`]: `major` labelled with bold lines, `minor` light lines.
pub struct Axis<R> {
    inner: R,
    major: Vec<f64>,
    minor: Vec<f64>,
}

impl<R: Ranged<ValueType = f64>> Axis<R> {
    /// The axis `inner` with the ticks `t`.
    pub fn new(inner: R, t: &Ticks) -> Self {
        Self {
            inner,
            major: t.major.clone(),
            minor: t.minor.clone(),
        }
    }

    /// The axis `inner` labelled at `major` only, without light lines.
    pub fn labelled(inner: R, major: Vec<f64>) -> Self {
        Self {
            inner,
            major,
            minor: Vec::new(),
        }
    }
}

impl<R: Ranged<ValueType = f64>> Ranged for Axis<R> {
    type ValueType = f64;
    type FormatOption = DefaultFormatting;

    fn range(&self) -> Range<f64> {
        self.inner.range()
    }

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.minor.clone()
        } else {
            self.major.clone()
        }
    }

    fn axis_pixel_range(&self, limit: (i32, i32)) -> Range<i32> {
        self.inner.axis_pixel_range(limit)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    fn labels(t: &Ticks) -> Vec<String> {
        t.major.iter().map(|v| t.label(*v)).collect()
    }

    #[test]
    fn nice_steps_are_1_2_5() {
        assert_eq!(nice_step(10.0, 5), 2.0);
        assert_eq!(nice_step(1.0, 4), 0.5);
        assert!((nice_step(3e-4, 3) - 1e-4).abs() < 1e-18);
    }

    /// One notation per axis: the axis that mixed `0.02` and `-1e-2` now reads
    /// `-0.02 -0.01 0.00 0.01 0.02`.
    #[test]
    fn linear_axes_have_one_notation() {
        let t = Ticks::linear(-0.021, 0.021, 5);
        assert_eq!(labels(&t), ["-0.02", "-0.01", "0.00", "0.01", "0.02"]);
        assert_eq!(t.multiplier(), None);
        let t = Ticks::linear(0.0, 1000.0, 5);
        assert_eq!(labels(&t), ["0", "200", "400", "600", "800", "1000"]);
        let t = Ticks::linear(-0.3, 1.2, 4);
        assert_eq!(labels(&t), ["0.0", "0.5", "1.0"]);
        // small values: shared power of ten
        let t = Ticks::linear(-3.1e-7, 1.1e-7, 9);
        assert_eq!(t.multiplier().as_deref(), Some("×1e-7"));
        assert_eq!(
            labels(&t),
            ["-3.0", "-2.5", "-2.0", "-1.5", "-1.0", "-0.5", "0.0", "0.5", "1.0"]
        );
        assert_eq!(t.describe("error [m]"), "error [m] (×1e-7)");
        // large values
        let t = Ticks::linear(-1e5, 1.6e6, 4);
        assert_eq!(t.multiplier().as_deref(), Some("×1e6"));
        assert_eq!(labels(&t), ["0.0", "0.5", "1.0", "1.5"]);
        // no "-0", and minor lines between the labels only
        let t = Ticks::linear(-1.0, 1.0, 4);
        assert!(labels(&t).contains(&"0.0".to_string()));
        assert!(t.minor.iter().all(|m| !t.major.contains(m)));
        assert!(!t.minor.is_empty());
        // a range narrower than one nice step still gets two labels
        let t = Ticks::linear(0.11, 0.19, 2);
        assert!(t.major.len() >= 2, "{:?}", t.major);
    }

    /// Every decade labelled, the top one included.
    #[test]
    fn log_axes_label_every_decade_including_the_top() {
        let t = Ticks::log(0.3, 1500.0, 10);
        assert_eq!(labels(&t), ["1", "10", "100", "1000"]);
        let t = Ticks::log(2e-9, 3e2, 20);
        assert_eq!(t.major.len(), 11);
        assert_eq!(labels(&t).last().map(String::as_str), Some("1e2"));
        assert_eq!(labels(&t).first().map(String::as_str), Some("1e-8"));
        assert!(labels(&t).contains(&"1e0".to_string()), "one notation");
        // too many decades for the panel: every m-th, counted down from the top
        let t = Ticks::log(1e-20, 5e2, 6);
        assert_eq!(labels(&t).last().map(String::as_str), Some("1e2"));
        assert!(t.major.len() <= 6, "{:?}", labels(&t));
        assert!(t.minor.contains(&1e1), "unlabelled decades are grid lines");
        // within two decades: 1-2-5
        let t = Ticks::log(1.5, 60.0, 10);
        assert_eq!(labels(&t), ["2", "5", "10", "20", "50"]);
        let t = Ticks::log(0.15, 40.0, 10);
        assert_eq!(labels(&t), ["0.2", "0.5", "1", "2", "5", "10", "20"]);
        // within a factor of 2.5: linear ticks
        let t = Ticks::log(3.0, 6.0, 5);
        assert!(t.major.len() >= 2 && t.major.iter().all(|v| (3.0..=6.0).contains(v)));
    }
}

//! Unit tests of the plot module: decimation, legend, SVG rendering, glyph placement.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use super::*;
use decimate::decimate;

#[test]
fn decimation_preserves_min_and_max_per_column() {
    let n = 100_000;
    let (x0, x1, cols) = (0.0, 100.0, 700);
    // a noisy sine plus one 2-sample spike at t = 50.005
    let pts: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let x = x1 * i as f64 / n as f64;
            let noise = (((i as u64).wrapping_mul(2_654_435_761) % 1000) as f64) * 1e-3;
            let spike = if (50_005..50_007).contains(&i) {
                40.0
            } else {
                0.0
            };
            (x, (x * 0.3).sin() + noise + spike)
        })
        .collect();
    let d = decimate(&pts, x0, x1, cols);
    assert!(d.len() <= 2 * cols, "{}", d.len());
    assert!(d.windows(2).all(|w| w[0].0 <= w[1].0), "x order kept");
    let col = |x: f64| ((x - x0) / (x1 - x0) * cols as f64).floor() as usize;
    for c in 0..cols {
        let inside: Vec<f64> = pts.iter().filter(|p| col(p.0) == c).map(|p| p.1).collect();
        let kept: Vec<f64> = d.iter().filter(|p| col(p.0) == c).map(|p| p.1).collect();
        let lo = inside.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = inside.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let klo = kept.iter().copied().fold(f64::INFINITY, f64::min);
        let khi = kept.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        assert_eq!((lo, hi), (klo, khi), "column {c}");
    }
    assert!(d.iter().any(|p| p.1 > 40.0), "the spike survives");
    // short series are untouched
    assert_eq!(decimate(&pts[..10], x0, x1, cols), pts[..10].to_vec());
}

#[test]
fn online_columns_match_batch_decimation_per_channel() {
    let mut m = MinMaxColumns::new(0.0, 10.0, 5, 2);
    for i in 0..100 {
        let x = i as f64 * 0.1;
        m.push(x, &[x, -x]);
    }
    m.push(f64::NAN, &[1.0, 1.0]);
    m.push(3.0, &[f64::NAN, f64::INFINITY]);
    let s0 = m.series(0);
    assert_eq!(s0.len(), 10);
    assert_eq!(s0[0], (0.0, 0.0));
    assert!((s0[9].1 - 9.9).abs() < 1e-12);
    let s1 = m.series(1);
    assert!((s1[9].1 + 9.9).abs() < 1e-12);
}

#[test]
fn legend_is_outside_the_panels_and_figures_render() {
    register_font().unwrap();
    let f = Figure {
        panels: vec![Panel {
            title: "p".into(),
            x_label: "time [s]".into(),
            y_label: "y [m]".into(),
            bands: vec![Band {
                name: "a ± σ".into(),
                color_of: "a".into(),
                points: (0..50).map(|i| (i as f64, -1.0, 1.0)).collect(),
                outline: false,
            }],
            series: vec![
                Series::line("a", (0..50).map(|i| (i as f64, (i as f64).sin())).collect()),
                Series::dashed("true", vec![(0.0, 0.5), (49.0, 0.5)]),
            ],
            ..Panel::default()
        }],
        cols: 1,
        size: (600, 400),
    };
    let l = Legend::of(&f.panels);
    assert_eq!(l.entries.len(), 3);
    assert_eq!(l.height(600), LEGEND_ROW_PX + 8);
    let svg = f.svg().unwrap();
    assert!(svg.contains("a ± σ") && svg.contains("true"));
    assert!(!svg.contains("<script"));
}

/// The lowest row of ink (coverage above a quarter) of `text` drawn at `size` px into a
/// 60 × 60 bitmap by the PNG backend.
fn ink_bottom(text: &str, size: u32) -> Option<usize> {
    const W: usize = 60;
    let mut buf = vec![255u8; W * W * 3];
    {
        let backend = BitMapBackend::with_buffer(&mut buf, (W as u32, W as u32));
        let root = Raster::new(backend, dejavu::sans::regular())
            .unwrap()
            .into_drawing_area();
        let style = ("sans-serif", size).into_font().color(&BLACK);
        root.draw(&Text::new(text.to_string(), (10, 10), style))
            .unwrap();
        root.present().unwrap();
    }
    (0..W)
        .rev()
        .find(|&y| (0..W).any(|x| buf[(y * W + x) * 3] < 192))
}

/// Every glyph sits on one baseline at every size, odd ones included: plotters' own
/// font path rounds each glyph's offset toward zero, which at 15 and 17 px puts flat
/// letters (`w`, `x`, `z`, capitals) a pixel off their round-shouldered neighbours
/// (`m`, `n`, `r`, `h`) and made "Forward" read "ForWard".
#[test]
fn glyphs_share_one_baseline_at_every_size() {
    register_font().unwrap();
    for size in [14, 15, 16, 17] {
        let bottoms: Vec<(char, Option<usize>)> = "mnrwxzvhiklFWHE"
            .chars()
            .map(|c| (c, ink_bottom(&c.to_string(), size)))
            .collect();
        let first = bottoms[0].1;
        assert!(first.is_some());
        assert!(
            bottoms.iter().all(|b| b.1 == first),
            "{size} px: ink bottom rows differ: {bottoms:?}"
        );
    }
}

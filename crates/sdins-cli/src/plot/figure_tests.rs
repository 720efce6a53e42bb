//! The figure test: every kind of figure (line panels, bands, log axes, markers with error
//! bars, bars, multi-panel layouts) is rendered to PNG with data that overshoot the axes,
//! each panel's series in a color no other panel uses, and the decoded image must have no
//! pixel within RGB distance 8 of that color outside the panel's plotting area grown by
//! 1 px. The series have no legend names, so that the legend strip holds none of the
//! colors either.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use super::*;

/// Decoded RGB pixels.
struct Image {
    w: usize,
    h: usize,
    rgb: Vec<[u8; 3]>,
}

fn decode(path: &Path) -> Image {
    let file = std::fs::File::open(path).expect("PNG written");
    let mut reader = png::Decoder::new(file).read_info().expect("PNG header");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("PNG data");
    let channels = match info.color_type {
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        other => panic!("unexpected PNG color type {other:?}"),
    };
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    let rgb = buf[..info.buffer_size()]
        .chunks(channels)
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    Image {
        w: info.width as usize,
        h: info.height as usize,
        rgb,
    }
}

/// `c` drawn with opacity `alpha` over white.
fn over_white(c: RGBColor, alpha: f64) -> [u8; 3] {
    let m = |v: u8| (f64::from(v) * alpha + 255.0 * (1.0 - alpha)).round() as u8;
    [m(c.0), m(c.1), m(c.2)]
}

fn near(p: [u8; 3], c: [u8; 3]) -> bool {
    let d: i32 = (0..3)
        .map(|k| (i32::from(p[k]) - i32::from(c[k])).pow(2))
        .sum();
    d <= 64
}

/// Pixels of color `c` outside every rectangle of `allowed` grown by 1 px.
fn stray(img: &Image, c: [u8; 3], allowed: &[PixelRect]) -> Vec<(usize, usize)> {
    let inside = |x: usize, y: usize| {
        let (x, y) = (x as i32, y as i32);
        allowed
            .iter()
            .any(|(rx, ry)| x >= rx.start - 1 && x <= rx.end && y >= ry.start - 1 && y <= ry.end)
    };
    let mut out = Vec::new();
    for y in 0..img.h {
        for x in 0..img.w {
            if near(img.rgb[y * img.w + x], c) && !inside(x, y) {
                out.push((x, y));
            }
        }
    }
    out
}

fn tmp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("sdins-figure-test-{}", std::process::id()));
    std::fs::create_dir_all(&d).expect("temp dir");
    d.join(name)
}

/// Render `fig` and check every color key: its line color and its band color may only
/// appear inside the panels that use the key.
fn check_figure(name: &str, fig: &Figure) -> Vec<String> {
    let path = tmp(&format!("{name}.png"));
    let rects: Vec<PixelRect> = fig
        .png_rects(&path)
        .expect("PNG rendered")
        .into_iter()
        .map(|r| r.expect("every test panel has data"))
        .collect();
    assert_eq!(
        rects.len(),
        fig.panels.len(),
        "{name}: one plotting area per panel"
    );
    let img = decode(&path);
    let legend = Legend::of(&fig.panels);
    let mut keys: Vec<String> = Vec::new();
    for p in &fig.panels {
        for k in p
            .series
            .iter()
            .map(|s| s.color_key().to_string())
            .chain(p.bands.iter().map(|b| b.color_of.clone()))
        {
            if !keys.contains(&k) {
                keys.push(k);
            }
        }
    }
    let mut failures = Vec::new();
    for k in &keys {
        let allowed: Vec<PixelRect> = fig
            .panels
            .iter()
            .zip(&rects)
            .filter(|(p, _)| {
                p.series.iter().any(|s| s.color_key() == k)
                    || p.bands.iter().any(|b| &b.color_of == k)
            })
            .map(|(_, r)| r.clone())
            .collect();
        let c = legend.color_of(k);
        let mut colors = vec![("line", [c.0, c.1, c.2])];
        for outline in [false, true] {
            let has = fig.panels.iter().any(|p| {
                p.bands
                    .iter()
                    .any(|b| &b.color_of == k && b.outline == outline)
            });
            if has {
                colors.push(("band", over_white(c, band_alpha(outline))));
            }
        }
        for (what, rgb) in colors {
            let s = stray(&img, rgb, &allowed);
            if !s.is_empty() {
                failures.push(format!(
                    "{name}: {} {what} pixels of key {k} outside its panel, e.g. {:?}",
                    s.len(),
                    &s[..s.len().min(4)]
                ));
            }
        }
    }
    failures
}

/// A zigzag with sharp reversals (the min/max decimation of noise), huge values before
/// x = 20 and a spike at x = 70.
fn zigzag(n: usize, x1: f64) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let x = x1 * i as f64 / n as f64;
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            let big = if x < 0.2 * x1 { 1e3 } else { 1.0 };
            let spike = if (i * 10) / n == 7 && i % 97 == 0 {
                50.0
            } else {
                0.0
            };
            (x, sign * (big + 0.3 * (x * 0.7).sin()) + spike)
        })
        .collect()
}

fn key(i: usize) -> String {
    format!("k{i}")
}

fn band(i: usize, pts: Vec<(f64, f64, f64)>) -> Band {
    Band {
        name: String::new(),
        color_of: key(i),
        points: pts,
        outline: i == 0,
    }
}

fn line(i: usize, pts: Vec<(f64, f64)>) -> Series {
    Series::line(String::new(), pts).colored_as(key(i))
}

/// The panel kinds, panel `i` in color `i`.
fn panels() -> Vec<Panel> {
    let zz = zigzag(6000, 100.0);
    let fit = Some(20.0);
    vec![
        // linear lines with ±3σ-like band, range fitted after the transient
        Panel {
            title: "linear, fitted after x = 20".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            y_fit_from_x: fit,
            bands: vec![band(
                0,
                (0..200)
                    .map(|i| {
                        let x = i as f64 / 2.0;
                        let s = if x < 20.0 { 5e3 } else { 2.0 };
                        (x, -s, s)
                    })
                    .collect(),
            )],
            series: vec![line(0, zz.clone())],
            ..Panel::default()
        },
        // dashed lines leaving the range on both sides
        Panel {
            title: "dashed".into(),
            y_fit_from_x: fit,
            series: vec![
                line(1, vec![(0.0, 0.0), (100.0, 1.0)]),
                Series::dashed(String::new(), vec![(0.0, -1e4), (50.0, 1e4), (100.0, 0.5)])
                    .colored_as(key(1)),
            ],
            ..Panel::default()
        },
        // log y: decades of noise, zeros, negatives, and a band
        Panel {
            title: "log y".into(),
            log_y: true,
            y_fit_from_x: fit,
            bands: vec![band(
                2,
                (1..100)
                    .map(|i| (i as f64, 1e-30, if i < 20 { 1e30 } else { 1.0 }))
                    .collect(),
            )],
            series: vec![line(
                2,
                zz.iter()
                    .map(|&(x, y)| (x, y.abs() * 10f64.powi((x as i32 % 7) - 3)))
                    .chain([(100.0, 0.0), (100.5, -1.0)])
                    .collect(),
            )],
            ..Panel::default()
        },
        // log-log markers with error bars, markers on the frame
        Panel {
            title: "log-log points".into(),
            log_x: true,
            log_y: true,
            y_fit_from_x: Some(1.0),
            series: vec![
                Series::points(
                    String::new(),
                    (0..40)
                        .map(|i| {
                            let t = 0.01 * 1.4f64.powi(i);
                            (t, if t < 1.0 { 1e6 } else { 1.0 / t.sqrt() })
                        })
                        .collect(),
                    (0..40)
                        .map(|i| {
                            let t = 0.01 * 1.4f64.powi(i);
                            let y = if t < 1.0 { 1e6 } else { 1.0 / t.sqrt() };
                            (y * 1e-9, y * 1e9)
                        })
                        .collect(),
                )
                .colored_as(key(3)),
                Series::dashed(String::new(), vec![(1e-3, 1e9), (1e4, 1e-9)]).colored_as(key(3)),
            ],
            ..Panel::default()
        },
        // equal axes (ground track)
        Panel {
            title: "equal axes".into(),
            equal_axes: true,
            series: vec![line(
                4,
                (0..400)
                    .map(|i| {
                        let a = i as f64 * 0.05;
                        (1e5 * a.cos() + 2e5, 3e3 * a.sin())
                    })
                    .collect(),
            )],
            ..Panel::default()
        },
        // linear markers on the x edges, y outside the fitted range
        Panel {
            title: "points".into(),
            y_fit_from_x: Some(10.0),
            series: vec![Series::points(
                String::new(),
                (0..=100)
                    .map(|i| {
                        let x = i as f64;
                        (x, if x < 10.0 { 1e3 } else { (x * 0.3).sin() })
                    })
                    .collect(),
                (0..=100).map(|i| (-50.0 - i as f64, 50.0)).collect(),
            )
            .colored_as(key(5))],
            ..Panel::default()
        },
    ]
}

#[test]
fn every_series_and_band_stays_in_its_panel() {
    register_font().unwrap_or_else(|e| panic!("{e}"));
    let mut failures = Vec::new();
    // each kind alone, in a small and a large panel
    for (i, p) in panels().into_iter().enumerate() {
        for (k, size) in [(400, 300), (900, 600)].into_iter().enumerate() {
            let fig = Figure {
                panels: vec![p.clone()],
                cols: 1,
                size,
            };
            failures.extend(check_figure(&format!("kind{i}-{k}"), &fig));
        }
    }
    // the multi-panel layouts: 3 × 2 (every kind at once) and 3 × 3 (colors repeat)
    let all = panels();
    failures.extend(check_figure(
        "layout3x2",
        &Figure {
            panels: all.clone(),
            cols: 3,
            size: (1500, 800),
        },
    ));
    let mut nine = all.clone();
    nine.extend(all.into_iter().take(3));
    failures.extend(check_figure(
        "layout3x3",
        &Figure {
            panels: nine,
            cols: 3,
            size: (1500, 1150),
        },
    ));
    // bars: a negative value, a NaN and a value far above the others
    let bars = Bars {
        title: "bars".into(),
        y_label: "time [ns]".into(),
        bars: vec![
            ("a".into(), 500.0),
            ("b".into(), -200.0),
            ("c".into(), f64::NAN),
            ("d".into(), 1e4),
            ("e".into(), f64::INFINITY),
        ],
        size: (900, 400),
    };
    let path = tmp("bars.png");
    let rects = vec![bars.png_rect(&path).expect("bars rendered")];
    let img = decode(&path);
    for (i, c) in COLORS.iter().enumerate().take(bars.bars.len()) {
        let s = stray(&img, over_white(*c, BAR_ALPHA), &rects);
        if !s.is_empty() {
            failures.push(format!(
                "bars: {} pixels of bar {i} outside the plotting area, e.g. {:?}",
                s.len(),
                &s[..s.len().min(4)]
            ));
        }
    }
    if std::env::var_os("SDINS_KEEP_FIGURES").is_none() {
        let _ = std::fs::remove_dir_all(tmp("x").parent().expect("temp dir"));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

//! Self-contained HTML reports: tables and inline SVG figures, no scripts, no network.

use crate::error::CliError;
use crate::plot::Figure;
use std::fmt::Write as _;
use std::path::Path;

/// An HTML report under construction.
#[derive(Default)]
pub struct Report {
    title: String,
    body: String,
}

/// Escape text for HTML.
pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

impl Report {
    /// New report with a title.
    pub fn new(title: &str) -> Self {
        Self {
            title: title.to_string(),
            body: String::new(),
        }
    }

    /// A section heading.
    pub fn heading(&mut self, text: &str) {
        let _ = writeln!(self.body, "<h2>{}</h2>", esc(text));
    }

    /// A paragraph of plain text.
    pub fn para(&mut self, text: &str) {
        let _ = writeln!(self.body, "<p>{}</p>", esc(text));
    }

    /// Preformatted text (e.g. a console table).
    #[allow(dead_code)]
    pub fn pre(&mut self, text: &str) {
        let _ = writeln!(self.body, "<pre>{}</pre>", esc(text));
    }

    /// A table with a header row.
    pub fn table(&mut self, header: &[&str], rows: &[Vec<String>]) {
        let _ = write!(self.body, "<table><tr>");
        for h in header {
            let _ = write!(self.body, "<th>{}</th>", esc(h));
        }
        let _ = writeln!(self.body, "</tr>");
        for r in rows {
            let _ = write!(self.body, "<tr>");
            for c in r {
                let _ = write!(self.body, "<td>{}</td>", esc(c));
            }
            let _ = writeln!(self.body, "</tr>");
        }
        let _ = writeln!(self.body, "</table>");
    }

    /// An inline SVG figure with a caption.
    pub fn figure(&mut self, fig: &Figure, caption: &str) -> Result<(), CliError> {
        self.svg(&fig.svg()?, caption);
        Ok(())
    }

    /// Write `dir/stem.svg` and `dir/stem.png` and embed the SVG with a caption.
    pub fn figure_file(
        &mut self,
        fig: &Figure,
        dir: &Path,
        stem: &str,
        caption: &str,
    ) -> Result<(), CliError> {
        let svg = fig.save(dir, stem)?;
        self.svg(&svg, &format!("{caption} ({stem}.svg, {stem}.png)"));
        Ok(())
    }

    /// Write `dir/stem.svg` and `dir/stem.png` of a bar chart and embed the SVG.
    pub fn bars_file(
        &mut self,
        b: &crate::plot::Bars,
        dir: &Path,
        stem: &str,
        caption: &str,
    ) -> Result<(), CliError> {
        let svg = b.save(dir, stem)?;
        self.svg(&svg, &format!("{caption} ({stem}.svg, {stem}.png)"));
        Ok(())
    }

    /// An inline SVG bar chart with a caption.
    pub fn bars(&mut self, b: &crate::plot::Bars, caption: &str) -> Result<(), CliError> {
        self.svg(&b.svg()?, caption);
        Ok(())
    }

    /// An SVG document (e.g. from plotters) inline with a caption.
    pub fn svg(&mut self, svg: &str, caption: &str) {
        // drop the XML prolog if any: the SVG is embedded in HTML
        let svg = svg.find("<svg").map_or(svg, |i| &svg[i..]);
        let _ = writeln!(
            self.body,
            "<figure>{svg}<figcaption>{}</figcaption></figure>",
            esc(caption)
        );
    }

    /// The whole HTML document.
    pub fn html(&self) -> String {
        format!(
            "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{t}</title>\n<style>\
body{{font-family:sans-serif;max-width:1500px;margin:2em auto;padding:0 1em;color:#222}}\
table{{border-collapse:collapse;margin:1em 0;font-size:14px}}th,td{{border:1px solid #bbb;padding:3px 8px;text-align:right}}\
th{{background:#eee}}td:first-child,th:first-child{{text-align:left}}pre{{background:#f6f6f6;padding:8px;overflow-x:auto;font-size:13px}}\
figure{{margin:1em 0}}figure svg{{max-width:100%;height:auto}}figcaption{{font-size:13px;color:#555}}</style></head>\n\
<body><h1>{t}</h1>\n<p>sdins {v}. Conventions: NED navigation frame, FRD body frame; attitude error ε from \
C_alg C_true<sup>T</sup> = I + [ε×]; position error δN = δL(R<sub>M</sub>+h), δE = δλ(R<sub>N</sub>+h)cos L, δD = −δh.</p>\n{b}</body></html>\n",
            t = esc(&self.title),
            v = env!("CARGO_PKG_VERSION"),
            b = self.body
        )
    }

    /// Write the report atomically.
    pub fn write(&self, dest: &Path) -> Result<(), CliError> {
        let html = self.html();
        debug_assert!(
            external_resources(&html).is_empty(),
            "a report must be self-contained"
        );
        crate::output::write_string(dest, &html)
    }
}

/// What in `html` would make a report depend on anything outside itself: script, link,
/// frame, object, embed or img elements, `src`/`href` attributes (looked for inside
/// tags; text is escaped, so it holds no raw `<`), CSS `url(` and `@import`. Empty for a
/// self-contained report. (The SVG namespace `xmlns="http://www.w3.org/2000/svg"` is a
/// name, not a resource, and is allowed.)
pub fn external_resources(html: &str) -> Vec<String> {
    let lower = html.to_ascii_lowercase();
    let mut found = Vec::new();
    for tag in lower.split('<').skip(1).filter_map(|t| t.split('>').next()) {
        let name = tag
            .split(|c: char| c.is_whitespace() || c == '/')
            .next()
            .unwrap_or("");
        if ["script", "link", "iframe", "object", "embed", "img"].contains(&name) {
            found.push(format!("<{name}>"));
        }
        for attr in [" src=", " href=", "xlink:href="] {
            if tag.contains(attr) {
                found.push(attr.trim().to_string());
            }
        }
    }
    for css in ["url(", "@import"] {
        if lower.contains(css) {
            found.push(css.to_string());
        }
    }
    found
}

/// Write `dir/run.toml` atomically: `sdins_version`, `git_commit` and `command` first,
/// then the command's own `fields` (scenario, seed, method, ...), everything needed to
/// reproduce the outputs of the folder.
pub fn write_run_toml(dir: &Path, fields: toml::Table) -> Result<(), CliError> {
    let mut t = toml::Table::new();
    t.insert("sdins_version".into(), env!("CARGO_PKG_VERSION").into());
    t.insert("git_commit".into(), crate::provenance::git_commit().into());
    t.insert("command".into(), crate::provenance::command_line().into());
    t.extend(fields);
    let text = toml::to_string(&t).map_err(|e| CliError::Other(e.to_string()))?;
    crate::output::write_string(&dir.join("run.toml"), &text)
}

/// Print what each `random_vibration` overlay realised and dropped, and a route's
/// per-waypoint report (stderr).
pub fn print_vibration(scn: &sdins_sim::scenario::Scenario) {
    for r in &scn.vibration {
        eprintln!("{}", r.summary());
    }
    // and a route's per-waypoint report
    if let Some(r) = &scn.route {
        for line in r.summary() {
            eprintln!("{line}");
        }
    }
}

/// The `random_vibration` overlays' power bookkeeping for `run.toml`: one table per overlay
/// with `components`, `df_hz` and per quantity (`accel` (m/s²)², `gyro` (rad/s)²) the
/// per-axis `[x, y, z]` arrays of specified, realised and dropped power.
pub fn vibration_toml(scn: &sdins_sim::scenario::Scenario) -> Option<toml::Value> {
    if scn.vibration.is_empty() {
        return None;
    }
    let list = scn
        .vibration
        .iter()
        .map(|r| {
            let mut t = toml::Table::new();
            t.insert("components".into(), (r.components as i64).into());
            t.insert("df_hz".into(), r.df_hz.into());
            for (name, p) in [("accel", &r.accel), ("gyro", &r.gyro)] {
                let Some(p) = p else { continue };
                let mut q = toml::Table::new();
                let arr = |f: &dyn Fn(&sdins_sim::truth::random_vibration::AxisPower) -> f64| {
                    toml::Value::Array(p.iter().map(|a| toml::Value::from(f(a))).collect())
                };
                q.insert("specified".into(), arr(&|a| a.specified));
                q.insert("realised".into(), arr(&|a| a.realised));
                q.insert("dropped_dc".into(), arr(&|a| a.dropped_dc));
                q.insert(
                    "dropped_above_nyquist".into(),
                    arr(&|a| a.dropped_above_nyquist),
                );
                q.insert(
                    "dropped_below_threshold".into(),
                    arr(&|a| a.dropped_below_threshold),
                );
                t.insert(name.into(), q.into());
            }
            toml::Value::Table(t)
        })
        .collect();
    Some(toml::Value::Array(list))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::plot::{Band, Figure, Panel, Series};

    #[test]
    fn reports_have_no_script_or_external_resource() {
        let mut r = Report::new("t <script>");
        r.para("a & b <script>alert(1)</script>");
        r.table(&["x"], &[vec!["<link href=x>".into()]]);
        let fig = Figure {
            panels: vec![Panel {
                series: vec![Series::line("a", vec![(0.0, 1.0), (1.0, 2.0)])],
                bands: vec![Band {
                    name: "b".into(),
                    color_of: "a".into(),
                    points: vec![(0.0, 0.0, 2.0), (1.0, 1.0, 3.0)],
                    outline: false,
                }],
                ..Panel::default()
            }],
            cols: 1,
            size: (400, 300),
        };
        r.figure(&fig, "caption").unwrap();
        let html = r.html();
        assert!(html.contains("<svg"));
        assert_eq!(external_resources(&html), Vec::<String>::new());
        // the check itself finds what it looks for
        assert_eq!(external_resources("<img src=\"x.png\">").len(), 2);
        assert_eq!(external_resources("<p><script>x</script>").len(), 1);
        assert_eq!(external_resources("<a href=\"https://x\">x</a>").len(), 1);
        assert!(external_resources("<p>a &lt;link href=x&gt;</p>").is_empty());
    }
}

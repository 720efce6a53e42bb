//! Input profiles: a small TOML file that keeps a logger's column maps for reuse
//! (`--profile FILE`; docs/own-data.md §"Input profiles"). One table per input kind:
//!
//! ```toml
//! [imu]
//! columns = "t_ms=time,gyro_x_dps=gx,gyro_y_dps=gy,gyro_z_dps=gz,accel_x_g=ax,accel_y_g=ay,accel_z_g=az"
//! axes = "x:+y,y:+x,z:-z"     # or mount_deg = [0, 0, 90]
//! time = "relative"           # relative | gps-sow | unix
//! gps_week = 2100             # seconds of week without week column
//! time_offset_s = 0.0
//! delim = "whitespace"        # auto | comma | whitespace | semicolon
//! header = "yes"              # auto | yes | no
//! rates = "trapezoid"         # trapezoid | hold
//! g_mps2 = 9.80665            # the g of _g and _mg
//! allow_gaps = false
//!
//! [gnss]
//! columns = "t_s=t,lat_deg=lat,lon_deg=lon,alt_msl_m=alt"
//! undulation_m = 31.2         # geoid undulation for alt_msl_m
//! sigma = [5, 5, 10, 0.05, 0.05, 0.05]   # N, E, D m [, vN, vE, vD m/s] when the file has none
//!
//! [reference]
//! columns = "…"
//! yaw = "enu"                 # ned | enu | enu-east
//! ```
//!
//! Every mistake (unknown key, wrong type, a setting of another kind, a bad map) is an
//! error naming `--profile FILE:LINE`.

use crate::io::columns::{ColumnMap, ColumnsError, InputKind, MapOrigin};
use crate::io::gnss_columns::{GnssColumns, GnssSigma};
use crate::io::imu_columns::ImuColumns;
use crate::io::reference_file::ColumnMap as ReferenceColumns;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    imu: Option<Section>,
    gnss: Option<Section>,
    reference: Option<Section>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Section {
    columns: Option<Spanned<String>>,
    axes: Option<Spanned<String>>,
    mount_deg: Option<Spanned<[f64; 3]>>,
    time: Option<Spanned<String>>,
    gps_week: Option<Spanned<u32>>,
    time_offset_s: Option<Spanned<f64>>,
    delim: Option<Spanned<String>>,
    header: Option<Spanned<String>>,
    rates: Option<Spanned<String>>,
    yaw: Option<Spanned<String>>,
    g_mps2: Option<Spanned<f64>>,
    allow_gaps: Option<Spanned<bool>>,
    undulation_m: Option<Spanned<f64>>,
    sigma: Option<Spanned<Vec<f64>>>,
}

/// A parsed input profile.
#[derive(Clone, Debug, PartialEq, Default)]
#[non_exhaustive]
pub struct Profile {
    /// the `[imu]` map
    pub imu: Option<ImuColumns>,
    /// the `[gnss]` map
    pub gnss: Option<GnssColumns>,
    /// the `[reference]` map
    pub reference: Option<ReferenceColumns>,
}

/// What a section gives besides its map.
struct Extras {
    gps_week: Option<u32>,
    offset_s: f64,
    g_mps2: Option<f64>,
    allow_gaps: Option<bool>,
    undulation_m: Option<f64>,
    sigma: Option<GnssSigma>,
}

fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

fn section(
    file: &Path,
    text: &str,
    kind: InputKind,
    s: Section,
) -> Result<(ColumnMap, Extras), ColumnsError> {
    let at = |span: std::ops::Range<usize>| MapOrigin::Profile {
        file: file.into(),
        line: line_of(text, span.start),
    };
    let origin = s.columns.as_ref().map_or_else(
        || MapOrigin::Profile {
            file: file.into(),
            line: 1,
        },
        |c| at(c.span()),
    );
    let mut map = ColumnMap::empty(kind, origin);
    if let Some(c) = &s.columns {
        map.merge_text(c.get_ref())?;
    }
    // settings: each checked with its own line
    let mut set = |key: &str, v: &Option<Spanned<String>>| -> Result<(), ColumnsError> {
        if let Some(v) = v {
            let keep = std::mem::replace(&mut map.origin, at(v.span()));
            map.set(key, v.get_ref())?;
            map.origin = keep;
        }
        Ok(())
    };
    set("axes", &s.axes)?;
    set("time", &s.time)?;
    set("delim", &s.delim)?;
    set("header", &s.header)?;
    set("rates", &s.rates)?;
    set("yaw", &s.yaw)?;
    if let Some(m) = &s.mount_deg {
        let v = m.get_ref();
        set(
            "mount_deg",
            &Some(Spanned::new(
                m.span(),
                format!("{}:{}:{}", v[0], v[1], v[2]),
            )),
        )?;
    }
    let only = |what: &str, span: std::ops::Range<usize>, ok: &[InputKind]| {
        if ok.contains(&kind) {
            Ok(())
        } else {
            Err(ColumnsError::map(
                &at(span),
                format!("`{what}` does not apply to [{}]", kind.name()),
            ))
        }
    };
    if let Some(g) = &s.g_mps2 {
        only("g_mps2", g.span(), &[InputKind::Imu])?;
        if !(g.get_ref().is_finite() && (9.0..=10.5).contains(g.get_ref())) {
            return Err(ColumnsError::map(
                &at(g.span()),
                format!("g_mps2 = {}: expected 9 .. 10.5 m/s²", g.get_ref()),
            ));
        }
    }
    if let Some(a) = &s.allow_gaps {
        only("allow_gaps", a.span(), &[InputKind::Imu])?;
    }
    if let Some(u) = &s.undulation_m {
        only(
            "undulation_m",
            u.span(),
            &[InputKind::Gnss, InputKind::Reference],
        )?;
    }
    let sigma = match &s.sigma {
        Some(v) => {
            only("sigma", v.span(), &[InputKind::Gnss])?;
            Some(
                GnssSigma::from_slice(v.get_ref())
                    .map_err(|e| ColumnsError::map(&at(v.span()), format!("sigma: {e}")))?,
            )
        }
        None => None,
    };
    if let Some(o) = &s.time_offset_s {
        if !o.get_ref().is_finite() {
            return Err(ColumnsError::map(
                &at(o.span()),
                "time_offset_s must be finite",
            ));
        }
    }
    Ok((
        map,
        Extras {
            gps_week: s.gps_week.map(Spanned::into_inner),
            offset_s: s.time_offset_s.map_or(0.0, Spanned::into_inner),
            g_mps2: s.g_mps2.map(Spanned::into_inner),
            allow_gaps: s.allow_gaps.map(Spanned::into_inner),
            undulation_m: s.undulation_m.map(Spanned::into_inner),
            sigma,
        },
    ))
}

impl Profile {
    /// Read a profile file.
    pub fn read(path: &Path) -> Result<Self, ColumnsError> {
        let text = crate::io::table::read_text(path)?;
        Self::parse(path, &text)
    }

    /// Parse the text of a profile (`file` names it in messages).
    pub fn parse(file: &Path, text: &str) -> Result<Self, ColumnsError> {
        let raw: Raw = toml::from_str(text).map_err(|e| {
            let line = e.span().map_or(1, |s| line_of(text, s.start));
            ColumnsError::map(
                &MapOrigin::Profile {
                    file: PathBuf::from(file),
                    line,
                },
                e.message().to_string(),
            )
        })?;
        let mut p = Profile::default();
        if let Some(s) = raw.imu {
            let (map, x) = section(file, text, InputKind::Imu, s)?;
            let mut c = ImuColumns::new(map);
            c.gps_week = x.gps_week;
            c.offset_s = x.offset_s;
            c.g_mps2 = x.g_mps2.unwrap_or(c.g_mps2);
            c.allow_gaps = x.allow_gaps.unwrap_or(false);
            p.imu = Some(c);
        }
        if let Some(s) = raw.gnss {
            let (map, x) = section(file, text, InputKind::Gnss, s)?;
            let mut c = GnssColumns::new(map);
            c.gps_week = x.gps_week;
            c.offset_s = x.offset_s;
            c.undulation_m = x.undulation_m;
            c.sigma = x.sigma;
            p.gnss = Some(c);
        }
        if let Some(s) = raw.reference {
            let (map, x) = section(file, text, InputKind::Reference, s)?;
            let mut c = ReferenceColumns::new(map);
            c.gps_week = x.gps_week;
            c.offset_s = x.offset_s;
            c.undulation_m = x.undulation_m;
            p.reference = Some(c);
        }
        Ok(p)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn profile_reads_and_locates_mistakes() {
        let f = Path::new("p.toml");
        let p = Profile::parse(
            f,
            "[imu]\ncolumns = \"t_ms=1,gyro_x_dps=2\"\naxes = \"x:+y,y:+x,z:-z\"\ng_mps2 = 9.81\ngps_week = 2000\n[gnss]\ncolumns = \"t_s=1\"\nsigma = [1, 2, 3]\nundulation_m = 30\n[reference]\ncolumns = \"t_s=1\"\nyaw = \"enu-east\"\n",
        )
        .unwrap();
        let imu = p.imu.unwrap();
        assert_eq!(imu.g_mps2, 9.81);
        assert_eq!(imu.gps_week, Some(2000));
        assert!(imu.map.axes.is_some());
        assert_eq!(p.gnss.unwrap().sigma.unwrap().pos_ned_m, [1.0, 2.0, 3.0]);
        assert_eq!(
            p.reference.unwrap().map.yaw,
            Some(crate::io::columns::YawConvention::EnuEast)
        );
        for (text, want) in [
            ("[imu]\ncolumns = \"t_s=1\"\naxes = \"x:+x,y:+y,z:-z\"\n", "--profile p.toml:3: axes="),
            ("[imu]\n\ncolumns = \"speed_mps=1\"\n", "--profile p.toml:3: unknown key `speed_mps`"),
            ("[imu]\ncolumnz = \"t_s=1\"\n", "--profile p.toml:2: unknown field `columnz`"),
            ("[gnss]\nyaw = \"ned\"\n", "--profile p.toml:2: `yaw` (the attitude convention) applies to reference maps only"),
            ("[imu]\nsigma = [1, 2, 3]\n", "--profile p.toml:2: `sigma` does not apply to [imu]"),
            ("[gnss]\nsigma = [1, 2]\n", "--profile p.toml:2: sigma: expected"),
            ("[imu]\ng_mps2 = 98.1\n", "--profile p.toml:2: g_mps2 = 98.1"),
            ("[imu]\ngps_week = -1\n", "--profile p.toml:2:"),
        ] {
            let e = Profile::parse(f, text).unwrap_err().to_string();
            assert!(e.starts_with(want), "{text}: {e}");
        }
    }
}

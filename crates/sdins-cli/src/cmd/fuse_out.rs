//! The outputs `sdins fuse` writes while the library streams its rows: nav.csv,
//! innovations.csv and smoothed.csv (committed only when the run succeeds), and the rows
//! the report plots.

use super::fuse_report::{ErrRow, Thin};
use crate::csv_out::{innovation_row, CsvOut, INNOVATION_HEADER};
use crate::error::CliError;
use crate::output::AtomicFile;
use sdins_core::aiding::ekf::{MeasKind, UpdateReport};
use std::path::Path;

/// The open tables of a run; the first write error is kept and reported at the end.
pub struct Tables<'a> {
    nav: CsvOut<'a>,
    inn: CsvOut<'a>,
    smo: Option<CsvOut<'a>>,
    err: Option<CliError>,
}

impl Tables<'_> {
    fn keep(&mut self, r: Result<(), CliError>) {
        if let Err(e) = r {
            self.err.get_or_insert(e);
        }
    }
    /// A forward row.
    pub fn nav(&mut self, row: &[f64]) {
        let r = self.nav.row(row);
        self.keep(r);
    }
    /// A smoothed row.
    pub fn smoothed(&mut self, row: &[f64]) {
        let r = match self.smo.as_mut() {
            Some(f) => f.row(row),
            None => Ok(()),
        };
        self.keep(r);
    }
    /// A measurement report.
    pub fn update(&mut self, u: &UpdateReport) {
        let r = self.inn.row(&innovation_row(u));
        self.keep(r);
    }
}

/// Create nav.csv, innovations.csv (and, when smoothing, smoothed.csv) in `out` with the
/// row header `header`, run `f` on them, and commit them if `f` and every write succeed.
pub fn with_tables<R>(
    out: &Path,
    smooth: bool,
    header: &[&str],
    f: impl FnOnce(&mut Tables<'_>) -> Result<R, CliError>,
) -> Result<R, CliError> {
    let mut nav = AtomicFile::create(&out.join("nav.csv"))?;
    let mut inn = AtomicFile::create(&out.join("innovations.csv"))?;
    let mut smo = if smooth {
        Some(AtomicFile::create(&out.join("smoothed.csv"))?)
    } else {
        None
    };
    let r = {
        let mut t = Tables {
            nav: CsvOut::new(&mut nav, header)?,
            inn: CsvOut::new(&mut inn, &INNOVATION_HEADER)?,
            smo: match smo.as_mut() {
                Some(f) => Some(CsvOut::new(f, header)?),
                None => None,
            },
            err: None,
        };
        let r = f(&mut t)?;
        if let Some(e) = t.err {
            return Err(e);
        }
        t.nav.finish()?;
        t.inn.finish()?;
        t.smo.map(CsvOut::finish).transpose()?;
        r
    };
    nav.commit()?;
    inn.commit()?;
    if let Some(f) = smo {
        f.commit()?;
    }
    Ok(r)
}

/// The rows the report plots.
pub struct Plotted {
    /// forward errors and σ
    pub forward: Thin<ErrRow>,
    /// smoothed errors and σ
    pub smoothed: Thin<ErrRow>,
    /// GNSS updates: (t, NIS, dof, accepted)
    pub gnss: Vec<(f64, f64, usize, bool)>,
}

impl Default for Plotted {
    fn default() -> Self {
        Self {
            forward: Thin::new(),
            smoothed: Thin::new(),
            gnss: Vec::new(),
        }
    }
}

impl Plotted {
    /// Keep a GNSS update (refused late ones have no NIS and are not plotted).
    pub fn update(&mut self, u: &UpdateReport) {
        if u.kind == MeasKind::Gnss && !u.late {
            self.gnss.push((u.t_s, u.nis, u.dof, u.accepted));
        }
    }
    /// The smallest interval between GNSS updates (1 s when there are fewer than two).
    pub fn fix_interval_s(&self) -> f64 {
        let i = self
            .gnss
            .windows(2)
            .map(|w| w[1].0 - w[0].0)
            .fold(f64::INFINITY, f64::min);
        if i.is_finite() && i > 0.0 {
            i
        } else {
            1.0
        }
    }
}

/// The RMSE rows of the report (attitude converted to degrees from the 7th value on).
pub fn rmse_rows(rows: &[(&str, Option<[f64; 9]>)], att_first: usize) -> Vec<(String, [f64; 9])> {
    rows.iter()
        .filter_map(|(n, v)| {
            v.map(|mut v| {
                for x in v.iter_mut().skip(att_first).take(3) {
                    *x = x.to_degrees();
                }
                (n.to_string(), v)
            })
        })
        .collect()
}

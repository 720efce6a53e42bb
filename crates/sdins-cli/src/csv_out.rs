//! CSV output through the `csv` crate: a header row, then records serialized with serde
//! (floats in their shortest round-trip form, so a value read back is the value written),
//! every record checked to have the header's number of fields.
//!
//! The hand-formatted writers this replaced were not faster: `cargo bench -p sdins-cli
//! --bench csv_out` measures 100 000 seven-column IMU rows both ways (docs/performance.md).

use crate::error::CliError;
use crate::output::AtomicFile;
use serde::Serialize;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// A CSV table being written into an [`AtomicFile`] (commit the file after [`CsvOut::finish`]).
pub struct CsvOut<'a> {
    w: csv::Writer<&'a mut BufWriter<File>>,
    path: PathBuf,
}

fn csv_err(path: &Path, e: csv::Error) -> CliError {
    let source = match e.into_kind() {
        csv::ErrorKind::Io(e) => e,
        other => std::io::Error::other(format!("{other:?}")),
    };
    CliError::Io {
        path: path.to_path_buf(),
        source,
    }
}

impl<'a> CsvOut<'a> {
    /// Start the table with `header`; `comments` are written first as `# …` lines.
    pub fn with_comments(
        file: &'a mut AtomicFile,
        comments: &[&str],
        header: &[&str],
    ) -> Result<Self, CliError> {
        let path = file.dest().to_path_buf();
        let out = file.writer();
        for c in comments {
            writeln!(out, "# {c}").map_err(|source| CliError::Io {
                path: path.clone(),
                source,
            })?;
        }
        let mut w = csv::WriterBuilder::new()
            .has_headers(false)
            .from_writer(out);
        w.write_record(header).map_err(|e| csv_err(&path, e))?;
        Ok(Self { w, path })
    }
    /// Start the table with `header`.
    pub fn new(file: &'a mut AtomicFile, header: &[&str]) -> Result<Self, CliError> {
        Self::with_comments(file, &[], header)
    }
    /// One record: a slice, an array or a tuple of numbers, strings and booleans.
    pub fn row<T: Serialize + ?Sized>(&mut self, record: &T) -> Result<(), CliError> {
        self.w.serialize(record).map_err(|e| csv_err(&self.path, e))
    }
    /// Flush the table into its file.
    pub fn finish(mut self) -> Result<(), CliError> {
        self.w.flush().map_err(|source| CliError::Io {
            path: self.path.clone(),
            source,
        })
    }
}

/// Header of the navigation tables `nav_<algo>.csv` of `sdins nav` and `sdins run`: the
/// columns of an sdins truth.csv, so either file reads back as a reference trajectory.
pub const NAV_HEADER: [&str; 10] = sdins_sim::io::truth_file::SDINS_TRUTH_COLUMNS;

/// Header of `err_<algo>.csv`: `sdins run` writes all 14 columns, `sdins nav` (errors
/// against a truth file) the first 10.
pub const ERR_HEADER: [&str; 14] = [
    "t_s",
    "pos_err_n_m",
    "pos_err_e_m",
    "pos_err_d_m",
    "vel_err_n_mps",
    "vel_err_e_mps",
    "vel_err_d_mps",
    "att_err_n_rad",
    "att_err_e_rad",
    "att_err_d_rad",
    "height_err_m",
    "roll_err_rad",
    "pitch_err_rad",
    "yaw_err_rad",
];

/// One record of [`NAV_HEADER`].
pub fn nav_row(t_s: f64, st: &sdins_core::nav::NavState) -> [f64; 10] {
    let d = 180.0 / std::f64::consts::PI;
    let e = st.euler();
    [
        t_s,
        st.lat_rad * d,
        st.lon_rad * d,
        st.h_m,
        st.v_n_mps.x,
        st.v_n_mps.y,
        st.v_n_mps.z,
        e.roll_rad * d,
        e.pitch_rad * d,
        e.yaw_rad * d,
    ]
}

/// Header of `innovations.csv` of `sdins fuse`: time of the update and of validity
/// \[s\], kind, rows, NIS, outcome, and the innovation ν = predicted − measured (first
/// `dof` values; back-propagated to the update for a delayed measurement).
pub const INNOVATION_HEADER: [&str; 20] = [
    "t_s",
    "t_valid_s",
    "kind",
    "dof",
    "nis",
    "accepted",
    "forced",
    "late",
    "nu_1",
    "nu_2",
    "nu_3",
    "nu_4",
    "nu_5",
    "nu_6",
    "nu_7",
    "nu_8",
    "nu_9",
    "nu_10",
    "nu_11",
    "nu_12",
];

/// One field of a heterogeneous record.
#[derive(Clone, Copy, Debug, Serialize)]
#[serde(untagged)]
pub enum Field {
    /// a number
    Num(f64),
    /// an integer
    Int(usize),
    /// a name
    Text(&'static str),
    /// a flag
    Flag(bool),
}

/// A record of [`INNOVATION_HEADER`] (times as the report gives them: the data's clock).
pub fn innovation_row(u: &sdins_core::aiding::ekf::UpdateReport) -> [Field; 20] {
    let mut r = [Field::Num(0.0); 20];
    r[0] = Field::Num(u.t_s);
    r[1] = Field::Num(u.t_valid_s);
    r[2] = Field::Text(u.kind.name());
    r[3] = Field::Int(u.dof);
    r[4] = Field::Num(u.nis);
    r[5] = Field::Flag(u.accepted);
    r[6] = Field::Flag(u.forced);
    r[7] = Field::Flag(u.late);
    for (f, x) in r[8..].iter_mut().zip(u.innovation) {
        *f = Field::Num(x);
    }
    r
}

/// A CSV table as a string (for small tables built in memory): header, then records. A
/// record whose length differs from the header's is an error.
pub fn table<T: Serialize>(
    header: &[&str],
    rows: impl IntoIterator<Item = T>,
) -> Result<String, CliError> {
    let bad = |e: csv::Error| CliError::Other(format!("CSV table: {e}"));
    let mut w = csv::WriterBuilder::new()
        .has_headers(false)
        .from_writer(Vec::new());
    w.write_record(header).map_err(bad)?;
    for r in rows {
        w.serialize(r).map_err(bad)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| CliError::Other(format!("CSV table: {e}")))?;
    String::from_utf8(bytes).map_err(|e| CliError::Other(format!("CSV table: {e}")))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn floats_round_trip_and_mixed_records() {
        let s = table(
            &["t_s", "kind", "ok", "x"],
            [
                (0.1_f64, "gnss", true, 1e-300_f64),
                (2.0, "nhc", false, -0.0),
            ],
        )
        .unwrap();
        let lines: Vec<&str> = s.lines().collect();
        assert_eq!(lines[0], "t_s,kind,ok,x");
        let f: Vec<&str> = lines[1].split(',').collect();
        assert_eq!(f[0].parse::<f64>().unwrap(), 0.1);
        assert_eq!(f[1], "gnss");
        assert_eq!(f[3].parse::<f64>().unwrap(), 1e-300);
        assert_eq!(lines.len(), 3);
        // a label and a sequence of optional numbers flatten into one record
        let s = table(&["m", "a", "b"], [("x", vec![Some(1.5), None])]).unwrap();
        assert_eq!(s, "m,a,b\nx,1.5,\n");
        // a record of the wrong length is refused
        assert!(table(&["a", "b"], [[1.0]]).is_err());
    }
}

//! RINEX observation files, versions 2.10/2.11 and 3.0x, GPS satellites only (other
//! systems of mixed files are skipped). Observation codes are kept as RINEX 3 codes; the
//! RINEX 2 types are mapped: C1→C1C, P1→C1W, L1→L1C, D1→D1C, S1→S1C, C2→C2X, P2→C2W,
//! L2→L2W, D2→D2W, S2→S2W, C5/L5/D5/S5→·5X. A value of exactly 0 is read as missing (RINEX 2
//! writers put 0.000 for untracked observables, as in `01.15o`).

use super::error::RinexError;
use super::text::{ascii_text, col, Ctx};
use sdins_core::gnss::GpsTime;
use std::path::Path;

/// A RINEX 3 observation code such as `C1C` (type, band, attribute).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ObsCode(pub [u8; 3]);

impl ObsCode {
    /// From a 3-character RINEX 3 code (`None` unless 3 ASCII characters).
    pub fn new(s: &str) -> Option<ObsCode> {
        let b = s.as_bytes();
        (b.len() == 3 && b.is_ascii()).then(|| ObsCode([b[0], b[1], b[2]]))
    }

    /// The RINEX 3 code of a RINEX 2 observation type.
    pub fn from_rinex2(t: &str) -> ObsCode {
        let b = t.as_bytes();
        let (k, f) = (
            b.first().copied().unwrap_or(b' '),
            b.get(1).copied().unwrap_or(b' '),
        );
        let attr = match (k, f) {
            (b'C', b'1') | (b'L', b'1') | (b'D', b'1') | (b'S', b'1') => b'C',
            (b'P', b'1') | (b'P', b'2') | (b'L', b'2') | (b'D', b'2') | (b'S', b'2') => b'W',
            (b'C', b'2') | (_, b'5') => b'X',
            _ => b' ',
        };
        let k = if k == b'P' { b'C' } else { k };
        ObsCode([k, f, attr])
    }

    /// The code as text.
    pub fn as_str(&self) -> &str {
        std::str::from_utf8(&self.0).unwrap_or("???")
    }
}

impl std::fmt::Display for ObsCode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One observation with its loss-of-lock indicator and signal-strength digit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObsValue {
    /// value (pseudorange m, phase cycles, Doppler Hz, signal strength dB-Hz)
    pub value: f64,
    /// loss-of-lock indicator (bit 0: possible cycle slip)
    pub lli: Option<u8>,
    /// signal-strength indicator 1–9
    pub ssi: Option<u8>,
}

/// The observations of one GPS satellite at one epoch, indexed like
/// [`ObsHeader::gps_types`].
#[derive(Clone, Debug, PartialEq)]
pub struct SatObs {
    /// PRN
    pub prn: u8,
    /// one entry per header observation type
    pub values: Vec<Option<ObsValue>>,
}

/// One observation epoch.
#[derive(Clone, Debug, PartialEq)]
pub struct ObsEpoch {
    /// receiver time tag, in GPS time (the receiver clock: true time + clock bias)
    pub t: GpsTime,
    /// epoch flag (0 OK, 1 power failure before this epoch)
    pub flag: u8,
    /// receiver clock offset written by the receiver \[s\], when present
    pub rx_clock_offset_s: Option<f64>,
    /// GPS satellites
    pub sats: Vec<SatObs>,
}

/// The header fields these readers use.
#[derive(Clone, Debug, PartialEq)]
pub struct ObsHeader {
    /// format version (2.10, 2.11, 3.04, …)
    pub version: f64,
    /// MARKER NAME
    pub marker_name: String,
    /// REC # / TYPE / VERS, receiver type
    pub receiver_type: String,
    /// APPROX POSITION XYZ \[m\]
    pub approx_position_e_m: Option<[f64; 3]>,
    /// ANTENNA: DELTA H/E/N \[m\]
    pub antenna_delta_hen_m: [f64; 3],
    /// GPS observation types (RINEX 3 codes)
    pub gps_types: Vec<ObsCode>,
    /// INTERVAL \[s\]
    pub interval_s: Option<f64>,
    /// TIME OF FIRST OBS
    pub first_obs: Option<GpsTime>,
}

/// A whole observation file.
#[derive(Clone, Debug, PartialEq)]
pub struct ObsFile {
    /// header
    pub header: ObsHeader,
    /// epochs with flag 0 or 1, in file order
    pub epochs: Vec<ObsEpoch>,
}

impl ObsFile {
    /// Index of an observation code in the header's GPS types.
    pub fn code_index(&self, code: &str) -> Option<usize> {
        let c = ObsCode::new(code)?;
        self.header.gps_types.iter().position(|t| *t == c)
    }

    /// The first of `codes` that the file has.
    pub fn first_code_index(&self, codes: &[&str]) -> Option<(usize, ObsCode)> {
        codes
            .iter()
            .find_map(|c| Some((self.code_index(c)?, ObsCode::new(c)?)))
    }
}

/// Reads a RINEX observation file (size-capped read, see [`crate::input::read_capped`]).
pub fn read_obs(path: &Path) -> Result<ObsFile, RinexError> {
    let name = path.display().to_string();
    let bytes = crate::input::read_capped(path).map_err(|source| RinexError::Io {
        file: name.clone(),
        source,
    })?;
    parse_obs(&bytes, &name)
}

fn time_field(
    ctx: &Ctx,
    ln: usize,
    line: &str,
    c: [(usize, usize); 6],
    yy2: bool,
) -> Result<GpsTime, RinexError> {
    let mut y = ctx.int(ln, line, c[0].0, c[0].1, "epoch year")?;
    if yy2 {
        y += if y < 80 { 2000 } else { 1900 };
    }
    let mo = ctx.int(ln, line, c[1].0, c[1].1, "epoch month")?;
    let d = ctx.int(ln, line, c[2].0, c[2].1, "epoch day")?;
    let h = ctx.int(ln, line, c[3].0, c[3].1, "epoch hour")?;
    let mi = ctx.int(ln, line, c[4].0, c[4].1, "epoch minute")?;
    let s = ctx.f64(ln, line, c[5].0, c[5].1, "epoch second")?;
    let ok = (1..=12).contains(&mo)
        && (1..=31).contains(&d)
        && (0..=24).contains(&h)
        && (0..=59).contains(&mi)
        && (0.0..61.0).contains(&s)
        && (1980..=2200).contains(&y);
    if !ok {
        return Err(ctx.field_err(
            ln,
            "epoch",
            format!("date/time out of range: {:?}", line.trim_end()),
        ));
    }
    Ok(GpsTime::from_calendar(
        y as i32, mo as u32, d as u32, h as u32, mi as u32, s,
    ))
}

struct HeaderOut {
    header: ObsHeader,
    /// RINEX 2 type count
    n_types2: usize,
    body_start: usize,
}

fn parse_header(ctx: &Ctx, lines: &[&str]) -> Result<HeaderOut, RinexError> {
    let mut h = ObsHeader {
        version: 0.0,
        marker_name: String::new(),
        receiver_type: String::new(),
        approx_position_e_m: None,
        antenna_delta_hen_m: [0.0; 3],
        gps_types: Vec::new(),
        interval_s: None,
        first_obs: None,
    };
    let mut n_types2 = 0usize;
    let mut types2: Vec<ObsCode> = Vec::new();
    let mut pending3: Option<(u8, usize)> = None;
    for (i, line) in lines.iter().enumerate() {
        let ln = i + 1;
        let label = col(line, 60, 80).trim();
        match label {
            "RINEX VERSION / TYPE" => {
                h.version = ctx.f64(ln, line, 0, 9, "RINEX VERSION")?;
                if col(line, 20, 21) != "O" {
                    return Err(RinexError::Unsupported {
                        file: ctx.file.into(),
                        line: ln,
                        what: format!(
                            "file type {:?} (not an observation file)",
                            col(line, 20, 21)
                        ),
                    });
                }
                if !(2.0..4.0).contains(&h.version) {
                    return Err(RinexError::Unsupported {
                        file: ctx.file.into(),
                        line: ln,
                        what: format!("RINEX version {}", h.version),
                    });
                }
            }
            "MARKER NAME" => h.marker_name = col(line, 0, 60).trim().to_string(),
            "REC # / TYPE / VERS" => h.receiver_type = col(line, 20, 40).trim().to_string(),
            "APPROX POSITION XYZ" => {
                h.approx_position_e_m = Some([
                    ctx.f64(ln, line, 0, 14, "APPROX POSITION X")?,
                    ctx.f64(ln, line, 14, 28, "APPROX POSITION Y")?,
                    ctx.f64(ln, line, 28, 42, "APPROX POSITION Z")?,
                ]);
            }
            "ANTENNA: DELTA H/E/N" => {
                for (k, f) in ["ANTENNA DELTA H", "ANTENNA DELTA E", "ANTENNA DELTA N"]
                    .iter()
                    .enumerate()
                {
                    h.antenna_delta_hen_m[k] = ctx
                        .opt_f64(ln, line, 14 * k, 14 * k + 14, f)?
                        .unwrap_or(0.0);
                }
            }
            "# / TYPES OF OBSERV" => {
                if col(line, 0, 6).trim().is_empty() {
                    // continuation line
                } else {
                    let n = ctx.int(ln, line, 0, 6, "# / TYPES OF OBSERV")?;
                    if !(0..=999).contains(&n) {
                        return Err(ctx.field_err(ln, "# / TYPES OF OBSERV", format!("{n}")));
                    }
                    n_types2 = n as usize;
                }
                for k in 0..9 {
                    let t = col(line, 10 + 6 * k, 12 + 6 * k).trim();
                    if !t.is_empty() && types2.len() < n_types2 {
                        types2.push(ObsCode::from_rinex2(t));
                    }
                }
            }
            "SYS / # / OBS TYPES" => {
                let sys = col(line, 0, 1).as_bytes().first().copied().unwrap_or(b' ');
                let (sys, n) = if sys == b' ' {
                    match pending3 {
                        Some(p) => p,
                        None => {
                            return Err(ctx.field_err(
                                ln,
                                "SYS / # / OBS TYPES",
                                "continuation line without a system",
                            ))
                        }
                    }
                } else {
                    let n = ctx.int(ln, line, 3, 6, "SYS / # / OBS TYPES count")?;
                    if !(0..=999).contains(&n) {
                        return Err(ctx.field_err(ln, "SYS / # / OBS TYPES count", format!("{n}")));
                    }
                    (sys, n as usize)
                };
                pending3 = Some((sys, n));
                if sys == b'G' {
                    for k in 0..13 {
                        let t = col(line, 7 + 4 * k, 10 + 4 * k).trim();
                        if !t.is_empty() && h.gps_types.len() < n {
                            let code = ObsCode::new(t).ok_or_else(|| {
                                ctx.field_err(ln, "SYS / # / OBS TYPES", format!("bad code {t:?}"))
                            })?;
                            h.gps_types.push(code);
                        }
                    }
                }
            }
            "INTERVAL" => h.interval_s = ctx.opt_f64(ln, line, 0, 10, "INTERVAL")?,
            "TIME OF FIRST OBS" => {
                let sys = col(line, 48, 51).trim();
                if !(sys.is_empty() || sys == "GPS") {
                    return Err(RinexError::Unsupported {
                        file: ctx.file.into(),
                        line: ln,
                        what: format!("time system {sys:?} (GPS only)"),
                    });
                }
                let c = [(0, 6), (6, 12), (12, 18), (18, 24), (24, 30), (30, 43)];
                h.first_obs = Some(time_field(ctx, ln, line, c, false)?);
            }
            "END OF HEADER" => {
                if h.version == 0.0 {
                    return Err(ctx.field_err(ln, "RINEX VERSION / TYPE", "missing"));
                }
                if h.version < 3.0 {
                    h.gps_types = types2;
                }
                return Ok(HeaderOut {
                    header: h,
                    n_types2,
                    body_start: i + 1,
                });
            }
            _ => {}
        }
    }
    Err(RinexError::Truncated {
        file: ctx.file.into(),
        line: lines.len(),
        what: "the header (no END OF HEADER)".into(),
    })
}

fn parse_value(
    ctx: &Ctx,
    ln: usize,
    line: &str,
    start: usize,
    code: &ObsCode,
) -> Result<Option<ObsValue>, RinexError> {
    let Some(v) = ctx.opt_f64(ln, line, start, start + 14, code.as_str())? else {
        return Ok(None);
    };
    if v == 0.0 {
        return Ok(None);
    }
    let digit = |c: &str| c.trim().parse::<u8>().ok();
    Ok(Some(ObsValue {
        value: v,
        lli: digit(col(line, start + 14, start + 15)),
        ssi: digit(col(line, start + 15, start + 16)),
    }))
}

/// Parses a RINEX observation file from bytes (non-ASCII bytes become spaces first);
/// `name` is used in error messages.
pub fn parse_obs(bytes: &[u8], name: &str) -> Result<ObsFile, RinexError> {
    let text = ascii_text(bytes);
    let lines: Vec<&str> = text.lines().map(|l| l.trim_end_matches('\r')).collect();
    let ctx = Ctx { file: name };
    let hd = parse_header(&ctx, &lines)?;
    let epochs = if hd.header.version >= 3.0 {
        parse_body3(&ctx, &lines, &hd)?
    } else {
        parse_body2(&ctx, &lines, &hd)?
    };
    Ok(ObsFile {
        header: hd.header,
        epochs,
    })
}

fn get_line<'a>(ctx: &Ctx, lines: &[&'a str], i: usize, what: &str) -> Result<&'a str, RinexError> {
    lines.get(i).copied().ok_or_else(|| RinexError::Truncated {
        file: ctx.file.into(),
        line: lines.len(),
        what: what.into(),
    })
}

fn parse_body2(ctx: &Ctx, lines: &[&str], hd: &HeaderOut) -> Result<Vec<ObsEpoch>, RinexError> {
    let ntypes = hd.n_types2;
    if ntypes == 0 || hd.header.gps_types.len() != ntypes {
        return Err(ctx.field_err(
            hd.body_start,
            "# / TYPES OF OBSERV",
            "missing or incomplete",
        ));
    }
    let lines_per_sat = ntypes.div_ceil(5);
    let mut out = Vec::new();
    let mut i = hd.body_start;
    while i < lines.len() {
        let line = lines[i];
        let ln = i + 1;
        if line.trim().is_empty() {
            i += 1;
            continue;
        }
        let flag = ctx.int(ln, line, 28, 29, "epoch flag").unwrap_or(0);
        let nsat = ctx.int(ln, line, 29, 32, "number of satellites")?;
        if !(0..=999).contains(&nsat) {
            return Err(ctx.field_err(ln, "number of satellites", format!("{nsat}")));
        }
        let nsat = nsat as usize;
        if (2..=5).contains(&flag) {
            i += 1 + nsat; // header records follow
            continue;
        }
        let t = time_field(
            ctx,
            ln,
            line,
            [(0, 3), (3, 6), (6, 9), (9, 12), (12, 15), (15, 26)],
            true,
        )?;
        let clk = ctx.opt_f64(ln, line, 68, 80, "receiver clock offset")?;
        // satellite list, 12 per line
        let mut ids: Vec<(u8, u8)> = Vec::with_capacity(nsat);
        let mut li = i;
        for k in 0..nsat {
            if k > 0 && k % 12 == 0 {
                li += 1;
            }
            let l = get_line(ctx, lines, li, "an epoch's satellite list")?;
            let s = col(l, 32 + 3 * (k % 12), 35 + 3 * (k % 12));
            let sys = s.as_bytes().first().copied().unwrap_or(b' ');
            let sys = if sys == b' ' { b'G' } else { sys };
            let prn = ctx.int(
                li + 1,
                l,
                33 + 3 * (k % 12),
                35 + 3 * (k % 12),
                "satellite number",
            )?;
            if !(1..=99).contains(&prn) {
                return Err(ctx.field_err(li + 1, "satellite number", format!("{prn}")));
            }
            ids.push((sys, prn as u8));
        }
        i = li + 1;
        let mut sats = Vec::new();
        for (sys, prn) in ids {
            let first = i;
            i += lines_per_sat;
            if flag == 6 || sys != b'G' {
                continue;
            }
            let mut values = Vec::with_capacity(ntypes);
            for (k, code) in hd.header.gps_types.iter().enumerate() {
                let li = first + k / 5;
                let l = get_line(ctx, lines, li, "an epoch's observations")?;
                values.push(parse_value(ctx, li + 1, l, 16 * (k % 5), code)?);
            }
            sats.push(SatObs { prn, values });
        }
        if i > lines.len() {
            return Err(RinexError::Truncated {
                file: ctx.file.into(),
                line: lines.len(),
                what: "an epoch's observations".into(),
            });
        }
        if flag <= 1 {
            out.push(ObsEpoch {
                t,
                flag: flag as u8,
                rx_clock_offset_s: clk,
                sats,
            });
        }
    }
    Ok(out)
}

fn parse_body3(ctx: &Ctx, lines: &[&str], hd: &HeaderOut) -> Result<Vec<ObsEpoch>, RinexError> {
    let ng = hd.header.gps_types.len();
    let mut out = Vec::new();
    let mut i = hd.body_start;
    while i < lines.len() {
        let line = lines[i];
        let ln = i + 1;
        if line.trim().is_empty() {
            i += 1;
            continue;
        }
        if !line.starts_with('>') {
            return Err(ctx.field_err(
                ln,
                "epoch record",
                format!("expected '>' at an epoch, found {:?}", line.trim_end()),
            ));
        }
        let flag = ctx.int(ln, line, 31, 32, "epoch flag")?;
        let nsat = ctx.int(ln, line, 32, 35, "number of satellites")?;
        if !(0..=999).contains(&nsat) {
            return Err(ctx.field_err(ln, "number of satellites", format!("{nsat}")));
        }
        let nsat = nsat as usize;
        i += 1;
        if flag >= 2 {
            i += nsat;
            continue;
        }
        let t = time_field(
            ctx,
            ln,
            line,
            [(2, 6), (7, 9), (10, 12), (13, 15), (16, 18), (18, 29)],
            false,
        )?;
        let clk = ctx.opt_f64(ln, line, 41, 56, "receiver clock offset")?;
        let mut sats = Vec::new();
        for _ in 0..nsat {
            let l = get_line(ctx, lines, i, "an epoch's observations")?;
            let lno = i + 1;
            i += 1;
            if !l.starts_with('G') {
                continue;
            }
            let prn = ctx.int(lno, l, 1, 3, "satellite number")?;
            if !(1..=99).contains(&prn) {
                return Err(ctx.field_err(lno, "satellite number", format!("{prn}")));
            }
            let mut values = Vec::with_capacity(ng);
            for (k, code) in hd.header.gps_types.iter().enumerate() {
                values.push(parse_value(ctx, lno, l, 3 + 16 * k, code)?);
            }
            sats.push(SatObs {
                prn: prn as u8,
                values,
            });
        }
        out.push(ObsEpoch {
            t,
            flag: flag as u8,
            rx_clock_offset_s: clk,
            sats,
        });
    }
    Ok(out)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    const V2: &str =
        "     2.11           OBSERVATION DATA    G (GPS)             RINEX VERSION / TYPE
TEST                                                        MARKER NAME
  4097216.6805  4429119.0287 -2065771.3676                  APPROX POSITION XYZ
     3    C1    P2    D1                                    # / TYPES OF OBSERV
  2015     1     8     0     0    0.0000000     GPS         TIME OF FIRST OBS
                                                            END OF HEADER
 15  1  8  0  0  0.0000000  0  2G02 05
  25127564.975 7  25127563.538          -12.5  
  21000000.125           0.000          300.25 
";

    #[test]
    fn rinex2_epoch_and_zero_as_missing() {
        let f = parse_obs(V2.as_bytes(), "t.o").unwrap();
        assert_eq!(
            f.header
                .gps_types
                .iter()
                .map(|c| c.to_string())
                .collect::<Vec<_>>(),
            ["C1C", "C2W", "D1C"]
        );
        assert_eq!(f.epochs.len(), 1);
        let e = &f.epochs[0];
        assert_eq!((e.t.week, e.t.sow_s), (1826, 345_600.0));
        assert_eq!(e.sats[0].prn, 2);
        assert_eq!(e.sats[1].prn, 5, "a blank system letter means GPS");
        let c1 = e.sats[0].values[0].unwrap();
        assert_eq!((c1.value, c1.lli, c1.ssi), (25_127_564.975, None, Some(7)));
        assert_eq!(e.sats[1].values[1], None);
        assert_eq!(e.sats[1].values[2].unwrap().value, 300.25);
    }

    /// Every single-character corruption and every truncation of a valid file parses or
    /// fails with a typed error: never a panic.
    #[test]
    fn corrupted_files_never_panic() {
        let b = V2.as_bytes();
        for i in 0..b.len() {
            for c in [b'x', b' ', b'9', b'-', b'\n', 0xd4] {
                let mut m = b.to_vec();
                m[i] = c;
                let _ = parse_obs(&m, "m.o");
            }
            let _ = parse_obs(&b[..i], "m.o");
        }
    }

    #[test]
    fn errors_name_file_line_and_field() {
        let bad = V2.replace("21000000.125", "21000x00.125");
        let e = parse_obs(bad.as_bytes(), "t.o").unwrap_err().to_string();
        assert_eq!(e, "t.o:9: C1C: not a number: \"21000x00.125\"");
        let cut: String = V2.lines().take(8).collect::<Vec<_>>().join("\n");
        let e = parse_obs(cut.as_bytes(), "t.o").unwrap_err().to_string();
        assert!(e.contains("file ends inside"), "{e}");
        let e = parse_obs(b"garbage", "t.o").unwrap_err().to_string();
        assert!(e.contains("END OF HEADER"), "{e}");
    }
}

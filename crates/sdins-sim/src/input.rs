//! Reading input files whole, with the cheap checks first: the readers of IMU, GNSS,
//! reference and parameter files parse the whole text in memory (a row of an IMU file
//! becomes 48 bytes of increments), so
//!
//! 1. a file above [`MAX_INPUT_BYTES`] is refused before it is opened;
//! 2. its first line is read alone (at most [`MAX_FIRST_LINE_BYTES`]) and refused, naming
//!    line 1, if it is not text (a NUL or another control byte than tab, vertical tab,
//!    form feed, carriage return or escape) or has no end within that many bytes; a reader
//!    may check its header there too ([`read_capped_with`]) — all before the rest is read;
//! 3. the rest is read into the same buffer, sized once from the file's length, and turned
//!    into text without a second copy ([`text_lossy`]), so a file of `n` bytes costs `n`
//!    bytes before parsing, not `2n`.

use std::io::Read;
use std::path::Path;

/// Largest input file read \[bytes\] (4 GiB: about 40 million IMU rows).
pub const MAX_INPUT_BYTES: u64 = 4 * 1024 * 1024 * 1024;

/// Longest first line \[bytes\]: every header and record line of the formats read is far
/// shorter; a first line without an end within this many bytes is not one of them.
pub const MAX_FIRST_LINE_BYTES: usize = 1024 * 1024;

/// Why a file was refused before it was read whole.
#[derive(Debug)]
pub enum Refused<E> {
    /// reading failed, or the file is too large or not text (kind `InvalidInput` or
    /// `InvalidData`, the message saying which)
    Io(std::io::Error),
    /// the reader's own check of the first line failed
    Header(E),
}

/// The file's bytes after the checks of the module documentation, or an I/O error (kind
/// `InvalidInput` when it is larger than [`MAX_INPUT_BYTES`], `InvalidData` when its first
/// line is not text), saying so.
pub fn read_capped(path: &Path) -> std::io::Result<Vec<u8>> {
    match read_capped_with(path, |_| Ok::<(), std::convert::Infallible>(())) {
        Ok(b) => Ok(b),
        Err(Refused::Io(e)) => Err(e),
        Err(Refused::Header(never)) => match never {},
    }
}

/// As [`read_capped`], with `check` run on the first line (lossy UTF-8, without its line
/// end) before the rest of the file is read.
pub fn read_capped_with<E>(
    path: &Path,
    check: impl FnOnce(&str) -> Result<(), E>,
) -> Result<Vec<u8>, Refused<E>> {
    let len = std::fs::metadata(path).map_err(Refused::Io)?.len();
    if len > MAX_INPUT_BYTES {
        return Err(Refused::Io(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                "the file is {:.2} GiB, more than the input cap of {} GiB (input files are read whole): split it",
                len as f64 / (1024.0 * 1024.0 * 1024.0),
                MAX_INPUT_BYTES / (1024 * 1024 * 1024)
            ),
        )));
    }
    let mut f = std::fs::File::open(path).map_err(Refused::Io)?;
    // the first line alone
    let mut buf: Vec<u8> = Vec::new();
    let first_end = loop {
        let start = buf.len();
        let want = (MAX_FIRST_LINE_BYTES + 1)
            .saturating_sub(start)
            .min(64 * 1024);
        let got = (&mut f)
            .take(want as u64)
            .read_to_end(&mut buf)
            .map_err(Refused::Io)?;
        if let Some(i) = buf[start..].iter().position(|&b| b == b'\n') {
            break start + i;
        }
        if got == 0 || buf.len() > MAX_FIRST_LINE_BYTES {
            break buf.len();
        }
    };
    let first = &buf[..first_end.min(buf.len())];
    let bad = |what: String| {
        Refused::Io(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("line 1: {what}: not a text file"),
        ))
    };
    if let Some(i) = first.iter().position(|&b| is_binary(b)) {
        let what = if first[i] == 0 {
            "a NUL byte".to_string()
        } else {
            format!("the control byte 0x{:02x}", first[i])
        };
        return Err(bad(format!("{what} at column {}", i + 1)));
    }
    if first_end > MAX_FIRST_LINE_BYTES {
        return Err(bad(format!(
            "no line end within the first {} MiB",
            MAX_FIRST_LINE_BYTES / (1024 * 1024)
        )));
    }
    let line = String::from_utf8_lossy(first);
    check(line.trim_end_matches('\r')).map_err(Refused::Header)?;
    // then one buffer for the whole file (the length may change meanwhile: it only sizes it)
    let cap = usize::try_from(len).unwrap_or(usize::MAX).saturating_add(1);
    buf.try_reserve_exact(cap.saturating_sub(buf.len()))
        .map_err(|e| {
            Refused::Io(std::io::Error::new(
                std::io::ErrorKind::OutOfMemory,
                format!("cannot hold the file in memory ({len} bytes): {e}"),
            ))
        })?;
    f.read_to_end(&mut buf).map_err(Refused::Io)?;
    Ok(buf)
}

/// Bytes that do not occur in text: C0 controls other than tab, line feed, vertical tab,
/// form feed, carriage return and escape.
fn is_binary(b: u8) -> bool {
    b < 0x20 && !matches!(b, b'\t' | b'\n' | 0x0b | 0x0c | b'\r' | 0x1b)
}

/// The bytes as text, invalid UTF-8 replaced by U+FFFD: no copy when they are valid.
pub fn text_lossy(bytes: Vec<u8>) -> String {
    match String::from_utf8(bytes) {
        Ok(s) => s,
        Err(e) => String::from_utf8_lossy(e.as_bytes()).into_owned(),
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn a_sparse_file_above_the_cap_is_refused_without_reading_it() {
        let p = std::env::temp_dir().join(format!("sdins-input-cap-{}", std::process::id()));
        let f = std::fs::File::create(&p).unwrap();
        f.set_len(MAX_INPUT_BYTES + 1).unwrap();
        let e = read_capped(&p).unwrap_err().to_string();
        assert!(e.contains("input cap of 4 GiB"), "{e}");
        let e = crate::io::imu_file::read_imu_file(&p, crate::io::imu_file::ImuFormat::Auto)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("input cap") && e.contains(&p.display().to_string()),
            "{e}"
        );
        std::fs::remove_file(&p).ok();
    }

    fn temp(name: &str, bytes: &[u8]) -> std::path::PathBuf {
        let p = std::env::temp_dir().join(format!("sdins-input-{name}-{}", std::process::id()));
        std::fs::write(&p, bytes).unwrap();
        p
    }

    #[test]
    fn the_first_line_is_checked_before_the_rest() {
        let p = temp("nul", b"t_s,a\x00b\n1,2\n");
        let e = read_capped(&p).unwrap_err().to_string();
        assert_eq!(e, "line 1: a NUL byte at column 6: not a text file");
        let long = vec![b'1'; MAX_FIRST_LINE_BYTES + 10];
        let p2 = temp("long", &long);
        let e = read_capped(&p2).unwrap_err().to_string();
        assert!(
            e.contains("line 1: no line end within the first 1 MiB"),
            "{e}"
        );
        // a NUL after line 1 is the parser's business; CRLF, tabs and no final newline pass
        let p3 = temp("ok", b"a,\tb\r\n1\x002");
        assert_eq!(read_capped(&p3).unwrap(), b"a,\tb\r\n1\x002");
        // the reader's check sees line 1 without its line end, before the rest is read
        let r = read_capped_with(&p3, |l| if l == "a,\tb" { Err(l.len()) } else { Ok(()) });
        assert!(matches!(r, Err(Refused::Header(4))));
        // a first line exactly at the cap passes
        let mut at_cap = vec![b'x'; MAX_FIRST_LINE_BYTES];
        at_cap.push(b'\n');
        let p4 = temp("cap", &at_cap);
        assert_eq!(read_capped(&p4).unwrap().len(), MAX_FIRST_LINE_BYTES + 1);
        for p in [p, p2, p3, p4] {
            std::fs::remove_file(p).ok();
        }
    }

    #[test]
    fn invalid_utf8_is_replaced_without_a_copy_when_valid() {
        let v = b"abc".to_vec();
        let ptr = v.as_ptr();
        let s = text_lossy(v);
        assert_eq!(s.as_ptr(), ptr);
        assert_eq!(text_lossy(vec![b'a', 0xff]), "a\u{fffd}");
    }
}

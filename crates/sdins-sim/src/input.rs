//! Reading input files whole, with a stated size cap: the readers of IMU, GNSS, reference
//! and parameter files parse the whole text in memory (a row of an IMU file becomes 48
//! bytes of increments), so a file above [`MAX_INPUT_BYTES`] is refused before it is read
//! instead of exhausting memory.

use std::path::Path;

/// Largest input file read \[bytes\] (4 GiB: about 40 million IMU rows).
pub const MAX_INPUT_BYTES: u64 = 4 * 1024 * 1024 * 1024;

/// The file's bytes, or an I/O error (kind `InvalidInput`) when it is larger than
/// [`MAX_INPUT_BYTES`], saying so.
pub fn read_capped(path: &Path) -> std::io::Result<Vec<u8>> {
    let len = std::fs::metadata(path)?.len();
    if len > MAX_INPUT_BYTES {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                "the file is {:.2} GiB, more than the input cap of {} GiB (input files are read whole): split it",
                len as f64 / (1024.0 * 1024.0 * 1024.0),
                MAX_INPUT_BYTES / (1024 * 1024 * 1024)
            ),
        ));
    }
    std::fs::read(path)
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
}

//! Output files: written to a temporary file in the same folder and renamed when
//! complete, so an interrupted run leaves either the whole file or none.

use crate::error::CliError;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// A file being written atomically: call [`AtomicFile::commit`] when done; dropping it
/// without committing removes the temporary file.
pub struct AtomicFile {
    tmp: PathBuf,
    dest: PathBuf,
    writer: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Start writing `dest` (its folder is created if missing).
    pub fn create(dest: &Path) -> Result<Self, CliError> {
        if let Some(dir) = dest.parent() {
            if dir.exists() && !dir.is_dir() {
                return Err(CliError::bad(format!(
                    "{}: the output folder is an existing file, not a folder",
                    dir.display()
                )));
            }
            if !dir.as_os_str().is_empty() {
                std::fs::create_dir_all(dir).map_err(|source| CliError::Io {
                    path: dir.to_path_buf(),
                    source,
                })?;
            }
        }
        let name = dest
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let tmp = dest.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
        let f = File::create(&tmp).map_err(|source| CliError::Io {
            path: tmp.clone(),
            source,
        })?;
        Ok(Self {
            tmp,
            dest: dest.to_path_buf(),
            writer: Some(BufWriter::with_capacity(1 << 20, f)),
        })
    }

    /// The buffered writer.
    pub fn writer(&mut self) -> &mut BufWriter<File> {
        // The writer is only taken by `commit`, which consumes self.
        match self.writer.as_mut() {
            Some(w) => w,
            None => unreachable!("AtomicFile writer used after commit"),
        }
    }

    /// Flush, sync and rename into place.
    pub fn commit(mut self) -> Result<(), CliError> {
        if let Some(mut w) = self.writer.take() {
            w.flush().map_err(|source| CliError::Io {
                path: self.tmp.clone(),
                source,
            })?;
            let f = w.into_inner().map_err(|e| CliError::Io {
                path: self.tmp.clone(),
                source: e.into_error(),
            })?;
            f.sync_all().map_err(|source| CliError::Io {
                path: self.tmp.clone(),
                source,
            })?;
        }
        std::fs::rename(&self.tmp, &self.dest).map_err(|source| CliError::Io {
            path: self.dest.clone(),
            source,
        })
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.writer.is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Write a whole string atomically.
pub fn write_string(dest: &Path, s: &str) -> Result<(), CliError> {
    let mut f = AtomicFile::create(dest)?;
    f.writer()
        .write_all(s.as_bytes())
        .map_err(|source| CliError::Io {
            path: dest.to_path_buf(),
            source,
        })?;
    f.commit()
}

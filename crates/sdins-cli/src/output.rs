//! Output files and folders.
//!
//! Each file is written to a temporary file and renamed when complete, so an interrupted
//! write leaves either the whole file or none ([`AtomicFile`]).
//!
//! A command's output folder is staged as a whole ([`claim`], then [`commit_all`] or
//! [`abort_all`], called by `main` after the command): every file the command writes below
//! a claimed folder goes to a staging folder `ROOT/.sdins-stage-PID/` instead, and only when
//! the command succeeded are the staged files renamed into place, so a failing run (an
//! error, SIGINT/SIGTERM, a full disk, a file-size limit) leaves the previous contents of
//! the folder untouched and no staged file behind. `ROOT/run.toml` ends with a
//! `[manifest]` table listing every file of the run (names relative to the folder, sizes
//! in bytes). Reusing a folder replaces the files of its previous run (those in its old
//! manifest; old files the new run does not write are removed) and refuses, with exit 2,
//! a folder holding any file that no manifest lists: sdins never deletes a user's files.
//! Output names cannot leave the folder (no `..`, no absolute paths), and default folder
//! names derived from scenario names keep only `[A-Za-z0-9._-]` ([`default_dir`]).
//!
//! The renames of the swap do not allocate data blocks (one filesystem), so a full disk
//! cannot interrupt them; only a SIGKILL or power loss inside the swap (microseconds)
//! could leave a mix, and then the old `run.toml` (renamed last) still names the old set.

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
    /// Start writing `dest` (its folder is created if missing). Below a [`claim`]ed output
    /// folder the file goes to the folder's staging area until [`commit_all`].
    pub fn create(dest: &Path) -> Result<Self, CliError> {
        let dest = &route(dest)?;
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

    /// The file's final path (for messages).
    pub fn dest(&self) -> &Path {
        &self.dest
    }
    /// The buffered writer of the temporary file.
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

/// Name of a default output folder `sdins-out/{prefix}{name}`, with every character of
/// `name` outside `[A-Za-z0-9._-]` replaced by `_` and a leading dot by `_`, so that no
/// scenario name can place outputs elsewhere (`../x`, `/etc`, `a/b`).
pub fn default_dir(prefix: &str, name: &str) -> PathBuf {
    let mut safe: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if safe.starts_with('.') || safe.is_empty() {
        safe.insert(0, '_');
    }
    PathBuf::from("sdins-out").join(format!("{prefix}{safe}"))
}

/// Prefix of the staging folder inside an output folder.
const STAGE_PREFIX: &str = ".sdins-stage-";

/// One claimed output folder.
struct Stage {
    root: PathBuf,
    dir: PathBuf,
    created_root: bool,
    old: Vec<String>,
    /// `dir/.lock`, flock'ed (exclusive) for the life of the run: a stage folder whose lock
    /// another process can take is a dead run's leftover ([`remove_stale_stages`])
    _lock: File,
}

thread_local! {
    /// The claimed folders of the command running on this thread (the CLI writes its
    /// outputs from the thread that runs the command; unit tests run commands side by side
    /// on separate threads).
    static STAGES: std::cell::RefCell<Vec<Stage>> = const { std::cell::RefCell::new(Vec::new()) };
}

fn with_stages<R>(f: impl FnOnce(&mut Vec<Stage>) -> R) -> R {
    STAGES.with(|s| f(&mut s.borrow_mut()))
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> CliError + '_ {
    move |source| CliError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Files below `dir`, as `/`-separated relative names with sizes, sorted; staging folders
/// and sub-folders holding their own manifest (`sdins montecarlo --out mc/shard0` inside
/// an `mc` run folder) are skipped.
fn list_files(dir: &Path) -> Result<Vec<(String, u64)>, CliError> {
    fn walk(base: &Path, rel: &str, out: &mut Vec<(String, u64)>) -> Result<(), CliError> {
        let here = if rel.is_empty() {
            base.to_path_buf()
        } else {
            base.join(rel)
        };
        for e in std::fs::read_dir(&here).map_err(io(&here))? {
            let e = e.map_err(io(&here))?;
            let name = e.file_name().to_string_lossy().into_owned();
            if rel.is_empty() && name.starts_with(STAGE_PREFIX) {
                continue;
            }
            let r = if rel.is_empty() {
                name
            } else {
                format!("{rel}/{name}")
            };
            let ft = e.file_type().map_err(io(&e.path()))?;
            if ft.is_dir() {
                // a nested folder of another sdins run (its own manifest) is neither this
                // run's nor a user's: left alone
                if read_manifest(&e.path()).is_none() {
                    walk(base, &r, out)?;
                }
            } else {
                let len = e.metadata().map(|m| m.len()).unwrap_or(0);
                out.push((r, len));
            }
        }
        Ok(())
    }
    let mut v = Vec::new();
    walk(dir, "", &mut v)?;
    v.sort();
    Ok(v)
}

/// Why a `[manifest]` name may not be deleted by a later run: it must be a relative path of
/// plain components (no `..`, no absolute path, no `.`) whose folders inside `root` are real
/// folders, not symbolic links leading elsewhere. None if it is safe.
fn unsafe_manifest_name(root: &Path, name: &str) -> Option<&'static str> {
    use std::path::Component;
    let p = Path::new(name);
    if name.is_empty() || p.is_absolute() || name.starts_with('/') {
        return Some("an absolute or empty path");
    }
    if !p.components().all(|c| matches!(c, Component::Normal(_))) {
        return Some("a path with `..` or `.`");
    }
    // every folder on the way must be a real folder inside root (a symbolic link would lead
    // the removal out of the output folder); the file itself may be a link: removing a link
    // removes the link, not its target
    let mut dir = root.to_path_buf();
    let comps: Vec<_> = p.components().collect();
    for c in &comps[..comps.len().saturating_sub(1)] {
        dir.push(c);
        match std::fs::symlink_metadata(&dir) {
            Ok(m) if m.file_type().is_symlink() => return Some("a path through a symbolic link"),
            _ => {}
        }
    }
    None
}

/// Refuse (exit 2) a folder whose `run.toml` manifest names a file outside it: a later run
/// removes the files of the previous manifest, so such a name (hand-edited or planted) would
/// make sdins delete a file outside the output folder.
fn check_manifest(root: &Path, names: &[String]) -> Result<(), CliError> {
    for n in names {
        if let Some(why) = unsafe_manifest_name(root, n) {
            return Err(CliError::bad(format!(
                "{}: its [manifest] lists {:?}, {why}: sdins only ever replaces files inside the output folder, so it refuses this folder (fix or remove run.toml)",
                root.join("run.toml").display(),
                n
            )));
        }
    }
    Ok(())
}

/// Remove the staging folders of dead runs in `root` (a notice on stderr for each): a stage
/// folder whose `.lock` can be locked belongs to no running process (a killed or crashed
/// run); a locked one belongs to a running sdins and is never touched.
fn remove_stale_stages(root: &Path) {
    let Ok(entries) = std::fs::read_dir(root) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if !name.starts_with(STAGE_PREFIX) || !e.file_type().is_ok_and(|t| t.is_dir()) {
            continue;
        }
        let lock_path = e.path().join(".lock");
        let stale = match File::open(&lock_path) {
            Ok(f) => try_lock(&f),
            // no lock file: a stage of an older sdins or one killed before locking
            Err(_) => true,
        };
        if stale && std::fs::remove_dir_all(e.path()).is_ok() {
            eprintln!(
                "sdins: note: removed {}, the staging folder of a run that did not finish",
                e.path().display()
            );
        }
    }
}

/// Take an exclusive `flock` on `f` without waiting; true if taken. Released when `f` is
/// closed, i.e. at the latest when the process ends, however it ends.
fn try_lock(f: &File) -> bool {
    use std::os::fd::AsRawFd;
    // SAFETY: flock on a file descriptor owned by `f`, valid for the call.
    #[allow(unsafe_code)]
    let r = unsafe { libc::flock(f.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
    r == 0
}

/// The file names of the `[manifest]` of `root/run.toml`, or None if there is none.
fn read_manifest(root: &Path) -> Option<Vec<String>> {
    let text = std::fs::read_to_string(root.join("run.toml")).ok()?;
    let t: toml::Table = text.parse().ok()?;
    let files = t.get("manifest")?.get("files")?.as_array()?;
    Some(
        files
            .iter()
            .filter_map(|f| f.get("name")?.as_str().map(str::to_string))
            .collect(),
    )
}

/// Claim `root` as this command's output folder: refuse it if it is a file or holds files
/// that its `run.toml` manifest does not list (exit 2, naming them), then create its
/// staging folder. A folder inside an already claimed one is part of that one's run.
pub fn claim(root: &Path) -> Result<(), CliError> {
    if with_stages(|st| st.iter().any(|s| root.starts_with(&s.root))) {
        return Ok(());
    }
    let stage = claim_new(root)?;
    with_stages(|st| st.push(stage));
    Ok(())
}

fn claim_new(root: &Path) -> Result<Stage, CliError> {
    if root.exists() && !root.is_dir() {
        return Err(CliError::bad(format!(
            "{}: the output folder is an existing file, not a folder",
            root.display()
        )));
    }
    let created_root = !root.exists();
    let mut old = Vec::new();
    if !created_root {
        let present = list_files(root)?;
        let listed = read_manifest(root);
        let known: Vec<String> = listed.clone().unwrap_or_default();
        let foreign: Vec<&str> = present
            .iter()
            .map(|(n, _)| n.as_str())
            .filter(|n| !(known.iter().any(|k| k == n) || (listed.is_some() && *n == "run.toml")))
            .collect();
        if !foreign.is_empty() {
            let shown: Vec<&str> = foreign.iter().take(10).copied().collect();
            return Err(CliError::bad(format!(
                "{}: the output folder holds {} file(s) that no sdins run.toml manifest lists ({}{}); sdins never deletes them: choose another --out or move them",
                root.display(),
                foreign.len(),
                shown.join(", "),
                if foreign.len() > shown.len() { ", ..." } else { "" }
            )));
        }
        check_manifest(root, &known)?;
        remove_stale_stages(root);
        old = known;
        if listed.is_some() {
            old.push("run.toml".into());
        }
    }
    std::fs::create_dir_all(root).map_err(io(root))?;
    let dir = root.join(format!("{STAGE_PREFIX}{}", std::process::id()));
    if dir.exists() {
        // this PID's folder from a dead process (PIDs are reused): not locked by anyone
        let _ = std::fs::remove_dir_all(&dir);
    }
    std::fs::create_dir(&dir).map_err(io(&dir))?;
    let lock_path = dir.join(".lock");
    let lock = File::create(&lock_path).map_err(io(&lock_path))?;
    if !try_lock(&lock) {
        return Err(CliError::Other(format!(
            "{}: cannot lock the staging folder",
            dir.display()
        )));
    }
    Ok(Stage {
        root: root.to_path_buf(),
        dir,
        created_root,
        old,
        _lock: lock,
    })
}

/// Where a file meant for `dest` is written: inside the staging folder of the claimed
/// output folder that holds it, else `dest` itself. A name that would leave the claimed
/// folder (`..`, an absolute path) is refused (exit 2).
pub fn route(dest: &Path) -> Result<PathBuf, CliError> {
    use std::path::Component;
    with_stages(|st| {
        for s in st.iter() {
            if let Ok(rel) = dest.strip_prefix(&s.root) {
                if rel.as_os_str().is_empty()
                    || !rel.components().all(|c| matches!(c, Component::Normal(_)))
                {
                    return Err(CliError::bad(format!(
                        "{}: output name leaves the output folder {}",
                        dest.display(),
                        s.root.display()
                    )));
                }
                return Ok(s.dir.join(rel));
            }
        }
        Ok(dest.to_path_buf())
    })
}

/// The `[manifest]` table of a run: every file with its size in bytes.
fn manifest_text(files: &[(String, u64)]) -> String {
    let mut s = String::from("\n[manifest]\n# every file sdins wrote in this run (besides run.toml); a later run into this folder replaces them\nfiles = [\n");
    for (name, bytes) in files {
        s.push_str(&format!(
            "  {{ name = {}, bytes = {bytes} }},\n",
            toml::Value::String(name.clone())
        ));
    }
    s.push_str("]\n");
    s
}

fn commit_one(s: &Stage) -> Result<(), CliError> {
    let files: Vec<(String, u64)> = list_files(&s.dir)?
        .into_iter()
        .filter(|(n, _)| n != "run.toml" && n != ".lock")
        .collect();
    // run.toml: the command's own, or a minimal one, followed by the manifest
    let staged_toml = s.dir.join("run.toml");
    let mut text = if staged_toml.exists() {
        std::fs::read_to_string(&staged_toml).map_err(io(&staged_toml))?
    } else {
        let mut t = toml::Table::new();
        t.insert("sdins_version".into(), env!("CARGO_PKG_VERSION").into());
        t.insert("git_commit".into(), crate::provenance::git_commit().into());
        t.insert("command".into(), crate::provenance::command_line().into());
        toml::to_string(&t).map_err(|e| CliError::Other(e.to_string()))?
    };
    text.push_str(&manifest_text(&files));
    let mut f = AtomicFile::create(&staged_toml)?;
    f.writer()
        .write_all(text.as_bytes())
        .map_err(io(&staged_toml))?;
    f.commit()?;
    // swap: the new files, then the old run's leftovers out, run.toml last
    for (name, _) in &files {
        let to = s.root.join(name);
        if let Some(p) = to.parent() {
            std::fs::create_dir_all(p).map_err(io(p))?;
        }
        std::fs::rename(s.dir.join(name), &to).map_err(io(&to))?;
    }
    for name in &s.old {
        if name != "run.toml" && !files.iter().any(|(n, _)| n == name) {
            let p = s.root.join(name);
            let _ = std::fs::remove_file(&p);
            // prune folders the old run created and left empty
            let mut d = p.parent();
            while let Some(dir) = d {
                if dir == s.root || std::fs::remove_dir(dir).is_err() {
                    break;
                }
                d = dir.parent();
            }
        }
    }
    let to = s.root.join("run.toml");
    std::fs::rename(&staged_toml, &to).map_err(io(&to))?;
    let _ = std::fs::remove_dir_all(&s.dir);
    Ok(())
}

fn discard(s: &Stage) {
    let _ = std::fs::remove_dir_all(&s.dir);
    if s.created_root {
        // only removes the folder if the run left it empty
        let _ = std::fs::remove_dir(&s.root);
    }
}

/// Swap every claimed folder's staged files in (called once the command succeeded). On a
/// failure the staging folders are removed and the error returned.
pub fn commit_all() -> Result<(), CliError> {
    let taken: Vec<Stage> = with_stages(std::mem::take);
    let mut result = Ok(());
    for s in &taken {
        if result.is_ok() {
            result = commit_one(s);
        }
        if result.is_err() {
            discard(s);
        }
    }
    result
}

/// Remove every staging folder (the command failed): the output folders keep their
/// previous contents.
pub fn abort_all() {
    let taken: Vec<Stage> = with_stages(std::mem::take);
    for s in &taken {
        discard(s);
    }
}

/// Finish a command: swap its staged outputs in if it succeeded ([`commit_all`]), discard
/// them if it failed ([`abort_all`]).
pub fn finish(result: Result<(), CliError>) -> Result<(), CliError> {
    match result {
        Ok(()) => commit_all(),
        // the result failed its own checks: its outputs are kept (exit 3)
        Err(e @ CliError::ResultFailedChecks(_)) => {
            commit_all()?;
            Err(e)
        }
        Err(e) => {
            abort_all();
            Err(e)
        }
    }
}

/// Largest number of data rows sdins writes to one output file.
pub const MAX_ROWS_PER_FILE: f64 = 1e8;
/// Largest estimated size of one output file \[bytes\] (20 GiB).
pub const MAX_BYTES_PER_FILE: f64 = 20.0 * 1024.0 * 1024.0 * 1024.0;

/// Refuse (exit 2), before anything is written, an output file that would hold more than
/// [`MAX_ROWS_PER_FILE`] rows or an estimated [`MAX_BYTES_PER_FILE`] bytes (`rows` ×
/// `bytes_per_row`); the message gives the estimate and what to change (`option`).
pub fn check_size(file: &str, rows: f64, bytes_per_row: f64, option: &str) -> Result<(), CliError> {
    let bytes = rows * bytes_per_row;
    if rows.is_finite() && rows <= MAX_ROWS_PER_FILE && bytes <= MAX_BYTES_PER_FILE {
        return Ok(());
    }
    Err(CliError::bad(format!(
        "{file} would hold about {rows:.3e} rows ({:.1} GiB), more than the cap of {MAX_ROWS_PER_FILE:.0e} rows or {:.0} GiB per file: {option}",
        bytes / (1024.0 * 1024.0 * 1024.0),
        MAX_BYTES_PER_FILE / (1024.0 * 1024.0 * 1024.0)
    )))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("sdins-output-unit-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    #[test]
    fn default_dirs_and_names_cannot_leave_the_output_folder() {
        assert_eq!(
            default_dir("run-", "turn-90dps"),
            Path::new("sdins-out/run-turn-90dps")
        );
        for evil in ["../../etc", "/etc/passwd", "a/b", "..", "", "x\\..\\y"] {
            let p = default_dir("", evil);
            assert_eq!(
                p.parent(),
                Some(Path::new("sdins-out")),
                "{evil} → {}",
                p.display()
            );
            let last = p.file_name().unwrap().to_string_lossy().into_owned();
            assert!(
                !last.starts_with('.') && !last.contains('/'),
                "{evil} → {last}"
            );
        }
        let root = tmp("route");
        claim(&root).unwrap();
        for bad in ["../x.csv", "a/../../x.csv"] {
            let e = route(&root.join(bad)).unwrap_err();
            assert_eq!(e.exit_code(), 2, "{bad}");
        }
        let ok = route(&root.join("sub/x.csv")).unwrap();
        assert!(ok.starts_with(&root) && ok.to_string_lossy().contains(STAGE_PREFIX));
        abort_all();
        assert!(!root.exists(), "a folder the failed run created is removed");
    }

    #[test]
    fn a_write_that_hits_dev_full_leaves_the_previous_run() {
        let root = tmp("devfull");
        claim(&root).unwrap();
        write_string(&root.join("a.csv"), "old a\n").unwrap();
        commit_all().unwrap();
        let before_a = std::fs::read_to_string(root.join("a.csv")).unwrap();
        let before_toml = std::fs::read_to_string(root.join("run.toml")).unwrap();

        claim(&root).unwrap();
        write_string(&root.join("a.csv"), "new a\n").unwrap();
        // the next staged file's temporary name is a symbolic link to /dev/full: its
        // writes fail with ENOSPC, as on a full disk
        let staged = route(&root.join("b.csv")).unwrap();
        let tmp_name = staged.with_file_name(format!(".b.csv.tmp-{}", std::process::id()));
        std::os::unix::fs::symlink("/dev/full", &tmp_name).unwrap();
        let e = finish(write_string(&root.join("b.csv"), &"x".repeat(1 << 21))).unwrap_err();
        assert!(e.to_string().contains("No space left"), "{e}");
        assert_eq!(
            std::fs::read_to_string(root.join("a.csv")).unwrap(),
            before_a
        );
        assert_eq!(
            std::fs::read_to_string(root.join("run.toml")).unwrap(),
            before_toml
        );
        let names: Vec<String> = std::fs::read_dir(&root)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names.len(), 2, "{names:?}");
        let _ = std::fs::remove_dir_all(&root);
    }
}

//! Provenance of an output folder: the commit, the command line and the scenario text
//! that `run.toml` records.

/// The git commit sdins was built from, if known at build time.
pub fn git_commit() -> &'static str {
    option_env!("SDINS_GIT_COMMIT").unwrap_or("unknown")
}

/// The command line of this process, space-separated (arguments that are not UTF-8 are
/// shown lossily, U+FFFD for each bad byte sequence: `env::args` would panic on them).
pub fn command_line() -> String {
    std::env::args_os()
        .map(|a| a.to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join(" ")
}

/// The text of a scenario as given on the command line: a built-in scenario's TOML, or
/// the file's content (empty if it cannot be read any more).
pub fn scenario_text(name_or_file: &str) -> String {
    match sdins_sim::scenario::builtin(name_or_file) {
        Some(b) => b.toml.to_string(),
        None => std::fs::read_to_string(name_or_file).unwrap_or_default(),
    }
}

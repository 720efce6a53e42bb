//! Every documented command runs (release, `#[ignore]`; CI runs it with
//! `cargo test --release --workspace -- --ignored`).
//!
//! The commands are extracted from the fenced code blocks of `README.md` and `docs/**/*.md`
//! (lines starting with `sdins `, `$ sdins `, `target/release/sdins ` or
//! `cargo run --release -p sdins-cli -- `, continuation lines joined, `# comments` dropped,
//! `NAME=value` lines of the same block kept as a prelude) and from the `Example:` /
//! `Examples:` section of every subcommand's `--help`. Each runs under `bash -c` in one
//! scratch folder (so `> my.toml` and `{0..7}` work as written), with `sdins` on `PATH`,
//! shortened by [`RULES`] where needed, within [`PER_COMMAND_S`] seconds each and
//! [`TOTAL_S`] in all. Commands that need `../shared/data` are skipped, with the reason
//! printed, only when that folder is absent.
//!
//! **Keeping it up to date:** a new documented command needs nothing unless it is slow,
//! needs an input file, or needs data: then add one line to [`RULES`].
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// Time limit per command [s] (the issue's "≤ 10 s each").
const PER_COMMAND_S: u64 = 10;
/// Time limit for all commands together [s] (the issue's "≤ 4 min in all").
const TOTAL_S: f64 = 240.0;

/// What a rule does to a command that contains its pattern.
#[derive(Clone, Copy, Debug)]
enum Action {
    /// replace the first text with the second
    Replace(&'static str, &'static str),
    /// add arguments (before any `>` or `|`) unless the first text is already there
    AppendUnless(&'static str, &'static str),
    /// run this shell command first in the scratch folder (untimed, 60 s limit)
    Before(&'static str),
    /// needs this path under `../shared/data`; skipped when it is absent
    NeedsData(&'static str),
    /// not run here, for the reason given
    Skip(&'static str),
}

/// One rule: applied, in list order, to every command containing `pattern`.
struct Rule {
    pattern: &'static str,
    action: Action,
}

const fn rule(pattern: &'static str, action: Action) -> Rule {
    Rule { pattern, action }
}

use Action::*;

/// The one list of per-command shortening and preparation rules.
const RULES: &[Rule] = &[
    // the full demo runs every paper case at full length (minutes)
    rule(
        "sdins demo",
        Skip("runs every paper case at full length; tests/demo.rs runs it (release, --ignored)"),
    ),
    rule("SLURM", Skip("a line of a SLURM batch script")),
    // 90-minute scenarios: the first minute shows that the command works
    rule("sdins run ", AppendUnless("--until-s", " --until-s 60")),
    // Monte Carlo: runs come in blocks of 16 and every shard needs one, so 128 runs
    // serve up to 8 shards; 10 s of each run
    rule("sdins montecarlo ", Replace("--runs 1000", "--runs 128")),
    rule("sdins montecarlo ", Replace("--runs 100 ", "--runs 16 ")),
    rule("sdins montecarlo ", Replace("--until-s 600", "--until-s 10")),
    rule("sdins montecarlo ", AppendUnless("--until-s", " --until-s 10")),
    // inputs the examples assume
    rule(
        "my.toml",
        Before("test -f my.toml || sdins scenarios mach1-east > my.toml"),
    ),
    rule(
        "my-cal.toml",
        Before("test -f my-cal.toml || sdins scenarios calibration > my-cal.toml"),
    ),
    // a street canyon: 60 s at 10 m/s with a sky mask (docs/scenarios.md `[raw_gnss]`)
    rule(
        "canyon.toml",
        Before("test -f canyon.toml || printf '%s\\n' 'name = \"canyon\"' '[start]' 'lat_deg = 45.0' 'lon_deg = 10.0' 'speed_mps = 10.0' '[imu]' 'rate_hz = 100.0' '[[segment]]' 'type = \"cruise\"' 'duration_s = 60.0' '[raw_gnss]' 'sky_mask_az_el_deg = [[0.0, 15.0], [80.0, 60.0], [100.0, 60.0], [180.0, 15.0], [260.0, 60.0], [280.0, 60.0]]' > canyon.toml"),
    ),
    rule(
        "--imu cal-imu/imu.csv",
        Before("test -f cal-imu/imu.csv || sdins truth calibration --out cal-imu --every 100 --quiet"),
    ),
    rule(
        "--imu imu.csv",
        Before("test -f imu.csv || sdins truth turn-90dps --out . --quiet"),
    ),
    // a recorded trajectory in a CSV of its own: sdins's truth with other column names
    rule(
        "--from-reference log.csv",
        Before("test -f log.csv || (sdins truth turn-90dps --out lg --quiet && sed '1s/.*/time,lat,lon,alt,vn,ve,vd,roll,pitch,yaw,qw,qx,qy,qz/' lg/truth.csv > log.csv)"),
    ),
    rule(
        "sdins merge mc/shard0 mc/shard1 mc/shard2 mc/shard3 ",
        Before("rm -rf mc && for i in 0 1 2 3; do sdins montecarlo mach1-east --runs 64 --seed 1 --until-s 5 --shard $i/4 --out mc/shard$i --quiet; done"),
    ),
    rule(
        "sdins merge mc/shard{0..7}",
        Before("rm -rf mc && for i in 0 1 2 3 4 5 6 7; do sdins montecarlo mach1-east --grade aviation --runs 128 --seed 1 --until-s 5 --shard $i/8 --out mc/shard$i --quiet; done"),
    ),
    // files of ../shared/data named without their folder in the --help examples
    rule(
        "trj10ms_imu.csv",
        Replace(" trj10ms_imu.csv", " ../shared/data/csv/psins/trj10ms_imu.csv"),
    ),
    rule(
        "trj10ms_avp.csv",
        Replace(" trj10ms_avp.csv", " ../shared/data/csv/psins/trj10ms_avp.csv"),
    ),
    rule("trj10ms_", NeedsData("csv/psins/trj10ms_imu.csv")),
    rule(
        "lasergyro.imu",
        Replace(" lasergyro.imu", " ../shared/data/psins/lasergyro.imu"),
    ),
    rule("lasergyro.imu", NeedsData("psins/lasergyro.imu")),
    rule(
        "motion_def-3d.csv",
        Replace(" motion_def-3d.csv", " ../shared/data/gnss_ins_sim/motion_def-3d.csv"),
    ),
    rule("gnss_ins_sim/", NeedsData("gnss_ins_sim/motion_def-3d.csv")),
    // the NaveGo reference of `sdins truth --help`
    rule(
        "--from-reference ref.csv",
        Replace(" ref.csv", " ../shared/data/csv/navego/ref.csv"),
    ),
    // the NaveGo example of `sdins fuse --help`
    rule(
        "imu1_params.txt",
        Replace(" imu1.csv", " ../shared/data/csv/navego/imu1.csv"),
    ),
    rule(
        "imu1_params.txt",
        Replace(" gnss.csv", " ../shared/data/csv/navego/gnss.csv"),
    ),
    rule(
        "imu1_params.txt",
        Replace(" ref.csv", " ../shared/data/csv/navego/ref.csv"),
    ),
    rule(
        "imu1_params.txt",
        Replace(" imu1_params.txt", " ../shared/data/csv/navego/imu1_params.txt"),
    ),
    rule("csv/navego/", NeedsData("csv/navego/imu1.csv")),
    // the RINEX files of the IGS station ABPO
    rule(
        " abpo0080.15o",
        Replace(" abpo0080.15o", " ../shared/data/psins_gnss/abpo0080.15o"),
    ),
    rule(
        " abpo0080.15n",
        Replace(" abpo0080.15n", " ../shared/data/psins_gnss/abpo0080.15n"),
    ),
    rule("psins_gnss/abpo", NeedsData("psins_gnss/abpo0080.15o")),
    // fuse Monte Carlo shards to merge: two small ones
    rule(
        "sdins fuse --merge mc/s0 mc/s1 ",
        Before("rm -rf mc && for i in 0 1; do sdins fuse dq-paper --grade tactical --no-gate --runs 32 --seed 1 --until-s 5 --shard $i/2 --out mc/s$i; done"),
    ),
    // a logger's own files, described in docs/own-data.md: tests/own_data_cli.rs writes
    // such files and runs these maps (worked_example_matches_sdins_files)
    rule(
        "--imu rates.csv",
        Skip("a logger's own files; own_data_cli runs the same maps on generated files"),
    ),
    rule(
        "--imu imu.txt",
        Skip("a logger's own files; own_data_cli runs the same maps on generated files"),
    ),
    rule("../shared/data", NeedsData("")),
];

/// A documented command and where it was found.
#[derive(Clone, Debug)]
struct Doc {
    source: String,
    /// `NAME=value` lines of the same code block
    prelude: Vec<String>,
    command: String,
}

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// `sdins …` with the invocation prefixes normalised, or `None` if the line is no command.
fn normalise(line: &str) -> Option<String> {
    let l = line.trim();
    let l = l.strip_prefix("$ ").unwrap_or(l).trim_start();
    let l = l.strip_prefix("time ").unwrap_or(l);
    for prefix in [
        "cargo run --release -p sdins-cli -- ",
        "cargo run -p sdins-cli -- ",
        "target/release/sdins ",
        "./target/release/sdins ",
    ] {
        if let Some(rest) = l.strip_prefix(prefix) {
            return Some(format!("sdins {rest}"));
        }
    }
    (l.starts_with("sdins ") || l == "sdins").then(|| l.to_string())
}

/// Drop a trailing `# comment` (a `#` after whitespace, outside quotes).
fn strip_comment(s: &str) -> String {
    let mut quote = None;
    let b: Vec<char> = s.chars().collect();
    for (i, &c) in b.iter().enumerate() {
        match (quote, c) {
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), c) if c == q => quote = None,
            (None, '#') if i > 0 && b[i - 1].is_whitespace() => {
                return b[..i].iter().collect::<String>().trim_end().to_string();
            }
            _ => {}
        }
    }
    s.trim_end().to_string()
}

/// A synopsis rather than a command: `[options]`, `...`, or an upper-case placeholder.
fn is_synopsis(cmd: &str) -> bool {
    cmd.contains('[')
        || cmd.contains("...")
        || cmd.split_whitespace().any(|t| {
            !t.starts_with('$')
                && t.chars().any(|c| c.is_ascii_uppercase())
                && t.chars()
                    .all(|c| c.is_ascii_uppercase() || c == '_' || c == '.')
        })
}

/// Commands in the fenced code blocks of one markdown file.
fn from_markdown(path: &Path, name: &str) -> Vec<Doc> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut out = Vec::new();
    let mut in_block = false;
    let mut prelude: Vec<String> = Vec::new();
    let mut lines = text.lines().enumerate().peekable();
    while let Some((n, line)) = lines.next() {
        if line.trim_start().starts_with("```") {
            in_block = !in_block;
            prelude.clear();
            continue;
        }
        if !in_block {
            continue;
        }
        let t = line.trim();
        if let Some((var, _)) = t.split_once('=') {
            if !var.is_empty() && var.chars().all(|c| c.is_ascii_uppercase() || c == '_') {
                prelude.push(t.to_string());
                continue;
            }
        }
        let Some(mut cmd) = normalise(t) else {
            continue;
        };
        while cmd.ends_with('\\') {
            cmd.pop();
            match lines.next() {
                Some((_, next)) => cmd = format!("{} {}", cmd.trim_end(), next.trim()),
                None => break,
            }
        }
        out.push(Doc {
            source: format!("{name}:{}", n + 1),
            prelude: prelude.clone(),
            command: strip_comment(&cmd),
        });
    }
    out
}

fn markdown_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            markdown_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "md")
            // cli.md is the --help text, whose examples are taken from --help itself
            && p.file_name().is_some_and(|n| n != "cli.md")
        {
            out.push(p);
        }
    }
}

fn sdins_output(args: &[&str]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args(args)
        .output()
        .unwrap();
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The examples of every subcommand's `--help`.
fn from_help() -> Vec<Doc> {
    let top = sdins_output(&["--help"]);
    let cmds: Vec<String> = top
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .filter(|c| c != "help")
        .collect();
    assert!(cmds.len() >= 5, "no subcommands found in:\n{top}");
    let mut out = Vec::new();
    for c in cmds {
        let help = sdins_output(&[&c, "--help"]);
        let mut in_examples = false;
        for line in help.lines() {
            let t = line.trim();
            if let Some(rest) = t
                .strip_prefix("Examples:")
                .or_else(|| t.strip_prefix("Example:"))
            {
                in_examples = true;
                if let Some(cmd) = normalise(rest) {
                    out.push(Doc {
                        source: format!("sdins {c} --help"),
                        prelude: Vec::new(),
                        command: cmd,
                    });
                }
                continue;
            }
            if in_examples {
                match normalise(t) {
                    Some(cmd) => out.push(Doc {
                        source: format!("sdins {c} --help"),
                        prelude: Vec::new(),
                        command: cmd,
                    }),
                    None => in_examples = false,
                }
            }
        }
    }
    out
}

/// The command as run, the preparation commands, and the reason to skip it, if any.
fn apply_rules(cmd: &str, data: Option<&Path>) -> (String, Vec<&'static str>, Option<String>) {
    let mut c = cmd.to_string();
    let mut before = Vec::new();
    for r in RULES {
        if !c.contains(r.pattern) {
            continue;
        }
        match r.action {
            Replace(a, b) => c = c.replacen(a, b, 1),
            AppendUnless(present, extra) => {
                if !c.contains(present) {
                    let at = [" > ", " | ", " >> "]
                        .iter()
                        .filter_map(|s| c.find(s))
                        .min()
                        .unwrap_or(c.len());
                    c.insert_str(at, extra);
                }
            }
            Before(s) => before.push(s),
            NeedsData(p) => {
                let present = data.is_some_and(|d| d.join(p).exists());
                if !present {
                    return (
                        c,
                        before,
                        Some(format!("../shared/data/{p} is absent in this checkout")),
                    );
                }
            }
            Skip(why) => return (c, before, Some(why.to_string())),
        }
    }
    (c, before, None)
}

fn bash(script: &str, dir: &Path, limit_s: u64) -> (bool, String) {
    let bin = Path::new(env!("CARGO_BIN_EXE_sdins")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let o = Command::new("timeout")
        .arg(limit_s.to_string())
        .args(["bash", "-c", script])
        .current_dir(dir)
        .env("PATH", path)
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    (o.status.success(), text)
}

#[test]
fn markdown_extraction_and_rules() {
    let dir = std::env::temp_dir().join(format!("sdins-doc-md-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let md = dir.join("x.md");
    std::fs::write(
        &md,
        "sdins prose is not a command\n```sh\nD=../shared/data/csv\n$ sdins run mach1-east --algo savage # comment\nsdins nav --imu $D/a.csv \\\n  --format psins\nsdins montecarlo SCENARIO --runs N\ncargo run --release -p sdins-cli -- demo\n```\n",
    )
    .unwrap();
    let docs = from_markdown(&md, "x.md");
    let cmds: Vec<&str> = docs.iter().map(|d| d.command.as_str()).collect();
    assert_eq!(
        cmds,
        [
            "sdins run mach1-east --algo savage",
            "sdins nav --imu $D/a.csv --format psins",
            "sdins montecarlo SCENARIO --runs N",
            "sdins demo",
        ]
    );
    assert_eq!(docs[1].prelude, ["D=../shared/data/csv"]);
    assert!(is_synopsis(cmds[2]) && !is_synopsis(cmds[0]) && !is_synopsis(cmds[1]));
    let (c, _, skip) = apply_rules("sdins run mach1-east --json > out.json", None);
    assert_eq!(c, "sdins run mach1-east --json --until-s 60 > out.json");
    assert!(skip.is_none());
    let (_, _, skip) = apply_rules("sdins allan --imu lasergyro.imu", None);
    assert!(skip.unwrap().contains("absent"));
    let (_, _, skip) = apply_rules("sdins demo --out x", None);
    assert!(skip.is_some());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
#[ignore = "runs every documented command: release mode with --ignored"]
fn every_documented_command_runs() {
    let root = repo_root();
    let data_dir = root.join("../shared/data");
    let data = data_dir.is_dir().then_some(data_dir.as_path());
    if data.is_none() {
        println!("note: ../shared/data is absent: commands that need it are skipped");
    }
    let mut files = vec![root.join("README.md")];
    markdown_files(&root.join("docs"), &mut files);
    let mut docs = Vec::new();
    for f in &files {
        let name = f.strip_prefix(&root).unwrap_or(f).display().to_string();
        docs.extend(from_markdown(f, &name));
    }
    let help = from_help();
    assert!(help.len() >= 10, "too few --help examples: {help:?}");
    docs.extend(help);

    // scratch folder: <tmp>/repo is the working folder, <tmp>/shared links the data
    let tmp = std::env::temp_dir().join(format!("sdins-doc-cmds-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    let work = tmp.join("repo");
    std::fs::create_dir_all(&work).unwrap();
    if data.is_some() {
        std::os::unix::fs::symlink(
            root.join("../shared").canonicalize().unwrap(),
            tmp.join("shared"),
        )
        .unwrap();
    }

    let t_all = Instant::now();
    let (mut ran, mut skipped, mut failures) = (0, 0, Vec::new());
    for d in &docs {
        if is_synopsis(&d.command) {
            println!("synopsis  {:<28} {}", d.source, d.command);
            continue;
        }
        let (cmd, before, skip) = apply_rules(&d.command, data);
        if let Some(why) = skip {
            println!("skipped   {:<28} {}  ({why})", d.source, d.command);
            skipped += 1;
            continue;
        }
        for b in &before {
            let (ok, text) = bash(b, &work, 60);
            assert!(ok, "{}: preparation `{b}` failed:\n{text}", d.source);
        }
        let script = d
            .prelude
            .iter()
            .map(String::as_str)
            .chain([cmd.as_str()])
            .collect::<Vec<_>>()
            .join("\n");
        let t0 = Instant::now();
        let (ok, text) = bash(&script, &work, PER_COMMAND_S);
        let s = t0.elapsed().as_secs_f64();
        println!("{:>6.2} s  {:<28} {cmd}", s, d.source);
        ran += 1;
        if !ok {
            failures.push(format!(
                "{}: `{cmd}` failed or took more than {PER_COMMAND_S} s ({s:.1} s):\n{}",
                d.source,
                text.lines()
                    .rev()
                    .take(15)
                    .collect::<Vec<_>>()
                    .into_iter()
                    .rev()
                    .collect::<Vec<_>>()
                    .join("\n")
            ));
        }
    }
    let total = t_all.elapsed().as_secs_f64();
    println!("{ran} documented commands ran, {skipped} skipped, {total:.1} s in all");
    let _ = std::fs::remove_dir_all(&tmp);
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    assert!(ran >= 20, "only {ran} commands ran");
    assert!(total <= TOTAL_S, "{total:.1} s > {TOTAL_S} s");
}

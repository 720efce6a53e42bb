//! `docs/cli.md` is the `--help` text of every command. This test fails when they
//! differ; regenerate with `SDINS_BLESS=1 cargo test -p sdins-cli --test cli_docs`.
#![allow(clippy::unwrap_used)]
use std::process::Command;

fn help(args: &[&str]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args(args)
        .arg("--help")
        .output()
        .unwrap();
    String::from_utf8_lossy(&o.stdout).replace("sdins.exe", "sdins")
}

fn commands() -> Vec<String> {
    // the command list as clap prints it under "Commands:"
    let top = help(&[]);
    top.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .filter(|c| c != "help")
        .collect()
}

fn render() -> String {
    let mut s = String::from(
        "# sdins command reference\n\nGenerated from `sdins --help` and `sdins COMMAND --help` (a test keeps it in step;\n\
         regenerate with `SDINS_BLESS=1 cargo test -p sdins-cli --test cli_docs`).\n\n## sdins\n\n```text\n",
    );
    s.push_str(&help(&[]));
    s.push_str("```\n");
    for c in commands() {
        s.push_str(&format!("\n## sdins {c}\n\n```text\n{}```\n", help(&[&c])));
    }
    s
}

#[test]
fn cli_reference_matches_help() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/cli.md");
    let want = render();
    if std::env::var("SDINS_BLESS").is_ok() {
        std::fs::write(path, &want).unwrap();
        return;
    }
    let have = std::fs::read_to_string(path).unwrap_or_default();
    assert!(
        have == want,
        "docs/cli.md is out of date: run SDINS_BLESS=1 cargo test -p sdins-cli --test cli_docs"
    );
    assert!(commands().len() >= 6);
}

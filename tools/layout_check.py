#!/usr/bin/env python3
"""The layout check (issue 23): no import circles, no oversized files, short command runs.

Rules, each failing the check:

1. sdins-sim: the graph of its top-level modules (``src/<top>.rs`` or ``src/<top>/``), with an
   edge A -> B for every ``crate::B`` path (or ``super::`` path resolving into B) written in A
   outside comments and ``#[cfg(test)]`` code, has no strongly connected component of more
   than one node.
2. sdins-cli: the same over its files (each ``.rs`` file is one node; a path names the deepest
   file it reaches).
3. Every ``.rs`` file under ``crates/*/src`` has at most 1 000 lines outside its
   ``#[cfg(test)]`` items and at most 1 500 lines in all.
4. With ``--command-runs``: every subcommand's ``pub fn run`` in ``crates/sdins-cli/src/cmd/``
   is at most 80 lines.

``--graph`` prints both graphs; ``--self-test`` checks the checker on made-up sources (a circle,
a grouped ``use``, a ``super::`` path, a test module, a long file) so that it cannot pass by
reading nothing.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MAX_LINES_NO_TESTS = 1000
MAX_LINES_ALL = 1500
MAX_RUN_LINES = 80


# ---------------------------------------------------------------- source cleaning


def strip_comments(src: str) -> str:
    """Blank out comments and string/char literal contents, keeping line structure."""
    out = []
    i, n = 0, len(src)
    while i < n:
        c = src[i]
        if src.startswith("//", i):
            j = src.find("\n", i)
            j = n if j < 0 else j
            i = j
            continue
        if src.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if src.startswith("/*", j):
                    depth += 1
                    j += 2
                elif src.startswith("*/", j):
                    depth -= 1
                    j += 2
                else:
                    j += 1
            out.append("".join(ch if ch == "\n" else " " for ch in src[i:j]))
            i = j
            continue
        m = re.match(r'r(#*)"', src[i:i + 10]) if c == "r" and (i == 0 or not (src[i - 1].isalnum() or src[i - 1] == "_")) else None
        if m:
            hashes = m.group(1)
            end = src.find('"' + hashes, i + len(m.group(0)))
            end = n if end < 0 else end + 1 + len(hashes)
            out.append('""' + "".join("\n" for ch in src[i:end] if ch == "\n"))
            i = end
            continue
        if c == '"':
            j = i + 1
            while j < n and src[j] != '"':
                j += 2 if src[j] == "\\" else 1
            out.append('""' + "".join("\n" for ch in src[i:j] if ch == "\n"))
            i = j + 1
            continue
        if c == "'":
            # a char literal ('a', '\n', '\u{..}') or a lifetime ('a)
            m = re.match(r"'(\\u\{[0-9a-fA-F]+\}|\\.|[^\\'])'", src[i:i + 12])
            if m:
                out.append("' '")
                i += len(m.group(0))
                continue
        out.append(c)
        i += 1
    return "".join(out)


def matching_brace(src: str, i: int) -> int:
    """Index just past the brace closing the one at src[i] (src without comments/strings)."""
    depth = 0
    for j in range(i, len(src)):
        if src[j] == "{":
            depth += 1
        elif src[j] == "}":
            depth -= 1
            if depth == 0:
                return j + 1
    return len(src)


CFG_TEST = re.compile(r"#\[cfg\(\s*test\s*\)\]")


def test_spans(clean: str) -> list[tuple[int, int]]:
    """Character spans of the items under #[cfg(test)] (to the end of the item)."""
    spans = []
    for m in CFG_TEST.finditer(clean):
        j = m.end()
        # the item ends at the first ';' before any '{', or at the brace block
        semi = clean.find(";", j)
        brace = clean.find("{", j)
        if brace >= 0 and (semi < 0 or brace < semi):
            spans.append((m.start(), matching_brace(clean, brace)))
        else:
            spans.append((m.start(), semi + 1 if semi >= 0 else len(clean)))
    return spans


def without_tests(clean: str) -> str:
    """The cleaned source with #[cfg(test)] items blanked (line structure kept)."""
    chars = list(clean)
    for a, b in test_spans(clean):
        for k in range(a, b):
            if chars[k] != "\n":
                chars[k] = " "
    return "".join(chars)


def test_module_files(clean: str) -> list[str]:
    """Names of `#[cfg(test)] mod x;` declarations (their files are test code)."""
    return re.findall(r"#\[cfg\(\s*test\s*\)\]\s*(?:#\[[^\]]*\]\s*)*mod\s+(\w+)\s*;", clean)


# ---------------------------------------------------------------- paths


def expand_use_tree(tree: str, prefix: list[str]) -> list[list[str]]:
    """Expand a `use` tree body such as `a::{b, c::{d, e}}` into full paths."""
    tree = tree.strip()
    paths: list[list[str]] = []
    # split the top level on commas
    depth, start, parts = 0, 0, []
    for k, ch in enumerate(tree):
        if ch == "{":
            depth += 1
        elif ch == "}":
            depth -= 1
        elif ch == "," and depth == 0:
            parts.append(tree[start:k])
            start = k + 1
    parts.append(tree[start:])
    for part in parts:
        part = part.strip()
        if not part:
            continue
        brace = part.find("{")
        if brace >= 0:
            head = [s for s in part[:brace].split("::") if s.strip()]
            inner = part[brace + 1: part.rfind("}")]
            paths += expand_use_tree(inner, prefix + [s.strip() for s in head])
        else:
            segs = [s.strip() for s in part.split(" as ")[0].split("::") if s.strip()]
            paths.append(prefix + segs)
    return paths


PATH_RE = re.compile(r"(?<![\w:])((?:crate|super|self)(?:\s*::\s*(?:\w+|\{))+)")


def referenced_paths(code: str) -> list[list[str]]:
    """Every crate::/super::/self:: path in the code, `use` groups expanded."""
    paths = []
    for m in PATH_RE.finditer(code):
        text = m.group(1)
        if text.endswith("{"):
            brace = m.end() - 1
            end = matching_brace(code, brace)
            head = [s.strip() for s in text[:-1].split("::") if s.strip()]
            paths += expand_use_tree(code[brace + 1: end - 1], head)
        else:
            paths.append([s.strip() for s in text.split("::") if s.strip()])
    return paths


def module_path(src_dir: Path, file: Path) -> list[str]:
    """The module path of a file: src/a/b.rs -> [a, b]; src/a/mod.rs -> [a]; lib.rs -> []."""
    rel = file.relative_to(src_dir).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] in ("mod", "lib", "main"):
        parts = parts[:-1]
    return parts


def resolve(path: list[str], here: list[str], is_mod_file: bool) -> list[str] | None:
    """Absolute module path (from the crate root) of a crate::/super::/self:: path."""
    if path[0] == "crate":
        return path[1:]
    # self and super are relative to the module the file defines
    cur = list(here)
    segs = list(path)
    while segs and segs[0] in ("super", "self"):
        if segs[0] == "super":
            if not cur:
                return None
            cur.pop()
        segs.pop(0)
    return cur + segs


# ---------------------------------------------------------------- graphs


def rust_files(src_dir: Path) -> list[Path]:
    return sorted(p for p in src_dir.rglob("*.rs"))


def load(file: Path) -> tuple[str, str]:
    raw = file.read_text(encoding="utf-8")
    clean = strip_comments(raw)
    return raw, clean


def test_only_files(src_dir: Path) -> set[Path]:
    """Files declared as `#[cfg(test)] mod x;` (and everything under them)."""
    out: set[Path] = set()
    for f in rust_files(src_dir):
        _, clean = load(f)
        here_dir = f.parent if f.name in ("mod.rs", "lib.rs", "main.rs") else f.with_suffix("")
        for name in test_module_files(clean):
            for cand in (here_dir / f"{name}.rs", here_dir / name / "mod.rs"):
                if cand.exists():
                    out.add(cand)
            d = here_dir / name
            if d.is_dir():
                out.update(d.rglob("*.rs"))
    return out


def sim_graph(src_dir: Path) -> dict[str, set[str]]:
    """Top-level module graph of a library crate."""
    tops = {module_path(src_dir, f)[0] for f in rust_files(src_dir) if module_path(src_dir, f)}
    skip = test_only_files(src_dir)
    graph: dict[str, set[str]] = {t: set() for t in tops}
    for f in rust_files(src_dir):
        here = module_path(src_dir, f)
        if not here or f in skip:
            continue
        _, clean = load(f)
        code = without_tests(clean)
        for p in referenced_paths(code):
            target = resolve(p, here, f.name == "mod.rs")
            if target and target[0] in tops and target[0] != here[0]:
                graph[here[0]].add(target[0])
    return graph


def file_graph(src_dir: Path) -> dict[str, set[str]]:
    """File-level graph of a binary crate: a path names the deepest file it reaches."""
    files = [f for f in rust_files(src_dir)]
    skip = test_only_files(src_dir)
    by_mod = {tuple(module_path(src_dir, f)): str(f.relative_to(src_dir)) for f in files}
    graph: dict[str, set[str]] = {v: set() for v in by_mod.values()}
    for f in files:
        if f in skip:
            continue
        here = module_path(src_dir, f)
        name = str(f.relative_to(src_dir))
        _, clean = load(f)
        code = without_tests(clean)
        for p in referenced_paths(code):
            target = resolve(p, here, f.name == "mod.rs")
            if target is None:
                continue
            # the deepest existing module file along the path
            best = None
            for k in range(len(target), -1, -1):
                if tuple(target[:k]) in by_mod:
                    best = by_mod[tuple(target[:k])]
                    break
            if best and best != name and tuple(target[:1]) != ():
                # a path into the crate root (main.rs) itself is not an edge
                if best in ("main.rs", "lib.rs"):
                    continue
                # a path to a module's own child is a declaration, not a dependency upward
                graph[name].add(best)
    return graph


def sccs(graph: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's strongly connected components."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    counter = [0]
    sys.setrecursionlimit(10000)

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def circles(graph: dict[str, set[str]]) -> list[list[str]]:
    return [c for c in sccs(graph) if len(c) > 1]


def describe_circle(graph: dict[str, set[str]], comp: list[str]) -> str:
    members = set(comp)
    edges = [f"{a} -> {b}" for a in comp for b in sorted(graph[a]) if b in members]
    return "{" + ", ".join(comp) + "}: " + "; ".join(edges)


# ---------------------------------------------------------------- sizes


def size_problems(files: list[Path]) -> list[str]:
    problems = []
    for f in files:
        raw, clean = load(f)
        total = raw.count("\n") + (0 if raw.endswith("\n") or not raw else 1)
        # lines outside #[cfg(test)] items: the lines the test spans cover are subtracted
        spans = test_spans(clean)
        in_tests = sum(clean.count("\n", a, b) + 1 for a, b in spans)
        outside = total - in_tests
        rel = f.relative_to(ROOT) if f.is_relative_to(ROOT) else f
        if outside > MAX_LINES_NO_TESTS:
            problems.append(f"{rel}: {outside} lines outside #[cfg(test)] (limit {MAX_LINES_NO_TESTS})")
        if total > MAX_LINES_ALL:
            problems.append(f"{rel}: {total} lines in all (limit {MAX_LINES_ALL})")
    return problems


RUN_FN = re.compile(r"^(\s*)pub(?:\([^)]*\))?\s+fn\s+run\s*[<(]", re.M)


def run_length_problems(cmd_dir: Path) -> list[str]:
    problems = []
    if not cmd_dir.is_dir():
        return problems
    for f in sorted(cmd_dir.rglob("*.rs")):
        raw, clean = load(f)
        for m in RUN_FN.finditer(clean):
            brace = clean.find("{", m.end())
            semi = clean.find(";", m.end())
            if brace < 0 or (0 <= semi < brace and clean[m.end():semi].count("(") <= clean[m.end():semi].count(")")):
                continue
            end = matching_brace(clean, brace)
            start_line = clean.count("\n", 0, m.start()) + 1
            end_line = clean.count("\n", 0, end - 1) + 1
            length = end_line - start_line + 1
            if length > MAX_RUN_LINES:
                problems.append(
                    f"{f.relative_to(ROOT) if f.is_relative_to(ROOT) else f}:{start_line}: `run` is {length} lines (limit {MAX_RUN_LINES})"
                )
    return problems


# ---------------------------------------------------------------- main


def check(root: Path, verbose: bool = False, runs: bool = True) -> list[str]:
    problems: list[str] = []
    sim_src = root / "crates/sdins-sim/src"
    cli_src = root / "crates/sdins-cli/src"
    g_sim = sim_graph(sim_src)
    g_cli = file_graph(cli_src)
    if verbose:
        for name, g in (("sdins-sim (top-level modules)", g_sim), ("sdins-cli (files)", g_cli)):
            print(f"# {name}")
            for a in sorted(g):
                print(f"{a} -> {', '.join(sorted(g[a])) or '-'}")
    for c in circles(g_sim):
        problems.append("sdins-sim import circle " + describe_circle(g_sim, c))
    for c in circles(g_cli):
        problems.append("sdins-cli import circle " + describe_circle(g_cli, c))
    files = sorted(p for p in (root / "crates").glob("*/src/**/*.rs"))
    problems += size_problems(files)
    if runs:
        problems += run_length_problems(cli_src / "cmd")
    return problems


def self_test() -> None:
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        root = Path(d)
        sim = root / "crates/sdins-sim/src"
        cli = root / "crates/sdins-cli/src/cmd"
        (sim / "b").mkdir(parents=True)
        cli.mkdir(parents=True)
        (sim / "lib.rs").write_text("pub mod a;\npub mod b;\npub mod c;\n")
        # a -> b through a grouped use; b -> a through super:: from a nested file;
        # c -> a only inside a test module and a comment (no edge)
        (sim / "a.rs").write_text("use crate::{x::y, b::{Thing, other::Z}};\n")
        (sim / "b/mod.rs").write_text("mod inner;\n")
        (sim / "b/inner.rs").write_text("fn f() { super::super::a::g(); }\n")
        (sim / "c.rs").write_text(
            "// crate::a::f\n/* crate::b */\nlet s = \"crate::a\";\n#[cfg(test)]\nmod tests { use crate::a::f; }\n"
        )
        (root / "crates/sdins-cli/src/main.rs").write_text("mod cmd;\n")
        (cli / "mod.rs").write_text("pub mod p;\npub mod q;\n")
        (cli / "p.rs").write_text("use super::q::X;\npub fn run() {\n" + "    a();\n" * 90 + "}\n")
        (cli / "q.rs").write_text("use crate::cmd::p::Y;\n" + "// x\n" * 1001)
        problems = check(root)
        text = "\n".join(problems)
        expect = [
            "sdins-sim import circle {a, b}",
            "sdins-cli import circle {cmd/p.rs, cmd/q.rs}",
            "`run` is 92 lines",
            "cmd/q.rs: 1002 lines outside",
        ]
        missing = [e for e in expect if e not in text]
        unexpected = [p for p in problems if "c.rs" in p and "circle" in p]
        g = sim_graph(sim)
        if missing or unexpected or g["c"]:
            print("layout_check self-test FAILED", file=sys.stderr)
            print("problems found:\n  " + "\n  ".join(problems), file=sys.stderr)
            print(f"missing: {missing}; c's edges: {g['c']}", file=sys.stderr)
            sys.exit(1)
    print("layout_check self-test: ok")


def main(argv: list[str]) -> int:
    if "--self-test" in argv:
        self_test()
        return 0
    # rule 4 waits for issue 24 (the commands' procedures moving into sdins-sim)
    problems = check(ROOT, verbose="--graph" in argv, runs="--command-runs" in argv)
    if problems:
        print("layout check failed:", file=sys.stderr)
        for p in problems:
            print("  " + p, file=sys.stderr)
        return 1
    print("layout check: no import circles, file sizes and command runs within limits")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

"""Shared fixtures: the `sdins` CLI binary (the reference the Python numbers must equal
to the last bit) and the repository root."""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _find_cli():
    env = os.environ.get("SDINS_BIN")
    if env:
        return pathlib.Path(env)
    for p in (ROOT / "target" / "release" / "sdins", ROOT / "target" / "debug" / "sdins"):
        if p.exists():
            return p
    return None


@pytest.fixture(scope="session")
def cli():
    """Run the CLI; returns (exit code, stdout, stderr). Fails (never skips) when the
    binary is missing: build it with `cargo build --release -p sdins-cli`."""
    exe = _find_cli()
    if exe is None or not exe.exists():
        pytest.fail(
            "the sdins CLI is needed as the reference: cargo build --release -p sdins-cli "
            "(or set SDINS_BIN)"
        )

    def run(*args):
        r = subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True)
        return r.returncode, r.stdout, r.stderr

    return run


@pytest.fixture(scope="session")
def shared_data():
    d = ROOT.parent / "shared" / "data"
    if not d.is_dir():
        pytest.skip(f"external data folder {d} is absent")
    return d

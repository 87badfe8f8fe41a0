"""Shared fixtures: the repository's paths and the CLI binary (the Python API
is checked against it on the same inputs)."""

import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = ROOT / "examples"


@pytest.fixture(scope="session")
def cli_exe():
    """The `vibroimpact` CLI binary (built by `cargo test --workspace
    --release`, or here if missing)."""
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    exe = target / "release" / "vibroimpact"
    if not exe.exists():
        subprocess.run(
            ["cargo", "build", "--release", "-p", "vibroimpact-cli"], cwd=ROOT, check=True
        )
    return str(exe)


@pytest.fixture(scope="session")
def cli(cli_exe):
    """Runs the `vibroimpact` CLI and returns its parsed JSON output."""
    exe = cli_exe

    def run(*args):
        out = subprocess.run(
            [str(exe), *map(str, args), "--format", "json"],
            cwd=ROOT,
            capture_output=True,
            text=True,
        )
        assert out.returncode == 0, out.stderr
        return json.loads(out.stdout)

    return run

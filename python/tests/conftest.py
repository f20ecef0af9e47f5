"""Shared helpers of the hpge_cv tests: the repository root and the command line to compare with."""

import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def cli_path():
    """The hpge-cv binary built from this checkout ($HPGE_CV_BIN, else target/{debug,release})."""
    env = os.environ.get("HPGE_CV_BIN")
    if env:
        return Path(env)
    for profile in ("debug", "release"):
        p = ROOT / "target" / profile / "hpge-cv"
        if p.is_file():
            return p
    return None


@pytest.fixture(scope="session")
def cli():
    """Runs hpge-cv with arguments in the repository root: (exit code, stdout, stderr)."""
    path = cli_path()
    if path is None:
        pytest.skip("no hpge-cv binary: run `cargo build` first or set HPGE_CV_BIN")

    def run(*args):
        p = subprocess.run(
            [str(path), *map(str, args)], cwd=ROOT, capture_output=True, text=True, timeout=900
        )
        return p.returncode, p.stdout, p.stderr

    return run


@pytest.fixture(scope="session")
def cli_json(cli):
    """Runs hpge-cv and parses its one JSON object on stdout (asserting exit code 0)."""

    def run(*args):
        code, out, err = cli(*args)
        assert code == 0, err
        return json.loads(out)

    return run

"""Shared fixtures: the workspace root, the `porofrac` command built beside the package,
and a runner for it."""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def command_path() -> pathlib.Path:
    """The `porofrac` command of this workspace (POROFRAC_BIN overrides)."""
    return pathlib.Path(os.environ.get("POROFRAC_BIN", ROOT / "target" / "release" / "porofrac"))


@pytest.fixture(scope="session")
def root() -> pathlib.Path:
    return ROOT


@pytest.fixture(scope="session")
def porofrac_bin() -> pathlib.Path:
    p = command_path()
    if not p.exists():
        pytest.fail(f"{p} is missing: build it with `cargo build --release -p porofrac-cli`")
    return p


@pytest.fixture
def run_command(porofrac_bin, tmp_path):
    """Run `porofrac run SCENE --out DIR --set K=V ...`; returns DIR."""

    def run(scene, sets=(), name="cmd"):
        out = tmp_path / name
        args = [str(porofrac_bin), "run", str(scene), "--out", str(out)]
        for k, v in sets:
            args += ["--set", f"{k}={v}"]
        subprocess.run(args, check=True, cwd=tmp_path, capture_output=True)
        return out

    return run

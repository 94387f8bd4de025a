"""The measures of the analysis scripts under scripts/ against their closed-form checks."""

import pathlib
import subprocess
import sys

SCRIPTS = pathlib.Path(__file__).resolve().parents[2] / "scripts"


def test_the_fold_cells_measures_match_their_closed_forms():
    # Cell stress of eq. 7 on a square lattice with known forces, p and q invariant under
    # rotation, dilatations of an affine stretch, the hull of a unit square.
    p = subprocess.run(
        [sys.executable, str(SCRIPTS / "nscd_f1_figures_check.py")],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert p.returncode == 0, p.stdout + p.stderr
    assert "all checks pass" in p.stdout, p.stdout
    assert not any(line.startswith("FAIL") for line in p.stdout.splitlines()), p.stdout

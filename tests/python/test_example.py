"""python/examples/plot_snaps.py (docs/python.md's example) runs, writes its PNG, and its data
show the jumps: at each snapped row the force changes by far more than between the other
rows, once on the way out and once on the way back."""
import importlib.util
import os
import subprocess
import sys

import numpy as np

from conftest import SOURCE_DIR

EXAMPLE = SOURCE_DIR / "python" / "examples" / "plot_snaps.py"


def load_example():
    spec = importlib.util.spec_from_file_location("plot_snaps", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_example_writes_the_png(tmp_path):
    out = tmp_path / "snaps.png"
    run = subprocess.run([sys.executable, str(EXAMPLE), "--out", str(out)], capture_output=True, text=True,
                         timeout=60, env=dict(os.environ))
    assert run.returncode == 0, run.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 10000
    assert "zeeman: 201 rows" in run.stdout


def test_the_jumps_are_in_the_data():
    curves = load_example().snap_curves(SOURCE_DIR)
    assert set(curves) == {"zeeman", "curve2d_snap"}
    for name, c in curves.items():
        jumps = np.abs(np.diff(c["f"]))
        snapped = np.flatnonzero(c["snapped"])
        assert len(snapped) == 2, (name, snapped)  # one snap out, one back
        half = len(c["u"]) // 2
        assert snapped[0] < half < snapped[1], (name, snapped)
        # The path is symmetric, the snaps are not: hysteresis.
        assert abs(c["u"][snapped[0]] - c["u"][snapped[1]]) > 0.1, name
        typical = np.median(jumps)
        for row in snapped:
            assert jumps[row - 1] > 10 * typical, (name, row, jumps[row - 1], typical)

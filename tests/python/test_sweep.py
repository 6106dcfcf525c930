"""snapthread.sweep() against snapthread-sweep: the same table, row by row and column by
column, on every shipped scene along its grasp.path (as `--path` runs it), bit for bit where
the CLI writes every digit (--exact), and along --from/--to with the CLI's other options."""
import math
import threading
import time

import numpy as np
import pytest

import snapthread
from conftest import SOURCE_DIR, run_sweep_cli

SCENES = sorted((SOURCE_DIR / "scenes").glob("*.yaml"))


def test_every_shipped_scene_is_here():
    assert len(SCENES) >= 9
    assert all(snapthread.load_scene(str(s)).path.shape[0] >= 2 for s in SCENES), "a scene without a path"


def assert_same_table(header, rows, table, digits=12, where=""):
    """The CLI's text equals the module's numbers written as the CLI writes them (`digits`
    significant digits; every digit for --exact), except solve_us (a wall time)."""
    assert list(table) == header, where
    for name in header:
        assert len(table[name]) == len(rows), (where, name)
    for i, row in enumerate(rows):
        assert len(row) == len(header), (where, i)
        for name, text in zip(header, row):
            value = table[name][i]
            at = "%s row %d column %s: CLI %s, module %r" % (where, i, name, text, value)
            if name == "solve_us":
                assert value >= 0, at
            elif table[name].dtype.kind == "U":
                assert text == value, at
            elif table[name].dtype.kind == "i":
                assert int(text) == value, at
            elif text in ("nan", "-nan"):
                assert math.isnan(value), at
            elif digits == 17:
                assert float(text) == value, at
            else:
                assert text == "%.*g" % (digits, value), at


@pytest.mark.parametrize("scene", SCENES, ids=lambda s: s.stem)
def test_path_sweep_equals_cli(scene):
    header, rows = run_sweep_cli("--scene", scene, "--path")
    assert_same_table(header, rows, snapthread.sweep(str(scene), path=True), where=scene.name)


def test_zeeman_path_bit_for_bit():
    scene = SOURCE_DIR / "scenes" / "zeeman.yaml"
    header, rows = run_sweep_cli("--scene", scene, "--path", "--exact")
    table = snapthread.sweep(str(scene), path=True)
    assert_same_table(header, rows, table, digits=17, where="zeeman --exact")
    # The jump is in the data: the wheel snaps once on the way out and once back.
    assert table["snapped"].sum() == 2
    assert set(table["status"]) <= {"regular", "near-fold", "snapped"}


def test_from_to_back_method_and_set_equal_cli():
    scene = SOURCE_DIR / "scenes" / "curve2d_snap.yaml"
    header, rows = run_sweep_cli("--scene", scene, "--from", "9,-1", "--to", "9,1.5", "--steps", 9, "--back",
                                 "--method", "newton-ls", "--set", "params.n=12", "--set", "solver.cutoff=1e-9")
    table = snapthread.sweep(str(scene), start=(9, -1), end=(9, 1.5), steps=9, back=True, method="newton-ls",
                             set={"params.n": 12, "solver.cutoff": 1e-9})
    assert_same_table(header, rows, table, where="curve2d --from/--to")
    assert len(table["step"]) == 19 and set(table["method"]) == {"newton-ls"}


def test_column_types():
    table = snapthread.sweep(str(SOURCE_DIR / "scenes" / "knot_overhand.yaml"), path=True, steps=5)
    assert table["step"].dtype == np.int64 and table["f_x"].dtype == np.float64
    assert table["status"].dtype.kind == "U"
    # Two grasps: the second's columns, and every rod column, before force_error.
    assert {"u2_x", "f2_z", "roll_deg", "t_x", "negative_pivots"} <= set(table)
    assert list(table)[-1] == "force_error"
    error = table["force_error"]
    assert ((error >= 0) | (error == -1)).all() and error[0] >= 0  # -1: not estimated


def test_bad_arguments_raise():
    zeeman = str(SOURCE_DIR / "scenes" / "zeeman.yaml")
    with pytest.raises(ValueError, match="path=True"):
        snapthread.sweep(zeeman)
    with pytest.raises(ValueError, match="method"):
        snapthread.sweep(zeeman, path=True, method="magic")
    with pytest.raises(ValueError, match="steps"):
        snapthread.sweep(zeeman, path=True, steps=0)
    with pytest.raises(ValueError, match="start/end"):
        snapthread.sweep(zeeman, start=(0, 3, 1), end=(1, 3, 1))
    with pytest.raises(snapthread.SceneError, match="params.n"):
        snapthread.sweep(str(SOURCE_DIR / "scenes" / "curve2d_snap.yaml"), path=True, set=["params.n=1"])
    with pytest.raises((snapthread.SceneError, snapthread.InputFileError)):
        snapthread.sweep(str(SOURCE_DIR / "scenes" / "no_such_scene.yaml"), path=True)


def test_sweep_releases_the_gil():
    """Another Python thread runs while a sweep solves: its longest pause stays far below
    the sweep's duration (with the GIL held it would wait the whole sweep)."""
    knot = str(SOURCE_DIR / "scenes" / "knot_overhand.yaml")
    worker = threading.Thread(target=snapthread.sweep, args=(knot,), kwargs={"path": True})
    start = time.perf_counter()
    worker.start()
    last, longest_pause = time.perf_counter(), 0.0
    while worker.is_alive():
        now = time.perf_counter()
        longest_pause = max(longest_pause, now - last)
        last = now
        time.sleep(0.001)
    duration = time.perf_counter() - start
    assert duration > 0.2, "the sweep was too short to tell"
    assert longest_pause < 0.5 * duration, (longest_pause, duration)

"""The module's objects: registries and options with their docs, scenes with overrides, the
tracker's results (the same numbers as the sweep along the same controls), shapes without
copies, knot types and statuses."""
import math

import numpy as np
import pytest

import snapthread
from conftest import SOURCE_DIR


def scene_file(name):
    return str(SOURCE_DIR / "scenes" / (name + ".yaml"))


def test_registries_and_options_have_docs():
    names = [m.name for m in snapthread.models()]
    assert names[:4] == ["zeeman", "cusp", "curve2d", "thread3d"] and "rod" in names
    curve2d = snapthread.find_model("curve2d")
    assert curve2d.is_chain and curve2d.doc
    n = next(p for p in curve2d.params if p.name == "n")
    assert n.kind == "integer" and n.expected().startswith("an integer") and n.doc
    assert snapthread.find_model("no-such-model") is None
    assert [s.name for s in snapthread.solvers()] == ["newton", "newton-ls", "higher-order"]
    assert all(s.doc for s in snapthread.solvers())
    assert "zeeman" in snapthread.model_help()
    for field in ("method", "cutoff", "force_tolerance", "max_iterations", "linear_solver"):
        assert getattr(snapthread.SolverOptions, field).__doc__
    assert snapthread.Tracker.step.__doc__ and snapthread.sweep.__doc__
    options = snapthread.SolverOptions()
    options.validate()
    options.cutoff = -1.0
    with pytest.raises(ValueError, match="cutoff"):
        options.validate()


def test_load_scene_with_overrides():
    scene = snapthread.load_scene(scene_file("curve2d_snap"), set=["params.n=14", "solver.method=newton"])
    assert scene.model == "curve2d" and scene.params["n"] == 14 and scene.solver.method == "newton"
    assert scene.params["bending"] == 1.0  # set in the file
    same = snapthread.load_scene(scene_file("curve2d_snap"), set={"params.n": 14, "solver.method": "newton"})
    assert same.params == scene.params
    assert scene.path.shape == (3, 2) and scene.grasp_start.tolist() == [9.0, -4.0]
    assert scene.grasp_layout.num_controls == 2 and scene.grasps == [""]
    with pytest.raises(snapthread.SceneError, match="params.n"):
        snapthread.load_scene(scene_file("curve2d_snap"), set=["params.n=1"])
    text = "model: zeeman\ngrasp:\n  start: [-1.0, 3.0]\n"
    assert snapthread.parse_scene(text).model == "zeeman"


def test_tracker_follows_the_sweep():
    """Stepping a Tracker through path_controls() gives the sweep's numbers exactly."""
    scene = snapthread.load_scene(scene_file("zeeman"))
    table = snapthread.sweep(scene_file("zeeman"), path=True)
    controls = snapthread.path_controls(scene)
    assert controls.shape == (len(table["step"]), 2)
    tracker = snapthread.Tracker(scene)
    snapped = []
    for i, u in enumerate(controls):
        r = tracker.reset(u) if i == 0 else tracker.step(u)
        snapped.append(i > 0 and r.snapped)
        assert r.force.tolist() == [table["f_x"][i], table["f_y"][i]], i
        assert r.force_error == table["force_error"][i] and r.iterations == table["iterations"][i]
        assert str(r.status) == table["status"][i] and str(r.termination) == table["termination"][i]
        assert r.stiffness.shape == (2, 2) and np.allclose(r.stiffness, r.stiffness.T, atol=1e-9)
        assert r.usable
    assert snapped == table["snapped"].astype(bool).tolist() and sum(snapped) == 2


def test_step_result_fields_and_views():
    scene = snapthread.load_scene(scene_file("curve2d_snap"))
    tracker = snapthread.Tracker(scene)
    r = tracker.step(np.array([9.0, -3.9]))
    assert r.converged and r.termination == snapthread.Termination.converged
    assert 0 <= r.force_error <= max(r.force_target, 1e-6)
    assert not r.force.flags.writeable and r.force.shape == (2,)
    state = tracker.state
    assert not state.flags.writeable and state.shape == (tracker.num_states,)
    assert np.shares_memory(state, tracker.state)  # a view into the tracker, no copy
    nodes = tracker.nodes()
    assert nodes.shape == (11, 3) and not nodes.flags.owndata and (nodes[:, 2] == 0).all()
    assert nodes[-1, :2].tolist() == [9.0, -3.9]  # the grasped end
    assert str(snapthread.Status.near_fold) == "near-fold"
    bad = tracker.step(np.array([9.0, math.nan]))
    assert bad.status == snapthread.Status.failed and not bad.usable
    with pytest.raises(TypeError):
        tracker.step("not controls")


def test_options_switch_without_losing_the_state():
    tracker = snapthread.Tracker(snapthread.load_scene(scene_file("curve2d_snap")))
    before = np.array(tracker.state)
    options = tracker.options
    options.method = "newton"
    tracker.options = options
    assert tracker.options.method == "newton"
    assert np.array_equal(before, tracker.state)


def test_knot_types():
    assert snapthread.Tracker(snapthread.load_scene(scene_file("zeeman"))).knot() is None
    assert snapthread.Tracker(snapthread.load_scene(scene_file("thread3d_loop"))).knot().name == "unknot"
    t = np.linspace(0, 1.9 * np.pi, 200)  # an open trefoil: its ends apart, then closed far away
    trefoil = np.column_stack([np.sin(t) + 2 * np.sin(2 * t), np.cos(t) - 2 * np.cos(2 * t), -np.sin(3 * t)])
    assert snapthread.identify_knot(trefoil).name == "trefoil"


def test_the_overhand_knot_ties():
    """The knot scene followed with a Tracker: unknot at the start, trefoil at the end."""
    scene = snapthread.load_scene(scene_file("knot_overhand"))
    tracker = snapthread.Tracker(scene)
    controls = snapthread.path_controls(scene)
    tracker.reset(controls[0])
    assert tracker.knot().name == "unknot"
    for u in controls[1:]:
        assert tracker.step(u).usable
    assert tracker.knot().name == "trefoil"

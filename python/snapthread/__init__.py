"""snapthread from Python: scenes, the model and solver registries, the equilibrium tracker
and the quasi-static sweep of the C++ core (docs/python.md).

    import snapthread
    table = snapthread.sweep("scenes/zeeman.yaml", path=True)   # dict of NumPy arrays
    scene = snapthread.load_scene("scenes/curve2d_snap.yaml", set=["params.n=20"])
    tracker = snapthread.Tracker(scene)
    result = tracker.step(scene.path[1])   # force, stiffness, status, force_error, ...
"""
from ._snapthread import (  # noqa: F401  (the public API)
    GraspLayout,
    InputFileError,
    KnotInfo,
    ModelInfo,
    ParamSpec,
    Scene,
    SceneError,
    SolverInfo,
    SolverOptions,
    Status,
    StepResult,
    Termination,
    Tracker,
    find_model,
    identify_knot,
    load_scene,
    model_help,
    models,
    parse_scene,
    path_controls,
    solvers,
    sweep,
)

__all__ = [
    "GraspLayout", "InputFileError", "KnotInfo", "ModelInfo", "ParamSpec", "Scene", "SceneError",
    "SolverInfo", "SolverOptions", "Status", "StepResult", "Termination", "Tracker", "find_model",
    "identify_knot", "load_scene", "model_help", "models", "parse_scene", "path_controls", "solvers", "sweep",
]

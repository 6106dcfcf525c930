#!/usr/bin/env python3
"""Force against displacement through two snaps: the Zeeman machine's jump and the snap of
curve2d_snap's strip, each swept out and back along its scene's grasp.path with
snapthread.sweep(), drawn with matplotlib (Agg: no display needed) into one PNG.

    PYTHONPATH=build/python python3 python/examples/plot_snaps.py --out snaps.png

The marked points are the rows where the state snapped (the sweep's `snapped` column):
the force jumps there, at a different place on the way out than on the way back.
"""
import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
import numpy as np  # noqa: E402

import snapthread  # noqa: E402

SOURCE_DIR = pathlib.Path(__file__).resolve().parents[2]
SCENES = ("zeeman", "curve2d_snap")


def snap_curve(scene_file, steps=100):
    """One scene's sweep along its path, reduced to what the chart shows: the grasp's
    coordinate that the path moves (the axis with the largest range), the force component
    along it, and which rows snapped."""
    table = snapthread.sweep(str(scene_file), path=True, steps=steps)
    axes = ("x", "y", "z")
    spans = [np.ptp(table["u_" + a]) for a in axes]
    axis = axes[int(np.argmax(spans))]
    return {
        "axis": axis,
        "u": table["u_" + axis],
        "f": table["f_" + axis],
        "snapped": table["snapped"].astype(bool),
        "status": table["status"],
    }


def snap_curves(source_dir=SOURCE_DIR, steps=100):
    return {name: snap_curve(pathlib.Path(source_dir) / "scenes" / (name + ".yaml"), steps) for name in SCENES}


def plot(curves, out):
    fig, panels = plt.subplots(1, len(curves), figsize=(5.5 * len(curves), 4.2))
    for ax, (name, c) in zip(np.atleast_1d(panels), curves.items()):
        half = len(c["u"]) // 2 + 1  # the path goes out and comes back
        ax.plot(c["u"][:half], c["f"][:half], "-", color="#1f77b4", label="out")
        ax.plot(c["u"][half - 1:], c["f"][half - 1:], "-", color="#ff7f0e", label="back")
        ax.plot(c["u"][c["snapped"]], c["f"][c["snapped"]], "o", color="#d62728", label="snapped")
        ax.set_title(name)
        ax.set_xlabel("grasp %s (model units)" % c["axis"])
        ax.set_ylabel("force f_%s (model units)" % c["axis"])
        ax.grid(True, alpha=0.3)
        ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="snaps.png", help="PNG to write (default: snaps.png)")
    parser.add_argument("--steps", type=int, default=100, help="steps per leg of each path (default: 100)")
    args = parser.parse_args()
    curves = snap_curves(steps=args.steps)
    plot(curves, args.out)
    for name, c in curves.items():
        print("%s: %d rows, snapped at %s = %s" % (name, len(c["u"]), c["axis"],
                                                  np.array2string(c["u"][c["snapped"]], precision=3)))
    print("wrote", args.out)


if __name__ == "__main__":
    main()

"""Shared fixtures of the Python module's tests: the source tree, the programs' folder and
snapthread-sweep's CSV of a run (ctest sets SNAPTHREAD_SOURCE_DIR and SNAPTHREAD_BIN_DIR;
run by hand, they default to this checkout and its build/)."""
import csv
import io
import os
import pathlib
import subprocess

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("SNAPTHREAD_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
BIN_DIR = pathlib.Path(os.environ.get("SNAPTHREAD_BIN_DIR", SOURCE_DIR / "build" / "bin"))


@pytest.fixture
def source_dir():
    return SOURCE_DIR


def run_sweep_cli(*args):
    """snapthread-sweep's CSV for `args` as (header, rows of text)."""
    out = subprocess.run([str(BIN_DIR / "snapthread-sweep"), *map(str, args)], check=True,
                         capture_output=True, text=True, timeout=60).stdout
    table = list(csv.reader(io.StringIO(out)))
    return table[0], table[1:]

"""Shared fixtures: the CLI binary (GYRODRIFT_CLI, set by CTest), CSV round trips that keep every
bit (shortest round-trip text both ways), and the reference data folder."""

import csv
import json
import math
import os
import pathlib
import subprocess

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("GYRODRIFT_CLI", str(ROOT / "build/apps/gyrodrift/gyrodrift"))
    if not os.access(path, os.X_OK):
        pytest.fail(f"no gyrodrift CLI at {path} (set GYRODRIFT_CLI)")

    def run(*args, check=True, cwd=None):
        r = subprocess.run([path, *map(str, args)], capture_output=True, text=True, cwd=cwd)
        if check and r.returncode != 0:
            raise AssertionError(f"gyrodrift {' '.join(map(str, args))}: exit {r.returncode}\n"
                                 f"{r.stdout}{r.stderr}")
        return r
    return run


@pytest.fixture(scope="session")
def testdata():
    return pathlib.Path(os.environ.get("GYRODRIFT_TESTDATA_DIR", ROOT.parent / "shared/testdata"))


def write_csv(path, columns):
    """Writes {name: array} with repr(), Python's shortest round-trip text, as the CLI's to_chars."""
    names = list(columns)
    with open(path, "w", newline="") as f:
        f.write(",".join(names) + "\n")
        for row in zip(*(columns[n] for n in names)):
            f.write(",".join(repr(float(v)) for v in row) + "\n")


def read_csv(path):
    """{name: float64 array}, each cell through float() (correctly rounded, so bit-exact)."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    return {name: np.array([float(r[i]) for r in body]) for i, name in enumerate(header)}


def read_json(path):
    with open(path) as f:
        return json.load(f)


def same_bits(a, b):
    """Equal arrays, NaN matching NaN (JSON writes NaN as null: pass None for it)."""
    a = np.asarray([math.nan if v is None else v for v in np.atleast_1d(a)], dtype=float)
    b = np.asarray([math.nan if v is None else v for v in np.atleast_1d(b)], dtype=float)
    return a.shape == b.shape and np.array_equal(a, b, equal_nan=True)

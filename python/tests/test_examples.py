"""The examples of docs/python.md run as a new user runs them: the plots write their figures, the
fleet on its Dask LocalCluster writes and prints its table."""

import os
import pathlib
import subprocess
import sys

import pytest

EXAMPLES = pathlib.Path(__file__).resolve().parents[2] / "examples" / "python"


@pytest.mark.parametrize("script, figure", [("allan_compensation.py", "allan.png"),
                                            ("decompose_imfs.py", "imfs.png")])
def test_example_runs_and_writes_its_figure(tmp_path, script, figure):
    r = subprocess.run([sys.executable, str(EXAMPLES / script), str(tmp_path)],
                       capture_output=True, text=True, env=dict(os.environ))
    assert r.returncode == 0, r.stderr
    png = tmp_path / figure
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert f"wrote {png}" in r.stdout


def test_fleet_example_calibrates_its_fleet_on_dask(tmp_path):
    r = subprocess.run([sys.executable, str(EXAMPLES / "fleet_run.py"), str(tmp_path)],
                       capture_output=True, text=True, env=dict(os.environ))
    assert r.returncode == 0, r.stderr
    table = (tmp_path / "calibration" / "fleet.csv").read_text().splitlines()
    assert len(table) == 1 + 2 * 3  # a header, 2 IMUs of 3 axes
    assert sum("'serial': 'SN-000" in line for line in r.stdout.splitlines()) == 6

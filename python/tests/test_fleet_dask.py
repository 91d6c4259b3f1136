"""gyrodrift.fleet on a LocalCluster of 2 workers writes what `gyrodrift calibrate` writes: fleet.csv
byte for byte apart from the unit_seconds column, and each unit's model.json identical. The fleet
is built as tests/cli/calibrate_test.cc builds its own, from the independent family's units."""

import csv
import gzip
import io
import subprocess
import sys
import os

import numpy as np
import pytest

import gyrodrift as gd
import gyrodrift.fleet
from conftest import write_csv

AXES = """
[[axis]]
target = "gyro_x"
temperature = "temp_x"
truth = "drift_x"

[[axis]]
target = "gyro_y"
temperature = ["temp_y"]
truth = "drift_y"
"""


def unit_file(testdata, name):
    with gzip.open(testdata / "gyro_thermal_family/units" / name, "rt") as f:
        rows = list(csv.reader(f))
    return {h: np.array([float(r[i]) for r in rows[1:]]) for i, h in enumerate(rows[0])}


def write_imu_log(testdata, path, ux, uy, mission):
    def file(u):
        return f"unit{u}_test8h_mission.csv.gz" if mission else f"unit{u}_train16h.csv.gz"
    x, y = unit_file(testdata, file(ux)), unit_file(testdata, file(uy))
    columns = {"time_s": x["time_s"], "gyro_x": x["rate_dph"], "gyro_y": y["rate_dph"],
               "temp_x": x["temperature_c"], "temp_y": y["temperature_c"]}
    if mission:
        for axis, u in (("x", ux), ("y", uy)):
            columns[f"drift_{axis}"] = unit_file(
                testdata, f"unit{u}_test8h_mission_truth.csv.gz")["drift_dph"]
    write_csv(path, columns)


@pytest.fixture(scope="module")
def fleet(testdata, tmp_path_factory):
    d = tmp_path_factory.mktemp("fleet")
    (d / "logs").mkdir()
    text = 'method = "thermal"\nrate_unit = "dph"\n[limits]\nremoved_share_min = 0.5\n' + AXES
    for i, (ux, uy) in enumerate(((1, 2), (3, 4)), start=1):
        sn = f"SN{i}"
        write_imu_log(testdata, d / f"logs/{sn}_cal.csv", ux, uy, False)
        write_imu_log(testdata, d / f"logs/{sn}_ver.csv", ux, uy, True)
        text += (f'\n[[unit]]\nserial = "{sn}"\ncalibration = "logs/{sn}_cal.csv"\n'
                 f'verification = ["logs/{sn}_ver.csv"]\n')
    (d / "fleet.toml").write_text(text)
    return d


def without_unit_seconds(path):
    rows = list(csv.reader(io.StringIO(path.read_text())))
    k = rows[0].index("unit_seconds")
    return [r[:k] + r[k + 1:] for r in rows]


def test_dask_fleet_matches_calibrate(cli, fleet):
    cli("calibrate", fleet / "fleet.toml", "-o", fleet / "cli", "--threads", "2", "-q")
    r = gyrodrift.fleet.calibrate(fleet / "fleet.toml", fleet / "dask", workers=2)
    assert r["units"] == 2 and r["calibrated"] == 2 and r["errors"] == 0, r["summary"]
    assert len(r["rows"]) == 4 and {row["serial"] for row in r["rows"]} == {"SN1", "SN2"}

    # Byte-identical fleet.csv apart from the timing column: the raw text is compared, row by row.
    cli_csv, dask_csv = (fleet / "cli/fleet.csv"), (fleet / "dask/fleet.csv")
    assert without_unit_seconds(cli_csv) == without_unit_seconds(dask_csv)
    k = cli_csv.read_text().splitlines()[0].split(",").index("unit_seconds")
    assert [line.split(",")[:k] for line in cli_csv.read_text().splitlines()] == \
           [line.split(",")[:k] for line in dask_csv.read_text().splitlines()]
    for sn in ("SN1", "SN2"):
        for name in ("model.json", "verification_1_compensated.csv", "allan.csv"):
            assert (fleet / "cli" / sn / name).read_bytes() == \
                   (fleet / "dask" / sn / name).read_bytes(), f"{sn}/{name}"
    assert (fleet / "dask/fleet.html").stat().st_size > 0

    # A rerun, through a running scheduler's address (--scheduler), skips both units (their
    # summary.json matches), as calibrate's rerun does.
    from dask.distributed import LocalCluster
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster:
        p = subprocess.run([sys.executable, "-m", "gyrodrift.fleet", str(fleet / "fleet.toml"),
                            "-o", str(fleet / "dask"), "--scheduler", cluster.scheduler_address],
                           capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert "2 units: 0 calibrated, 2 skipped" in p.stdout, p.stdout
    assert without_unit_seconds(dask_csv) == without_unit_seconds(cli_csv)

    # The in-process binding of RunFleet agrees too.
    direct = gd.calibrate(fleet / "fleet.toml", fleet / "direct", threads=2)
    assert [{k: v for k, v in row.items() if k != "unit_seconds"} for row in direct["rows"]] == \
           [{k: v for k, v in row.items() if k != "unit_seconds"} for row in r["rows"]]


def test_command_line_entry_point(fleet):
    # Usage errors exit 2 with the library's message, before any cluster starts.
    p = subprocess.run([sys.executable, "-m", "gyrodrift.fleet", str(fleet / "missing.toml"),
                        "-o", str(fleet / "x")], capture_output=True, text=True, env=os.environ)
    assert p.returncode == 4 and "missing.toml" in p.stderr, p.stderr
    p = subprocess.run([sys.executable, "-m", "gyrodrift.fleet", str(fleet / "fleet.toml"),
                        "-o", str(fleet / "x"), "--workers", "0"], capture_output=True, text=True)
    assert p.returncode == 2 and "--workers" in p.stderr

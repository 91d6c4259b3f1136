#!/usr/bin/env python3
"""Fleet calibration wall time: `gyrodrift calibrate --threads T` against gyrodrift.fleet on a Dask
LocalCluster of W worker processes, on a fleet of two-axis IMUs built from the independent
family's units 1-4 (as python/tests/test_fleet_dask.py builds it; 16 h calibration and 8 h
verification logs at 1 Hz). Every run calibrates every unit (--force), one after the other.

    PYTHONPATH=build/python /usr/bin/python3 bench/python/bench_fleet.py \
        --cli build/apps/gyrodrift/gyrodrift --imus 6

The Dask figure includes starting the cluster (a few seconds) and is what a user waits for.
"""

import argparse
import itertools
import os
import pathlib
import platform
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "python/tests"))
from test_fleet_dask import AXES, write_imu_log  # noqa: E402

import gyrodrift.fleet  # noqa: E402


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cli", default="build/apps/gyrodrift/gyrodrift")
    p.add_argument("--testdata", default=str(pathlib.Path(__file__).resolve().parents[3] /
                                             "shared/testdata"))
    p.add_argument("--imus", type=int, default=6)
    a = p.parse_args()
    testdata = pathlib.Path(a.testdata)
    pairs = list(itertools.permutations(range(1, 5), 2))[:a.imus]
    with tempfile.TemporaryDirectory() as d:
        d = pathlib.Path(d)
        (d / "logs").mkdir()
        text = 'method = "thermal"\nrate_unit = "dph"\n' + AXES
        for i, (ux, uy) in enumerate(pairs, start=1):
            write_imu_log(testdata, d / f"logs/SN{i}_cal.csv", ux, uy, False)
            write_imu_log(testdata, d / f"logs/SN{i}_ver.csv", ux, uy, True)
            text += (f'\n[[unit]]\nserial = "SN{i}"\ncalibration = "logs/SN{i}_cal.csv"\n'
                     f'verification = ["logs/SN{i}_ver.csv"]\n')
        (d / "fleet.toml").write_text(text)
        print(f"{platform.node()}, {os.cpu_count()} cores, "
              f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {len(pairs)} IMUs x 2 axes, "
              f"load average {os.getloadavg()[0]:.1f}")
        for threads in (1, 2):
            start = time.monotonic()
            subprocess.run([a.cli, "calibrate", str(d / "fleet.toml"), "-o", str(d / "cli"),
                            "--threads", str(threads), "--force", "-q"], check=True)
            print(f"gyrodrift calibrate --threads {threads}: {time.monotonic() - start:6.2f} s")
        for workers in (1, 2):
            start = time.monotonic()
            r = gyrodrift.fleet.calibrate(d / "fleet.toml", d / "dask", workers=workers,
                                          force=True)
            assert r["calibrated"] == len(pairs), r["summary"]
            print(f"gyrodrift.fleet --workers {workers}:      {time.monotonic() - start:6.2f} s")


if __name__ == "__main__":
    main()

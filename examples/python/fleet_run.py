#!/usr/bin/env python3
"""Calibrate a small fleet on a Dask LocalCluster of 2 worker processes and print the fleet table
(pass/fail per unit and axis against the manifest's limits).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/fleet_run.py [OUT_DIR]

The fleet is made by scripts/make-fleet.py from the independent gyro family
(../shared/testdata/gyro_thermal_family): 2 three-axis IMUs, 4-h calibration and 2-h
verification logs: 4 h of calibration is short, and an axis may fail its limits (the table says
which and why). Running it again skips the finished units (pass force=True to redo them).
"""

import csv
import os
import subprocess
import sys

import gyrodrift.fleet

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
out = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else "fleet_example")
if not os.path.exists(os.path.join(out, "fleet.toml")):
    subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "make-fleet.py"), "2", "4", "2",
                    out], check=True)

if __name__ == "__main__":  # Dask's worker processes import this file: run the fleet once
    result = gyrodrift.fleet.calibrate(os.path.join(out, "fleet.toml"),
                                       os.path.join(out, "calibration"), workers=2)
    print(result["summary"])
    with open(os.path.join(out, "calibration", "fleet.csv"), newline="") as f:
        for row in csv.DictReader(f):
            print({k: row[k] for k in list(row)[:6]})

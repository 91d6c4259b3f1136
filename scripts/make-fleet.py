#!/usr/bin/env python3
"""Builds a fleet of three-axis IMUs from the independent gyro family, for `gyrodrift calibrate`.

usage: make-fleet.py UNITS CAL_HOURS VER_HOURS OUT_DIR [--first-family-unit K]

IMU i (1-based) takes family units K+3(i-1), K+3(i-1)+1, K+3(i-1)+2 as its x, y and z gyros (each
with its own temperature sensor: temp_x, temp_y, temp_z). Its calibration log is run 1 of those
units (calibration programme, CAL_HOURS), its verification log run 2 (mission programme,
VER_HOURS) with the true drift of each axis (drift_x, drift_y, drift_z). Writes
OUT_DIR/logs/SN-XXXX_{cal,ver}.csv and OUT_DIR/fleet.toml. Needs numpy (Debian python3-numpy) and
../shared/testdata/gyro_thermal_family/generate.py.
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
GENERATE = os.path.join(HERE, "..", "..", "shared", "testdata", "gyro_thermal_family", "generate.py")


def run(unit, run_seed, hours, style, tmp):
    out = os.path.join(tmp, f"u{unit}_r{run_seed}.csv")
    truth = os.path.join(tmp, f"u{unit}_r{run_seed}_truth.csv")
    subprocess.run([sys.executable, GENERATE, str(unit), str(run_seed), str(hours), out, truth,
                    "--style", style], check=True)
    data = np.genfromtxt(out, delimiter=",", names=True)
    drift = np.genfromtxt(truth, delimiter=",", names=True)["drift_dph"]
    return data, drift


def write(path, columns):
    names = list(columns)
    table = np.column_stack([columns[n] for n in names])
    np.savetxt(path, table, delimiter=",", header=",".join(names), comments="", fmt="%.17g")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("units", type=int)
    ap.add_argument("cal_hours", type=float)
    ap.add_argument("ver_hours", type=float)
    ap.add_argument("out_dir")
    ap.add_argument("--first-family-unit", type=int, default=1)
    a = ap.parse_args()
    os.makedirs(os.path.join(a.out_dir, "logs"), exist_ok=True)
    manifest = [
        "# A fleet of three-axis IMUs built from the independent gyro family (scripts/make-fleet.py).",
        'method = "thermal"', 'rate_unit = "dph"', "", "[limits]",
        "residual_drift_rms = 0.05     # deg/h, 100-s means of the compensated output",
        "bias_instability_dph = 0.05", "removed_share_min = 0.75", ""]
    for axis in "xyz":
        manifest += ["[[axis]]", f'target = "gyro_{axis}"', f'temperature = "temp_{axis}"',
                     f'truth = "drift_{axis}"', ""]
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(a.units):
            serial = f"SN-{i + 1:04d}"
            family = [a.first_family_unit + 3 * i + k for k in range(3)]
            for kind, run_seed, hours, style in (("cal", 1, a.cal_hours, "calibration"),
                                                 ("ver", 2, a.ver_hours, "mission")):
                columns = {}
                runs = [run(u, run_seed, hours, style, tmp) for u in family]
                columns["time_s"] = runs[0][0]["time_s"]
                for axis, (data, _) in zip("xyz", runs):
                    columns[f"gyro_{axis}"] = data["rate_dph"]
                for axis, (data, _) in zip("xyz", runs):
                    columns[f"temp_{axis}"] = data["temperature_c"]
                if kind == "ver":
                    for axis, (_, drift) in zip("xyz", runs):
                        columns[f"drift_{axis}"] = drift
                write(os.path.join(a.out_dir, "logs", f"{serial}_{kind}.csv"), columns)
            manifest += ["[[unit]]", f'serial = "{serial}"  # family units {family}',
                         f'calibration = "logs/{serial}_cal.csv"',
                         f'verification = ["logs/{serial}_ver.csv"]', ""]
            print(f"{serial}: family units {family}", flush=True)
    with open(os.path.join(a.out_dir, "fleet.toml"), "w") as f:
        f.write("\n".join(manifest))


if __name__ == "__main__":
    main()

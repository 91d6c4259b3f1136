#!/usr/bin/env python3
"""Fleet calibration wall time: `gyrodrift calibrate --threads T` against gyrodrift.fleet on Dask
LocalClusters of W worker processes (one thread each), on a fleet of two-axis IMUs built from the
independent family's units 1-4 (as python/tests/test_fleet_dask.py builds it: IMU i takes an
ordered pair of those units as its x and y gyros; calibration log the first --cal-hours of the
16-h calibration run, verification log the 8-h mission run with the true drift, 1 Hz).

    PYTHONPATH=build/python /usr/bin/python3 bench/python/bench_fleet.py \\
        --cli build/apps/gyrodrift/gyrodrift --imus 8 --cal-hours 8 --method ms-elm --repeats 3

Each cluster is started once and kept running, as a production line keeps one: its start-up
(the LocalCluster and gyrodrift imported on every worker) is timed apart from the calibrations.
Every calibration redoes every unit (force), one configuration after the other within each
repetition (CLI 1 thread, CLI 2 threads, Dask 1 worker, Dask 2 workers, ...), so that a change of
the machine's load hits all of them alike; the figure is the median over the repetitions. The
load average (1 min) is printed before each run: other processes may share the machine. At the
end the outputs of every configuration are compared byte for byte with those of the CLI's first
(serial) configuration, apart from the timings (fleet.csv's unit_seconds column, and the same
cells in each unit's summary.json).

Not a test: it prints figures (and exits 1 when outputs differ). `make test` runs it once on 2
units of 1-h calibration logs as a smoke test (`bench.python_fleet`).
"""

import argparse
import csv
import io
import itertools
import json
import os
import pathlib
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "python/tests"))
from test_fleet_dask import AXES, write_imu_log  # noqa: E402

import gyrodrift.fleet  # noqa: E402


def without_unit_seconds_csv(text):
    rows = list(csv.reader(io.StringIO(text)))
    k = rows[0].index("unit_seconds")
    return [r[:k] + r[k + 1:] for r in rows]


def differences(reference, other, serials):
    """What differs between two output folders, apart from the timings: [] when nothing."""
    out = []
    if without_unit_seconds_csv((reference / "fleet.csv").read_text()) != \
            without_unit_seconds_csv((other / "fleet.csv").read_text()):
        out.append("fleet.csv")
    for sn in serials:
        names = sorted(p.name for p in (reference / sn).iterdir())
        if sorted(p.name for p in (other / sn).iterdir()) != names:
            out.append(f"{sn}/ (file names)")
            continue
        for name in names:
            a, b = (reference / sn / name), (other / sn / name)
            if name == "summary.json":
                a, b = json.loads(a.read_text()), json.loads(b.read_text())
                k = a["columns"].index("unit_seconds")
                for s in (a, b):
                    s["rows"] = [row[:k] + row[k + 1:] for row in s["rows"]]
                same = a == b
            else:
                same = a.read_bytes() == b.read_bytes()
            if not same:
                out.append(f"{sn}/{name}")
    return out


def children_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def workers_cpu(client):
    def cpu():
        import resource
        r = resource.getrusage(resource.RUSAGE_SELF)
        return r.ru_utime + r.ru_stime
    return sum(client.run(cpu).values())


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cli", default="build/apps/gyrodrift/gyrodrift")
    p.add_argument("--testdata", default=str(pathlib.Path(__file__).resolve().parents[3] /
                                             "shared/testdata"))
    p.add_argument("--imus", type=int, default=8, help="units of the fleet, at most 12")
    p.add_argument("--cal-hours", type=float, default=8.0,
                   help="hours of the calibration run kept (at most 16)")
    p.add_argument("--method", default="thermal", help="the manifest's method (compensate mode)")
    p.add_argument("--repeats", type=int, default=3, help="timed calibrations per configuration")
    p.add_argument("--threads", default="1,2", help="gyrodrift calibrate --threads to time "
                                                   "(comma-separated; empty: none)")
    p.add_argument("--workers", default="1,2", help="LocalCluster worker processes to time "
                                                   "(comma-separated; empty: none)")
    a = p.parse_args()
    pairs = list(itertools.permutations(range(1, 5), 2))
    if not 1 <= a.imus <= len(pairs) or not 0 < a.cal_hours <= 16 or a.repeats < 1:
        p.error("--imus must be in [1, 12], --cal-hours in (0, 16], --repeats >= 1")
    pairs = pairs[:a.imus]
    threads = [int(t) for t in a.threads.split(",") if t]
    workers = [int(w) for w in a.workers.split(",") if w]
    testdata = pathlib.Path(a.testdata)
    serials = [f"SN{i}" for i in range(1, len(pairs) + 1)]

    from dask.distributed import Client, LocalCluster

    with tempfile.TemporaryDirectory() as d:
        d = pathlib.Path(d)
        (d / "logs").mkdir()
        text = f'method = "{a.method}"\nrate_unit = "dph"\n' + AXES
        for sn, (ux, uy) in zip(serials, pairs):
            write_imu_log(testdata, d / f"logs/{sn}_cal.csv", ux, uy, False, hours=a.cal_hours)
            write_imu_log(testdata, d / f"logs/{sn}_ver.csv", ux, uy, True)
            text += (f'\n[[unit]]\nserial = "{sn}"\ncalibration = "logs/{sn}_cal.csv"\n'
                     f'verification = ["logs/{sn}_ver.csv"]\n')
        manifest = d / "fleet.toml"
        manifest.write_text(text)
        print(f"{platform.node()}, {os.cpu_count()} cores, {platform.processor() or platform.machine()}, "
              f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; {len(pairs)} IMUs x 2 axes, "
              f"{a.cal_hours:g}-h calibration + 8-h verification logs at 1 Hz, method {a.method}; "
              f"median of {a.repeats}")

        configurations = []  # (name, run() -> seconds, cpu() -> seconds, output folder)
        for t in threads:
            out = d / f"cli-threads{t}"

            def run_cli(t=t, out=out):
                subprocess.run([a.cli, "calibrate", str(manifest), "-o", str(out), "--threads",
                                str(t), "--force", "-q"], check=True)
            configurations.append((f"gyrodrift calibrate --threads {t}", run_cli, children_cpu,
                                   out))
        clusters = []
        try:
            for w in workers:
                start = time.monotonic()
                cluster = LocalCluster(n_workers=w, threads_per_worker=1, processes=True,
                                       dashboard_address=":0")  # any free port
                client = Client(cluster)
                client.run(lambda: __import__("gyrodrift.fleet"))
                print(f"LocalCluster of {w} worker{'s' if w > 1 else ''} started in "
                      f"{time.monotonic() - start:.2f} s (load average "
                      f"{os.getloadavg()[0]:.1f})")
                clusters.append((cluster, client))
                out = d / f"dask-workers{w}"

                def run_dask(client=client, out=out):
                    r = gyrodrift.fleet.calibrate(manifest, out, client=client, force=True)
                    assert r["calibrated"] == len(pairs) and r["errors"] == 0, r["summary"]
                configurations.append((f"gyrodrift.fleet, {w} worker{'s' if w > 1 else ''}",
                                       run_dask, lambda client=client: workers_cpu(client), out))

            times = {name: [] for name, *_ in configurations}
            cpus = {name: [] for name, *_ in configurations}
            for r in range(a.repeats):
                for name, run, cpu, _ in configurations:
                    load = os.getloadavg()[0]
                    cpu0, start = cpu(), time.monotonic()
                    run()
                    seconds, cpu_seconds = time.monotonic() - start, cpu() - cpu0
                    times[name].append(seconds)
                    cpus[name].append(cpu_seconds)
                    print(f"  run {r + 1}: {name:36s} {seconds:7.2f} s  (CPU {cpu_seconds:7.2f} s; "
                          f"load average before {load:.1f})", flush=True)
        finally:
            for cluster, client in clusters:
                client.close()
                cluster.close()

        # Speed-up against the first configuration of the same runner (the CLI's, Dask's): the
        # ratio of the medians, and the median of the ratios within each repetition (the runs
        # of one repetition follow each other, so they share the machine's load more closely).
        print("median wall time (CPU time of the run's processes), speed-up:")
        firsts = {}
        for name, *_ in configurations:
            first = firsts.setdefault(name.split(",")[0].split(" --")[0], name)
            m = statistics.median(times[name])
            paired = statistics.median(f / t for f, t in zip(times[first], times[name]))
            print(f"  {name:36s} {m:7.2f} s  ({statistics.median(cpus[name]):7.2f} s)  "
                  f"{statistics.median(times[first]) / m:4.2f}x (paired {paired:4.2f}x) "
                  f"of {first}")
        reference, differ = configurations[0][3], False
        for name, _, _, out in configurations[1:]:
            diff = differences(reference, out, serials)
            differ |= bool(diff)
            print(f"outputs of {name} against {configurations[0][0]}: "
                  f"{'identical apart from unit_seconds' if not diff else 'DIFFER: ' + ', '.join(diff)}")
        print(f"load average (1, 5, 15 min) at the end: "
              f"{', '.join(f'{v:.1f}' for v in os.getloadavg())}")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())

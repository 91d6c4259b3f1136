"""gyrodrift.fleet on a LocalCluster of 2 workers writes what `gyrodrift calibrate` writes: fleet.csv
byte for byte apart from the unit_seconds column, and each unit's model.json identical; a worker
killed in the middle of a unit costs a retry, not the run. The fleet is built as
tests/cli/calibrate_test.cc builds its own, from the independent family's units."""

import csv
import gzip
import io
import json
import os
import re
import signal
import subprocess
import sys

import numpy as np
import pytest

import gyrodrift as gd
import gyrodrift.fleet
from distributed.diagnostics.plugin import WorkerPlugin
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


def write_imu_log(testdata, path, ux, uy, mission, hours=None):
    """A two-axis log (family units ux, uy): the 16-h calibration run, or the 8-h mission run with
    the true drift; `hours` keeps only the first hours (bench/python/bench_fleet.py)."""
    def file(u):
        return f"unit{u}_test8h_mission.csv.gz" if mission else f"unit{u}_train16h.csv.gz"
    x, y = unit_file(testdata, file(ux)), unit_file(testdata, file(uy))
    columns = {"time_s": x["time_s"], "gyro_x": x["rate_dph"], "gyro_y": y["rate_dph"],
               "temp_x": x["temperature_c"], "temp_y": y["temperature_c"]}
    if mission:
        for axis, u in (("x", ux), ("y", uy)):
            columns[f"drift_{axis}"] = unit_file(
                testdata, f"unit{u}_test8h_mission_truth.csv.gz")["drift_dph"]
    if hours is not None:
        keep = x["time_s"] < hours * 3600.0
        columns = {name: v[keep] for name, v in columns.items()}
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
    # Each front end skips what the other calibrated, however the manifest is named: calibrate
    # from the manifest's folder (a relative name), then the Dask runner (an absolute one) on
    # its output. The fingerprint names each log by its path from the manifest's folder.
    cli("calibrate", "fleet.toml", "-o", "relative", "-q", cwd=fleet)
    p = subprocess.run([sys.executable, "-m", "gyrodrift.fleet", str(fleet / "fleet.toml"),
                        "-o", str(fleet / "relative"), "--workers", "1"], capture_output=True,
                       text=True, env=os.environ)
    assert p.returncode == 0, p.stderr
    assert "2 units: 0 calibrated, 2 skipped" in p.stdout, p.stdout

    # The in-process binding of RunFleet agrees too, and reports the share of the units done.
    done = []
    direct = gd.calibrate(fleet / "fleet.toml", fleet / "direct", threads=2, progress=done.append)
    assert [{k: v for k, v in row.items() if k != "unit_seconds"} for row in direct["rows"]] == \
           [{k: v for k, v in row.items() if k != "unit_seconds"} for row in r["rows"]]
    assert done == [0.5, 1.0]

    # Stopped after the first unit (as Ctrl-C stops it): that unit is written whole, the fleet's
    # files are not, and the exception is the call's.
    def stop(fraction):
        raise RuntimeError("stop")
    with pytest.raises(RuntimeError, match="stop"):
        gd.calibrate(fleet / "fleet.toml", fleet / "stopped", threads=1, progress=stop)
    assert [(fleet / "stopped" / sn / "summary.json").exists() for sn in ("SN1", "SN2")] == \
           [True, False]
    assert not (fleet / "stopped/fleet.csv").exists()


def test_command_line_entry_point(fleet):
    # Usage errors exit 2 with the library's message, before any cluster starts.
    p = subprocess.run([sys.executable, "-m", "gyrodrift.fleet", str(fleet / "missing.toml"),
                        "-o", str(fleet / "x")], capture_output=True, text=True, env=os.environ)
    assert p.returncode == 2 and "missing.toml: no such file" in p.stderr, p.stderr  # as the CLI
    p = subprocess.run([sys.executable, "-m", "gyrodrift.fleet", str(fleet / "fleet.toml"),
                        "-o", str(fleet / "x"), "--workers", "0"], capture_output=True, text=True)
    assert p.returncode == 2 and "--workers = 0: must be" in p.stderr, p.stderr
    # The function refuses the same before a cluster starts (-1 started one with no worker, and
    # the units waited for ever), and a log inside the output folder.
    for workers in (-1, 0, "2", True):
        with pytest.raises(gd.UsageError, match="^workers = "):
            gyrodrift.fleet.calibrate(fleet / "fleet.toml", fleet / "x", workers=workers)
    p = subprocess.run([sys.executable, "-m", "gyrodrift.fleet", str(fleet / "fleet.toml"),
                        "-o", str(fleet)], capture_output=True, text=True, env=os.environ)
    assert p.returncode == 2 and len(p.stderr.splitlines()) == 1, p.stderr


class KillWorkerInUnit(WorkerPlugin):
    """Kills the first worker process that starts a unit with SIGKILL, as the out-of-memory killer
    would, while the unit's C++ calibration runs on it: once the task is executing and its thread
    is inside the `_unit` call (polled every 10 ms on the worker's event loop, which is also what
    would report the task's end, so the task cannot be reported done between the check and the
    kill). Just before, it leaves in the unit's folder the half-written temporaries a kill in the
    unit's write phase leaves (`<file>.gyrodrift-tmp.<pid>`), for the retry to clean up.

    Files in `log_dir`: `start.<pid>.<key>` for every unit a worker starts (the retry shows as a
    second start of the same key by another process), `claim` (one kill in all: the first worker
    to start a unit claims it; restarted workers get the plugin too) and `killed` (JSON: pid, key,
    serial and the temporaries left)."""

    def __init__(self, log_dir):
        self.log_dir = str(log_dir)

    def setup(self, worker):
        self.worker = worker

    def transition(self, key, start, finish, **kwargs):
        if finish != "executing" or not str(key).startswith("_unit-"):
            return
        open(os.path.join(self.log_dir, f"start.{os.getpid()}.{key}"), "w").close()
        try:
            os.close(os.open(os.path.join(self.log_dir, "claim"), os.O_CREAT | os.O_EXCL))
        except FileExistsError:
            return
        self.worker.loop.call_later(0.01, self._kill_in_unit, key)

    def _kill_in_unit(self, key):
        ts = self.worker.state.tasks.get(key)
        if ts is None or ts.state != "executing":
            # Done before it was caught (not with these logs): the next unit to start is the one.
            os.remove(os.path.join(self.log_dir, "claim"))
            return
        frames = [f for f in sys._current_frames().values()
                  if f.f_code is gyrodrift.fleet._unit.__code__]
        if not frames:
            self.worker.loop.call_later(0.01, self._kill_in_unit, key)
            return
        args = frames[0].f_locals
        serial = gd._gyrodrift._manifest_serials(args["manifest_path"])[args["index"]]
        folder = os.path.join(args["output_dir"], serial)
        os.makedirs(folder, exist_ok=True)  # RunUnit creates it just before its writes
        left = []
        for name in ("model.json", "allan.csv", "summary.json"):
            left.append(os.path.join(folder, f"{name}.gyrodrift-tmp.{os.getpid()}"))
            with open(left[-1], "w") as f:
                f.write('{"half": ')
        with open(os.path.join(self.log_dir, "killed"), "w") as f:
            json.dump({"pid": os.getpid(), "key": key, "serial": serial, "left": left}, f)
        os.kill(os.getpid(), signal.SIGKILL)


def leftovers(folder):
    return sorted(str(p) for p in folder.rglob("*") if re.search(r"\.gyrodrift-(tmp|bak)\.\d+$", p.name))


def test_killed_worker_is_retried(fleet, tmp_path):
    # Four units (SN3 and SN4 reuse the logs of SN1 and SN2) on 2 workers of one thread each.
    text = (fleet / "fleet.toml").read_text()
    for sn, logs in (("SN3", "SN1"), ("SN4", "SN2")):
        text += (f'\n[[unit]]\nserial = "{sn}"\ncalibration = "logs/{logs}_cal.csv"\n'
                 f'verification = ["logs/{logs}_ver.csv"]\n')
    manifest = fleet / "fleet4.toml"
    manifest.write_text(text)
    serials = ["SN1", "SN2", "SN3", "SN4"]
    log = tmp_path / "log"
    log.mkdir()

    from dask.distributed import Client, LocalCluster
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        reference = gyrodrift.fleet.calibrate(manifest, tmp_path / "ref", client=client)
        pids = set(client.run(os.getpid).values())
        client.register_worker_plugin(KillWorkerInUnit(log), name="kill-worker-in-unit")
        r = gyrodrift.fleet.calibrate(manifest, tmp_path / "kill", client=client)

    # One worker was killed in the middle of a unit, and that unit ran again in another process.
    assert (log / "killed").exists(), "no worker was killed"
    killed = json.loads((log / "killed").read_text())
    assert killed["pid"] in pids
    with pytest.raises(ProcessLookupError):
        os.kill(killed["pid"], 0)
    starts = {}
    for p in log.glob("start.*"):
        pid, key = p.name.split(".", 2)[1:]
        starts.setdefault(key, []).append(int(pid))
    assert len(starts) == 4
    assert sorted(len(v) for v in starts.values()) == [1, 1, 1, 2], starts
    assert len(set(starts[killed["key"]])) == 2 and killed["pid"] in starts[killed["key"]]

    # The run completed: every unit calibrated (none skipped: the killed one wrote nothing) ...
    assert r["units"] == 4 and r["calibrated"] == 4 and r["errors"] == 0, r["summary"]
    assert reference["calibrated"] == 4, reference["summary"]
    # ... with the files of a run without the kill, byte for byte apart from the timings ...
    ref, kill = tmp_path / "ref", tmp_path / "kill"
    assert without_unit_seconds(kill / "fleet.csv") == without_unit_seconds(ref / "fleet.csv")
    for sn in serials:
        names = sorted(p.name for p in (ref / sn).iterdir())
        assert sorted(p.name for p in (kill / sn).iterdir()) == names, sn
        assert "model.json" in names and "verification_1_compensated.csv" in names
        for name in names:
            if name == "summary.json":
                a, b = (json.loads((d / sn / name).read_text()) for d in (ref, kill))
                k = a["columns"].index("unit_seconds")
                for s in (a, b):
                    s["rows"] = [row[:k] + row[k + 1:] for row in s["rows"]]
                assert a == b, f"{sn}/{name}"
            else:
                assert (kill / sn / name).read_bytes() == (ref / sn / name).read_bytes(), \
                    f"{sn}/{name}"
    # ... and no temporary left: the retry's write removed those of the killed process.
    assert all(not os.path.exists(p) for p in killed["left"])
    assert leftovers(kill) == [] and leftovers(ref) == []

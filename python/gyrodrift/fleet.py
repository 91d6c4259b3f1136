"""Fleet calibration on Dask: ``gyrodrift calibrate`` with one Dask task per unit.

    python3 -m gyrodrift.fleet fleet.toml -o calibration [--workers 4]
    python3 -m gyrodrift.fleet fleet.toml -o calibration --scheduler tcp://host:8786

Each task runs the C++ per-unit calibration (fleet::RunUnit: fit, verify, Allan, limits; the
unit's folder written atomically, skipped when its summary.json matches) and returns the unit's
fleet.csv rows; the client then writes fleet.csv and fleet.html (fleet::FinishFleet). The files
are those ``gyrodrift calibrate`` writes, apart from the timings. The workers must see the
manifest, the logs and the output folder at the same paths (one machine, or a shared file
system). Without ``--scheduler`` a LocalCluster of ``--workers`` processes (default: every core),
one thread each, runs the units (each unit on one thread).

A worker that dies while it holds a unit (the out-of-memory killer, a lost machine) costs a
retry: the scheduler gives the unit to another worker, up to Dask's
``distributed.scheduler.allowed-failures`` times (3 by default), then fails the run with Dask's
KilledWorker. A unit's files reach their names only by one atomic rename of the set, so a killed
unit leaves no partial file; the retry's write removes the dead process's temporaries.
"""

import argparse
import numbers
import os
import sys
import time

from . import _gyrodrift


def _unit(manifest_path, index, output_dir, force):
    # Imported on the worker: the task ships only plain arguments.
    from gyrodrift import _gyrodrift as core
    return core._calibrate_unit(manifest_path, index, output_dir, force)


def calibrate(manifest_path, output_dir, *, client=None, scheduler=None, workers=None,
              force=False):
    """Calibrates every unit of the manifest as one Dask task each; returns what
    ``gyrodrift.calibrate`` returns. Give a ``client``, a ``scheduler`` address, or neither for a
    LocalCluster of ``workers`` processes (default: every core)."""
    from dask.distributed import Client, LocalCluster

    if workers is not None and (isinstance(workers, bool)
                                or not isinstance(workers, numbers.Integral)
                                or not 1 <= workers <= 1024):
        raise _gyrodrift.UsageError(f"workers = {workers!r}: must be an integer in [1, 1024]")
    manifest_path = os.path.abspath(manifest_path)
    output_dir = os.path.abspath(output_dir)
    start = time.monotonic()
    # The manifest, its logs and their columns, and that no log lies in the output folder: before
    # any cluster starts.
    serials = _gyrodrift._manifest_serials(manifest_path, output_dir)
    try:
        os.makedirs(output_dir, exist_ok=True)
    except OSError as e:
        raise _gyrodrift.FileError(f"{output_dir}: cannot create the output folder ({e.strerror})")
    if not os.access(output_dir, os.W_OK):  # else every unit would run, then fleet.csv fail
        raise _gyrodrift.FileError(f"{os.path.join(output_dir, 'fleet.csv')}: cannot open for "
                                   "writing (Permission denied)")
    cluster = None
    own_client = client is None
    if client is None:
        if scheduler:
            client = Client(scheduler)
        else:
            cluster = LocalCluster(n_workers=workers or os.cpu_count(), threads_per_worker=1,
                                   processes=True, dashboard_address=None)
            client = Client(cluster)
    try:
        # pure=False: a rerun must run again (the unit decides itself whether to skip).
        futures = [client.submit(_unit, manifest_path, i, output_dir, force, pure=False)
                   for i in range(len(serials))]
        runs = client.gather(futures)
    finally:
        if own_client:
            client.close()
            if cluster is not None:
                cluster.close()
    return _gyrodrift._finish_fleet(manifest_path, output_dir, runs, time.monotonic() - start)


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python3 -m gyrodrift.fleet",
        description="Calibrate a fleet of gyros from a TOML manifest, one Dask task per unit "
                    "(the files gyrodrift calibrate writes).")
    parser.add_argument("manifest", help="calibration manifest (TOML)")
    parser.add_argument("-o", "--output", required=True, help="output folder (created if missing)")
    parser.add_argument("--scheduler", help="address of a running Dask scheduler "
                                            "(default: a LocalCluster on this machine)")
    parser.add_argument("--workers", type=int, default=None,
                        help="LocalCluster worker processes (default: every core)")
    parser.add_argument("--force", action="store_true",
                        help="redo units already calibrated with the same settings")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing on success")
    a = parser.parse_args(argv)
    if not os.path.isfile(a.manifest):  # a usage error, as gyrodrift calibrate says it
        print(f"error: {a.manifest}: no such file", file=sys.stderr)
        return 2
    try:
        r = calibrate(a.manifest, a.output, scheduler=a.scheduler, workers=a.workers,
                      force=a.force)
    except _gyrodrift.UsageError as e:
        text = str(e)  # the keyword as the flag that set it
        print(f"error: {'--' + text if text.startswith('workers = ') else text}", file=sys.stderr)
        return 2
    except _gyrodrift.DataError as e:
        print(f"error: {e}", file=sys.stderr)
        return 3
    except _gyrodrift.FileError as e:
        print(f"error: {e}", file=sys.stderr)
        return 4
    except OSError as e:  # a scheduler that cannot be reached
        print(f"error: {a.scheduler or 'the cluster'}: {e}", file=sys.stderr)
        return 4
    if not a.quiet:
        for row in r["rows"]:
            if row["status"] == "error":
                print(f"error: unit {row['serial']}: {row['failures']}")
        print(f"{r['summary']}\nwrote {a.output}/fleet.csv and {a.output}/fleet.html")
    # Exit code 5 as gyrodrift calibrate: a unit failed its limits or could not be calibrated.
    return 0 if r["all_pass"] else 5


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Binding overhead of gyrodrift.decompose: the same decomposition of 1e5 samples timed from Python
and from C++ (decompose_timing, built by the Python package's CMake), median of 3 rounds of 5
each.

    cmake --build build --target _gyrodrift decompose_timing
    PYTHONPATH=build/python /usr/bin/python3 bench/python/bench_decompose.py \
        --timing build/bench/python/decompose_timing

Prints one line per configuration: C++ median, Python median, their difference (the overhead:
converting the input, the (N, K) result and the report, and releasing the GIL), and the IMF count
(the same in both, as a check that the same work was timed). The C++ and Python runs alternate, so
a machine shared with other jobs loads both alike. The first configuration (one fixed sift per
IMF) computes little, so the conversion shows; the others are the defaults.
"""

import argparse
import json
import os
import platform
import statistics
import subprocess
import tempfile
import time

import numpy as np

import gyrodrift as gd


def signal(n, seed=1):
    rng = np.random.default_rng(seed)
    t = np.arange(n, dtype=float)
    return np.sin(t / 50.0) + 0.5 * np.sin(t / 7.0) + 0.3 * rng.standard_normal(n) + 1e-5 * t


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--timing", default="build/bench/python/decompose_timing")
    p.add_argument("--samples", type=int, default=100_000)
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--quick", action="store_true", help="leave out BEEMDAN (about 12 s a run)")
    a = p.parse_args()
    x = signal(a.samples)
    print(f"{platform.node()} {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, N = {a.samples}, "
          f"threads = {a.threads}, median of {a.rounds} x {a.repeats}, "
          f"load average {os.getloadavg()[0]:.1f}")
    # (method, ensemble, stop rule, fixed sifts)
    configs = [("emd", 1, "fixed", 1), ("emd", 1, "rilling", 10), ("beemdan", 10, "rilling", 10)]
    # The cheap configuration is repeated more: its difference is the overhead, a few ms, and a
    # shared machine's noise is as large.
    repeats = {"fixed": a.repeats * 4}
    if a.quick:
        configs = configs[:2]
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "x.f64")
        x.astype("<f8").tofile(path)
        for method, ensemble, stop, sifts in configs:
            cpp, py, k = [], [], None
            # Rounds alternate between the C++ program and Python so a machine shared with other
            # jobs loads both alike; each round drops its first call (a fresh process's first
            # allocations fault pages in) and times `repeats` more.
            for _ in range(a.rounds):
                n = repeats.get(stop, a.repeats)
                out = subprocess.run([a.timing, path, method, str(ensemble), "1", str(a.threads),
                                      str(n + 1), stop, str(sifts)],
                                     capture_output=True, text=True, check=True)
                c = json.loads(out.stdout)
                cpp += c["seconds"][1:]
                k = c["imfs"]
                for i in range(n + 1):
                    start = time.perf_counter()
                    imfs, _, _ = gd.decompose(x, method=method, ensemble=ensemble, seed=1,
                                              threads=a.threads, stop=stop, fixed_sifts=sifts)
                    if i:
                        py.append(time.perf_counter() - start)
                assert imfs.shape[1] == k, (imfs.shape, k)
            c, q = statistics.median(cpp), statistics.median(py)
            label = f"{method} {stop}" + (f" {sifts}" if stop == "fixed" else "") + \
                (f" I={ensemble}" if method != "emd" else "")
            print(f"{label:20s} n={len(py):<3d} C++ {c * 1e3:9.2f} ms   Python {q * 1e3:9.2f} ms   "
                  f"overhead {(q - c) * 1e3:+8.2f} ms ({100 * (q - c) / c:+.2f} %)   K = {k}")

if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Binding overhead of gyrodrift.decompose: the same decomposition of 1e5 samples timed from Python
and from C++ (decompose_timing, built by the Python package's CMake), median of 5 each.

    cmake --build build --target _gyrodrift decompose_timing
    PYTHONPATH=build/python /usr/bin/python3 bench/python/bench_decompose.py \
        --timing build/bench/python/decompose_timing

Prints one line per configuration: C++ median, Python median, their difference (the overhead:
converting the input, the (N, K) result and the report, and releasing the GIL), and the IMF count
(the same in both, as a check that the same work was timed).
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
    p.add_argument("--threads", type=int, default=1)
    a = p.parse_args()
    x = signal(a.samples)
    print(f"{platform.node()} {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, N = {a.samples}, "
          f"threads = {a.threads}, median of {a.repeats}")
    configs = [("emd", 1), ("beemdan", 10)]
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "x.f64")
        x.astype("<f8").tofile(path)
        for method, ensemble in configs:
            out = subprocess.run([a.timing, path, method, str(ensemble), "1", str(a.threads),
                                  str(a.repeats)], capture_output=True, text=True, check=True)
            cpp = json.loads(out.stdout)
            py = []
            for _ in range(a.repeats):
                start = time.perf_counter()
                imfs, _, _ = gd.decompose(x, method=method, ensemble=ensemble, seed=1,
                                          threads=a.threads)
                py.append(time.perf_counter() - start)
            c, q = statistics.median(cpp["seconds"]), statistics.median(py)
            assert imfs.shape[1] == cpp["imfs"], (imfs.shape, cpp["imfs"])
            print(f"{method:8s} I={ensemble:<3d} C++ {c * 1e3:9.2f} ms   Python {q * 1e3:9.2f} ms   "
                  f"overhead {(q - c) * 1e3:+8.2f} ms ({100 * (q - c) / c:+.2f} %)   "
                  f"K = {cpp['imfs']}")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Decompose a simulated gyro log with BEEMDAN and plot its IMFs (imfs.png).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/decompose_imfs.py [OUT_DIR]
"""

import sys

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import gyrodrift as gd  # noqa: E402

out = sys.argv[1] if len(sys.argv) > 1 else "."
sim = gd.simulate(duration=2 * 3600, seed=7)
imfs, residue, report = gd.decompose(sim["rate_dph"], method="beemdan", ensemble=50, seed=7)
print(report["summary"])

hours = sim["time_s"] / 3600
rows = imfs.shape[1] + 2
fig, axes = plt.subplots(rows, 1, figsize=(8, 1.2 * rows), sharex=True)
axes[0].plot(hours, sim["rate_dph"], lw=0.5)
axes[0].set_ylabel("rate")
for k in range(imfs.shape[1]):
    axes[k + 1].plot(hours, imfs[:, k], lw=0.5)
    axes[k + 1].set_ylabel(f"IMF {k + 1}")
# The drift spreads over the slowest modes: the last IMF and the residue together follow it.
axes[-1].plot(hours, imfs[:, -1] + residue, label="last IMF + residue")
axes[-1].plot(hours, sim["truth"]["drift_dph"], "--", label="true drift")
axes[-1].legend(fontsize="small")
axes[-1].set_xlabel("time [h]")
fig.suptitle("BEEMDAN of a simulated FOG log [deg/h]")
fig.tight_layout(rect=(0, 0, 1, 0.98))
fig.savefig(f"{out}/imfs.png", dpi=100)
assert np.allclose(imfs.sum(axis=1) + residue, sim["rate_dph"])
print(f"wrote {out}/imfs.png")

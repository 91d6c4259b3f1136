#!/usr/bin/env python3
"""Fit a compensation model on one simulated run, compensate another, and plot the Allan deviation
before and after (allan.png): the thermal drift's rise at long taus is what compensation removes.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/allan_compensation.py [OUT_DIR]
"""

import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import gyrodrift as gd  # noqa: E402

out = sys.argv[1] if len(sys.argv) > 1 else "."
train = gd.simulate(duration=8 * 3600, seed=1)
test = gd.simulate(duration=8 * 3600, profile="chamber-b", seed=2)

model = gd.DriftModel().fit(train["rate_dph"], train["temperature_c"], mode="compensate", seed=1)
print(model.summary)
compensated = model.compensate(test["rate_dph"], test["temperature_c"])

fig, ax = plt.subplots(figsize=(6, 4))
for label, x in (("before", test["rate_dph"]), ("after", compensated)):
    a = gd.allan(x, rate_hz=1.0, taus="octave")
    ax.errorbar(a["tau_s"], a["dev"], yerr=[a["dev"] - a["dev_lo"], a["dev_hi"] - a["dev"]],
                marker=".", capsize=2, label=f"{label} compensation")
    terms = a["noise_terms"]
    if "error" in terms:
        print(f"{label:6s}: noise terms not fitted: {terms['error']}")
        continue
    b = terms["B"]
    b_text = f"{b['value']:.4g} +- {b['sigma']:.2g} deg/h" if b["identified"] else "not identified"
    print(f"{label:6s}: curve minimum {terms['min_dev_dph']:.4g} deg/h at {terms['min_dev_tau_s']:.4g} s,"
          f" bias instability B {b_text}")
ax.set(xscale="log", yscale="log", xlabel="tau [s]", ylabel="overlapping ADEV [deg/h]",
       title="Allan deviation of a test run")
ax.grid(True, which="both", alpha=0.3)
ax.legend()
fig.tight_layout()
fig.savefig(f"{out}/allan.png", dpi=100)
print(f"wrote {out}/allan.png")

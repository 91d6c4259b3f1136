"""A duty-cycled log in Python as on the CLI: ``fit(..., logged=...)`` on the filled log writes
the model file ``gyrodrift fit --gaps carry`` writes, and ``allan(..., logged=...)`` gives
``gyrodrift allan --gaps carry``'s deviations."""

import json

import numpy as np
import pytest

import gyrodrift as gd
from conftest import read_csv, write_csv


@pytest.mark.parametrize("method", ["poly", "thermal"])
def test_carry_matches_cli(cli, tmp_path, method):
    sim = gd.simulate(duration=4 * 3600, seed=6)
    keep = (sim["time_s"] % 300.0) < 30.0  # 30 s of every 300 s
    write_csv(tmp_path / "bursts.csv",
              {k: sim[k][keep] for k in ("time_s", "rate_dph", "temperature_c")})
    cli("fit", tmp_path / "bursts.csv", "-t", "rate_dph", "-T", "temperature_c", "--mode",
        "compensate", "-m", method, "--gaps", "carry", "-q", "-o", tmp_path / "cli.json")
    # The filled log as the CLI reads it, with the made-up rows marked.
    cli("compensate", tmp_path / "cli.json", tmp_path / "bursts.csv", "--gaps", "interpolate", "-q",
        "-o", tmp_path / "filled.csv")
    filled = read_csv(tmp_path / "filled.csv")
    logged = filled["interpolated"] == 0
    assert logged.sum() == keep.sum()
    y = np.where(logged, filled["rate_dph"], np.nan)  # the made-up rows are never read
    m = gd.DriftModel().fit(y, filled["temperature_c"], mode="compensate", method=method,
                            logged=logged, source=str(tmp_path / "bursts.csv"))
    m.save(tmp_path / "py.json")
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    if method == "thermal":  # 10 % of the rows logged: the sparse-log ridge (docs/drift.md 4.8)
        report = json.loads((tmp_path / "py.json").read_text())["model"]["sub_models"][0][
            "thermal"]["report"]
        assert report["prior_samples"] == 16.0

    cli("allan", tmp_path / "bursts.csv", "-c", "rate_dph", "--rate-hz", "1", "--gaps", "carry",
        "-q", "-o", tmp_path / "adev.csv")
    out = read_csv(tmp_path / "adev.csv")
    r = gd.allan(y, rate_hz=1.0, logged=logged)
    assert np.array_equal(r["n_terms"], out["n_terms"])
    assert np.array_equal(r["dev"], out["dev"])


def test_carry_needs_a_method_without_a_decomposition():
    sim = gd.simulate(duration=7200, seed=5)
    logged = np.arange(sim["rate_dph"].size) % 10 < 5
    with pytest.raises(gd.UsageError, match="logged rows only"):
        gd.DriftModel().fit(sim["rate_dph"], sim["temperature_c"], mode="compensate",
                            method="ms-elm", ensemble=5, logged=logged)

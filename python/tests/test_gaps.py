"""A duty-cycled log in Python as on the CLI: ``fit(..., logged=...)`` on the filled log writes
the model file ``gyrodrift fit --gaps carry`` writes, ``compensation_summary(..., logged=...)``
gives ``gyrodrift compensate --gaps carry``'s figures, and ``allan(..., logged=...)`` gives
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
    # The compensation's figures over the logged rows, as compensate --gaps carry reports them.
    cli("compensate", tmp_path / "cli.json", tmp_path / "bursts.csv", "--gaps", "carry", "-q",
        "-o", tmp_path / "carried.csv")
    side = json.loads((tmp_path / "carried.csv.json").read_text())
    summary = m.compensation_summary(filled["temperature_c"], filled["rate_dph"], logged=logged)
    assert summary["samples"] == side["samples"] == keep.sum()
    for when in ("before", "after"):
        for figure in ("mean", "rms", "std"):
            assert summary[when][figure] == side[when][figure], (when, figure)

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


def test_records_joined_match_cli_split(cli, tmp_path):
    # A log with a hole analysed as two records (allan --gaps split): the records joined on one
    # grid with a break between them, so no cluster pair spans the hole.
    sim = gd.simulate(duration=2 * 3600, seed=4)
    keep = (sim["time_s"] < 3000.0) | (sim["time_s"] > 4000.0)
    write_csv(tmp_path / "holed.csv", {k: sim[k][keep] for k in ("time_s", "rate_dph")})
    cli("allan", tmp_path / "holed.csv", "-c", "rate_dph", "--rate-hz", "1", "--gaps", "split",
        "-q", "-o", tmp_path / "split.csv")
    out = read_csv(tmp_path / "split.csv")
    x = sim["rate_dph"][keep]
    second = int(np.argmax(sim["time_s"][keep] > 4000.0))
    r = gd.allan(x, rate_hz=1.0, record_starts=[second])
    assert np.array_equal(r["n_terms"], out["n_terms"])
    assert np.array_equal(r["dev"], out["dev"])
    with pytest.raises(gd.UsageError, match="logged and record_starts: give one"):
        gd.allan(x, rate_hz=1.0, record_starts=[second], logged=np.ones(x.size, bool))
    with pytest.raises(gd.DataError, match=r"^record_starts\[0\] = 0: record starts must"):
        gd.allan(x, rate_hz=1.0, record_starts=[0])

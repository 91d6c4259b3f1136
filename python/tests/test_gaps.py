"""A log with gaps in Python as on the CLI: ``read_log`` reads it as the commands do, and
``fit(..., logged=...)`` on the filled log writes the model file ``gyrodrift fit --gaps carry``
writes, ``compensation_summary(..., logged=...)`` gives ``gyrodrift compensate --gaps carry``'s
figures, ``allan(..., logged=...)`` gives ``gyrodrift allan --gaps carry``'s deviations, and
``record_starts`` does what ``--gaps split`` does."""

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
    log = gd.read_log(tmp_path / "bursts.csv", gaps="carry")
    logged = log["logged"]
    assert logged.sum() == keep.sum()
    filled = log["columns"]
    y = np.where(logged, filled["rate_dph"], np.nan)  # the made-up rows are never read
    m = gd.DriftModel().fit(y, filled["temperature_c"], mode="compensate", method=method,
                            logged=logged, rate_hz=log["rate_hz"],
                            source=str(tmp_path / "bursts.csv"))
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
    summary = m.compensation_summary(filled["rate_dph"], filled["temperature_c"], logged=logged)
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


def test_read_log_fills_and_splits_as_the_cli(cli, tmp_path):
    sim = gd.simulate(duration=3 * 3600, seed=8)
    keep = (sim["time_s"] % 600.0) < 120.0  # 2 min of every 10
    write_csv(tmp_path / "bursts.csv",
              {k: sim[k][keep] for k in ("time_s", "rate_dph", "temperature_c")})
    # The filled rows: those compensate --gaps interpolate writes, the made-up ones marked.
    cli("fit", tmp_path / "bursts.csv", "-t", "rate_dph", "-T", "temperature_c", "--mode",
        "compensate", "-m", "poly", "--gaps", "carry", "-q", "-o", tmp_path / "carry.json")
    cli("compensate", tmp_path / "carry.json", tmp_path / "bursts.csv", "--gaps", "interpolate",
        "-q", "-o", tmp_path / "filled.csv")
    filled = read_csv(tmp_path / "filled.csv")
    for gaps in ("interpolate", "carry"):
        log = gd.read_log(tmp_path / "bursts.csv", gaps=gaps)
        assert list(log["columns"]) == ["time_s", "rate_dph", "temperature_c"]
        for name, values in log["columns"].items():
            assert np.array_equal(values, filled[name]), (gaps, name)
        assert np.array_equal(log["logged"], filled["interpolated"] == 0)
        assert log["record_starts"] == []
        assert log["rate_hz"] == 1.0 and log["rate_source"] == "from the steps of time_s"
        assert "gaps" in log["notes"][0]

    # Split: the records' starts, which fit and allan take as --gaps split does.
    log = gd.read_log(tmp_path / "bursts.csv", gaps="split")
    assert log["logged"] is None and len(log["record_starts"]) == 18
    assert np.array_equal(log["columns"]["rate_dph"], sim["rate_dph"][keep])
    cli("fit", tmp_path / "bursts.csv", "-t", "rate_dph", "-T", "temperature_c", "--mode",
        "compensate", "-m", "thermal", "--gaps", "split", "-q", "-o", tmp_path / "split.json")
    m = gd.DriftModel().fit(log["columns"]["rate_dph"], log["columns"]["temperature_c"],
                            mode="compensate", method="thermal", rate_hz=log["rate_hz"],
                            record_starts=log["record_starts"],
                            source=str(tmp_path / "bursts.csv"))
    m.save(tmp_path / "py.json")
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "split.json").read_bytes()

    # What the CLI refuses, read_log refuses with its message.
    with pytest.raises(gd.DataError, match="time_s jumps by 481 s before data row 120"):
        gd.read_log(tmp_path / "bursts.csv")
    with pytest.raises(gd.UsageError, match="^gaps = 'fill': must be one of"):
        gd.read_log(tmp_path / "bursts.csv", gaps="fill")
    with pytest.raises(gd.UsageError, match="^rate_hz = 0: must be in"):
        gd.read_log(tmp_path / "bursts.csv", rate_hz=0)
    with pytest.raises(gd.UsageError, match="^skip_rows = -1"):
        gd.read_log(tmp_path / "bursts.csv", skip_rows=-1)
    with pytest.raises(gd.UsageError, match="^skip_rows = 4294967296: must be an integer"):
        gd.read_log(tmp_path / "bursts.csv", skip_rows=2 ** 32)
    with pytest.raises(gd.FileError):
        gd.read_log(tmp_path / "missing.csv")


def test_read_log_of_a_capture_without_time_warns_of_the_rate(tmp_path):
    # A serial capture: a banner, no header row, no time column.
    (tmp_path / "capture.txt").write_text("BMI270 ready\n25.5,1.0\n25.5,2.0\n25.6,4.0\n")
    with pytest.warns(UserWarning, match=r"has no time_s column: .* \(give rate_hz= if"):
        log = gd.read_log(tmp_path / "capture.txt", names=["temp_c", "gx"], skip_rows=1)
    assert np.array_equal(log["columns"]["gx"], [1.0, 2.0, 4.0])
    assert log["rate_source"] == "assumed: no rate_hz and no time_s column"
    log = gd.read_log(tmp_path / "capture.txt", names="temp_c,gx".split(","), skip_rows=1,
                      rate_hz=100.0)
    assert log["rate_hz"] == 100.0 and log["rate_source"] == "given by rate_hz"

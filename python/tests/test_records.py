"""Several calibration runs as records of one run, in Python as on the CLI: ``fit(...,
record_starts=...)`` writes the model file ``gyrodrift fit A.csv B.csv`` writes, and
``compensate(..., record_starts=...)`` gives ``gyrodrift compensate --gaps split``'s numbers."""

import numpy as np
import pytest

import gyrodrift as gd
from conftest import read_csv, write_csv


def test_records_match_cli(cli, tmp_path):
    a = gd.simulate(duration=4 * 3600, seed=3)
    b = gd.simulate(duration=3 * 3600, seed=4)
    for name, sim, offset in (("a", a, 0.0), ("b", b, 0.0), ("b_late", b, 4 * 3600 + 1800.0)):
        write_csv(tmp_path / f"{name}.csv", {"time_s": sim["time_s"] + offset,
                                             "rate_dph": sim["rate_dph"],
                                             "temperature_c": sim["temperature_c"]})
    cli("fit", tmp_path / "a.csv", tmp_path / "b.csv", "-t", "rate_dph", "-T", "temperature_c",
        "--mode", "compensate", "-q", "-o", tmp_path / "cli.json")

    y = np.concatenate([a["rate_dph"], b["rate_dph"]])
    t = np.concatenate([a["temperature_c"], b["temperature_c"]])
    starts = [a["rate_dph"].size]
    m = gd.DriftModel().fit(y, t, mode="compensate", record_starts=starts,
                            source=f"{tmp_path / 'a.csv'},{tmp_path / 'b.csv'}")
    m.save(tmp_path / "py.json")
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()

    # One log with a 30-min hole, split at it by the CLI; the same records in Python.
    joined = {k: np.concatenate([read_csv(tmp_path / "a.csv")[k], read_csv(tmp_path / "b_late.csv")[k]])
              for k in ("time_s", "rate_dph", "temperature_c")}
    write_csv(tmp_path / "gap.csv", joined)
    cli("compensate", tmp_path / "cli.json", tmp_path / "gap.csv", "--gaps", "split", "-q",
        "-o", tmp_path / "c.csv")
    out = read_csv(tmp_path / "c.csv")
    assert np.array_equal(m.compensate(y, t, record_starts=starts), out["compensated"])
    est, _ = m.estimate(t, record_starts=starts)
    assert np.array_equal(est, out["drift_est"])


def test_records_need_the_thermal_method():
    sim = gd.simulate(duration=7200, seed=5)
    with pytest.raises(gd.UsageError, match="several records"):
        gd.DriftModel().fit(sim["rate_dph"], sim["temperature_c"], mode="compensate",
                            method="ms-elm", ensemble=5, record_starts=[3600])
    with pytest.raises(gd.DataError, match="record starts"):
        gd.DriftModel().fit(sim["rate_dph"], sim["temperature_c"], mode="compensate",
                            record_starts=[0])

"""The logs people have and the runs they plan, from Python: read_ulog and ulog_columns give the
numbers `gyrodrift convert` gives (the same CSV, to the bit), and plan the programme `gyrodrift
plan` writes."""

import os
import pathlib

import numpy as np
import pytest

import gyrodrift as gd
from conftest import read_csv

TESTDATA = pathlib.Path(os.environ.get("GYRODRIFT_TESTDATA_DIR",
                                       pathlib.Path(__file__).resolve().parents[3] / "shared/testdata"))
LOG = TESTDATA / "px4_ulog_samples" / "sample_log_small.ulg"


def test_read_ulog_lists_three_gyro_instances_with_temperature():
    log = gd.read_ulog(str(LOG))
    gyros = [s for s in log["series"] if s["topic"] == "sensor_gyro"]
    assert [s["instance"] for s in gyros] == [0, 1, 2]
    for s in gyros:
        assert "temperature" in s["fields"] and s["samples"] == 6 and s["decoded"]
    # pyulog's first sample of instance 0 (tests/unit/io/ulog_test.cc).
    assert gyros[0]["timestamp_us"][0] == 21312030
    assert gyros[0]["values"]["x"][0] == -0.04130320996046066
    assert len(log["parameters"]) == 980 and log["warnings"] == []
    # A path object and one topic as a string (not its letters) read the same.
    one = gd.read_ulog(LOG, decode="sensor_gyro")
    assert [s["values"]["x"][0] for s in one["series"] if s["topic"] == "sensor_gyro"][0] == \
        gyros[0]["values"]["x"][0]
    # --list names every series on a line of its own, however many fields it has.
    assert len(log["listing"].splitlines()) == 2 + len(log["series"]) + 3


def test_a_damaged_logs_text_and_bad_arguments_raise_gyrodrift_errors(tmp_path):
    # A value that is not UTF-8 (the 'P' of sys_name = PX4 made 0xff): replaced, not a
    # UnicodeDecodeError.
    data = bytearray(LOG.read_bytes())
    at = data.find(b"sys_namePX4") + len(b"sys_name")
    data[at] = 0xFF
    damaged = tmp_path / "damaged.ulg"
    damaged.write_bytes(bytes(data))
    assert gd.read_ulog(str(damaged))["info"]["sys_name"] == "\ufffdX4"
    with pytest.raises(gd.FileError, match="is a directory"):
        gd.read_ulog(str(tmp_path))
    for bad in (-1, 256):
        with pytest.raises(gd.UsageError, match=rf"instance = {bad}: must be an integer in \[0, 255\]"):
            gd.ulog_columns(str(LOG), instance=bad)
    with pytest.raises(gd.UsageError, match="named twice"):
        gd.ulog_columns(str(LOG), instance=0, axes=("x", "x"))


def test_ulog_columns_are_what_convert_writes(cli, tmp_path):
    cli("convert", LOG, "--instance", "1", "--units", "dps", "-o", tmp_path / "g.csv")
    written = read_csv(tmp_path / "g.csv")
    columns = gd.ulog_columns(str(LOG), instance=1, units="dps")
    for name in ("time_s", "x_dps", "y_dps", "z_dps", "temperature_c"):
        np.testing.assert_array_equal(columns[name], written[name])


def test_plan_is_what_the_cli_writes(cli, tmp_path):
    cli("plan", "--hours", "12", "--min", "-40", "--max", "70", "-o", tmp_path / "p.csv")
    written = read_csv(tmp_path / "p.csv")
    p = gd.plan(hours=12, min_c=-40, max_c=70)
    np.testing.assert_array_equal(p["time_s"], written["time_s"])
    np.testing.assert_array_equal(p["temperature_c"], written["temperature_c"])
    sim = gd.simulate(profile=(p["time_s"], p["temperature_c"]), duration=3600, seed=1)
    assert len(sim["rate_dph"]) == 3600
    # The plan's file as simulate --profile FILE reads it, in Python as in the CLI.
    cli("simulate", "--profile", tmp_path / "p.csv", "--duration", "1h", "--seed", "1", "-q",
        "-o", tmp_path / "s.csv")
    from_file = gd.simulate(profile=tmp_path / "p.csv", duration=3600, seed=1)
    assert np.array_equal(from_file["rate_dph"], read_csv(tmp_path / "s.csv")["rate_dph"])
    assert np.array_equal(from_file["rate_dph"], sim["rate_dph"])
    with pytest.raises(gd.UsageError, match=r"^profile = nope.csv: must be chamber, chamber-b, "):
        gd.simulate(profile="nope.csv")
    with pytest.raises(gd.UsageError, match="it needs 8.4 h or more"):
        gd.plan(hours=4, min_c=-40, max_c=80)

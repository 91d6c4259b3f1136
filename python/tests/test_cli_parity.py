"""The Python API and the CLI give the same numbers, to the bit, for the same inputs and options:
simulate, decompose, allan, fit + compensate (and the model file itself), evaluate."""

import csv
import math

import numpy as np
import pytest

import gyrodrift as gd
from conftest import read_csv, read_json, same_bits, write_csv


@pytest.fixture(scope="module")
def sim_csv(cli, tmp_path_factory):
    """A 2-hour simulated log written by the CLI (the same seed is simulated in Python below)."""
    path = tmp_path_factory.mktemp("parity") / "sim.csv"
    cli("simulate", "--duration", "2h", "--seed", "7", "-q", "-o", path)
    return path


def test_simulate_matches_cli(sim_csv):
    logged = read_csv(sim_csv)
    sim = gd.simulate(duration=7200, seed=7)
    for name in ("time_s", "rate_dph", "temperature_c"):
        assert np.array_equal(sim[name], logged[name]), name
    for name in ("drift_dph", "shupe_dph", "stress_dph", "bias_dph", "noise_dph"):
        assert np.array_equal(sim["truth"][name], logged[name]), name


@pytest.mark.parametrize("method,extra", [("beemdan", ["--ensemble", "20"]),
                                          ("emd", []),
                                          ("ceemdan", ["--ensemble", "10", "--stop", "snumber"])])
def test_decompose_matches_cli(cli, tmp_path, method, extra):
    rng = np.random.default_rng(11)
    t = np.arange(3000.0)
    x = np.sin(t / 17.0) + 0.3 * np.sin(t / 3.1) + 0.2 * rng.standard_normal(t.size) + 1e-3 * t
    write_csv(tmp_path / "x.csv", {"x": x})
    cli("decompose", tmp_path / "x.csv", "-c", "x", "--method", method, "--seed", "5",
        "-j", "2", "-q", *extra, "-o", tmp_path / "imfs.csv")
    out = read_csv(tmp_path / "imfs.csv")
    side = read_json(tmp_path / "imfs.csv.json")["report"]

    kw = dict(ensemble=int(extra[1])) if extra else {}
    if "--stop" in extra:
        kw["stop"] = "snumber"
    imfs, residue, report = gd.decompose(x, method=method, seed=5, threads=1, **kw)
    assert imfs.shape == (x.size, side["imfs"])
    for k in range(imfs.shape[1]):
        assert np.array_equal(imfs[:, k], out[f"imf{k + 1}"]), f"imf{k + 1}"
    assert np.array_equal(residue, out["residue"])
    for key in ("summary", "sifts_per_imf", "sift_cap_hits", "noise_assisted_stages",
                "stop_reason", "seed", "ensemble_size"):
        assert report[key] == side[key], key
    assert same_bits(report["mode_log2_energy"], side["mode_log2_energy"])


@pytest.mark.parametrize("dev,taus", [("oadev", "octave"), ("mdev", "decade"),
                                      ("totdev", "1,4,16,64")])
def test_allan_matches_cli(cli, sim_csv, tmp_path, dev, taus):
    cli("allan", sim_csv, "-c", "rate_dph", "--rate-hz", "1", "--dev", dev, "--taus", taus,
        "-q", "-o", tmp_path / "a.csv")
    out = read_csv(tmp_path / "a.csv")
    side = read_json(tmp_path / "a.csv.json")

    x = read_csv(sim_csv)["rate_dph"]
    grid = taus if not taus[0].isdigit() else [float(v) for v in taus.split(",")]
    r = gd.allan(x, rate_hz=1.0, dev=dev, taus=grid, threads=2)
    for key in ("tau_s", "dev", "dev_lo", "dev_hi", "n_terms"):
        assert np.array_equal(np.asarray(r[key], dtype=float), out[key]), key
    assert same_bits(r["edf"], [p["edf"] for p in side["points"]])
    assert list(r["alpha"]) == [p["alpha"] for p in side["points"]]
    assert r["summary"] == side["summary"] and r["dev_unit"] == side["dev_unit"]
    terms, side_terms = r["noise_terms"], side["noise_terms"]
    assert terms["source_dev"] == side_terms["source_dev"]
    assert terms["summary"] == side_terms["summary"]
    for name in "QNBKR":
        for field in ("value", "sigma", "identified", "evidence_chi2", "slope_reading"):
            assert same_bits(terms[name][field], side_terms[name][field]), (name, field)


def test_noise_terms_of_a_bare_curve_match_the_result_fit(sim_csv):
    x = read_csv(sim_csv)["rate_dph"]
    r = gd.allan(x, rate_hz=1.0)
    bare = gd.noise_terms(r["tau_s"], r["dev"], r["edf"], sample_period_s=1.0)
    assert bare["N"]["identified"]
    for name in "QNBKR":
        assert same_bits(bare[name]["value"], r["noise_terms"][name]["value"]), name


def test_fit_and_compensate_match_cli(cli, sim_csv, tmp_path):
    cli("fit", sim_csv, "--target", "rate_dph", "--temperature", "temperature_c",
        "--mode", "compensate", "--seed", "3", "-j", "2", "-q", "-o", tmp_path / "cli_model.json")
    cli("compensate", tmp_path / "cli_model.json", sim_csv, "-q", "-o", tmp_path / "comp.csv")
    comp = read_csv(tmp_path / "comp.csv")

    log = read_csv(sim_csv)
    y, temperature = log["rate_dph"], log["temperature_c"]
    model = gd.DriftModel().fit(y, temperature, mode="compensate", seed=3, threads=1,
                                target="rate_dph", temperature_columns=["temperature_c"],
                                source=str(sim_csv))
    assert model.method == "thermal" and model.mode == "compensate"
    # The model file is the CLI's, byte for byte (same options, same source, same doubles), though
    # fitted on another thread count: a model file records none (format 6).
    model.save(tmp_path / "py_model.json")
    assert (tmp_path / "py_model.json").read_bytes() == (tmp_path / "cli_model.json").read_bytes()

    estimate, sd = model.estimate(temperature)
    assert np.array_equal(estimate, comp["drift_est"])
    assert np.array_equal(sd, comp["drift_sd"])
    assert np.array_equal(model.compensate(y, temperature), comp["compensated"])
    # And the CLI's file, loaded in Python, compensates the same.
    loaded = gd.DriftModel.load(tmp_path / "cli_model.json")
    assert loaded.summary == model.summary
    assert np.array_equal(loaded.compensate(y, temperature), comp["compensated"])
    thermal = loaded.sub_models[0]["thermal"]
    assert thermal is not None
    assert len(thermal["regressors"]) == len(thermal["coefficients"]) == len(thermal["sd"])
    assert any("temperature_c" in name for name in thermal["regressors"])
    assert np.all(np.isfinite(thermal["sd"]))
    # What compensation did, as the CLI printed and kept it (drift::SummariseCompensation).
    side = read_json(tmp_path / "comp.csv.json")
    summary = loaded.compensation_summary(y, temperature)
    for when in ("before", "after"):
        for figure in ("mean", "rms", "std", "slow_variation"):
            assert summary[when][figure] == side[when][figure], (when, figure)
    assert summary["slow_variation_blocks"] == side["slow_variation_blocks"] == 12
    assert summary["outside_share"] == side["outside_training_temperature_share"]
    assert summary["drift_sd_mean"] == side["drift_sd_mean"]
    assert "truth_removed" not in summary
    # Against the true drift, as compensate --truth.
    cli("compensate", tmp_path / "cli_model.json", sim_csv, "--truth", "drift_dph", "-q", "-o",
        tmp_path / "truth.csv")
    side = read_json(tmp_path / "truth.csv.json")["truth"]
    summary = loaded.compensation_summary(y, temperature, truth=log["drift_dph"])
    assert summary["truth_rms"] == side["rms"]
    assert summary["residual_rms"] == side["residual_rms"]
    assert 100.0 * summary["truth_removed"] == side["removed_percent"]
    printed = cli("compensate", tmp_path / "cli_model.json", sim_csv, "-o",
                  tmp_path / "comp2.csv").stdout
    assert summary["table"] in printed
    # The coefficients in physical units, as `fit` prints them.
    printed = cli("fit", sim_csv, "--target", "rate_dph", "--temperature", "temperature_c",
                  "--mode", "compensate", "--seed", "3", "-o", tmp_path / "m2.json").stdout
    (coefficients,) = loaded.coefficients()
    assert coefficients["reference_c"][0] == pytest.approx(np.mean(temperature), abs=1e-9)
    for term in coefficients["terms"]:
        assert f"{term['term']:<40} {term['value']:>12.6g} +- " in printed, term
        assert term["unit"].startswith("dph")
    (at_20,) = loaded.coefficients(reference_temperature=20.0)
    assert at_20["reference_c"] == [20.0]
    assert at_20["terms"][0]["term"] == "bias"


def test_fit_settings_map_as_the_cli_flags(cli, sim_csv, tmp_path):
    # One mapping of the settings (drift::MakeDriftOptions): the same model file, and the same
    # refusal naming the keyword where the CLI names the flag.
    cli("fit", sim_csv, "-t", "rate_dph", "-T", "temperature_c", "--mode", "compensate",
        "--hysteresis", "on", "--reference-temperature", "20", "-q", "-o", tmp_path / "cli.json")
    log = read_csv(sim_csv)
    model = gd.DriftModel().fit(log["rate_dph"], log["temperature_c"], mode="compensate",
                                hysteresis="on", reference_temperature=20, target="rate_dph",
                                temperature_columns=["temperature_c"], source=str(sim_csv))
    model.save(tmp_path / "py.json")
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    assert read_json(tmp_path / "py.json")["options"]["thermal"]["hysteresis"] == "on"
    assert "hysteresis" in model.sub_models[0]["thermal"]
    with pytest.raises(ValueError, match=r"^hysteresis = 'off': must be auto unless mode"):
        gd.DriftModel().fit(log["rate_dph"], log["temperature_c"], mode="compensate",
                            method="poly", hysteresis="off")
    with pytest.raises(ValueError, match=r"^lags = 8: must be left unset in mode 'compensate'"):
        gd.DriftModel().fit(log["rate_dph"], log["temperature_c"], mode="compensate", lags=8)


def test_fit_units_as_the_cli_flag(cli, sim_csv, tmp_path):
    # The target's unit (fit --units, units=) is kept in the model file, labels the estimates and
    # scales the PX4 export: a deg/s gyro fitted in Python exports as the CLI's does.
    sim = read_csv(sim_csv)
    axes = {"x": sim["rate_dph"], "y": -0.5 * sim["rate_dph"], "z": 2.0 * sim["rate_dph"]}
    write_csv(tmp_path / "xyz.csv", {"time_s": sim["time_s"],
                                     **{f"{a}_dps": v / 3600.0 for a, v in axes.items()},
                                     "temperature_c": sim["temperature_c"]})
    cli("fit", tmp_path / "xyz.csv", "-t", "x_dps,y_dps,z_dps", "-T", "temperature_c",
        "--mode", "compensate", "--units", "dps", "-q", "-o", tmp_path / "cli.json")
    log = read_csv(tmp_path / "xyz.csv")
    fit = dict(mode="compensate", temperature_columns=["temperature_c"],
               source=str(tmp_path / "xyz.csv"))
    models = [gd.DriftModel().fit(log[f"{a}_dps"], log["temperature_c"], target=f"{a}_dps",
                                  units="dps", **fit) for a in axes]
    gd.DriftModel.save_axes(tmp_path / "py.json", models)
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    assert models[0].coefficients()[0]["terms"][0]["unit"].startswith("dps")
    # The same numbers recorded as deg/h would export 3600 times too small a correction.
    dph = [gd.DriftModel().fit(log[f"{a}_dps"], log["temperature_c"], target=f"{a}_dps", **fit)
           for a in axes]
    gd.DriftModel.save_axes(tmp_path / "dph.json", dph)
    px4 = [gd.export(tmp_path / name, format="px4", device_ids=[1])
           for name in ("py.json", "cli.json", "dph.json")]
    assert px4[0] == px4[1] != px4[2]
    with pytest.raises(gd.UsageError, match=r"^units = 'knots': must be"):
        gd.DriftModel().fit(log["x_dps"], log["temperature_c"], units="knots", **fit)


def test_two_axis_model_file_matches_cli(cli, tmp_path):
    # Two axes of one IMU: the simulator's output and a second unit's, each with its own sensor.
    a, b = gd.simulate(duration=3600, seed=1), gd.simulate(duration=3600, seed=2, preset="tactical")
    write_csv(tmp_path / "imu.csv", {"time_s": a["time_s"], "gyro_x": a["rate_dph"],
                                     "gyro_y": b["rate_dph"], "temp_x": a["temperature_c"],
                                     "temp_y": b["temperature_c"]})
    cli("fit", tmp_path / "imu.csv", "--target", "gyro_x,gyro_y", "--temperature", "temp_x,temp_y",
        "--mode", "compensate", "-j", "1", "-q", "-o", tmp_path / "cli.json")
    both = np.column_stack([a["temperature_c"], b["temperature_c"]])
    models = [gd.DriftModel().fit(y, both, target=name, temperature_columns=["temp_x", "temp_y"],
                                  threads=1, source=str(tmp_path / "imu.csv"))
              for name, y in (("gyro_x", a["rate_dph"]), ("gyro_y", b["rate_dph"]))]
    gd.DriftModel.save_axes(tmp_path / "py.json", models)
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    axes = gd.DriftModel.load_axes(tmp_path / "cli.json")
    assert [m.target for m in axes] == ["gyro_x", "gyro_y"]
    assert axes[1].temperature_columns == ["temp_x", "temp_y"]
    with pytest.raises(gd.UsageError, match="2 axes"):
        gd.DriftModel.load(tmp_path / "cli.json")
    assert gd.DriftModel.load(tmp_path / "cli.json", axis="gyro_y").summary == models[1].summary


def test_causal_predict_matches_cli_and_takes_its_window_options(cli, sim_csv, tmp_path):
    """`predict --window --mirror --windows --causal-ensemble` and DriftModel.predict(window=,
    mirror=, windows=, causal_ensemble=) give the same bits; each reaches the windows (none
    differs from the default)."""
    log = read_csv(sim_csv)
    y = log["rate_dph"][:1200]
    model = gd.DriftModel().fit(y[:900], mode="predict", method="ms-elm", ensemble=10,
                                realisations=20, seed=2, threads=2, target="rate_dph")
    model.save(tmp_path / "m.json")
    write_csv(tmp_path / "log.csv", {"time_s": log["time_s"][:1200], "rate_dph": y})
    cli("predict", tmp_path / "m.json", tmp_path / "log.csv", "--window", "64", "--mirror",
        "0.25", "--windows", "2", "--causal-ensemble", "3", "-j", "2", "-q", "-o",
        tmp_path / "p.csv")
    settings = dict(window=64, mirror=0.25, windows=2, causal_ensemble=3)
    first, p = model.predict(y, threads=2, **settings)
    assert np.array_equal(p, read_csv(tmp_path / "p.csv")["prediction"][-p.size:])
    for name in ("mirror", "windows", "causal_ensemble"):
        other = {k: v for k, v in settings.items() if k != name}
        assert not np.array_equal(p, model.predict(y, threads=2, **other)[1]), name
    with pytest.raises(gd.UsageError, match=r"^mirror = -1: must be"):
        model.predict(y, window=64, mirror=-1)
    with pytest.raises(gd.UsageError, match=r"^causal_ensemble = -1: must be"):
        model.predict(y, window=64, causal_ensemble=-1)


@pytest.mark.parametrize("mode,args,kwargs", [
    ("predict", ["--methods", "ms-elm,poly", "--protocol", "both", "--window", "64",
                 "--mirror", "0.25", "--windows", "2", "--causal-ensemble", "3", "--repeats", "2",
                 "--ensemble", "10", "--realisations", "20"],
     dict(methods=["ms-elm", "poly"], protocol="both", window=64, mirror=0.25, windows=2,
          causal_ensemble=3, repeats=2, ensemble=10, realisations=20)),
    ("compensate", ["--methods", "thermal,poly", "--temperature", "temperature_c"],
     dict(methods="thermal,poly")),
    ("predict", ["--methods", "persistence,trailing-mean,exp-smoothing,kalman-level,kalman-trend",
                 "--protocol", "causal", "--horizon", "10"],
     dict(methods="persistence,trailing-mean,exp-smoothing,kalman-level,kalman-trend",
          protocol="causal", horizon=10)),
])
def test_evaluate_matches_cli(cli, sim_csv, tmp_path, mode, args, kwargs):
    cli("evaluate", sim_csv, "--target", "rate_dph", "--truth", "drift_dph", "--mode", mode,
        "--seed", "2", "-j", "2", "-q", *args, "-o", tmp_path / "eval.csv")
    with open(tmp_path / "eval.csv", newline="") as f:
        table = list(csv.DictReader(f))
    log = read_csv(sim_csv)
    temperature = log["temperature_c"] if mode == "compensate" else None
    r = gd.evaluate(log["rate_dph"], temperature, log["drift_dph"], mode=mode, seed=2, threads=2,
                    **kwargs)
    assert len(r["rows"]) == len(table)
    for row, cli_row in zip(r["rows"], table):
        assert (row["method"], row["protocol"]) == (cli_row["method"], cli_row["protocol"])
        for name in ("rmse", "rmse_std", "mae", "max_abs", "rmse_measured", "slow_removed"):
            value = float(cli_row[name])
            assert row[name] == value or (math.isnan(row[name]) and math.isnan(value)), \
                (row["method"], row["protocol"], name)
    # The references open every table.
    assert list(dict.fromkeys(row["method"] for row in r["rows"]))[:2] == ["none", "constant"]
    assert r["first_test_sample"] == round(0.7 * len(log["rate_dph"]))


@pytest.mark.parametrize("fmt, extra", [("c", []), ("json-coefficients", []),
                                        ("px4", ["--device-id", "2490378"])])
def test_export_matches_cli(cli, sim_csv, tmp_path, fmt, extra):
    """gd.export gives the bytes `gyrodrift export` writes; the autopilot form PX4's file holds is
    the one the model shows."""
    sim = read_csv(sim_csv)
    three = tmp_path / "xyz.csv"
    write_csv(three, {"time_s": sim["time_s"], "x_dph": sim["rate_dph"],
                      "y_dph": -0.5 * sim["rate_dph"], "z_dph": 2.0 * sim["rate_dph"],
                      "temperature_c": sim["temperature_c"]})
    model = tmp_path / "m.json"
    cli("fit", three, "-t", "x_dph,y_dph,z_dph", "-T", "temperature_c", "--mode", "compensate",
        "-q", "-o", model)
    out = tmp_path / "out"
    cli("export", model, "--format", fmt, *extra, "-q", "-o", out)
    ids = [2490378] if fmt == "px4" else []
    assert gd.export(model, format=fmt, device_ids=ids) == out.read_text()
    autopilot = gd.DriftModel.load(model, axis="x_dph").sub_models[0]["thermal"]["autopilot"]
    assert 0 <= autopilot["degree"] <= 3 and "in (T - " in autopilot["summary"]
    if fmt == "px4":
        with pytest.raises(gd.UsageError, match="device_ids"):
            gd.export(model, format="px4")


def test_demo_matches_cli(cli, tmp_path):
    # The same study and folder as `gyrodrift demo` (study::RunDemo), but for the wall times.
    cli("demo", "-o", tmp_path / "cli", "-q", "--duration", "2h", "--methods", "thermal,poly",
        "--ensemble", "4", "--window", "32")
    fractions = []
    r = gd.demo(tmp_path / "py", duration=7200, methods="thermal,poly", ensemble=4, window=32,
                progress=fractions.append)
    assert r["simulated"] and r["report"] == str(tmp_path / "py" / "report.html")
    assert fractions and fractions == sorted(fractions) and 0 <= fractions[0] <= fractions[-1] <= 1
    for name in r["files"]:
        ours, theirs = tmp_path / "py" / name, tmp_path / "cli" / name
        if name.endswith("_table.csv"):  # every column but the seconds
            a, b = (list(csv.reader(open(p, newline=""))) for p in (ours, theirs))
            assert a[0] == b[0] and len(a) == len(b)
            kept = [i for i, column in enumerate(a[0]) if not column.endswith("_s")]
            assert [[row[i] for i in kept] for row in a] == [[row[i] for i in kept] for row in b]
        elif name == "demo.json":
            a, b = read_json(ours)["options"], read_json(theirs)["options"]
            assert a.pop("output") == str(tmp_path / "py") and b.pop("output") == str(tmp_path / "cli")
            assert a == b
        elif name != "report.html":
            assert ours.read_bytes() == theirs.read_bytes(), name
    assert "thermal" in r["tables"]["compensate"]
    with pytest.raises(gd.UsageError, match=r"^target, temperature, rate_hz, units and gaps need "
                                            r"input"):
        gd.demo(tmp_path / "x", target="rate_dph")
    with pytest.raises(gd.UsageError, match=r"^input needs target"):
        gd.demo(tmp_path / "x", input=tmp_path / "py" / "run_a.csv")

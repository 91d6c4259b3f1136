"""The Python API on its own: shapes, errors as Python exceptions with the library's messages,
array conversion, predict mode, model files of several axes, and the GIL released in long calls."""

import re
import threading
import time

import numpy as np
import pytest

import gyrodrift as gd


def test_decompose_sums_back_and_accepts_lists_and_float32():
    t = np.arange(1024.0)
    x = np.sin(t / 9.0) + 0.01 * t
    imfs, residue, report = gd.decompose(x.astype(np.float32), method="emd")
    assert imfs.ndim == 2 and imfs.shape[0] == x.size and imfs.shape[1] == report["imfs"] >= 1
    np.testing.assert_allclose(imfs.sum(axis=1) + residue, x.astype(np.float32), atol=1e-9)
    same = gd.decompose(list(x.astype(np.float32)), method="emd")
    assert np.array_equal(same[0], imfs)
    # The same bits for any thread count (the library's promise, kept through the binding).
    a = gd.decompose(x, ensemble=8, seed=2, threads=1)[0]
    b = gd.decompose(x, ensemble=8, seed=2, threads=2)[0]
    assert np.array_equal(a, b)


def test_errors_are_python_exceptions_with_the_library_messages(tmp_path):
    with pytest.raises(gd.UsageError, match="no-such") as e:
        gd.decompose(np.arange(100.0), method="no-such")
    assert isinstance(e.value, ValueError)
    with pytest.raises(gd.UsageError, match=r"^ensemble = 0: must be"):
        gd.decompose(np.arange(100.0), ensemble=0)
    x = np.sin(np.arange(100.0))
    x[10] = np.nan
    with pytest.raises(gd.DataError) as e:
        gd.decompose(x)
    assert isinstance(e.value, ValueError) and not isinstance(e.value, gd.UsageError)
    with pytest.raises(gd.FileError) as e:
        gd.DriftModel.load(tmp_path / "missing.json")
    assert isinstance(e.value, OSError) and "missing.json" in str(e.value)
    with pytest.raises(gd.UsageError, match="1-D array"):
        gd.allan(np.zeros((3, 3, 3)), rate_hz=1.0)
    with pytest.raises(gd.UsageError, match="rate_hz"):
        gd.allan(np.ones(100), rate_hz=-1.0)
    with pytest.raises(gd.UsageError, match="temperature"):
        gd.DriftModel().fit(np.ones(100), mode="compensate")
    with pytest.raises(gd.UsageError, match="pair of arrays"):
        gd.simulate(profile=3)
    with pytest.raises(gd.UsageError, match=r"hidden = 2.5: must be auto or an integer"):
        gd.DriftModel().fit(np.ones(100), mode="predict", hidden=2.5)
    with pytest.raises(gd.FileError, match="nonexistent.toml"):
        gd.calibrate(tmp_path / "nonexistent.toml", tmp_path / "out")
    with pytest.raises(gd.UsageError, match="not fitted"):
        gd.DriftModel().summary
    with pytest.raises(gd.FileError, match="is a directory"):
        gd.DriftModel.load(tmp_path)
    with pytest.raises(gd.DataError, match=r"sample 3 is 1e\+200: no instrument logs"):
        gd.allan(np.array([0.1, 0.2, 1e200, 0.1, 0.3]), rate_hz=1.0)
    with pytest.raises(gd.UsageError, match=r"noise_realisations: an \(N, I\) array"):
        gd.decompose(np.arange(100.0), method="eemd", noise_realisations=np.zeros((100, 0)))
    # Integers beyond the C types: one line naming the argument (pybind listed the signature).
    with pytest.raises(gd.UsageError, match=r"^ensemble = 1099511627776: must be an integer in "
                                            r"\[-2\^31, 2\^31\)$"):
        gd.decompose(np.arange(100.0), method="eemd", ensemble=2**40)
    with pytest.raises(gd.UsageError, match=r"^seed = -1: must be an integer in \[0, 2\^64\)$"):
        gd.simulate(duration=600, seed=-1)
    with pytest.raises(gd.UsageError, match=r"^device_ids = -1: must be an integer in \[0, 2\^32\)"):
        gd.export([], format="px4", device_ids=[-1])
    with pytest.raises(TypeError):  # a wrong type stays pybind's TypeError
        gd.decompose(np.arange(100.0), ensemble="many")
    with pytest.raises(TypeError):  # a float parameter's large integer is not blamed for it
        gd.allan(np.arange(100.0), rate_hz=1, fit_tau_max=10**10, units=5)
    with pytest.raises(gd.UsageError, match=r"methods = 5: must be a method name"):
        gd.evaluate(np.arange(100.0), methods=5)
    # Column names a model file could not be read back with.
    s = gd.simulate(duration=3600, seed=5)
    for names, says in (({"temperature_columns": [""]}, "temperature = '': must be a column name"),
                        ({"temperature_columns": ["a,b"]}, "temperature = 'a,b': must be a column"),
                        ({"target": ""}, "target = '': must be a column name")):
        with pytest.raises(gd.UsageError, match="^" + re.escape(says)):
            gd.DriftModel().fit(s["rate_dph"], s["temperature_c"], **names)
    with pytest.raises(gd.UsageError, match=r"^logged = '0101': must be a sequence of bools"):
        gd.allan(np.arange(4.0), rate_hz=1.0, logged="0101")
    with pytest.raises(gd.UsageError, match=r"^models: must be a sequence of DriftModel"):
        gd.DriftModel.save_axes(tmp_path / "m.json", ["x"])
    # Refusals name the keyword given, not the library's field.
    with pytest.raises(gd.UsageError, match=r"^asymmetry = 0.6: must be"):
        gd.simulate(duration=600, asymmetry=0.6)
    with pytest.raises(gd.UsageError, match=r"^duration = 0: must be"):
        gd.simulate(duration=0)
    with pytest.raises(gd.UsageError, match=r"^rate = -1: must be"):
        gd.plan(rate=-1)
    with pytest.raises(gd.UsageError, match=r"^dwell_min = 0: must be"):
        gd.plan(dwell_min=0)
    # A constant signal is refused by the library, for Python as for the CLI.
    with pytest.raises(gd.DataError, match=r"^x is constant \(every sample is 2\): it has no osc"):
        gd.decompose(np.full(100, 2.0))
    with pytest.raises(gd.DataError, match=r"^x is constant \(every sample is 2\): its Allan"):
        gd.allan(np.full(100, 2.0), rate_hz=1.0)
    with pytest.raises(gd.DataError, match=r"adev_dph point 2 is nan: every deviation must be"):
        gd.noise_terms([1, 2, 4, 8], [1, np.nan, .5, .4], [10] * 4)
    with pytest.raises(gd.DataError, match=r"edf point 1 is 0: every EDF must be"):
        gd.noise_terms([1, 2, 4, 8, 16], [1, .7, .5, .4, .3], [0] * 5)


def test_calibrate_never_writes_over_its_own_logs(tmp_path):
    # A verification log inside the output folder would be replaced by fleet.csv: refused, as the
    # CLI refuses it, and the log is left as it was.
    rng = np.random.default_rng(1)
    t = np.arange(600.0)
    temp = 20 + 10 * np.sin(t / 200)
    log = tmp_path / "fleet.csv"
    np.savetxt(log, np.c_[t, 0.01 * temp + rng.normal(0, 0.01, t.size), temp], delimiter=",",
               header="time_s,gyro,temp", comments="")
    before = log.read_bytes()
    manifest = tmp_path / "m.toml"
    manifest.write_text('[[axis]]\ntarget = "gyro"\ntemperature = "temp"\n'
                        '[[unit]]\nserial = "SN1"\ncalibration = "fleet.csv"\n'
                        'verification = ["fleet.csv"]\n')
    with pytest.raises(gd.UsageError, match="lies inside the output folder"):
        gd.calibrate(manifest, tmp_path)
    assert log.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fleet.csv", "m.toml"]


def test_allan_white_noise_has_the_expected_slope():
    x = np.random.default_rng(3).standard_normal(1 << 14)
    r = gd.allan(x, rate_hz=1.0, taus="octave")
    # White rate noise: sigma(tau) = sigma / sqrt(tau).
    slope = np.polyfit(np.log(r["tau_s"][:8]), np.log(r["dev"][:8]), 1)[0]
    assert -0.6 < slope < -0.4
    assert np.all(r["dev_lo"] <= r["dev"]) and np.all(r["dev"] <= r["dev_hi"])
    assert r["noise_terms"]["N"]["identified"]


def test_simulate_profile_from_samples_and_truth_apart():
    profile = (np.array([0.0, 1800.0, 3600.0]), np.array([20.0, 40.0, 20.0]))
    sim = gd.simulate(duration=3600, profile=profile, seed=2)
    assert len(sim["rate_dph"]) == 3600 and "drift_dph" not in sim
    assert np.ptp(sim["truth"]["chamber_c"]) > 15
    quiet = gd.simulate(duration=600, noise=False, seed=2)
    assert np.all(quiet["truth"]["noise_dph"] == 0)


def test_predict_mode_and_multi_axis_files(tmp_path):
    sim = gd.simulate(duration=1800, seed=4)
    y = sim["rate_dph"]
    m = gd.DriftModel().fit(y, mode="predict", method="elm", lags=4, seed=1)
    first, p = m.predict(y, protocol="paper")
    assert first == 4 and p.shape == (y.size - 4,)
    assert np.sqrt(np.mean((p - y[4:]) ** 2)) < 2 * np.std(y)
    with pytest.raises(gd.UsageError, match="compensate"):
        m.estimate(sim["temperature_c"])
    m.save(tmp_path / "p.json")
    back = gd.DriftModel.load(tmp_path / "p.json")
    assert np.array_equal(back.predict(y, protocol="paper")[1], p)
    # Compensate mode with lags is refused, as the CLI refuses --lags there.
    with pytest.raises(gd.UsageError, match="lags"):
        gd.DriftModel().fit(y, sim["temperature_c"], mode="compensate", lags=4)


def test_long_calls_release_the_gil():
    # While decompose runs in a thread, this thread keeps running Python.
    x = np.sin(np.arange(20000.0) / 7.0) + np.random.default_rng(0).standard_normal(20000)
    done = threading.Event()
    worker = threading.Thread(target=lambda: (gd.decompose(x, ensemble=20, threads=1), done.set()))
    start = time.monotonic()
    worker.start()
    ticks = 0
    while not done.is_set() and time.monotonic() - start < 60:
        ticks += 1
        time.sleep(0.001)
    worker.join()
    assert done.is_set() and ticks > 10


def test_select_modes_groups_a_decomposition_into_series_that_add_up():
    rng = np.random.default_rng(5)
    t = np.arange(8192.0)
    slow = 2.0 * np.sin(2 * np.pi * t / 4000.0) + 1e-4 * t
    x = rng.normal(size=t.size) + slow
    imfs, residue, _ = gd.decompose(x, method="emd")
    s = gd.select_modes(x, imfs, residue, realisations=20, seed=3)
    kinds = [g["kind"] for g in s["groups"]]
    assert kinds[0] == "noise" and kinds[-1] == "drift"
    total = sum(g["series"] for g in s["groups"])
    np.testing.assert_allclose(total, imfs.sum(axis=1) + residue, atol=1e-12 * np.abs(x).max())
    # The noise group holds the white noise, the drift group the slow part.
    noise = s["groups"][0]["series"]
    drift = s["groups"][-1]["series"]
    assert abs(np.std(noise) - 1.0) < 0.15
    assert np.sqrt(np.mean((drift - slow) ** 2)) < 0.5 * np.std(slow)
    assert len(s["pdf_distance"]) == imfs.shape[1] == len(s["self_distance"])
    assert s["noise_level_seed"] == 3 and "noise{" in s["summary"]
    with pytest.raises(gd.UsageError, match="criterion"):
        gd.select_modes(x, imfs, residue, criterion="nope")
    # Refusals name the keywords, as the CLI's name its flags.
    with pytest.raises(gd.UsageError, match=r"^realisations = 1: must be"):
        gd.select_modes(x, imfs, residue, realisations=1)
    with pytest.raises(gd.UsageError, match=r"^confidence = 2: must be"):
        gd.select_modes(x, imfs, residue, confidence=2)
    with pytest.raises(gd.UsageError, match=r"^window = 1: must be"):
        gd.evaluate(x, window=1)
    with pytest.raises(gd.UsageError, match=r"^mirror = 1.5: must be"):
        gd.evaluate(x, mirror=1.5)
    with pytest.raises(gd.UsageError, match=r"^mirror = 2: must be"):
        gd.demo("/nonexistent/never-written", mirror=2)
    with pytest.raises(gd.UsageError, match=r"^windows = 0: must be"):
        gd.evaluate(x, windows=0)
    with pytest.raises(gd.UsageError, match=r"^windows = 17: must be"):
        gd.demo("/nonexistent/never-written", windows=17)
    with pytest.raises(gd.UsageError, match=r"^causal_ensemble = -1: must be"):
        gd.evaluate(x, causal_ensemble=-1)
    with pytest.raises(gd.UsageError, match=r"^window = 4: must be"):
        gd.demo("/nonexistent/never-written", window=4)


def test_a_temperature_that_is_not_degc_is_warned_of_before_the_fit():
    sim = gd.simulate(duration=3600, seed=3)
    counts = np.round(sim["temperature_c"] * 512.0)  # a die-temperature register, not degC
    with pytest.warns(UserWarning, match=r"^temperature column 'temp_raw' runs from .* outside "
                                         r"-80\.\.200 degC; whole numbers only: raw ADC counts\?"):
        model = gd.DriftModel().fit(sim["rate_dph"], counts, mode="compensate",
                                    temperature_columns=["temp_raw"])
    # And before evaluate and compensate, as the CLI's commands warn.
    kelvin = sim["temperature_c"] + 273.15
    with pytest.warns(UserWarning, match=r"^temperature column 'temp_raw' runs from"):
        model.compensate(sim["rate_dph"], counts)
    with pytest.warns(UserWarning, match=r"^temperature column 'temperature_c' runs from .* kelvin\?"):
        gd.evaluate(sim["rate_dph"], kelvin, mode="compensate", methods="constant")
    assert gd.temperature_warning(sim["temperature_c"]) == ""
    assert "whole numbers only" in gd.temperature_warning(counts, "temp_raw")


def test_export_takes_fitted_models_as_their_files(tmp_path):
    sim = gd.simulate(duration=2 * 3600, seed=11)
    x = gd.DriftModel().fit(sim["rate_dph"], sim["temperature_c"])
    y = gd.DriftModel().fit(-0.5 * sim["rate_dph"], sim["temperature_c"], target="rate_y")
    x.save(tmp_path / "x.json")
    y.save(tmp_path / "y.json")
    assert gd.export([x, y], prefix="imu") == gd.export(
        [tmp_path / "x.json", tmp_path / "y.json"], prefix="imu")
    assert gd.export(x, format="json-coefficients") == gd.export(
        tmp_path / "x.json", format="json-coefficients")
    with pytest.raises(gd.UsageError, match="give model files or DriftModel objects, not both"):
        gd.export([x, tmp_path / "y.json"])
    with pytest.raises(gd.UsageError, match="not fitted"):
        gd.export(gd.DriftModel())


def test_what_the_calibration_cannot_identify_is_a_user_warning_as_fit_prints_it():
    sim = gd.simulate(duration=3 * 3600, seed=3)
    with pytest.warns(UserWarning, match=r"^calibration run \(signal\): thermal states could lag"):
        model = gd.DriftModel().fit(sim["rate_dph"], sim["temperature_c"])
    assert any(w.startswith("thermal states could lag")
               for w in model.sub_models[0]["thermal"]["warnings"])


def test_a_model_pickles_as_its_file_and_checks_a_stated_rate():
    import copy
    import pickle
    sim = gd.simulate(duration=3600, seed=7)
    with pytest.warns(UserWarning):
        m = gd.DriftModel().fit(sim["rate_dph"], sim["temperature_c"])
    # Sent to a Dask worker or a process pool: the same model, bit for bit, not a shared core.
    for twin in (pickle.loads(pickle.dumps(m)), copy.deepcopy(m)):
        assert twin._core is not m._core
        assert np.array_equal(twin.estimate(sim["temperature_c"])[0],
                              m.estimate(sim["temperature_c"])[0])
    assert not pickle.loads(pickle.dumps(gd.DriftModel())).fitted
    # The lags count samples: data at another rate than the model's is refused when stated.
    assert m.rate_hz == 1.0
    with pytest.raises(gd.DataError, match=r"the data is sampled at 10 Hz \(given by rate_hz\), "
                                           r"the model was fitted at 1 Hz") as refused:
        m.compensate(sim["rate_dph"], sim["temperature_c"], rate_hz=10)
    assert "time_s" not in str(refused.value)  # the rate was stated, not read from time stamps
    with pytest.raises(gd.UsageError, match="rate_hz = nan"):
        m.estimate(sim["temperature_c"], rate_hz=float("nan"))
    assert np.array_equal(m.compensate(sim["rate_dph"], sim["temperature_c"], rate_hz=1.005),
                          m.compensate(sim["rate_dph"], sim["temperature_c"]))


def test_coefficients_take_the_reference_temperatures_fit_takes():
    sim = gd.simulate(duration=3600, seed=7)
    with pytest.warns(UserWarning):
        m = gd.DriftModel().fit(sim["rate_dph"], sim["temperature_c"])
    assert m.coefficients(reference_temperature=25.0)[0]["reference_c"] == [25.0]
    for bad in (1e308, float("nan"), -273.0):
        with pytest.raises(gd.UsageError, match="reference_temperature = .*must be in"):
            m.coefficients(reference_temperature=bad)

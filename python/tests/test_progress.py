"""Long calls report progress to a callable and stop cleanly: at Ctrl-C (a real SIGINT to this
process) and at an exception the callable raises, both raised from the call; a callable never
changes a result."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import gyrodrift as gd


def _noisy(n, seed=3):
    rng = np.random.default_rng(seed)
    t = np.arange(float(n))
    return np.sin(t / 40.0) + 0.01 * t / 100.0 + 0.5 * rng.normal(size=n)


def test_decompose_reports_progress_without_changing_the_result():
    x = _noisy(4000)
    seen = []
    with_progress = gd.decompose(x, method="iceemdan", ensemble=12, seed=4, threads=2,
                                 progress=seen.append)
    alone = gd.decompose(x, method="iceemdan", ensemble=12, seed=4, threads=2)
    assert np.array_equal(with_progress[0], alone[0])
    assert np.array_equal(with_progress[1], alone[1])
    assert len(seen) >= 12  # one report per realisation and stage at least
    assert all(0.0 <= f <= 1.0 for f in seen)
    assert all(b >= a for a, b in zip(seen, seen[1:]))
    # Every ensemble method ends at 1 (the stage-based estimates stop short of it).
    for method in ("eemd", "ceemdan", "iceemdan", "beemdan"):
        ends = []
        gd.decompose(x[:1000], method=method, ensemble=4, progress=ends.append)
        assert ends[-1] == 1.0, method


def test_fit_and_causal_predict_report_progress():
    x = _noisy(1500)
    fractions = []
    m = gd.DriftModel().fit(x, mode="predict", method="ms-elm", ensemble=10, realisations=20,
                            threads=2, progress=fractions.append)
    assert fractions and fractions[-1] == pytest.approx(1.0)
    assert all(b >= a for a, b in zip(fractions, fractions[1:]))
    same = gd.DriftModel().fit(x, mode="predict", method="ms-elm", ensemble=10, realisations=20,
                               threads=2)
    windows = []
    first, p = m.predict(x, protocol="causal", window=64, threads=2, progress=windows.append)
    assert windows and windows[-1] == pytest.approx(1.0)
    assert np.array_equal(p, same.predict(x, protocol="causal", window=64, threads=2)[1])


def test_an_exception_from_the_callable_stops_the_call_and_is_raised():
    class Stop(Exception):
        pass

    calls = []

    def progress(fraction):
        calls.append(fraction)
        if len(calls) == 3:
            raise Stop("enough")

    start = time.monotonic()
    with pytest.raises(Stop, match="enough"):
        gd.decompose(_noisy(20000), method="iceemdan", ensemble=100, threads=2, progress=progress)
    # Stopped at the next report: the full call (100 realisations x ~14 stages) takes far longer.
    assert len(calls) == 3
    assert time.monotonic() - start < 5.0
    with pytest.raises(gd.UsageError, match="progress: must be a callable"):
        gd.decompose(_noisy(100), progress=3)


def test_ctrl_c_stops_a_long_decomposition_and_raises_keyboard_interrupt():
    x = _noisy(100000)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            # Uninterrupted this takes well over the 10 s bound below (100 realisations of 1e5).
            gd.decompose(x, method="beemdan", ensemble=100, threads=2)
    finally:
        timer.cancel()
    assert time.monotonic() - start < 10.0
    # The module is usable afterwards.
    imfs, residue, _ = gd.decompose(x[:2000], method="emd")
    np.testing.assert_allclose(imfs.sum(axis=1) + residue, x[:2000], atol=1e-9)

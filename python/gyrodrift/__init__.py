"""gyrodrift: gyroscope thermal-drift modelling and compensation, from Python.

The compiled module ``_gyrodrift`` calls the same C++ library as the ``gyrodrift`` command line
tool, so the same inputs and options give the same numbers, to the bit. Arrays go in and come
out as numpy float64 arrays; keyword arguments are named as the CLI's flags (``-`` as ``_``).

Example::

    import gyrodrift as gd
    sim = gd.simulate(duration=7200, seed=7)
    imfs, residue, report = gd.decompose(sim["rate_dph"], method="beemdan", seed=7)
    a = gd.allan(sim["rate_dph"], rate_hz=1.0)
    model = gd.DriftModel().fit(sim["rate_dph"], sim["temperature_c"], mode="compensate")
    compensated = model.compensate(sim["rate_dph"], sim["temperature_c"])

Errors are ``UsageError`` (a bad option, a ValueError), ``DataError`` (data that cannot be
processed, a ValueError) and ``FileError`` (an OSError), with the library's one-line messages.
See docs/python.md.
"""

import inspect
import numbers
import os
import warnings

from . import _gyrodrift
from ._gyrodrift import DataError, FileError, UsageError, __version__

__all__ = [
    "DataError", "DriftModel", "FileError", "UsageError", "__version__", "allan", "calibrate",
    "decompose", "demo", "evaluate", "export", "fit_defaults", "noise_terms", "plan", "read_log",
    "read_ulog", "select_modes", "simulate", "temperature_warning", "ulog_columns",
]


# pybind refuses an integer beyond its C type with a TypeError that names no argument and lists
# the whole signature; _call names the argument instead. Only the integer parameters are looked
# at (a float parameter takes any integer), each with its C type's range.
_INT = (-2 ** 31, 2 ** 31, "[-2^31, 2^31)")
_INTEGER_RANGES = {
    **{name: _INT for name in ("ensemble", "threads", "max_imfs", "max_sifts", "s_number",
                               "fixed_sifts", "noise_stages", "realisations", "instance",
                               "repeats", "horizon", "window", "skip_rows",
                               "ulog_instance")},
    "seed": (0, 2 ** 64, "[0, 2^64)"),
    "device_ids": (0, 2 ** 32, "[0, 2^32)"),
}


def _flags(logged):
    """`logged` as the list of bools the library takes ([] for None); a string is refused (its
    letters would each read as True)."""
    if logged is None:
        return []
    if isinstance(logged, (str, bytes)):
        raise UsageError(f"logged = {logged!r}: must be a sequence of bools, one per sample")
    return [bool(v) for v in logged]


def _call(function, *args, **kwargs):
    try:
        return function(*args, **kwargs)
    except TypeError as error:
        if "incompatible function arguments" not in str(error):
            raise
        for name, value in kwargs.items():
            if name not in _INTEGER_RANGES:
                continue
            lo, hi, text = _INTEGER_RANGES[name]
            values = value if isinstance(value, (list, tuple)) else [value]
            for v in values:
                if isinstance(v, numbers.Integral) and not isinstance(v, bool) and not lo <= v < hi:
                    raise UsageError(f"{name} = {v}: must be an integer in {text}") from None
        raise


def decompose(x, *, method="beemdan", stop="rilling", ensemble=100, noise=0.2, seed=1, threads=0,
              max_imfs=0, max_sifts=0, s_number=4, fixed_sifts=10, sd=0.2,
              noise_scaling="colominas2014", bound="ensemble", band=0.99, noise_stages=3,
              noise_realisations=None, progress=None):
    """Splits a signal into IMFs and a residue (EMD, EEMD, CEEMDAN, ICEEMDAN, BEEMDAN).

    As ``gyrodrift decompose``; ``noise_realisations`` (an (N, I) array, one white-noise
    realisation per column) replaces ``--noise-file``. Results do not depend on ``threads``.
    ``progress``: a callable given the fraction done (a float in [0, 1], not decreasing) as the
    ensemble advances; it runs on a worker thread. Ctrl-C, or an exception the callable raises,
    stops the call at its next report and is raised from it (plain EMD reports no progress and
    stops only at its end).

    Returns ``(imfs, residue, report)``: imfs an (N, K) array, one IMF per column, so that
    ``imfs.sum(axis=1) + residue == x`` up to rounding; report a dict (summary, sifts_per_imf,
    noise_assisted_stages, stop_reason, ...) as in the CLI's sidecar.

    >>> import numpy as np, gyrodrift as gd
    >>> t = np.arange(2000.0)
    >>> imfs, residue, report = gd.decompose(np.sin(t / 5) + 0.01 * t, method="emd")
    >>> imfs.shape[0]
    2000
    """
    return _call(
        _gyrodrift.decompose,
        x, method=method, stop=stop, ensemble=ensemble, noise=noise, seed=seed, threads=threads,
        max_imfs=max_imfs, max_sifts=max_sifts, s_number=s_number, fixed_sifts=fixed_sifts,
        sd=sd, noise_scaling=noise_scaling, bound=bound, band=band, noise_stages=noise_stages,
        noise_realisations=noise_realisations, progress=progress)


def allan(x, *, rate_hz, type="rate", dev="oadev", taus="octave", units="dph", confidence=0.683,
          threads=0, fit_tau_min=0.0, fit_tau_max=float("inf"), logged=None, record_starts=()):
    """Allan-family deviation with confidence intervals and the IEEE 952 noise terms.

    As ``gyrodrift allan`` (both call the library's one allan operation, tasks::RunAllan).
    ``taus`` is "all", "octave", "decade", a comma-separated list or a sequence of averaging
    times in s, each a whole number of sample periods (another is refused, naming the nearest).
    ``logged``: one bool per sample of a record with gaps on its time grid, False where the
    sample is missing (its value, NaN or a filled one, is not used): as ``gyrodrift allan
    --gaps carry``, the overlapping estimators (oadev, ohdev) skip the cluster pairs that hold a
    missing sample. ``record_starts``: the first sample of every record after the first, for
    records given one after the other (as ``gyrodrift allan --gaps split``): they are analysed on
    one grid with a missing sample between them, so no cluster pair spans a break.

    Returns a dict: ``tau_s``, ``m``, ``dev``, ``dev_lo``, ``dev_hi``, ``n_terms``, ``edf``,
    ``alpha``, ``alpha_identified`` (arrays, one entry per tau), ``dev_unit``, ``summary`` and
    ``noise_terms`` (Q, N, B, K, R each a dict with value, sigma, identified, ...; or
    ``{"error": ...}`` when the curve has too few points to fit).

    >>> import numpy as np, gyrodrift as gd
    >>> r = gd.allan(np.random.default_rng(1).normal(size=4096), rate_hz=1.0)
    >>> round(float(r["tau_s"][0]), 1)
    1.0
    """
    return _call(_gyrodrift.allan, x, rate_hz=rate_hz, type=type, dev=dev, taus=taus,
                 units=units, confidence=confidence, threads=threads, fit_tau_min=fit_tau_min,
                 fit_tau_max=fit_tau_max,
                 logged=_flags(logged),
                 record_starts=list(record_starts))


def noise_terms(tau_s, adev_dph, edf, *, fit_tau_min=0.0, fit_tau_max=float("inf"),
                min_share=0.1, significance=0.05, sample_period_s=0.0):
    """IEEE 952 noise terms fitted to a bare Allan-deviation curve (deg/h) with its EDF.

    Returns the dict ``allan(...)["noise_terms"]`` has (without ``source_dev``).

    >>> import numpy as np, gyrodrift as gd
    >>> r = gd.allan(np.random.default_rng(1).normal(size=4096), rate_hz=1.0)
    >>> gd.noise_terms(r["tau_s"], r["dev"], r["edf"])["N"]["identified"]
    True
    """
    return _call(_gyrodrift.noise_terms, tau_s, adev_dph, edf, fit_tau_min=fit_tau_min,
                 fit_tau_max=fit_tau_max, min_share=min_share, significance=significance,
                 sample_period_s=sample_period_s)


def simulate(*, duration=None, profile="chamber", preset="navigation", rate_hz=1.0, seed=1,
             winding="", asymmetry=None, input_rate_dph=0.0, noise=True):
    """Simulates a fibre optic gyro's thermal drift in a temperature chamber.

    As ``gyrodrift simulate``: ``duration`` in seconds (None: the programme's own length),
    ``profile`` a built-in programme name ("chamber", "chamber-b", "sine"), a CSV file with
    columns time_s and temperature_c (as ``--profile FILE``) or a pair of arrays
    ``(time_s, temperature_c)``; ``noise=False`` is ``--no-noise``.

    Returns a dict with what a user would log, ``time_s``, ``rate_dph`` and ``temperature_c``,
    apart from ``truth`` (a dict: drift_dph, shupe_dph, stress_dph, bias_dph, noise_dph and the
    true temperatures), plus ``summary``.

    >>> import gyrodrift as gd
    >>> sim = gd.simulate(duration=600, seed=7)
    >>> len(sim["rate_dph"]), sorted(sim["truth"])[0]
    (600, 'bias_dph')
    """
    if isinstance(profile, os.PathLike):
        profile = os.fspath(profile)
    return _call(_gyrodrift.simulate, duration=duration, profile=profile, preset=preset,
                 rate_hz=rate_hz, seed=seed, winding=winding, asymmetry=asymmetry,
                 input_rate_dph=input_rate_dph, noise=noise)


def read_log(path, *, gaps="error", rate_hz=None, delimiter="auto", names=(), skip_rows=0,
             bad_lines="error", ulog_topic="sensor_gyro", ulog_instance=0, ulog_units="dph"):
    """Reads a gyro log as the CLI's ``fit``, ``compensate``, ``evaluate`` and ``allan`` read it:
    a CSV (or a PX4 ULog, known by its first bytes), its gaps in ``time_s`` refused or handled
    under ``gaps`` (``error``, ``interpolate``, ``split``, ``carry``: docs/cli.md), its sample
    rate given or taken from ``time_s``. The keywords are the CLI's flags; ``names`` are the
    columns of a file without a header row (``--no-header --columns``).

    Returns a dict: ``columns`` (name -> float64 array, the file's order, gaps filled under
    ``interpolate`` and ``carry``), ``rate_hz`` and ``rate_source``, ``logged`` (bools, False on
    the rows made up across a gap; None when every row was logged), ``record_starts`` (under
    ``split``, the first row of every later record), ``notes`` (the CLI's notes on gaps and time
    steps) and ``path``. A rate assumed for want of ``time_s`` is a ``UserWarning``, as the CLI
    warns. Hand ``logged`` (carry) or ``record_starts`` (split) on to ``DriftModel.fit``,
    ``compensation_summary`` and ``allan``: the numbers are then the CLI's.

    >>> import os, tempfile, gyrodrift as gd
    >>> path = os.path.join(tempfile.mkdtemp(), "bursts.csv")
    >>> with open(path, "w") as f:
    ...     _ = f.write("time_s,rate_dph\\n1,0.5\\n2,0.4\\n5,0.7\\n6,0.6\\n")
    >>> log = gd.read_log(path, gaps="carry")
    >>> log["columns"]["time_s"], log["logged"]
    (array([1., 2., 3., 4., 5., 6.]), array([ True,  True, False, False,  True,  True]))
    """
    if isinstance(names, str):  # one name, not its letters
        names = [names]
    return _call(_gyrodrift.read_log, os.fspath(path), gaps=gaps, rate_hz=rate_hz,
                 delimiter=delimiter, names=[str(n) for n in names], skip_rows=skip_rows,
                 bad_lines=bad_lines, ulog_topic=ulog_topic, ulog_instance=ulog_instance,
                 ulog_units=ulog_units)


def read_ulog(path, *, decode=("sensor_gyro",)):
    """Reads a PX4 ULog file, as ``gyrodrift convert LOG.ulg --list`` does (docs/ulog.md).

    Returns a dict: ``version``, ``start_us``, ``info``, ``parameters``, ``dropouts``,
    ``appended``, ``warnings`` (damage skipped, with byte offsets), ``listing`` (the text of
    ``--list``) and ``series``, one dict per subscription (``topic``, ``instance``, ``fields``,
    ``types``, ``samples``, ``first_us``, ``last_us``); the series of the topics named in
    ``decode`` (``"*"``: every topic) also hold ``timestamp_us`` and ``values`` (field -> array).
    """
    if isinstance(decode, (str, os.PathLike)):  # one topic, not its letters
        decode = [decode]
    return _gyrodrift.read_ulog(os.fspath(path), decode=[str(t) for t in decode])


def ulog_columns(path, *, topic="sensor_gyro", instance=0, axes=("x", "y", "z"),
                 temperature_field="temperature", units="dph"):
    """The columns ``gyrodrift convert`` writes for one series: ``time_s``, ``<axis>_<units>``
    (the rad/s fields converted) and ``temperature_c``, as arrays, plus ``warnings``."""
    if isinstance(axes, str):
        axes = [axes]
    return _call(_gyrodrift.ulog_columns, os.fspath(path), topic=topic, instance=instance,
                 axes=list(axes),
                 temperature_field=temperature_field, units=units)


def plan(*, hours=8.0, min_c=-20.0, max_c=60.0, rate=0.0, dwell_min=80.0):
    """A thermal-chamber programme that identifies a compensate-mode model, as ``gyrodrift plan``
    writes it (docs/drift.md 4.9): ``time_s`` and ``temperature_c`` (set points; pass them to
    ``simulate(profile=(time_s, temperature_c))``), ``steps``, ``rate_k_per_min``, ``warnings``
    and ``explanation``.

    >>> import gyrodrift as gd
    >>> p = gd.plan(hours=8, min_c=-20, max_c=60)
    >>> len(p["steps"]), p["rate_k_per_min"]
    (8, 1.5)
    """
    return _gyrodrift.plan(hours=hours, min_c=min_c, max_c=max_c, rate=rate, dwell_min=dwell_min)


class DriftModel:
    """A drift model (MS-ELM, the thermal model or a baseline), as ``gyrodrift fit`` makes it.

    >>> import gyrodrift as gd
    >>> sim = gd.simulate(duration=3600, seed=7)
    >>> m = gd.DriftModel().fit(sim["rate_dph"], sim["temperature_c"], mode="compensate")
    >>> m.method
    'thermal'
    >>> est, sd = m.estimate(sim["temperature_c"])
    >>> out = m.compensate(sim["rate_dph"], sim["temperature_c"])   # rate_dph - est
    """

    def __init__(self, _core=None):
        self._core = _core if _core is not None else _gyrodrift.DriftModel()

    def fit(self, y, temperature=None, *, mode="compensate", target="rate_dph",
            temperature_columns=None, source="python", units="dph", record_starts=(),
            logged=None, progress=None, **settings):
        """Fits the model on output ``y`` and ``temperature`` (N, or (N, C) for C channels, degC).

        ``settings``: the fit settings as keywords, named and defaulted as the library's
        ``FitSettings`` (``fit_defaults()`` and this signature list them all; None keeps a
        default), each as the ``gyrodrift fit`` flag of its name (``-`` as ``_``; docs/cli.md
        says what each does). Among them: ``method`` ("auto": ms-elm in predict mode, thermal
        in compensate mode), ``lags`` an int or "auto" (predict mode only), ``hidden`` "auto" or
        an int, ``rate_hz`` the sample rate (the CLI reads it from a time_s column),
        ``time_constants`` seconds, ``hysteresis`` ("auto", "on" or "off": the thermal models'
        hysteresis term, tried on calibrations with 12 h or more of logged samples; the fitted
        term is in ``sub_models[g]["thermal"]["hysteresis"]``). The settings map onto the library's
        options as the CLI's flags do; a refusal names the keyword, and a keyword that names no
        setting raises TypeError. ``target`` and ``temperature_columns`` are the column
        names written into the model file (the CLI's compensate reads those columns), ``units``
        the unit of ``y`` ("dph", "dps" or "rads"), as ``gyrodrift fit --units``:
        kept in the model file, it labels every estimate and scales the PX4 export.
        Several calibration runs (or one log split at its gaps, as ``--gaps split``) are given
        one after the other with ``record_starts`` the first sample of each run after the first:
        the thermal model's lag states restart there (``fit A.csv B.csv``; method thermal in
        compensate mode only). ``logged``: one bool per sample, False on rows made up across a
        gap (``--gaps carry``: a duty-cycled log filled on its time grid); the thermal states run
        over every row, the fit uses the logged ones only (compensate mode, a method without a
        decomposition; ``y`` on the made-up rows is ignored and may be NaN). Score and report on
        the logged rows too. ``progress``: a callable given the fraction of the fit done, as for
        ``decompose`` (Ctrl-C stops the fit at its next report). What the calibration run could
        not identify is a ``UserWarning`` each, as ``gyrodrift fit`` prints it ("calibration run
        (signal): no cooling ramp: ..."; also in ``sub_models[g]["thermal"]["warnings"]``, beside
        the ``advice``). Returns self.
        """
        self._core.fit(y, temperature, mode=mode, target=target,
                       temperature_columns=temperature_columns, source=source, units=units,
                       record_starts=list(record_starts),
                       logged=_flags(logged),
                       progress=progress, **settings)
        for sub in self._core.sub_models:
            for text in (sub.get("thermal") or {}).get("warnings", []):
                warnings.warn(f"calibration run ({sub['name']}): {text}", UserWarning, stacklevel=2)
        return self

    def estimate(self, temperature, *, record_starts=(), rate_hz=None):
        """Compensate mode: ``(estimate, sd)`` of the drift at every temperature sample (sd NaN
        for models without an uncertainty band); with ``record_starts`` every record is estimated
        on its own, as ``gyrodrift compensate --gaps split`` does after each gap. The samples are
        taken to be at the model's rate (the ``rate_hz`` property): its lags count samples.
        ``rate_hz``: the data's rate, Hz, checked against the model's as ``gyrodrift compensate``
        checks a log's (a ``DataError`` beyond 1 %)."""
        return self._core.estimate(temperature, record_starts=list(record_starts),
                                   rate_hz=rate_hz)

    def compensate(self, y, temperature, *, record_starts=(), rate_hz=None):
        """Compensate mode: ``y - estimate(temperature)``, the ``compensated`` column of
        ``gyrodrift compensate``. The output first, then its temperature, as ``fit`` and
        ``predict`` take them. ``rate_hz`` as for ``estimate``."""
        return self._core.compensate(temperature, y, record_starts=list(record_starts),
                                     rate_hz=rate_hz)

    def compensation_summary(self, y, temperature, *, record_starts=(), drift_window_s=600.0,
                             logged=None, truth=None, rate_hz=None):
        """Compensate mode: what compensating ``y`` does to it, the figures ``gyrodrift
        compensate`` prints and keeps in its sidecar. Returns a dict: ``before`` and ``after``
        (each ``mean``, ``rms`` about zero, ``std`` about the mean and ``slow_variation``, the RMS
        about their mean of ``drift_window_s`` block means, NaN on a log shorter than two blocks),
        ``samples``, ``slow_variation_block_s``, ``slow_variation_blocks``, ``table`` (the
        printed lines), ``outside_share`` (the share of the rows beyond the calibration's
        temperatures) and ``drift_sd_mean`` (identified models, else NaN). The blocks are timed
        at the model's sample rate (docs/drift.md 1.5); ``drift_window_s`` as ``compensate
        --drift-window-s`` and the manifest key. ``logged``: one bool per sample,
        False on rows made up across a gap (``--gaps carry``): the figures use the logged rows
        only. ``truth``: the true drift (the simulator's ``drift_dph``), as ``compensate
        --truth``: adds ``truth_rms``, ``residual_rms`` (of truth - estimate) and
        ``truth_removed`` = 1 - residual_rms / truth_rms. ``rate_hz`` as for ``estimate``."""
        return self._core.compensation_summary(
            temperature, y, record_starts=list(record_starts), drift_window_s=drift_window_s,
            logged=_flags(logged), truth=truth, rate_hz=rate_hz)

    def coefficients(self, *, reference_temperature=None):
        """The thermal sub-models' coefficients in physical units, as ``gyrodrift fit`` prints
        them: per sub-model a dict of ``sub_model``, ``reference_c`` (per channel: the given
        ``reference_temperature``, else the model's, else the calibration's mean), ``terms``
        (each ``term``, ``power``, ``state``, ``unit`` such as "dph/K", "dph/K^2",
        "dph/(K/min)", ``value`` and ``sd``: the bias at the reference, then per K^k of
        (temperature or state level - reference), per K/min of a state's rate, the hysteresis
        term in target units) and ``state_range_c`` (each state's level range in calibration,
        where its powers are polynomials). Empty for models without identified thermal
        sub-models (docs/drift.md 1.5)."""
        return self._core.coefficients(reference_temperature=reference_temperature)

    def predict(self, y, temperature=None, *, horizon=1, protocol="causal", window=2896,
                mirror=0.5, windows=6, causal_ensemble=1, threads=0, progress=None, rate_hz=None):
        """Predict mode, as ``gyrodrift predict``: returns ``(first, prediction)``, the
        horizon-step-ahead predictions of y[first:], first being the model's history.
        ``window``, ``mirror``, ``windows`` and ``causal_ensemble`` as ``--window``, ``--mirror``,
        ``--windows`` and ``--causal-ensemble``. ``progress``: a callable given the fraction of the
        causal origins decomposed, as for ``decompose``. ``rate_hz`` as for ``estimate`` (its
        lags and windows count samples)."""
        return self._core.predict(y, temperature, horizon=horizon, protocol=protocol,
                                  window=window, mirror=mirror, windows=windows,
                                  causal_ensemble=causal_ensemble, threads=threads,
                                  progress=progress, rate_hz=rate_hz)

    def save(self, path):
        """Writes the model file ``gyrodrift fit`` writes (JSON, exact doubles, checksummed)."""
        self._core.save(str(path))

    @classmethod
    def load(cls, path, axis=None):
        """Reads a model file (written by ``gyrodrift fit`` or ``save``). A file of several axes
        needs ``axis``, the target column name; ``load_axes`` returns them all."""
        axes = cls.load_axes(path)
        if axis is None:
            if len(axes) != 1:
                raise UsageError(f"{path} holds {len(axes)} axes "
                                 f"({', '.join(a.target for a in axes)}): pass axis=")
            return axes[0]
        for a in axes:
            if a.target == axis:
                return a
        raise UsageError(f"axis = {axis}: must be one of {', '.join(a.target for a in axes)}")

    @staticmethod
    def save_axes(path, models):
        """Writes several fitted models (one per axis, each with its own ``target``) into one
        model file, as ``gyrodrift fit --target gyro_x,gyro_y,...`` does."""
        if not all(isinstance(m, DriftModel) for m in models):
            raise UsageError("models: must be a sequence of DriftModel")
        _gyrodrift.DriftModel.save_axes(str(path), [m._core for m in models])

    @classmethod
    def load_axes(cls, path):
        """Every axis of a model file, in file order."""
        return [cls(core) for core in _gyrodrift.DriftModel.load_axes(str(path))]

    summary = property(lambda self: self._core.summary, doc="One-line summary of the model.")
    sub_models = property(
        lambda self: self._core.sub_models,
        doc="Sub-models: name, imfs, learner summary (None for one predicted by its training "
            "``mean``), baseline summary (the baselines' one sub-model), and for identified "
            "thermal models ``thermal`` (regressors named by the temperature columns, "
            "coefficients, sd).")
    mode = property(lambda self: self._core.mode)
    method = property(lambda self: self._core.method)
    target = property(lambda self: self._core.target)
    temperature_columns = property(lambda self: self._core.temperature_columns)
    temperature_range_c = property(lambda self: self._core.temperature_range_c,
                                   doc="Training temperature range (min, max), degC.")
    fitted = property(lambda self: self._core.fitted)
    rate_hz = property(lambda self: self._core.rate_hz, doc="The rate fitted at, Hz.")

    # Pickled (Dask, multiprocessing, copy.deepcopy) as the model file's text: exact doubles.
    def __getstate__(self):
        return {"model_file": self._core.to_text() if self.fitted else None}

    def __setstate__(self, state):
        text = state["model_file"]
        self._core = (_gyrodrift.DriftModel.from_text(text) if text is not None
                      else _gyrodrift.DriftModel())

    def __repr__(self):
        return f"DriftModel({self.summary!r})" if self.fitted else "DriftModel(unfitted)"


def export(models, *, format="c", single_precision=False, prefix="gyro_comp", device_ids=()):
    """The text ``gyrodrift export`` writes for compensate-mode model files (docs/firmware.md):
    ``format="c"`` a C99 header, ``"json-coefficients"`` their coefficients, ``"px4"`` the
    parameters of PX4's thermal compensation (one model file of axes x, y, z per gyro, one
    ``device_ids`` entry each). ``models``: a path or a list of paths, their axes in order, or
    a ``DriftModel`` or a list of them (one axis each: x, y, z in order for ``"px4"``).
    A model's ``sub_models[0]["thermal"]["autopilot"]`` is the form ``"px4"`` writes.

    >>> import gyrodrift as gd
    >>> sim = gd.simulate(duration=3600, seed=7)
    >>> model = gd.DriftModel().fit(sim["rate_dph"], sim["temperature_c"])
    >>> print(gd.export(model).splitlines()[0])                          # doctest: +ELLIPSIS
    /* gyro_comp.h: thermal drift compensation of 1 gyro axis, generated by gyrodrift ... export.
    >>> params = gd.export("imu0.json", format="px4", device_ids=[2490378])  # doctest: +SKIP
    """
    if isinstance(models, (str, os.PathLike, DriftModel)):
        models = [models]
    items = [m._core if isinstance(m, DriftModel) else os.fspath(m) for m in models]
    return _call(_gyrodrift.export, items, format=format, single_precision=single_precision,
                 prefix=prefix, device_ids=list(device_ids))


def temperature_warning(temperature, name="temperature"):
    """The warning ``gyrodrift fit`` prints before the work for a temperature column that does
    not look like degC (outside -80..200 degC, or whole numbers only, as raw ADC counts step),
    saying what is assumed; "" when it looks like degC. ``DriftModel.fit`` issues it as a
    UserWarning.

    >>> import gyrodrift as gd
    >>> gd.temperature_warning([25.1, 25.2, 25.4])
    ''
    >>> gd.temperature_warning([64000.0, 64012.0, 64100.0], "temp").split(";")[0]
    "temperature column 'temp' runs from 64000 to 64100, outside -80..200 degC"
    """
    return _gyrodrift.temperature_warning(temperature, name)


def select_modes(x, imfs, residue, *, criterion="pdf", distance="l2", realisations=100,
                 confidence=0.99, seed=1, band=0.99, threads=0):
    """Groups a decomposition's IMFs into noise / mixed / drift, as MS-ELM does (docs/selection.md).

    ``imfs`` (N, K) and ``residue`` (N) as ``decompose`` returns them; ``criterion`` "pdf" (the
    PDF-similarity criterion, three groups), "komaty" or "energy" (two groups); ``distance`` l2,
    l1, hellinger, jensen-shannon or bhattacharyya; ``realisations``, ``confidence`` and ``seed``
    set the white-noise level's Monte-Carlo, ``band`` the energy band's confidence (0.95 or
    0.99). Returns a dict: the curves per IMF (``pdf_distance`` D_k, ``self_distance`` G_k,
    ``noise_level``, ``log2_energy``, ``energy_band_log2_upper``), the boundaries (``k_star``,
    ``k_noise``, ``mixed_end``, ``energy_signal_start``), ``groups`` (kind, imfs, has_residue,
    series) and ``summary``.

    >>> import numpy as np, gyrodrift as gd
    >>> t = np.arange(4096.0)
    >>> x = np.random.default_rng(2).normal(size=t.size) + 3 * np.sin(t / 300)
    >>> imfs, residue, _ = gd.decompose(x, method="emd")
    >>> s = gd.select_modes(x, imfs, residue, realisations=20)
    >>> [g["kind"] for g in s["groups"]][0]
    'noise'
    """
    return _call(_gyrodrift.select_modes, x, imfs, residue, criterion=criterion,
                 distance=distance, realisations=realisations, confidence=confidence, seed=seed,
                 band=band, threads=threads)


def evaluate(y, temperature=None, truth=None, *, mode="predict", methods="all", protocol="both",
             split=0.7, repeats=1, horizon=1, window=2896, mirror=0.5, windows=6,
             causal_ensemble=1, progress=None,
             **settings):
    """Scores methods on one record that cannot cheat, as ``gyrodrift evaluate``: a chronological
    split (fit on the first ``split`` of the record, score on the rest), ``repeats`` seeds, the
    paper and causal protocols (predict mode), against ``truth`` when given (else the output).

    ``methods`` is "all" or a list (or comma-separated string) of method names; the references
    "none" (a zero estimate) and "constant" (the training mean) are always scored first. The model
    settings are ``DriftModel.fit``'s settings keywords but ``method`` (``fit_defaults()``);
    ``window``, ``mirror``, ``windows`` and ``causal_ensemble`` as ``--window``, ``--mirror``,
    ``--windows`` and ``--causal-ensemble``; ``progress`` as for
    ``decompose``. Returns a dict:
    ``rows`` (one dict per method and protocol: rmse, rmse_std, mae, max_abs, rmse_measured
    (against the output itself), slow_removed (share of the slow variation, 10-min block means,
    removed; nan on a test block shorter than 10 min), train_s, predict_s, the last repeat's
    ``estimate`` on the test block, model_summary, notes), ``first_test_sample``, ``reference``
    (what the rows were scored against), ``table`` (text), ``notes`` (a list: the lines the CLI
    prints after its table).

    >>> import gyrodrift as gd
    >>> sim = gd.simulate(duration=7200, seed=3)
    >>> r = gd.evaluate(sim["rate_dph"], truth=sim["truth"]["drift_dph"], methods=["poly"],
    ...                 protocol="paper")
    >>> [row["method"] for row in r["rows"]], r["first_test_sample"]
    (['none', 'constant', 'poly'], 5040)
    """
    return _call(
        _gyrodrift.evaluate,
        y, temperature, truth, mode=mode, methods=methods, protocol=protocol, split=split,
        repeats=repeats, horizon=horizon, window=window, mirror=mirror, windows=windows,
        causal_ensemble=causal_ensemble, progress=progress,
        **settings)


def fit_defaults():
    """The fit settings ``DriftModel.fit`` and ``evaluate`` take as keywords, each with its
    default: the library's own (``drift::FitSettings``), the one home of every default. A
    setting added to the library is a keyword here with nothing else to edit.

    >>> import gyrodrift as gd
    >>> gd.fit_defaults()["ensemble"], gd.fit_defaults()["method"]
    (100, 'auto')
    """
    return _gyrodrift.fit_defaults()


def _show_settings(function, skip=()):
    """Lists the fit settings, with the library's defaults, in ``function``'s signature (for
    help() and IDEs; the call takes them through ``**settings``)."""
    signature = inspect.signature(function)
    params = [p for p in signature.parameters.values() if p.kind is not p.VAR_KEYWORD]
    params += [inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=default)
               for name, default in fit_defaults().items() if name not in skip]
    function.__signature__ = signature.replace(parameters=params)


_show_settings(DriftModel.fit)
_show_settings(evaluate, skip=("method",))


def calibrate(manifest_path, output_dir, *, force=False, threads=0, progress=None):
    """Calibrates a fleet from a TOML manifest, as ``gyrodrift calibrate`` (docs/calibration.md).

    Returns a dict: ``rows`` (fleet.csv's rows, each a dict of its columns, as text), the counts
    (units, calibrated, skipped, errors, failed_limits), ``all_pass`` and ``summary``. Units
    that fail their limits are rows, not exceptions. ``progress``: a callable given the share of
    the units done. Ctrl-C stops the run once the units under way are written (those done stay;
    a rerun skips them). ``gyrodrift.fleet`` runs the same on Dask.
    """
    return _call(_gyrodrift.calibrate, str(manifest_path), str(output_dir), force=force,
                 threads=threads, progress=progress)


def demo(output="gyrodrift-demo", *, input=None, target=None, temperature=None, rate_hz=None,
         units="dph", duration=28800.0, ensemble=20, realisations=20, window=256, mirror=0.5,
         windows=6, causal_ensemble=1, methods="all", seed=1, threads=0, gaps="error",
         progress=None):
    """The whole study of ``gyrodrift demo`` (docs/demo.md): simulate a navigation-grade FOG (or
    study ``input``, a log of your own: its ``target`` and ``temperature`` columns, ``rate_hz``
    or its time_s column, ``units`` of its output, ``gaps``), decompose and group it, compare
    MS-ELM and every baseline in predict and compensate mode, the Allan deviation before and
    after; writes the same folder as the CLI to ``output`` (data, models, tables, demo.json and
    report.html, one atomic set). ``duration`` (s, at least 7200), ``ensemble``,
    ``realisations``, ``window``, ``mirror``, ``windows``, ``causal_ensemble`` and ``methods``
    size the study as the CLI's flags of those names.
    ``progress``: a callable given the fraction of the run done (Ctrl-C stops it).

    Returns a dict: ``output``, ``files`` (the names written), ``report`` (its path),
    ``simulated``, ``compensated_by``, ``best_by``, ``tables`` (``predict``, ``compensate``,
    ``noise_terms``, ``settings``, ``timing``: the text the CLI prints) and ``seconds``.

    >>> import tempfile, gyrodrift as gd
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     r = gd.demo(folder + "/study", duration=7200, methods="thermal,poly", ensemble=4,
    ...                 window=32)
    >>> r["files"][-2:], r["compensated_by"]
    (['report.html', 'demo.json'], 'thermal (train A test B)')
    """
    return _call(_gyrodrift.demo, str(output), input="" if input is None else str(input),
                 target="" if target is None else str(target),
                 temperature="" if temperature is None else str(temperature), rate_hz=rate_hz,
                 units=units, duration=duration, ensemble=ensemble, realisations=realisations,
                 window=window, mirror=mirror, windows=windows, causal_ensemble=causal_ensemble,
                 methods=methods, seed=seed,
                 threads=threads,
                 gaps=gaps, progress=progress)

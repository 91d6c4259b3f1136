"""Each Python default has one home, the library's settings struct (issue 25).

The compiled module reads its keyword defaults from default-constructed C++ settings (AllanSettings,
DecomposeSettings, ...); the pure-Python wrappers in __init__.py repeat them in their signatures
for help() and IDEs, and __init__.pyi lists the same parameters (its defaults are `...`). These
tests fail when a wrapper's default differs from the compiled one, or when the stub's parameters
differ from the wrapper's, so a default changed in C++ cannot be left behind.

The fit settings (DriftModel.fit, evaluate) are typed nowhere in Python: the calls take them as
**settings through the library's one reader (tasks::FitSettingsFromJson), and the signatures show
gd.fit_defaults(), drift::FitSettings{} as JSON.
"""

import ast
import inspect
import json
import math
import os

import pytest

import gyrodrift
from gyrodrift import _gyrodrift

PAIRS = [
    ("decompose", gyrodrift.decompose, _gyrodrift.decompose),
    ("allan", gyrodrift.allan, _gyrodrift.allan),
    ("noise_terms", gyrodrift.noise_terms, _gyrodrift.noise_terms),
    ("simulate", gyrodrift.simulate, _gyrodrift.simulate),
    ("plan", gyrodrift.plan, _gyrodrift.plan),
    ("read_log", gyrodrift.read_log, _gyrodrift.read_log),
    ("export", gyrodrift.export, _gyrodrift.export),
    ("select_modes", gyrodrift.select_modes, _gyrodrift.select_modes),
    ("evaluate", gyrodrift.evaluate, _gyrodrift.evaluate),
    ("calibrate", gyrodrift.calibrate, _gyrodrift.calibrate),
    ("demo", gyrodrift.demo, _gyrodrift.demo),
    ("DriftModel.fit", gyrodrift.DriftModel.fit, _gyrodrift.DriftModel.fit),
    ("DriftModel.predict", gyrodrift.DriftModel.predict, _gyrodrift.DriftModel.predict),
    ("DriftModel.compensation_summary", gyrodrift.DriftModel.compensation_summary,
     _gyrodrift.DriftModel.compensation_summary),
]


def split_top_level(text):
    """Splits a parameter list at the commas outside brackets and quotes."""
    parts, depth, quote, start = [], 0, None, 0
    for i, c in enumerate(text):
        if quote:
            quote = None if c == quote else quote
        elif c in "'\"":
            quote = c
        elif c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
        elif c == "," and depth == 0:
            parts.append(text[start:i].strip())
            start = i + 1
    parts.append(text[start:].strip())
    return [p for p in parts if p]


def compiled_defaults(function):
    """{name: default text} of a pybind11 function, read from the signature line of its doc."""
    line = function.__doc__.split("\n")[0]
    params = line[line.index("(") + 1:line.rindex(") ->")]
    out = {}
    for p in split_top_level(params):
        if p in ("*", "/") or "=" not in p:
            continue
        name, default = p.split(":", 1)[0].strip(), p.rsplit("=", 1)[1].strip()
        out[name] = default
    return out


def shown(value):
    """A Python default as pybind11 prints one."""
    if isinstance(value, float) and math.isinf(value):
        return "inf" if value > 0 else "-inf"
    if isinstance(value, tuple):
        return repr(list(value))
    return repr(value)


@pytest.mark.parametrize("name,wrapper,compiled", PAIRS, ids=[p[0] for p in PAIRS])
def test_wrapper_defaults_are_the_compiled_ones(name, wrapper, compiled):
    ours = compiled_defaults(compiled)
    checked = 0
    for p in inspect.signature(wrapper).parameters.values():
        if p.default is inspect.Parameter.empty or p.name not in ours:
            continue
        # None, () and [] stand for "not given" in a wrapper that converts them.
        if p.default is None or p.default == () or p.default == []:
            continue
        assert shown(p.default) == ours[p.name], f"{name}({p.name}=...)"
        checked += 1
    assert checked > 0 or name == "calibrate"


SETTINGS_CALLS = {"DriftModel.fit": (), "evaluate": ("method",)}


def stub_functions():
    path = os.path.join(os.path.dirname(gyrodrift.__file__), "__init__.pyi")
    tree = ast.parse(open(path).read())
    found = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            found[node.name] = node
        elif isinstance(node, ast.ClassDef):
            for item in node.body:
                if isinstance(item, ast.FunctionDef):
                    found[f"{node.name}.{item.name}"] = item
    return found


def stub_parameters(node):
    a = node.args
    positional = a.posonlyargs + a.args
    defaulted = {p.arg for p in positional[len(positional) - len(a.defaults):]}
    defaulted |= {p.arg for p, d in zip(a.kwonlyargs, a.kw_defaults) if d is not None}
    names = [p.arg for p in positional + a.kwonlyargs]
    return names, defaulted


@pytest.mark.parametrize("name,wrapper,compiled", PAIRS, ids=[p[0] for p in PAIRS])
def test_stub_lists_the_wrappers_parameters(name, wrapper, compiled):
    stubs = stub_functions()
    assert name in stubs, f"__init__.pyi has no {name}"
    names, defaulted = stub_parameters(stubs[name])
    params = list(inspect.signature(wrapper).parameters.values())
    if name in SETTINGS_CALLS:
        # The stub takes the settings as **settings; the shown signature lists them.
        assert stubs[name].args.kwarg.arg == "settings"
        settings = [k for k in gyrodrift.fit_defaults() if k not in SETTINGS_CALLS[name]]
        assert [p.name for p in params[-len(settings):]] == settings
        params = params[:-len(settings)]
    assert names == [p.name for p in params]
    assert defaulted == {p.name for p in params if p.default is not inspect.Parameter.empty}


def test_a_changed_default_would_be_seen():
    # The check itself: a wrapper default that differs from the compiled one is caught.
    ours = compiled_defaults(_gyrodrift.allan)
    assert ours["dev"] == "'oadev'" and shown("adev") != ours["dev"]
    assert ours["fit_tau_max"] == "inf"


@pytest.mark.parametrize("name", SETTINGS_CALLS)
def test_the_shown_settings_defaults_are_the_librarys(name):
    wrapper = gyrodrift.evaluate if name == "evaluate" else gyrodrift.DriftModel.fit
    shown_defaults = {p.name: p.default for p in inspect.signature(wrapper).parameters.values()}
    defaults = gyrodrift.fit_defaults()
    for key in SETTINGS_CALLS[name]:
        del defaults[key]
    assert defaults and all(shown_defaults[k] == v for k, v in defaults.items())
    assert defaults["ensemble"] == 100 and defaults["hysteresis"] == "auto"


def test_the_settings_defaults_are_the_ones_a_call_uses(tmp_path):
    # Every setting given at its shown default fits the model of no setting given, to the bit;
    # None is "the default" too.
    sim = gyrodrift.simulate(duration=3600, seed=7)
    y, t = sim["rate_dph"], sim["temperature_c"]
    plain = gyrodrift.DriftModel().fit(y, t)
    given = gyrodrift.DriftModel().fit(y, t, **gyrodrift.fit_defaults())
    nones = gyrodrift.DriftModel().fit(y, t, **{k: None for k in gyrodrift.fit_defaults()})
    for m in (given, nones):
        assert m.summary == plain.summary
        assert (m.estimate(t)[0] == plain.estimate(t)[0]).all()
    changed = gyrodrift.DriftModel().fit(y, t, method="poly")
    assert changed.method == "poly"
    # A setting the bindings never name (standard_errors) reaches the fit and its model file.
    gyrodrift.DriftModel().fit(y, t, standard_errors=0.5).save(tmp_path / "m.json")
    with open(tmp_path / "m.json") as f:
        assert json.load(f)["options"]["thermal"]["standard_errors"] == 0.5


def test_an_unknown_setting_is_refused_naming_it():
    with pytest.raises(TypeError, match="unexpected keyword argument 'ensembel'"):
        gyrodrift.DriftModel().fit([1.0, 2.0], [20.0, 21.0], ensembel=10)
    with pytest.raises(TypeError, match="unexpected keyword argument 'method'"):
        gyrodrift.evaluate([1.0, 2.0], method="poly")
    with pytest.raises(TypeError, match="'has_temperature'"):
        gyrodrift.DriftModel().fit([1.0, 2.0], [20.0, 21.0], has_temperature=True)
    with pytest.raises(gyrodrift.UsageError, match=r"^ensemble = \"many\": must be an integer"):
        gyrodrift.DriftModel().fit([1.0, 2.0], [20.0, 21.0], ensemble="many")

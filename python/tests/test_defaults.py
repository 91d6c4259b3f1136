"""Each Python default has one home, the library's settings struct (issue 25).

The compiled module reads its keyword defaults from default-constructed C++ settings (AllanSettings,
DecomposeSettings, drift::FitSettings, ...); the pure-Python wrappers in __init__.py repeat them
in their signatures for help() and IDEs, and __init__.pyi lists the same parameters (its defaults
are `...`). These tests fail when a wrapper's default differs from the compiled one, or when the
stub's parameters differ from the wrapper's, so a default changed in C++ cannot be left behind.
"""

import ast
import inspect
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
    ("export", gyrodrift.export, _gyrodrift.export),
    ("select_modes", gyrodrift.select_modes, _gyrodrift.select_modes),
    ("evaluate", gyrodrift.evaluate, _gyrodrift.evaluate),
    ("calibrate", gyrodrift.calibrate, _gyrodrift.calibrate),
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
    params = inspect.signature(wrapper).parameters.values()
    assert names == [p.name for p in params]
    assert defaulted == {p.name for p in params if p.default is not inspect.Parameter.empty}


def test_a_changed_default_would_be_seen():
    # The check itself: a wrapper default that differs from the compiled one is caught.
    ours = compiled_defaults(_gyrodrift.allan)
    assert ours["dev"] == "'oadev'" and shown("adev") != ours["dev"]
    assert ours["fit_tau_max"] == "inf"

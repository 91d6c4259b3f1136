"""The examples in the package's docstrings run and print what they say."""

import doctest

import gyrodrift


def test_docstring_examples():
    result = doctest.testmod(gyrodrift, optionflags=doctest.ELLIPSIS)
    assert result.attempted >= 10
    assert result.failed == 0

"""Shared fixtures of the TSFM tests (001_0b92a7da96e7aa46.txt)."""

import warnings

import pytest

from gripkit.systems.tsfm import parameters as z


@pytest.fixture(scope="module")
def left():
    """The left finger of Table II (its seed contradictions reported by warnings, silenced here)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return z.left_finger()

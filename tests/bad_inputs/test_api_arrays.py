"""Bad arrays at the Python API (audit of the API, items 3 and 4): empty records to the nonlinear
identifications and complex numbers to any identification or filter are a DataError naming the
argument, from the shared conversions (``gripkit.arguments.real_array``, ``sysid.checks``,
``one_signal``, ``signals.filters.samples``), never numpy's ComplexWarning with the imaginary
part dropped, nor ``cannot reshape array of size 0``."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from gripkit import DataError, signals, sysid

RNG = np.random.default_rng(0)
U = RNG.uniform(-1.0, 1.0, 300)
Y = np.tanh(np.convolve(U, [0.0, 0.5, 0.3])[:300]) + 0.01 * RNG.standard_normal(300)
EMPTY = np.array([])


@pytest.mark.parametrize("call, phrase", [
    (lambda: sysid.narx(EMPTY, EMPTY), "narx: u holds no samples"),
    (lambda: sysid.hammerstein_wiener(EMPTY, EMPTY), "hw: u holds no samples"),
    (lambda: sysid.nlss((EMPTY, EMPTY)), "nlss: data: the signals hold no samples"),
    (lambda: sysid.nlss((np.zeros((0, 2)), np.zeros((0, 1)))), r"no samples \(u \(0, 2\)"),
], ids=["narx", "hammerstein_wiener", "nlss", "nlss two inputs"])
def test_empty_records_to_nonlinear_identification(call, phrase):
    with pytest.raises(DataError, match=phrase):
        call()


@pytest.mark.parametrize("call, name", [
    (lambda: sysid.arx(U + 1j * U, Y, na=1, nb=2, nk=1), "input u"),
    (lambda: sysid.armax(U, Y + 1j * Y, na=1, nb=2, nc=1, nk=1), "output y"),
    (lambda: sysid.oe(U + 1j * U, Y, nb=2, nf=1, nk=1), "input u"),
    (lambda: sysid.n4sid(U + 0j, Y, 2), "input u"),
    (lambda: sysid.tfest(U + 1j * U, Y, 1, 0, dt=0.01), "input u"),
    (lambda: sysid.frf(U, Y + 1j * Y), "output y"),
    (lambda: sysid.narx(U + 1j * U, Y), "narx: u"),
    (lambda: sysid.hammerstein_wiener(U, [complex(v) for v in Y]), "hw: y"),
    (lambda: sysid.nlss((U + 1j * U, Y)), "nlss: data: u"),
    (lambda: signals.lowpass(U + 1j * U, 1.0, dt=0.1), "x"),
    (lambda: signals.highpass([1j, 2.0, 3.0], 1.0, dt=0.1), "x"),
], ids=["arx", "armax", "oe", "n4sid", "tfest", "frf", "narx", "hw", "nlss", "lowpass",
        "highpass list"])
def test_complex_numbers_are_refused_naming_the_argument(call, name):
    """The error names the argument; no ComplexWarning comes first (the warning filter turns
    one into an error, which would not be a DataError)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", np.exceptions.ComplexWarning)
        with pytest.raises(DataError, match=rf"^{name}: expected real numbers, found complex"):
            call()


def test_real_values_in_a_complex_free_list_pass():
    """Integers and floats mixed in a list are real numbers: the conversion keeps them."""
    from gripkit.arguments import real_array

    assert real_array([1, 2.5, np.float32(3)], "u").tolist() == [1.0, 2.5, 3.0]
    with pytest.raises(DataError, match="u: expected an array of numbers, found str"):
        real_array("abc", "u")

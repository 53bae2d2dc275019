"""What the single-channel nonlinear families share (gripkit.sysid.nonlinear.single_channel):
the divergence band of a free run, the check of one signal, the fit, each headed by the
family's name."""

import numpy as np
import pytest

from gripkit.errors import DataError
from gripkit.sysid import HWModel, NARXModel
from gripkit.sysid.nonlinear.single_channel import (DIVERGENCE_FACTOR, FreeRunModel, fit_percent,
                                                    not_constant, one_signal)


def test_divergence_band_is_1000_spans_about_the_middle():
    """y_range (−1, 3): middle 1, span 4, band 1 ∓ 1000·4; NARX and HW models take it."""
    assert DIVERGENCE_FACTOR == 1e3
    assert FreeRunModel(y_range=(-1.0, 3.0))._limits() == (1.0 - 4000.0, 1.0 + 4000.0)
    assert issubclass(NARXModel, FreeRunModel) and issubclass(HWModel, FreeRunModel)
    m = FreeRunModel(input_name="V", output_name="x")
    assert (m.inputs, m.outputs) == (("V",), ("x",))


def test_one_signal_flattens_a_column_and_names_bad_input():
    np.testing.assert_array_equal(one_signal([[1.0], [2.0]], "u", "narx"), [1.0, 2.0])
    with pytest.raises(DataError, match=r"hw: y must be one signal \(shape \(N,\)\), found "
                                        r"shape \(2, 2\)"):
        one_signal(np.ones((2, 2)), "y", "hw")
    with pytest.raises(DataError, match="hysteresis: u has 1 non-finite samples"):
        one_signal([0.0, np.nan], "u", "hysteresis")


def test_not_constant_names_the_value_the_length_and_the_fix():
    """A signal of one value is refused with its value and length; one that moves by 1e-300
    (np.ptp > 0) passes."""
    with pytest.raises(DataError, match=r"^hysteresis: the input 'V' is constant \(2\.5 in all 4 "
                                        r"samples\); a hysteresis needs an input sweep$"):
        not_constant(np.full(4, 2.5), "the input 'V'", "hysteresis",
                     "a hysteresis needs an input sweep")
    assert not_constant(np.array([0.0, 1e-300]), "the output", "narx", "fix") is None


def test_fit_percent_of_a_known_error_and_of_a_constant_output():
    """y = (0, 2): ‖y − ȳ‖ = √2; ŷ = (0, 1): ‖y − ŷ‖ = 1 → 100 (1 − 1/√2) = 29.289… %."""
    y = np.array([0.0, 2.0])
    assert fit_percent(y, np.array([0.0, 1.0]), "narx") == pytest.approx(
        100.0 * (1.0 - 1.0 / np.sqrt(2.0)), rel=1e-15)
    with pytest.raises(DataError, match="hammerstein_wiener: the fit is undefined for a "
                                        "constant output"):
        fit_percent(np.ones(3), np.ones(3), "hammerstein_wiener")

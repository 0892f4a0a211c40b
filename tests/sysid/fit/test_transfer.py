"""Transfer-function structures and fits (issue 32, item 2) against responses of known transfer functions."""

from __future__ import annotations

import numpy as np
import pytest

from flightlogs.errors import FitError, ModelError
from sysid.fit.transfer import TransferOptions, fit_transfer_function
from sysid.freqresp import FrequencyResponse
from sysid.model.transfer import Term, parse_transfer_function

ROLL = "p/delta_lat = b2*s^2/(s^4 + a3*s^3 + a2*s^2 + a1*s + a0)"
TRUTH = np.array([1360.0, 28.9, 236.24, 1223.6, 1176.0])


def _response(num: np.ndarray, den: np.ndarray, tau: float, *, coherence: float = 0.95) -> FrequencyResponse:
    omega = np.geomspace(0.5, 50.0, 120)
    s = 1j * omega
    value = np.polyval(num, s) / np.polyval(den, s) * np.exp(-s * tau)
    n = omega.size
    return FrequencyResponse(
        input="delta_lat",
        output="p",
        omega=omega,
        response=value,
        coherence=np.full(n, coherence),
        random_error=np.zeros(n),
        input_autospectrum=np.ones(n),
        output_autospectrum=np.abs(value) ** 2,
        cross_spectrum=value,
        windows_s=(10.0,),
        fit_range=(0.5, 50.0),
    )


def test_the_structure_reads_as_polynomials_linear_in_their_parameters() -> None:
    tf = parse_transfer_function("p / delta_lat = (-2*b1*s + 3)/(s^2 - a1*s + 0.5*a0)")
    assert (tf.output, tf.input, tf.parameters) == ("p", "delta_lat", ("b1", "a1", "a0"))
    assert tf.numerator == (Term(-2.0, "b1", 1), Term(3.0, None, 0))
    assert tf.denominator == (Term(1.0, None, 2), Term(-1.0, "a1", 1), Term(0.5, "a0", 0))
    num, den = tf.coefficients(np.array([1.0, 2.0, 4.0]))
    assert num.tolist() == [-2.0, 3.0] and den.tolist() == [1.0, -2.0, 2.0]
    s = np.array([0.5j, 3j])
    n_fixed, d_fixed, n_basis, d_basis = tf.basis(s)
    values = np.array([1.0, 2.0, 4.0])
    np.testing.assert_allclose(n_fixed + n_basis @ values, np.polyval(num, s))
    np.testing.assert_allclose(d_fixed + d_basis @ values, np.polyval(den, s))


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("p = b/(s + a)", "no OUTPUT/INPUT = ... pair"),
        ("p/delta_lat = b*a/(s + c)", "b*a is a product of parameters"),
        ("p/delta_lat = b/(a*s + c)", "every term carries a parameter, so numerator and denominator scale together"),
        ("p/delta_lat = b*sin(s)/(s + a)", "'sin(s)' is not a term"),
        ("p/delta_lat = 1/(s + 2)", "no parameter to fit"),
        ("p/delta_lat = b/(s + ", "not an expression"),
    ],
)
def test_a_structure_not_of_the_form_is_one_sentence(text: str, message: str) -> None:
    with pytest.raises(ModelError) as caught:
        parse_transfer_function(text)
    assert message in str(caught.value) and "\n" not in str(caught.value)


def test_a_noise_free_response_gives_the_truth_and_the_same_answer_twice() -> None:
    tau = 0.0215
    response = _response(np.array([TRUTH[0], 0.0, 0.0]), np.r_[1.0, TRUTH[1:]], tau)
    structure = parse_transfer_function(ROLL)
    first = fit_transfer_function(response, structure, TransferOptions(delay=True))
    values = np.array([c.value for c in first.coefficients])
    np.testing.assert_allclose(values, np.r_[TRUTH, tau], rtol=1e-6)
    assert first.cost < 1e-8 and first.stable and first.minimum_phase and first.notes == ()
    again = fit_transfer_function(response, structure, TransferOptions(delay=True))
    assert [c.value for c in again.coefficients] == [c.value for c in first.coefficients]
    np.testing.assert_allclose(first.evaluate(response.omega), response.response, rtol=1e-6)


def test_an_unstable_or_non_minimum_phase_fit_is_said() -> None:
    # a right-half-plane zero at 3 rad/s and an unstable pole at 0.8 rad/s
    response = _response(np.array([-2.0, 6.0]), np.polymul([1.0, -0.8], [1.0, 10.0]), 0.0)
    fit = fit_transfer_function(response, parse_transfer_function("p/delta_lat = (b1*s + b0)/(s^2 + a1*s + a0)"))
    assert not fit.stable and not fit.minimum_phase
    assert any("unstable fit, pole(s) at 0.8" in note for note in fit.notes)
    assert any("non-minimum phase, zero(s) at 3" in note for note in fit.notes)


def test_a_band_that_misses_the_coherent_range_is_one_sentence() -> None:
    response = _response(np.array([1.0]), np.array([1.0, 1.0]), 0.0)
    with pytest.raises(FitError, match=r"p/delta_lat: the band 60-90 rad/s misses the coherent range 0.5-50 rad/s"):
        fit_transfer_function(
            response, parse_transfer_function("p/delta_lat = b/(s + a)"), TransferOptions(band_rad_s=(60.0, 90.0))
        )


def test_an_uninformed_coefficient_is_flagged_with_its_bound() -> None:
    """A pole far below the band: its coefficient has a large CR, and the note says so."""
    response = _response(np.array([5.0]), np.polymul([1.0, 0.002], [1.0, 8.0]), 0.0)
    fit = fit_transfer_function(response, parse_transfer_function("p/delta_lat = b/(s^2 + a1*s + a0)"))
    a0 = next(c for c in fit.coefficients if c.name == "a0")
    assert a0.cr_percent > 20.0
    assert any(note.startswith("p/delta_lat: a0 not identified to the guidelines (CR") for note in fit.notes)

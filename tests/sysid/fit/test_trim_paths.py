"""A response the structure reaches only through a trim too small to carry it is left out (issue 33's fleet J_ave).

The hover structure (eq. 3.5) reaches body w from the pitch input only through ``U0 q`` (and the trim
angles): in still air that path is gone, and what a pitch sweep leaves in body w is the products the
linearisation drops. The boundary is where the trim path equals the same path at the swings (the products
left out scale with the swings), not a value tuned on a corpus; the cases here are analytic, the 200-log
fleet's J_ave (tests/cli/test_batch.py) the data.
"""

from __future__ import annotations

import numpy as np
import pytest

from sysid.fit.trim_paths import TRIM_FRACTION, trim_only_responses
from sysid.freqresp import FrequencyResponse
from sysid.model.assemble import structure_model
from sysid.model.toml_format import load_structure

_OMEGA = np.geomspace(1.0, 20.0, 30)
_SWINGS = {"delta_lon": {"u": 0.3, "v": 0.1, "w": 0.03, "phi": 0.01, "theta": 0.05}}


def _response(output: str, constants: dict[str, float]) -> FrequencyResponse:
    """The structure's own response (coherence 1) at its starting values and these trims."""
    structure = load_structure("hover")
    model = structure_model(structure, structure.values(), constants=constants, include_wind=False)[0]
    h = model.frequency_response(_OMEGA)[:, model.outputs.index(output), model.inputs.index("delta_lon")]
    ones = np.ones(_OMEGA.size)
    return FrequencyResponse(
        input="delta_lon",
        output=output,
        omega=_OMEGA,
        response=h,
        coherence=ones,
        random_error=0.01 * ones,
        input_autospectrum=ones,
        output_autospectrum=np.abs(h) ** 2,
        cross_spectrum=h,
        windows_s=(10.0,),
        fit_range=(1.0, 20.0),
    )


def _trims(u0: float) -> dict[str, float]:
    return load_structure("hover").default_constants() | {"U0": u0}


@pytest.mark.parametrize(
    ("u0", "dropped"),
    [
        (0.0, True),  # still air: no path at all
        (0.01, True),  # the fleet's trims
        (0.5 * TRIM_FRACTION * 0.3, True),  # half the threshold
        (2.0 * TRIM_FRACTION * 0.3, False),  # twice the threshold: the kinematic path carries the response
        (-5.4, False),  # the chapter 3 campaign's strong wind
    ],
)
def test_body_w_from_the_pitch_input_is_fitted_only_where_the_trim_airspeed_carries_it(
    u0: float, dropped: bool
) -> None:
    structure = load_structure("hover")
    constants = _trims(u0)
    responses = [_response("w", constants), _response("q", constants), _response("u", constants)]
    found = trim_only_responses(structure, responses, structure.values(), constants, _SWINGS)
    assert [d.pair for d in found] == (["w/delta_lon"] if dropped else [])
    if dropped:
        (reason,) = [d.reason for d in found]
        assert f"U0 {u0:+.2g} m/s" in reason and "u 0.3 m/s" in reason and "not fitted" in reason


def test_a_pair_with_its_own_path_is_never_left_out_however_small_the_trims() -> None:
    """q, u and theta answer the pitch input through M_lon and X_lon: no trim is needed, none is asked."""
    structure = load_structure("hover")
    constants = _trims(0.0)
    responses = [_response(name, constants) for name in ("q", "u", "theta", "ax")]
    assert trim_only_responses(structure, responses, structure.values(), constants, {"delta_lon": {}}) == ()

"""Frequency responses to and from HDF5, with units and a schema version.

Layout (schema version 2: text in fixed-length UTF-8 in the checksummed HDF5 1.10 format, see
:mod:`flightlogs.store.schema`; version 1 files, with variable-length text, are still read)::

    /                         attrs: schema, schema_version, software, created_utc
    /responses/<nnn>/         attrs: input, output, input_unit, output_unit, windows_s,
                                     conditioned_on (JSON list), fit_range (2 floats; absent before gating),
                                     reference (absent when none), whole_record (bool; absent: False)
    /responses/<nnn>/omega                 float64 (n_freq,), attrs unit = "rad/s"
    /responses/<nnn>/response              complex128 (n_freq,), attrs unit = "<output>/<input>"
    /responses/<nnn>/coherence             float64 (n_freq,), unit "1"
    /responses/<nnn>/random_error          float64 (n_freq,), unit "1" (fraction of the magnitude)
    /responses/<nnn>/input_autospectrum    float64 (n_freq,), unit "<input>^2/(rad/s)"
    /responses/<nnn>/output_autospectrum   float64 (n_freq,), unit "<output>^2/(rad/s)"
    /responses/<nnn>/cross_spectrum        complex128 (n_freq,), unit "<input>*<output>/(rad/s)"

``<nnn>`` is the zero-padded position, so the order written is the order read.
``reference`` and ``whole_record`` are optional attributes: files written
before them read as responses without a reference or whole-record member,
and older readers ignore them.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

import h5py
import numpy as np

from flightlogs.store.schema import create_schema_file, open_schema, put_text, stamp_schema, text
from flightlogs.writers.atomic import atomic_output
from sysid.freqresp.response import FrequencyResponse

__all__ = ["write_responses", "read_responses", "RESPONSES_SCHEMA_VERSION"]

_SCHEMA = "flight-sysid frequency responses"
#: Layout version written by :func:`write_responses`.
RESPONSES_SCHEMA_VERSION = 2
_ARRAYS = (
    "omega",
    "response",
    "coherence",
    "random_error",
    "input_autospectrum",
    "output_autospectrum",
    "cross_spectrum",
)


def write_responses(path: str | Path, responses: Sequence[FrequencyResponse]) -> Path:
    """Write responses to an HDF5 file, atomically (the file appears only once complete).

    Parameters
    ----------
    path : str or Path
        Destination ``.h5``; its folder must exist.
    responses : sequence of FrequencyResponse
        Responses to store, gated (``fit_range`` set) or not.

    Returns
    -------
    Path
        The file written.

    Examples
    --------
    >>> import tempfile
    >>> omega = np.array([1.0, 2.0])
    >>> h = FrequencyResponse(input="delta_lon", output="q", omega=omega, response=np.array([1 + 1j, 2j]),
    ...                       coherence=np.array([0.9, 0.8]), random_error=np.array([0.01, 0.02]),
    ...                       input_autospectrum=np.ones(2), output_autospectrum=np.ones(2),
    ...                       cross_spectrum=np.ones(2, complex), windows_s=(4.0,),
    ...                       input_unit="%", output_unit="rad/s")
    >>> target = Path(tempfile.mkdtemp()) / "fr.h5"
    >>> write_responses(target, [h]) == target
    True
    >>> (back,) = read_responses(target)
    >>> back.pair, back.input_unit, bool(np.array_equal(back.response, h.response))
    ('q/delta_lon', '%', True)
    """
    with atomic_output(path) as tmp, create_schema_file(tmp) as h5:
        stamp_schema(h5, _SCHEMA, RESPONSES_SCHEMA_VERSION)
        group = h5.create_group("responses")
        width = max(3, len(str(len(responses))))
        for k, response in enumerate(responses):
            _write_one(group.create_group(f"{k:0{width}d}"), response)
    return Path(path)


def read_responses(path: str | Path) -> tuple[FrequencyResponse, ...]:
    """Read responses written by :func:`write_responses`, in the order written.

    Parameters
    ----------
    path : str or Path
        The ``.h5`` file.

    Returns
    -------
    tuple of FrequencyResponse

    Raises
    ------
    LogFormatError
        If the file is not a responses file of this schema, or of a newer version.
    """
    with open_schema(
        Path(path),
        _SCHEMA,
        RESPONSES_SCHEMA_VERSION,
        what="responses",
        not_hdf5="an HDF5 file",
        wrong_schema="HDF5 file holds no flight-sysid frequency responses.",
    ) as (h5, _):
        group = h5["responses"]
        return tuple(_read_one(group[key]) for key in sorted(group))


def _write_one(group: h5py.Group, response: FrequencyResponse) -> None:
    put_text(group.attrs, "input", response.input)
    put_text(group.attrs, "output", response.output)
    put_text(group.attrs, "input_unit", response.input_unit)
    put_text(group.attrs, "output_unit", response.output_unit)
    group.attrs["windows_s"] = np.asarray(response.windows_s, dtype=np.float64)
    put_text(group.attrs, "conditioned_on", json.dumps(list(response.conditioned_on)))
    if response.fit_range is not None:
        group.attrs["fit_range"] = np.asarray(response.fit_range, dtype=np.float64)
    if response.reference is not None:
        put_text(group.attrs, "reference", response.reference)
    group.attrs["whole_record"] = bool(response.whole_record)
    units = _units(response)
    for name in _ARRAYS:
        dataset = group.create_dataset(name, data=np.asarray(getattr(response, name)))
        put_text(dataset.attrs, "unit", units[name])


def _units(response: FrequencyResponse) -> dict[str, str]:
    x, y = response.input_unit or "input", response.output_unit or "output"
    return {
        "omega": "rad/s",
        "response": f"({y})/({x})",
        "coherence": "1",
        "random_error": "1",
        "input_autospectrum": f"({x})^2/(rad/s)",
        "output_autospectrum": f"({y})^2/(rad/s)",
        "cross_spectrum": f"({x})*({y})/(rad/s)",
    }


def _read_one(group: h5py.Group) -> FrequencyResponse:
    arrays = {name: group[name][()] for name in _ARRAYS}
    fit = group.attrs.get("fit_range")
    reference = group.attrs.get("reference")
    return FrequencyResponse(
        input=text(group.attrs["input"]),
        output=text(group.attrs["output"]),
        windows_s=tuple(float(t) for t in np.atleast_1d(group.attrs["windows_s"])),
        conditioned_on=tuple(json.loads(text(group.attrs["conditioned_on"]))),
        input_unit=text(group.attrs["input_unit"]),
        output_unit=text(group.attrs["output_unit"]),
        fit_range=None if fit is None else (float(fit[0]), float(fit[1])),
        reference=None if reference is None else text(reference),
        whole_record=bool(group.attrs.get("whole_record", False)),
        **arrays,
    )

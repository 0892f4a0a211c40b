"""Composite, conditioned frequency responses from records (Tischler's FRESPID, MISOSA, COMPOSITE)."""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import replace
from typing import cast

import numpy as np

from flightlogs.errors import DataError, MissingSignalError
from flightlogs.record import Record
from sysid.freqresp._composite import composite_pair
from sysid.freqresp._spectra import WindowSpectra, WindowTransforms, window_transforms
from sysid.freqresp._whole import member_possible, whole_record_floor, whole_record_spectra
from sysid.freqresp.options import ResponseOptions
from sysid.freqresp.response import FrequencyResponse

__all__ = ["ChannelWindows", "frequency_responses", "frequency_response_sets", "automatic_window_lengths"]

_N_AUTOMATIC_WINDOWS = 5
_MIN_WINDOW_SAMPLES = 16
_RATE_TOLERANCE = 1e-6


def frequency_responses(
    records: Sequence[Record],
    inputs: Sequence[str],
    outputs: Sequence[str],
    options: ResponseOptions = ResponseOptions(),
    *,
    quiet: Sequence[Record] = (),
) -> tuple[FrequencyResponse, ...]:
    """Composite frequency responses of every output to every input.

    Parameters
    ----------
    records : sequence of Record
        Pieces of flight on one uniform time base (the same rate), trim
        removed; several trials of the same maneuver are combined in the
        spectral sense: windows never straddle two records, and the spectra
        are averaged over all windows of all records.
    inputs : sequence of str
        Input signal names (``delta_lon``, ``wind_lon`` ...). With more than
        one, each response is conditioned on the other inputs (MISO).
    outputs : sequence of str
        Output signal names (``q``, ``ax`` ...).
    options : ResponseOptions, optional
        Grid, windows, overlap, taper, reference, whole-record member.
    quiet : sequence of Record, optional
        Flight with the same signals and rate but none of this excitation
        (other axes' maneuvers, hover: :func:`~sysid.freqresp.quiet_records`).
        In closed loop they measure the floor the autopilot's feedback of
        disturbances and noise puts into the inputs and outputs; without a
        reference, that floor is removed from the responses (see Notes).

    Returns
    -------
    tuple of FrequencyResponse
        For each output, for each input, in the order given. ``coherence`` is
        the partial coherence when conditioned; the spectra stored are then
        the conditioned ones (so that ``response = cross / input`` and,
        without a reference, ``coherence = |cross|^2 / (input output)`` hold
        for every response).

    Raises
    ------
    MissingSignalError
        If a record lacks a signal named (the reference included).
    DataError
        If the records differ in rate, hold NaNs, are shorter than every
        window, an input or the reference never varies, the reference is
        also an input or output, or the grid exceeds the Nyquist frequency.

    Notes
    -----
    Per window length: every window of every record is mean-removed, tapered
    and Fourier transformed at the grid frequencies (chirp-z on an evenly
    spaced grid, a matrix product on a log grid), the auto and cross spectra
    averaged (Welch). The window lengths are then combined per frequency with
    weights ``1 / eps_r^2``, ``eps_r = sqrt(1 - g^2) / (|g| sqrt(2 n_d))``
    (Bendat & Piersol), ``n_d`` the overlap-corrected number of averages
    (less one per conditioning input), see :mod:`sysid.freqresp._composite`.
    Grid points below ``2 pi min_cycles / T`` of the longest window ``T`` are
    left out; with the whole-record member (``options.whole_record``; more
    records than inputs, one input, or no reference:
    :mod:`sysid.freqresp._whole`) ``T`` is the longest record. With ``options.reference`` the estimate of the first input is the
    instrumental-variable one (:mod:`sysid.freqresp._conditioning`).

    Closed loop without a reference: where the excitation does not dominate
    the input, the input also carries the feedback ``x_d = -C y_d`` of
    disturbances and sensor noise, coherent with the output through the
    controller's inverse, and ``G_xy / G_xx`` tends to ``P (1 - f)`` (``f``
    the feedback's share of ``G_xx``, the loop gain high) with a coherence
    that barely drops. With `quiet` records, the same spectra computed on
    them (same windows; smoothed whole-record transforms for the member) are
    that feedback's floor ``F``, stationary over a flight; the response is
    ``(G_jy - F_jy) / (G_jj - F_jj)`` (spectra conditioned on the other
    inputs), and where the excitation does not carry at least
    ``options.min_excitation_ratio`` times the floor's input power the
    coherence is set to zero (feedback-dominated: not fitted). The coherence
    is otherwise the measured one.

    Examples
    --------
    >>> import numpy as np
    >>> from pathlib import Path
    >>> t = np.arange(6000) / 100.0
    >>> x = np.random.default_rng(0).normal(size=t.size)
    >>> columns = {"delta_lon": x, "q": 2.0 * x}
    >>> record = Record(time_s=t, columns=columns, units={"delta_lon": "%", "q": "rad/s"}, trim={}, source=Path("sim"))
    >>> (h,) = frequency_responses([record], ["delta_lon"], ["q"])
    >>> h.pair, bool(np.allclose(h.response, 2.0)), bool(np.all(h.coherence > 0.999))
    ('q/delta_lon', True, True)
    """
    return frequency_response_sets(records, [(inputs, outputs, quiet)], options)[0]


def frequency_response_sets(
    records: Sequence[Record],
    sets: Sequence[tuple[Sequence[str], Sequence[str], Sequence[Record]]],
    options: ResponseOptions = ResponseOptions(),
    *,
    windows: ChannelWindows | None = None,
) -> tuple[tuple[FrequencyResponse, ...], ...]:
    """:func:`frequency_responses` of several sets of inputs and outputs of the same records, at once.

    Each set is ``(inputs, outputs, quiet)`` as :func:`frequency_responses` takes them; its responses are
    that function's for them (to rounding: the windows' spectra of a channel pair do not depend on the
    other channels). A channel in several sets is transformed once per window: the longitudinal axis's
    outputs are two sets (w conditioned on the thrust too), of 6 and 5 channels with the excitation as
    reference, 8 in all.

    Parameters
    ----------
    records : sequence of Record
        As :func:`frequency_responses`'s.
    sets : sequence of (sequence of str, sequence of str, sequence of Record)
        Inputs, outputs and quiet records of each set.
    options : ResponseOptions, optional
        As :func:`frequency_responses`'s, for every set.
    windows : ChannelWindows, optional
        The records' windowed transforms made so far (with the same `options`), to take those of channels
        already transformed from; by default made here.

    Returns
    -------
    tuple of tuple of FrequencyResponse
        Each set's responses, as :func:`frequency_responses` returns them.

    Raises
    ------
    MissingSignalError, DataError
        As :func:`frequency_responses`, for any set.
    """
    reference = options.reference
    extra = () if reference is None else (reference,)
    named = [(tuple(inputs), tuple(outputs), quiet) for inputs, outputs, quiet in sets]
    for inputs, outputs, _ in named:
        _check_names(inputs, outputs, reference)
    if not records:
        raise DataError("no records to compute frequency responses from")
    dt = _common_step(records)
    if options.omega_max > np.pi / dt:
        raise DataError(
            f"omega_max={options.omega_max:g} rad/s is above the Nyquist frequency "
            f"{np.pi / dt:.1f} rad/s of the {1 / dt:g} Hz records"
        )
    channels = tuple(dict.fromkeys(c for inputs, outputs, _ in named for c in (*inputs, *extra, *outputs)))
    data = [_channels(record, channels) for record in records]
    for name in dict.fromkeys(c for inputs, _, _ in named for c in (*inputs, *extra)):
        if all(np.ptp(block[channels.index(name)]) == 0 for block in data):
            what = f"reference {name}" if name in extra else f"input {name}"
            raise DataError(f"{what} does not vary in any record: nothing excites the responses")
    lengths = _window_samples(data, dt, options)
    windows = ChannelWindows(records, options) if windows is None else windows
    found = []
    for k, (inputs, outputs, quiet) in enumerate(named):
        mine_channels = (*inputs, *extra, *outputs)
        rows = [channels.index(c) for c in mine_channels]
        mine = data if rows == list(range(len(channels))) else [block[rows] for block in data]
        instrument = len(inputs) if reference is not None else None
        whole = options.whole_record and member_possible(len(data), len(inputs), instrument)
        longest = max(block.shape[1] for block in data) if whole else max(lengths)
        omega = _grid(options, dt, longest)
        later = {c for ins, outs, _ in named[k + 1 :] for c in (*ins, *extra, *outs)}  # asked for again: kept
        spectra = [windows.spectra(mine_channels, n, omega, keep=later) for n in lengths]
        assert all(s is not None for s in spectra)  # every length fits the longest record (_window_samples)
        members = cast(list[WindowSpectra], spectra)
        found.append(_set_responses(records, mine, dt, omega, members, inputs, outputs, whole, quiet, options))
    return tuple(found)


class ChannelWindows:
    """The windows' Fourier transforms of the channels of a set of records, each channel transformed once per
    window length and grid.

    The search for the mixer inputs that move with an axis's own (:func:`~sysid.freqresp.coupling.coupled_inputs`)
    transforms the axis's input, and the axis's responses, in sets conditioned on different inputs, share their
    inputs and reference: a channel that is asked for again is transformed once, its spectra with any other the
    products of the two transforms. What each request says to keep is kept, within :data:`_KEEP_BYTES` (a long
    record's windows would not fit): beyond, a channel is transformed each time it is asked for.

    Parameters
    ----------
    records : sequence of Record
        Records on one time base, as :func:`frequency_responses` takes them.
    options : ResponseOptions
        Overlap, taper, cycles and spacing of the windows.
    """

    def __init__(self, records: Sequence[Record], options: ResponseOptions) -> None:
        self._records, self._options = records, options
        self._dt = _common_step(records)
        self._kept: dict[tuple[int, bytes], tuple[WindowTransforms, dict[str, np.ndarray]]] = {}
        self._bytes = 0

    def spectra(
        self, channels: Sequence[str], n_window: int, omega: np.ndarray, *, keep: Collection[str] | None = None
    ) -> WindowSpectra | None:
        """The spectral matrix of `channels`, in that order, for windows of `n_window` samples on the grid `omega`
        (rad/s), as :func:`~sysid.freqresp._spectra.window_spectra` makes it; None when no record holds a window.
        Of the channels transformed for it, those in `keep` (None: all) are kept for the next requests.
        """
        options = self._options
        low = 2.0 * np.pi * options.min_cycles / (n_window * self._dt)
        key = (n_window, omega[omega >= low * (1.0 - 1e-12)].tobytes())  # the frequencies the window transforms
        made, kept = self._kept.get(key, (None, {}))
        missing = tuple(dict.fromkeys(c for c in channels if c not in kept))
        if missing:
            made = _transforms(
                [_channels(record, missing) for record in self._records], self._dt, n_window, omega, options
            )
            if made is None:
                return None
            fresh = {c: made.x[:, k, :] for k, c in enumerate(missing)}
            stored = {c: np.copy(x) for c, x in fresh.items() if keep is None or c in keep}  # not the whole batch
            size = sum(x.nbytes for x in stored.values())
            if stored and self._bytes + size <= _KEEP_BYTES:
                self._bytes += size
                self._kept[key] = (made, kept | stored)
            kept = kept | fresh
        assert made is not None
        return replace(made, x=np.stack([kept[c] for c in channels], axis=1)).spectra(omega)


#: Bytes of windowed transforms a :class:`ChannelWindows` keeps (on the 60-sweep campaign the longitudinal axis
#: keeps its input, the wind and the excitation, 11 MiB; a 400 Hz log's hour-long record would take gigabytes).
_KEEP_BYTES = 64 * 2**20


def _set_responses(
    records: Sequence[Record],
    data: Sequence[np.ndarray],
    dt: float,
    omega: np.ndarray,
    windows: list[WindowSpectra],
    inputs: tuple[str, ...],
    outputs: tuple[str, ...],
    whole: bool,
    quiet: Sequence[Record],
    options: ResponseOptions,
) -> tuple[FrequencyResponse, ...]:
    """One set's responses from its channels' `data` (inputs, reference, outputs) and windows' spectra."""
    reference = options.reference
    extra = () if reference is None else (reference,)
    channels = inputs + extra + outputs
    input_rows = list(range(len(inputs)))
    instrument = len(inputs) if reference is not None else None
    output_rows = [len(inputs) + len(extra) + o for o in range(len(outputs))]
    if whole:
        member = whole_record_spectra(
            data,
            dt,
            omega,
            inputs=input_rows,
            outputs=output_rows,
            instrument=instrument,
            min_cycles=options.min_cycles,
        )
        windows += [member] if member is not None else []
    floors = _floors(quiet, channels, dt, windows, omega, options) if reference is None else None
    units = _units(records, channels)
    found = []
    for o, output in enumerate(outputs):
        for j, name in enumerate(inputs):
            estimate = composite_pair(
                windows, omega, input_rows, j, output_rows[o], instrument, floors, options.min_excitation_ratio
            )
            found.append(
                FrequencyResponse(
                    input=name,
                    output=output,
                    omega=omega.copy(),
                    response=estimate.response,
                    coherence=estimate.coherence,
                    random_error=estimate.random_error,
                    input_autospectrum=estimate.input_autospectrum,
                    output_autospectrum=estimate.output_autospectrum,
                    cross_spectrum=estimate.cross_spectrum,
                    windows_s=estimate.windows_s,
                    conditioned_on=tuple(other for other in inputs if other != name),
                    input_unit=units[name],
                    output_unit=units[output],
                    reference=reference,
                    whole_record=estimate.whole_record,
                )
            )
    return tuple(found)


def automatic_window_lengths(longest_record_s: float, omega_min: float) -> tuple[float, ...]:
    """Five window lengths, s: geometric from ``2 pi / (5 omega_min)`` to half the longest record.

    The shortest is capped at a quarter of the longest (Tischler: window
    lengths from about ``1 / (5 f_min)`` up to half the record).

    Parameters
    ----------
    longest_record_s : float
        Duration of the longest record, s.
    omega_min : float
        Lowest frequency of interest, rad/s.

    Returns
    -------
    tuple of float
        Increasing lengths, s.

    Examples
    --------
    >>> [round(t, 2) for t in automatic_window_lengths(34.0, 0.5)]
    [2.51, 4.05, 6.54, 10.54, 17.0]
    """
    longest = longest_record_s / 2.0
    shortest = min(2.0 * np.pi / (5.0 * omega_min), longest / 4.0)
    return tuple(float(t) for t in np.geomspace(shortest, longest, _N_AUTOMATIC_WINDOWS))


def _check_names(inputs: tuple[str, ...], outputs: tuple[str, ...], reference: str | None) -> None:
    if not inputs or not outputs:
        raise DataError(f"need at least one input and one output, got inputs={inputs}, outputs={outputs}")
    doubled = sorted({n for n in inputs + outputs if (inputs + outputs).count(n) > 1})
    if doubled:
        raise DataError(f"signal(s) {', '.join(doubled)} named twice among the inputs and outputs")
    if reference is not None and reference in inputs + outputs:
        raise DataError(f"reference {reference} is also an input or output; it must be the injected excitation")


def _common_step(records: Sequence[Record]) -> float:
    steps = [(r.end_s - r.start_s) / (r.time_s.size - 1) for r in records]
    if max(steps) - min(steps) > _RATE_TOLERANCE * min(steps):
        rates = ", ".join(f"{r.label or r.source.name}: {1 / s:.3f} Hz" for r, s in zip(records, steps))
        raise DataError(f"the records are not all at one rate ({rates}); resample them to one time base")
    return float(np.mean(steps))


def _channels(record: Record, channels: tuple[str, ...]) -> np.ndarray:
    missing = [name for name in channels if name not in record.signals]
    if missing:
        raise MissingSignalError(
            f"{record.source.name}: record {record.label!r} has no signal {', '.join(missing)} "
            f"(it has {', '.join(record.signals)})"
        )
    block = np.ascontiguousarray(np.vstack([record[name] for name in channels]))
    bad = [name for name, row in zip(channels, block) if not np.all(np.isfinite(row))]
    if bad:
        raise DataError(f"{record.source.name}: record {record.label!r} has NaN or infinite values in {', '.join(bad)}")
    return block


def _window_samples(data: Sequence[np.ndarray], dt: float, options: ResponseOptions) -> list[int]:
    longest = max(block.shape[1] for block in data)
    lengths_s = options.window_lengths_s or automatic_window_lengths((longest - 1) * dt, options.omega_min)
    samples = sorted({int(round(t / dt)) for t in lengths_s})
    too_short = [n * dt for n in samples if n < _MIN_WINDOW_SAMPLES]
    if too_short:
        raise DataError(f"window of {too_short[0]:g} s holds fewer than {_MIN_WINDOW_SAMPLES} samples at {1 / dt:g} Hz")
    too_long = [n * dt for n in samples if n > longest]
    if too_long:
        raise DataError(
            f"a window of {too_long[0]:g} s is longer than every record (the longest lasts {(longest - 1) * dt:.2f} s)"
        )
    return samples


def _grid(options: ResponseOptions, dt: float, longest: int) -> np.ndarray:
    """The grid from the lowest frequency the longest member (window or record, samples) resolves."""
    omega = options.grid()
    lowest = 2.0 * np.pi * options.min_cycles / (longest * dt)
    kept = omega[omega >= lowest * (1.0 - 1e-12)]
    if kept.size < 2:
        raise DataError(
            f"the longest window ({longest * dt:.2f} s) resolves nothing below "
            f"{lowest:.3g} rad/s, at or above omega_max={options.omega_max:g} rad/s"
        )
    return kept


def _windowed(
    data: Sequence[np.ndarray], dt: float, n_window: int, omega: np.ndarray, options: ResponseOptions
) -> WindowSpectra | None:
    """:func:`~sysid.freqresp._spectra.window_spectra` with the overlap, taper, cycles and spacing of `options`."""
    found = _transforms(data, dt, n_window, omega, options)
    return None if found is None else found.spectra(omega)


def _transforms(
    data: Sequence[np.ndarray], dt: float, n_window: int, omega: np.ndarray, options: ResponseOptions
) -> WindowTransforms | None:
    """:func:`~sysid.freqresp._spectra.window_transforms` with the overlap, taper, cycles and spacing of `options`."""
    return window_transforms(
        data,
        dt,
        n_window,
        omega,
        overlap=options.overlap,
        taper=options.taper,
        min_cycles=options.min_cycles,
        spacing=options.spacing,
    )


def _floors(
    quiet: Sequence[Record],
    channels: tuple[str, ...],
    dt: float,
    windows: Sequence[WindowSpectra],
    omega: np.ndarray,
    options: ResponseOptions,
) -> list[np.ndarray | None] | None:
    """Spectra of the `quiet` records matching each member (None where none is long enough); None without any."""
    if not quiet:
        return None
    step = _common_step(quiet)
    if abs(step - dt) > _RATE_TOLERANCE * dt:
        raise DataError(f"the quiet records are at {1 / step:.3f} Hz, the maneuvers at {1 / dt:.3f} Hz: resample them")
    data = [_channels(record, channels) for record in quiet]
    floors: list[np.ndarray | None] = []
    for window in windows:
        if window.noise_dof is not None:
            floors.append(whole_record_floor(data, dt, omega, options.min_cycles))
            continue
        found = _windowed(data, dt, int(round(window.window_s / dt)), omega, options)
        floors.append(None if found is None else found.spectra)
    return floors if any(f is not None for f in floors) else None


def _units(records: Sequence[Record], channels: tuple[str, ...]) -> dict[str, str]:
    return {name: records[0].units.get(name, "") for name in channels}

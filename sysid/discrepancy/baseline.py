"""The simulation's model, identified from SIM by equation error and evaluated on REAL.

Each output (a specific force or an angular acceleration) is regressed on
the four mixer inputs at lags 0 to 0.3 s (an impulse response that holds
the simulated delays and lags, whatever they are), their squares at four of
those lags (differential rotor speeds change the total thrust: a yaw sweep
pulls az down), the body velocities and rates, and a constant. Where SIM flew
in a logged wind (a real flight as the reference), u and v are read relative
to the air (``u_air``, ``v_air``: ground velocity less wind): the drag and
moments the sweeps identify then act on the wind too, and a REAL flight in
another wind is no discrepancy (read on the ground velocity, the fleet's
healthy flights against their first were named wind, 83 %, and a CG offset). Nothing about the vehicle is assumed. What REAL
does that this model of SIM does not is the discrepancy.

An input's square is left out when SIM flew it over too narrow a range for a curvature to show: when
the part of ``x²`` that a constant and ``x`` do not explain is under 1 % of its spread (a thrust held
at 0.45 ± 0.002 through a flight without height changes). Its coefficients would then be noise that
cancels within SIM's range and extrapolates outside it: a REAL vehicle that needs 3 % more thrust (a
sagging battery, a heavier one) would be predicted a roll and pitch moment from the thrust alone,
which was first read as a CG offset (found on another generator's flights).

A square is also left out when the flight the model is read on takes that input outside SIM's range
for more than a tenth of its samples (a REAL vehicle with worn motors hovers at 0.50 where SIM flew
0.44-0.46). The square's lag coefficients, each informed by SIM's narrow range, then change the
model's thrust dynamics, not only its level: on one SIM flight of four (another generator's), the
worn motors' 30 % thrust loss left az at 2.8 times its floor after the trim, and a thrust ceiling
was fitted to what the square extrapolated.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace

import numpy as np
from numpy.lib.stride_tricks import as_strided

from sysid.discrepancy.series import COMMANDS, OUTPUTS, FlightSeries

__all__ = ["BaselineModel", "fit_baseline", "Commands", "design_width"]

_LAG_S = 0.3  # longest input lag of the impulse responses, s
_STATES = ("u", "v", "w", "p", "q", "r")
_AIR = {"u": ("u_air", "wind_lon"), "v": ("v_air", "wind_lat")}  # where SIM flew in a logged wind: u, v on the air
_N_SQUARE_LAGS = 4  # the inputs' squares (a rotor's thrust grows with its speed squared) at this many lags
_MIN_CURVATURE_SHARE = 0.01  # std of (x - mean)² over std of x²: below it, SIM cannot inform x²'s coefficient
_MAX_OUTSIDE_SHARE = 0.10  # share of the flight read on outside SIM's range of an input: above it, no square

#: Mixer inputs to drive a prediction with (each shape (n,)); None: as logged.
Commands = Mapping[str, np.ndarray] | None


@dataclass(frozen=True, slots=True, kw_only=True)
class BaselineModel:
    """Linear equation-error model of the simulation.

    Parameters
    ----------
    coefficients : Mapping[str, ndarray]
        Per output, the regression coefficients, shape (n_regressors,).
    lags : ndarray of int, shape (n_lags,)
        Input lags, samples.
    states : tuple of str
        State regressors used.
    rate_hz : float
        Sample rate it was fitted at, Hz.
    squared : tuple of str
        Mixer inputs whose squares are regressors (those SIM varied enough to inform them).
    """

    coefficients: Mapping[str, np.ndarray]
    lags: np.ndarray
    states: tuple[str, ...]
    rate_hz: float
    squared: tuple[str, ...] = COMMANDS

    @property
    def signals(self) -> tuple[str, ...]:
        """The logged signals it reads: the mixer inputs and those its states are made of (``u_air``: ``u``, wind)."""
        read = [*COMMANDS]
        for state in self.states:
            read += next(([ground, wind] for ground, (air, wind) in _AIR.items() if air == state), [state])
        return tuple(dict.fromkeys(read))

    def predict(self, series: FlightSeries, commands: Commands = None) -> dict[str, np.ndarray]:
        """Each output as the simulation would have it on `series`, shape (n,) each.

        Parameters
        ----------
        series : FlightSeries
            A flight with the same signals.
        commands : Mapping[str, ndarray], optional
            Mixer inputs to use instead of the logged ones (delayed, lagged).
        """
        weights, spans = self._weights(), series.spans()
        inputs = commands if commands is not None else {c: series[c] for c in COMMANDS}
        total = self._steady(series)
        for k, name in enumerate(COMMANDS):  # lagged inputs times all outputs' weights at once: no whole design
            total += _lagged(spans, np.asarray(inputs[name]), self.lags) @ weights[self._linear_rows(k)]
        self._add_squares(total, spans, inputs, weights)
        return {o: total[:, j] for j, o in enumerate(self.coefficients)}

    def changed(self, series: FlightSeries) -> Callable[[Callable[[np.ndarray], np.ndarray]], dict[str, np.ndarray]]:
        """:meth:`predict` on `series` with every mixer input passed through one `change`, as a function of it.

        The change must be linear and time-invariant within each piece of the flight, holding a piece's
        first value before it (:func:`~sysid.discrepancy.catalogue._term.delayed`, :func:`~.first_order`): it then
        commutes with the model's impulse responses, whose lags hold the same first value. The part of
        each output the inputs make is computed once and changed (six columns), not each input before its
        lags (four inputs, 16 lags each), for each of a delay's or lag's 60 values; the squares of the
        changed inputs are lagged as :meth:`predict` lags them. Equal to ``predict(series, {c: change(x_c)})``
        to rounding.

        Parameters
        ----------
        series : FlightSeries
            A flight with the same signals.

        Returns
        -------
        callable
            ``predict(change)``: each output, shape (n,), with ``change(x)`` (shape (n,) to (n,)) applied to
            every mixer input.
        """
        weights, spans, steady = self._weights(), series.spans(), self._steady(series)
        made = np.zeros_like(steady)  # the part of each output the inputs make (their squares apart)
        for k, name in enumerate(COMMANDS):
            made += _lagged(spans, np.asarray(series[name]), self.lags) @ weights[self._linear_rows(k)]
        columns = [np.ascontiguousarray(made[:, j]) for j in range(made.shape[1])]

        def predict(change: Callable[[np.ndarray], np.ndarray]) -> dict[str, np.ndarray]:
            total = steady + np.column_stack([change(column) for column in columns])
            self._add_squares(total, spans, {c: change(np.asarray(series[c])) for c in self.squared}, weights)
            return {o: total[:, j] for j, o in enumerate(self.coefficients)}

        return predict

    def _weights(self) -> np.ndarray:
        """Every output's coefficients as columns, shape (n_regressors, n_outputs)."""
        return np.column_stack(list(self.coefficients.values()))

    def _linear_rows(self, k: int) -> slice:
        """The rows of mixer input `k`'s lags in the coefficients."""
        return slice(k * self.lags.size, (k + 1) * self.lags.size)

    def _steady(self, series: FlightSeries) -> np.ndarray:
        """The part of each output the states and the constant make on `series`, shape (n, n_outputs)."""
        first = len(COMMANDS) * self.lags.size + len(self.squared) * _square_lags(self.lags).size
        fixed = np.column_stack([_state(series, s) for s in self.states] + [np.ones(series.n)])
        return np.asarray(fixed @ self._weights()[first:])

    def _add_squares(
        self, total: np.ndarray, spans: list[slice], inputs: Mapping[str, np.ndarray], weights: np.ndarray
    ) -> None:
        """Add to `total` (shape (n, n_outputs)) the part of each output the squared `inputs` (each (n,)) make."""
        square_lags = _square_lags(self.lags)
        for k, name in enumerate(self.squared):
            first = len(COMMANDS) * self.lags.size + k * square_lags.size
            squares = _lagged(spans, np.asarray(inputs[name]) ** 2, square_lags)
            total += squares @ weights[first : first + square_lags.size]

    def recentred(self, thrust_shift: float) -> BaselineModel:
        """The model with the thrust command read `thrust_shift` lower by every output but az.

        A real vehicle that hovers at another thrust command (worn motors, another mass) sends the
        simulation's model outside the thrust range it was fitted on: the small cross-couplings it
        learned from the thrust command to the moments and side forces (noise, within SIM's range) then
        add constant moments no vehicle makes, which were named a CG offset. Those outputs read the
        thrust command about the real vehicle's own hover; az reads it as logged, and the thrust level
        is the trim's. Exact: the shift is folded into the coefficients (``(x - s)² = x² - 2 s x + s²``).

        Parameters
        ----------
        thrust_shift : float
            Real less simulated mean thrust command, as logged.
        """
        k = COMMANDS.index("delta_thr")
        square_lags = _square_lags(self.lags)
        n_lags, n_squares = self.lags.size, square_lags.size
        linear = slice(k * n_lags, (k + 1) * n_lags)
        out = {}
        for o, weights in self.coefficients.items():
            w = np.array(weights, dtype=float)
            if o != "az":
                constant = w[linear].sum() * -thrust_shift
                if "delta_thr" in self.squared:
                    first = len(COMMANDS) * n_lags + self.squared.index("delta_thr") * n_squares
                    squares = w[first : first + n_squares]
                    w[k * n_lags + np.searchsorted(self.lags, square_lags)] += -2.0 * thrust_shift * squares
                    constant += thrust_shift**2 * squares.sum()
                w[-1] += constant
            out[o] = w
        return replace(self, coefficients=out)

    def command_part(
        self, series: FlightSeries, command: str, values: np.ndarray | None = None
    ) -> dict[str, np.ndarray]:
        """The part of each output's prediction that one mixer input makes (its lags and square), shape (n,) each.

        What the simulation's vehicle produces per command on that axis: a moment or thrust that the real
        one makes more or less of (worn motors) is this part scaled.

        Parameters
        ----------
        series : FlightSeries
            A flight with the same signals.
        command : str
            One of ``delta_lat delta_lon delta_yaw delta_thr``.
        values : ndarray, shape (n,), optional
            The input to use instead of the logged one (clipped at a ceiling, say).
        """
        x = np.asarray(series[command] if values is None else values)
        k = COMMANDS.index(command)
        square_lags = _square_lags(self.lags)
        n_lags, n_squares = self.lags.size, square_lags.size
        weights = np.column_stack(list(self.coefficients.values()))
        spans = series.spans()
        total = _lagged(spans, x, self.lags) @ weights[k * n_lags : (k + 1) * n_lags]
        if command in self.squared:
            first = len(COMMANDS) * n_lags + self.squared.index(command) * n_squares
            total += _lagged(spans, x**2, square_lags) @ weights[first : first + n_squares]
        return {o: total[:, j] for j, o in enumerate(self.coefficients)}


def fit_baseline(
    series: FlightSeries, rows: np.ndarray | None = None, *, read_on: FlightSeries | None = None
) -> BaselineModel:
    """Least-squares fit of every output on samples `rows` (default all).

    Parameters
    ----------
    series : FlightSeries
        The simulation's flight.
    rows : ndarray of int, optional
        Samples to fit on (the others are held out).
    read_on : FlightSeries, optional
        The flight the model will predict (REAL): an input it takes outside SIM's range has no square.

    Returns
    -------
    BaselineModel
    """
    lags = np.arange(int(round(_LAG_S * series.rate_hz)) + 1)
    states = tuple(_AIR[s][0] if series.windy and s in _AIR else s for s in _STATES if s in series)
    use = slice(None) if rows is None else rows
    squared = tuple(
        c
        for c in COMMANDS
        if _curvature_share(series[c][use]) >= _MIN_CURVATURE_SHARE
        and (read_on is None or _outside_share(read_on[c], series[c][use]) <= _MAX_OUTSIDE_SHARE)
    )
    design = _design(series, lags, states, squared)[use]  # taken once, not per output
    # one factorisation of the design for every output (a least-squares fit per output took six)
    solved = np.linalg.lstsq(design, np.column_stack([series[o][use] for o in OUTPUTS]), rcond=None)[0]
    coefficients = {o: solved[:, j] for j, o in enumerate(OUTPUTS)}
    return BaselineModel(coefficients=coefficients, lags=lags, states=states, rate_hz=series.rate_hz, squared=squared)


def _curvature_share(x: np.ndarray) -> float:
    """Spread of ``(x - mean)²`` over that of ``x²``: the part of the square a constant and `x` leave (0..1).

    Examples
    --------
    >>> round(_curvature_share(np.array([-1.0, 0.0, 1.0])), 3)  # about zero: the square is all curvature
    1.0
    >>> _curvature_share(np.array([0.448, 0.45, 0.452])) < 0.01  # a narrow range far from zero
    True
    """
    spread = float(np.std(x**2))
    return float(np.std((x - x.mean()) ** 2)) / spread if spread > 0 else 0.0


def _outside_share(x: np.ndarray, fitted: np.ndarray) -> float:
    """The share of `x`'s samples outside the range of `fitted` (0..1).

    Examples
    --------
    >>> _outside_share(np.array([0.49, 0.50, 0.51, 0.45]), np.array([0.44, 0.46]))
    0.75
    """
    return float(np.mean((x < np.min(fitted)) | (x > np.max(fitted))))


def _design(series: FlightSeries, lags: np.ndarray, states: tuple[str, ...], squared: tuple[str, ...]) -> np.ndarray:
    """The regressors of the fit, shape (n, n_regressors), in the order :meth:`BaselineModel.predict` reads them."""
    spans = series.spans()
    columns = [_lagged(spans, series[c], lags) for c in COMMANDS]
    columns += [_lagged(spans, series[c] ** 2, _square_lags(lags)) for c in squared]
    columns.append(np.column_stack([_state(series, s) for s in states] + [np.ones(series.n)]))
    return np.column_stack(columns)


def design_width(lags: np.ndarray, states: tuple[str, ...], squared: tuple[str, ...]) -> int:
    """How many regressors the model has per output: each input at `lags`, the `squared` ones' squares, states, 1.

    Parameters
    ----------
    lags : ndarray of int, shape (n_lags,)
        Input lags, samples.
    states, squared : tuple of str
        As :class:`BaselineModel`.
    """
    return len(COMMANDS) * lags.size + len(squared) * _square_lags(lags).size + len(states) + 1


def _state(series: FlightSeries, name: str) -> np.ndarray:
    """A state regressor's values, shape (n,): a logged signal, or ``u_air``, ``v_air`` (ground velocity less wind), m/s."""
    for ground, (air, wind) in _AIR.items():
        if name == air:
            difference: np.ndarray = np.asarray(series[ground]) - np.asarray(series[wind])
            return difference
    return np.asarray(series[name])


def _square_lags(lags: np.ndarray) -> np.ndarray:
    return lags[:: max(1, lags.size // _N_SQUARE_LAGS)]


def _lagged(spans: list[slice], x: np.ndarray, lags: np.ndarray) -> np.ndarray:
    """Columns x(t - lag) per lag, each piece (`spans`, :meth:`FlightSeries.spans`) padded with its first value.

    No lag reaches across a gap.
    """
    out = np.empty((x.size, lags.size))
    longest = int(lags[-1])
    step = int(lags[1] - lags[0]) if lags.size > 1 else 1
    even = step > 0 and np.array_equal(lags, np.arange(0, longest + 1, step))  # 0, s, 2 s ... L: a strided view
    for rows in spans:
        piece = x[rows]
        padded = np.concatenate([np.full(longest, piece[0]), piece])
        if even:  # row t: x(t), x(t - s) .. x(t - L): a view walking back from each sample (a third cheaper to make
            # than numpy's checked sliding_window_view, 8 000 times a search)
            stride = padded.strides[0]
            out[rows] = as_strided(
                padded[longest:], shape=(piece.size, lags.size), strides=(stride, -step * stride), writeable=False
            )
            continue
        for j, lag in enumerate(lags.tolist()):  # a column at a time: slices, no gather of a (n, n_lags) window
            out[rows, j] = padded[longest - lag : longest - lag + piece.size]
    return out

"""Doublets fitted jointly with the closed loop's feedback, behind :func:`flightlogs.maneuvers.excitation_recovery.estimate_excitation`.

A short record (a doublet with a few seconds of hover either side) holds too
little quiet data to fit the controller's feedback on its own, and the
feedback left in the mixer input rings and hides the doublet. Around a burst
of activity the mixer input is instead modelled as

    u = K x + K_I ∫x + B s + a1 b1 + a2 b2 + ε,

the feedback states `x` and their running integrals (the PID integrators),
cubic B-splines ``B s`` with knots every ``_KNOT_S`` (slow outer loops:
position, velocity integrators, trim drift) and two adjacent boxes ``b1 b2``
of equal width, the doublet's pulses. The doublet's sharp edges are what
neither the smooth nuisance nor the states (integrals of the input) can
imitate. Start and width are scanned; for each candidate the least-squares
gain comes from running sums of the nuisance-projected residual and basis,
so the whole scan costs a few operations per candidate.

A 3-2-1-1 (four adjacent pulses of 3, 2, 1 and 1 units, signs alternating)
is fitted the same way, its template scanned in start and unit with one
amplitude, then each pulse given its own. Its long pulses and the steps
between them make some pair of adjacent pulses look like a doublet to the
scan (and to the half-wave classifier, once a poor feedback fit has bent
the pulses); where the 3-2-1-1 passes the doublet's rules with all four
pulses and explains the burst clearly better, it is returned instead.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import cast

import numpy as np

from flightlogs.maneuvers._rank import median

__all__: list[str] = []

_KNOT_S = 1.0  # nuisance B-spline knot spacing, s: slower than any doublet edge, faster than the outer loops
_MIN_PULSE_S, _MAX_PULSE_S = 0.1, 5.0  # pulse widths scanned, s
_COARSE_S = 0.05  # scan step before refining to single samples, s
_GRID_ELEMENTS = 1 << 20  # the (width, start, basis) arrays of one block of the scan stay under this many numbers
_REACH_S = 1.0  # a doublet may start this long before its burst and end this long after it, s
#: Each pulse must stand out of the residual noise by this many standard errors. Measured with the
#: rules off on 8 s windows of simulated chapter 3 logs (nonlinear octocopter, calm and strong wind):
#: hover reaches z = 5.0, 3-2-1-1s 6.7, multisines 9.3 and sweeps 22 (which the next rule rejects);
#: doublets of 5-15 % score 84 or more.
_Z_MIN = 10.0
#: The doublet must explain the burst: at most this share of the burst's energy, once the feedback is
#: removed, may remain. Measured as above: doublets leave at most 1 %; hover, 3-2-1-1s and multisines
#: 20 % or more, sweeps 17 % or more where their best pair of pulses is doublet-shaped with z >= 10.
_UNEXPLAINED_MAX = 0.05
_LEAD_S = 1.0  # the window holds at least this much before and after the doublet (no other maneuver there), s
_PULSE_RATIO_MAX = 3.0  # the pulses' amplitudes agree within this ratio (as the half-wave classifier)
_DOUBLET, _3211 = (1, 1), (3, 2, 1, 1)  # pulse widths in units of the scanned width
_UNITS = {"doublet": _DOUBLET, "3211": _3211}
_SIGNS = (1.0, -1.0, 1.0, -1.0)  # a 3-2-1-1's pulses, up to one common sign
#: A 3-2-1-1 that passes the rules above (all four pulses) replaces the best doublet when it leaves at
#: most this share of the energy the doublet leaves unexplained. Measured: on the closed-loop 3-2-1-1s
#: of the nonlinear octocopter (1 s unit, 10-15 %) the 3-2-1-1 leaves 0.01-3.6 % and the best doublet
#: 3.8-22 %, a ratio of 0.25 or less; on the 215 accepted doublet windows of the linear demo, the
#: chapter 3 campaign and the excitation tests no 3-2-1-1 passes the rules and the best one leaves
#: 0.97 times the doublet's share or more (on all 60 campaign doublets, 1400 times or more).
_BETTER_3211 = 0.5


@dataclass(frozen=True, slots=True, kw_only=True)
class DoubletFit:
    """One doublet or 3-2-1-1 found in a window (indices into the window).

    Parameters
    ----------
    first : int
        First sample of the first pulse.
    width : int
        Samples per pulse (a doublet), or per unit pulse (a 3-2-1-1: its
        pulses last 3, 2, 1 and 1 units).
    amplitudes : tuple of float
        Heights of the pulses, as logged (two, or four).
    z : tuple of float
        Their sizes in standard errors.
    unexplained : float
        Share of the burst's energy, feedback removed, the fit leaves.
    excitation : ndarray, shape (n_window,)
        The window's mixer input minus the fitted feedback and nuisance.
    """

    first: int
    width: int
    amplitudes: tuple[float, ...]
    z: tuple[float, ...]
    unexplained: float
    excitation: np.ndarray

    @property
    def kind(self) -> str:
        """``"doublet"`` or ``"3211"``."""
        return "doublet" if len(self.amplitudes) == 2 else "3211"


def fit_doublet(u: np.ndarray, states: np.ndarray, dt: float, burst: tuple[int, int]) -> DoubletFit | None:
    """The doublet or 3-2-1-1 that, with the feedback, explains the burst in a window, or None.

    A 3-2-1-1 is returned when it passes the doublet's rules with all four
    pulses and leaves at most `_BETTER_3211` of the energy the best doublet
    leaves; otherwise the doublet if it passes them.

    Parameters
    ----------
    u : ndarray, shape (n_window,)
        Finite mixer input of one axis.
    states : ndarray, shape (n_window, n_states)
        Finite feedback states of that axis (angles unwrapped).
    dt : float
        Sample interval, s.
    burst : tuple of int
        First and last sample of the activity in the window.
    """
    basis = _orthonormal(_nuisance(states, u.size, dt))
    resid = u - basis @ (basis.T @ u)
    doublet = _candidate(u, resid, basis, dt, burst, _DOUBLET)
    multistep = _candidate(u, resid, basis, dt, burst, _3211)
    if (
        multistep is not None
        and _accepted(multistep, u.size, dt)
        and (doublet is None or multistep.unexplained <= _BETTER_3211 * doublet.unexplained)
    ):
        return multistep
    return doublet if doublet is not None and _accepted(doublet, u.size, dt) else None


def _candidate(
    u: np.ndarray, resid: np.ndarray, basis: np.ndarray, dt: float, burst: tuple[int, int], units: tuple[int, ...]
) -> DoubletFit | None:
    """The best fit of adjacent pulses lasting `units` × a scanned width, whether or not it passes the rules."""
    best = _scan(resid, basis, dt, burst, units)
    if best is None:
        return None
    first, width = best
    edges = first + width * np.cumsum((0, *units))
    pulses = np.zeros((u.size, len(units)))
    for k in range(len(units)):
        pulses[edges[k] : edges[k + 1], k] = 1.0
    projected = pulses - basis @ (basis.T @ pulses)  # M b: the pulses with the nuisance removed
    gram = projected.T @ projected
    try:
        inverse = np.linalg.inv(gram)
    except np.linalg.LinAlgError:  # the pulses lie in the nuisance's span: nothing to tell apart
        return None
    amplitudes = inverse @ (projected.T @ resid)
    left = resid - projected @ amplitudes
    sigma = max(1.4826 * median(np.abs(left - median(left))), 1e-12 * float(np.max(np.abs(u)) + 1.0))
    z = np.abs(amplitudes) / (sigma * np.sqrt(np.diag(inverse)))
    excitation = pulses @ amplitudes + left
    lo, hi = min(burst[0], first), max(burst[1], int(edges[-1]) - 1)
    unexplained = float(np.sum(left[lo : hi + 1] ** 2) / max(np.sum(excitation[lo : hi + 1] ** 2), 1e-300))
    return DoubletFit(
        first=first,
        width=width,
        amplitudes=tuple(float(a) for a in amplitudes),
        z=tuple(float(v) for v in z),
        unexplained=unexplained,
        excitation=excitation,
    )


def _accepted(fit: DoubletFit, n: int, dt: float) -> bool:
    """Signs alternate, sizes within `_PULSE_RATIO_MAX`, each z >= `_Z_MIN`, the fit explains, 1 s either side."""
    a = np.abs(fit.amplitudes)
    alternating = all(x * y < 0 for x, y in zip(fit.amplitudes, fit.amplitudes[1:]))
    shaped = alternating and a.max() <= _PULSE_RATIO_MAX * a.min()
    lead = int(round(_LEAD_S / dt))
    framed = fit.first >= lead and n - fit.first - sum(_UNITS[fit.kind]) * fit.width >= lead
    return bool(shaped and framed and min(fit.z) >= _Z_MIN and fit.unexplained <= _UNEXPLAINED_MAX)


def _nuisance(states: np.ndarray, n: int, dt: float) -> np.ndarray:
    """States, their running integrals (centred) and cubic B-splines with knots every `_KNOT_S`."""
    t = np.arange(n) * dt
    intervals = max(1, int(np.ceil(t[-1] / _KNOT_S)))
    inner = np.linspace(0.0, t[-1], intervals + 1)
    knots = np.r_[[0.0] * 3, inner, [t[-1]] * 3]
    splines = _cubic_bsplines(t, knots)
    integrals = np.cumsum(states, axis=0) * dt
    columns = np.column_stack([states - states.mean(axis=0), integrals - integrals.mean(axis=0), splines])
    return columns


def _cubic_bsplines(t: np.ndarray, knots: np.ndarray) -> np.ndarray:
    """Cubic B-splines on `knots` (clamped, shape (n_knots,)) at `t` (n,): shape (n, n_knots - 4).

    ``scipy.interpolate.BSpline.design_matrix(t, knots, 3).toarray()`` by de Boor's recurrence for the
    four splines alive in each interval (SciPy's import costs more than a log's reading).
    """
    span = np.clip(np.searchsorted(knots, t, side="right") - 1, 3, knots.size - 5)
    values = np.zeros((t.size, 4))
    values[:, 0] = 1.0
    left, right = np.zeros((t.size, 4)), np.zeros((t.size, 4))
    for j in range(1, 4):
        left[:, j] = t - knots[span + 1 - j]
        right[:, j] = knots[span + j] - t
        saved = np.zeros(t.size)
        for r in range(j):
            share = values[:, r] / (right[:, r + 1] + left[:, j - r])
            values[:, r] = saved + right[:, r + 1] * share
            saved = left[:, j - r] * share
        values[:, j] = saved
    design = np.zeros((t.size, knots.size - 4))
    np.put_along_axis(design, span[:, None] - 3 + np.arange(4), values, axis=1)
    return design


def _orthonormal(columns: np.ndarray) -> np.ndarray:
    """Orthonormal basis of the column space (singular directions dropped)."""
    scale = np.linalg.norm(columns, axis=0)
    columns = columns[:, scale > 0] / scale[scale > 0]
    power, vectors = np.linalg.eigh(columns.T @ columns)  # the Gram matrix: fast for n >> k
    keep = power > 1e-10 * power[-1]
    return cast(np.ndarray, columns @ (vectors[:, keep] / np.sqrt(power[keep])))


#: A coarse scan's lattice of samples up to this many: its Gram matrix (rows^2 numbers) replaces the gathered rows.
_GRAM_ROWS = 1500


@dataclass(frozen=True, slots=True)
class _Gram:
    """Inner products of the running sums' rows at the samples of a coarse scan: ``gram(a, b)[...] = S[a] . S[b]``.

    The rows are taken less the scan's earliest, which leaves every difference
    of two rows (a box's projection) as it is and keeps the products small.
    """

    products: np.ndarray  # (n_rows, n_rows)
    position: np.ndarray  # (latest + 1,): row of each sample in `products`, -1 where not on the lattice

    def __call__(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return cast(np.ndarray, self.products[self.position[a], self.position[b]])


def _gram(sums: np.ndarray, widths: range, earliest: int, latest: int, offsets: np.ndarray) -> _Gram | None:
    """The Gram matrix of the rows a scan of `widths` from earliest, earliest + step, ... reaches; None if too large.

    Pulse edge ``c`` (`offsets`, in widths) of a box from ``earliest + step i``
    of width ``widths.start + step j`` lies at ``earliest + c widths.start +
    step (i + c j)``: one lattice per edge (one in all when the step divides
    the narrowest width).
    """
    step = widths.step
    rows = np.unique(np.concatenate([np.arange(earliest + int(c) * widths.start, latest + 1, step) for c in offsets]))
    if rows.size > _GRAM_ROWS:
        return None
    centred = sums[rows] - sums[earliest]
    position = np.full(latest + 1, -1, dtype=np.intp)
    position[rows] = np.arange(rows.size)
    return _Gram(products=centred @ centred.T, position=position)


def _scan(
    resid: np.ndarray, basis: np.ndarray, dt: float, burst: tuple[int, int], units: tuple[int, ...]
) -> tuple[int, int] | None:
    """(first, width) of the adjacent boxes lasting `units` × width that remove the most residual energy.

    Scanned on a coarse grid of starts and widths, then refined sample by
    sample around the best. The boxes' projections on the nuisance basis and
    their inner products with the residual are differences of running sums.
    A doublet's two boxes get a gain each; a 3-2-1-1's four are scanned as
    one template of alternating signs (its amplitudes are freed afterwards).
    """
    n, span = resid.size, sum(units)
    sums = np.vstack([np.zeros(basis.shape[1]), np.cumsum(basis, axis=0)])
    run = np.r_[0.0, np.cumsum(resid)]
    reach = int(round(_REACH_S / dt))
    earliest, latest = max(0, burst[0] - reach), min(n, burst[1] + reach + 1)  # latest: one past the last sample
    w_min = max(2, int(round(_MIN_PULSE_S / dt)))
    w_max = min(int(round(_MAX_PULSE_S / dt)) // max(units), (latest - earliest) // span)
    if w_max < w_min:
        return None
    grid = _best_on_grid if units == _DOUBLET else _best_template_on_grid
    step = max(1, int(round(_COARSE_S / dt)))
    coarse = range(w_min, w_max + 1, step)
    lattice = _gram(sums, coarse, earliest, latest, np.cumsum((0, *units)))
    best = grid(sums if lattice is None else lattice, run, coarse, earliest, latest, step)
    if best is None:
        return None
    first, width = best[1], best[2]
    widths = range(max(w_min, width - step), min(w_max, width + step) + 1)
    fine = grid(sums, run, widths, max(earliest, first - step), min(latest, first + span * (width + step) + step), 1)
    return (fine[1], fine[2]) if fine is not None else (first, width)


def _best_on_grid(
    sums: np.ndarray | _Gram, run: np.ndarray, widths: range, earliest: int, latest: int, step: int
) -> tuple[float, int, int] | None:
    """(gain, first, width) of the best doublet starting at earliest, earliest + step, ... and ending by `latest`.

    A block of widths at a time, every start at once (the starts past the end masked).
    """
    return _best_by_blocks(_doublet_block, sums, run, widths, earliest, latest, step)


def _best_template_on_grid(
    sums: np.ndarray | _Gram, run: np.ndarray, widths: range, earliest: int, latest: int, step: int
) -> tuple[float, int, int] | None:
    """(gain, first, width) of the best 3-2-1-1 (one amplitude, signs + - + -) on the grid, as :func:`_best_on_grid`."""
    return _best_by_blocks(_template_block, sums, run, widths, earliest, latest, step)


def _best_by_blocks(
    block: Callable[[np.ndarray | _Gram, np.ndarray, range, int, int, int], tuple[float, int, int] | None],
    sums: np.ndarray | _Gram,
    run: np.ndarray,
    widths: range,
    earliest: int,
    latest: int,
    step: int,
) -> tuple[float, int, int] | None:
    """The best of `block` over `widths` taken a few at a time (the grid's arrays stay under `_GRID_ELEMENTS`)."""
    starts = max(1, (latest - earliest) // step + 1)
    depth = 1 if isinstance(sums, _Gram) else sums.shape[1]  # a lookup per start and width, or a row of the basis
    per_block = max(1, _GRID_ELEMENTS // (starts * max(1, depth)))
    best: tuple[float, int, int] | None = None
    for lo in range(0, len(widths), per_block):
        found = block(sums, run, widths[lo : lo + per_block], earliest, latest, step)
        if found is not None and (best is None or found[0] > best[0]):  # equal gains: the narrower width
            best = found
    return best


def _doublet_block(
    sums: np.ndarray | _Gram, run: np.ndarray, widths: range, earliest: int, latest: int, step: int
) -> tuple[float, int, int] | None:
    grid = _grid(widths, earliest, latest, step, 2)
    if grid is None:
        return None
    width, first, ok = grid
    mid, end = first + width, first + 2 * width
    if isinstance(sums, _Gram):  # q1 = S[mid] - S[first], q2 = S[end] - S[mid], their products looked up
        ff, mm, ee = sums(first, first), sums(mid, mid), sums(end, end)
        fm, fe, me = sums(first, mid), sums(first, end), sums(mid, end)
        p11, p22, p12 = mm - 2 * fm + ff, ee - 2 * me + mm, me - mm - fe + fm
    else:
        q1, q2 = sums[mid] - sums[first], sums[end] - sums[mid]  # (n_widths, n_starts, n_basis)
        p11 = np.einsum("wij,wij->wi", q1, q1)
        p22 = np.einsum("wij,wij->wi", q2, q2)
        p12 = np.einsum("wij,wij->wi", q1, q2)
    v1, v2 = run[mid] - run[first], run[end] - run[mid]
    g11, g22, g12 = width - p11, width - p22, -p12
    det = g11 * g22 - g12 * g12
    ok &= det > 1e-9 * width * width
    gain = np.where(ok, (g22 * v1 * v1 - 2 * g12 * v1 * v2 + g11 * v2 * v2) / np.where(ok, det, 1.0), -np.inf)
    return _best_of(gain, width, first)


def _template_block(
    sums: np.ndarray | _Gram, run: np.ndarray, widths: range, earliest: int, latest: int, step: int
) -> tuple[float, int, int] | None:
    offsets = np.cumsum((0, *_3211))
    grid = _grid(widths, earliest, latest, step, int(offsets[-1]))
    if grid is None:
        return None
    width, first, ok = grid
    edges = [first + width * int(o) for o in offsets]
    if isinstance(sums, _Gram):  # q = sum_k c_k S[edge k]: |q|^2 from the products of the edges' rows
        c = np.diff(np.r_[0.0, _SIGNS, 0.0]) * -1.0  # -1, 2, -2, 2, -1
        pp = sum(
            (1.0 if k == m else 2.0) * c[k] * c[m] * sums(edges[k], edges[m])
            for k in range(len(edges))
            for m in range(k, len(edges))
        )
    else:
        q = sum(sign * (sums[edges[k + 1]] - sums[edges[k]]) for k, sign in enumerate(_SIGNS))
        pp = np.einsum("wij,wij->wi", q, q)
    v = sum(sign * (run[edges[k + 1]] - run[edges[k]]) for k, sign in enumerate(_SIGNS))
    g = offsets[-1] * width - pp
    ok &= g > 1e-9 * width
    gain = np.where(ok, v * v / np.where(ok, g, 1.0), -np.inf)
    return _best_of(gain, width, first)


def _grid(
    widths: range, earliest: int, latest: int, step: int, span: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Widths (n_widths, 1), starts (n_widths, n_starts) and which fit (`span` widths ending by `latest`)."""
    width = np.asarray(widths)
    width = width[earliest <= latest - span * width][:, None]  # the widths that fit at the earliest start
    if width.size == 0:
        return None
    starts = np.arange(earliest, latest - span * int(width[0, 0]) + 1, step)
    ok = starts[None, :] <= latest - span * width
    first = np.where(ok, starts[None, :], earliest)  # a start past the end reads the earliest; its gain is masked
    return width, first, ok


def _best_of(gain: np.ndarray, width: np.ndarray, first: np.ndarray) -> tuple[float, int, int] | None:
    """The grid's best (gain, first, width): the first in width, then start, order among equals."""
    w, i = np.unravel_index(int(np.argmax(gain)), gain.shape)
    best = float(gain[w, i])
    return (best, int(first[w, i]), int(width[w, 0])) if np.isfinite(best) else None

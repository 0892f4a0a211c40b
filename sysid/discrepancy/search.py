"""Discrepancy discovery: where a real flight departs from its simulation, which physics explains it, by how much.

1. **Baseline and noise floor.** The simulation's model (:mod:`.baseline`) is
   fitted on half of SIM's time blocks and its residual on the other half is
   each output's noise floor: what noise and model error alone leave. Every
   candidate term is also scored on that held-out SIM residual: its *null*
   score, what it gains on data where nothing is missing.
2. **Screen and select.** The model fitted on all of SIM predicts REAL. Each
   term of the library (:mod:`.terms`) is fitted on five of six time blocks
   of REAL and scored on the sixth, in turn (:mod:`.selection`). A term
   passes if its held-out score beats three times its null score and a
   floor (the first term: 1 % of the whole flight's residual and 5 % where
   it acts, so that an effect of 20 s near the ground is judged there; a
   later one: 5 % of the whole), and if 80 % of what it changes lies in at least 2 s of flight or in
   episodes 10 s apart (near the ground at take-off and at landing)
   (a touchdown's spike is no physics); of those that pass, the one that lowers the Bayesian information
   criterion most (effective samples, the parameter inside its shape
   counted) is kept; its contribution joins the model and the others are
   screened again (forward selection), until none passes. A delay and a lag compete:
   once one is kept the other is not tried.
3. **Model, locate and show.** Each kept term is fitted on all of REAL with
   its uncertainties; its band is where its contribution's power lies, its
   regime the flight variable its contribution follows; the residual RMS
   before and after is on held-out blocks.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np
from scipy.signal import welch

from sysid.discrepancy.baseline import BaselineModel, fit_baseline
from sysid.discrepancy.describe import describe_finding, parameters_of, summary_of
from sysid.discrepancy.result import DiscrepancyResult, Finding, FindingTraces, Regime
from sysid.discrepancy.selection import (
    TermFit,
    blocks,
    combined,
    cross_validated,
    effective_samples,
    fit_term,
    joined,
    split_joined,
)
from sysid.discrepancy.series import OUTPUTS, FlightSeries
from sysid.discrepancy.terms import Candidate, candidate_terms

__all__ = ["DiscrepancyOptions", "discover"]

_TRANSFORMS = ("time_delay", "actuator_lag")
_REGIMES = (
    ("height_agl", "m"),
    ("ground_speed", "m/s"),
    ("wind_speed", "m/s"),
    ("delta_thr", "as logged"),
    ("battery_v", "V"),
    ("t_flight", "s"),
)

_NULL_BLOCK_S = 4.0  # the simulated flight's alternate blocks for its noise floor: each half sees every manoeuvre
_SUPPORT_SHARE = 0.8  # a term's support: the samples that hold this share of its contribution ...
_MIN_SUPPORT_S = 2.0  # ... must span this much flight (a touchdown's spike: 0.3 s; a 15 m reposition's drag: 5 s),
_EPISODE_S = 0.25  # ... or recur: episodes of at least this long ...
_APART_S = 10.0  # ... this far apart (a ground effect at take-off and at landing, 1.1-1.9 s in all)

Progress = Callable[[str, int, int], None]


@dataclass(frozen=True, slots=True, kw_only=True)
class DiscrepancyOptions:
    """Choices of the search.

    Parameters
    ----------
    min_improvement : float
        Held-out share of the weighted residual a term must remove where it acts (the samples holding 80 % of
        its contribution) to be kept, whatever its null score.
    min_share : float
        Held-out share of the whole flight's weighted residual the first term must remove, whatever its null
        score (a later one: `min_improvement` of it) ...
    null_margin : float
        ... and this many times its score on held-out simulation data.
    max_findings : int
        Most effects reported.
    rotor_radius_m : float or None
        Propeller radius, m, if known: the ground effect's end is also given as Z/R.
    """

    min_improvement: float = 0.05
    min_share: float = 0.01
    null_margin: float = 3.0
    max_findings: int = 3
    rotor_radius_m: float | None = None


def discover(
    sim: Sequence[FlightSeries],
    real: Sequence[FlightSeries],
    options: DiscrepancyOptions = DiscrepancyOptions(),
    progress: Progress | None = None,
) -> DiscrepancyResult:
    """Find, model and prove what REAL does that SIM leaves out.

    Parameters
    ----------
    sim, real : sequence of FlightSeries
        The simulated and the real flights (of the same vehicle, similar missions).
    options : DiscrepancyOptions, optional
        Thresholds.
    progress : callable, optional
        ``progress(stage, done, total)``.

    Returns
    -------
    DiscrepancyResult
    """
    simulated, flown = _joined(sim), _joined(real)
    simulated = simulated.without([s for s in simulated.signals if s not in flown])  # a model of what both logged
    scale, null = _noise_floor(simulated)
    _report(progress, "simulation model", 1, 3)
    baseline = fit_baseline(simulated)
    y = {o: flown[o] for o in OUTPUTS}
    base = baseline.predict(flown)
    additions = {o: np.zeros(flown.n) for o in OUTPUTS}
    thrust = -base["az"]
    gain = float(np.dot(thrust, base["az"] - y["az"]) / max(float(np.dot(thrust, thrust)), 1e-300))
    additions["az"] = -gain * thrust  # the real thrust per input may differ by a constant factor: a trim
    trim = additions["az"]
    kept: list[tuple[TermFit, float, dict[str, np.ndarray], dict[str, np.ndarray]]] = []
    screened: dict[str, float] = {}
    held_out = combined(base, additions)  # the baseline is fitted on SIM: on REAL its prediction is held out already
    while len(kept) < options.max_findings:
        found = {t.candidate.effect for t, *_ in kept}
        exclude = tuple(found | (set(_TRANSFORMS) if found & set(_TRANSFORMS) else set()))
        scores = []
        linear = [fit for fit, *_ in kept if fit.candidate.kind == "linear"]
        without = _without(additions, linear)  # the kept linear terms refit with each linear newcomer
        current = combined(base, additions)
        # every term reads one thrust, the model's with the trim: two terms' thrust gains are then one column, whose
        # sum is measured, and not two near copies whose difference (the first term's contribution) a fit would use
        trimmed = {**current, "az": base["az"] + trim}
        for candidate in candidate_terms(flown, baseline, trimmed, exclude=exclude):
            together = candidate.kind == "linear" and bool(linear)
            trial, adds = (joined(candidate, linear), without) if together else (candidate, additions)
            reference = held_out if together else None  # judged against the kept terms' held-out prediction
            score, predicted = cross_validated(trial, y, base, adds, scale, reference, candidate.outputs)
            # once a term is kept, the residual where it acts holds its shape's error, which another term acting
            # there fits as well (a mass step at the low hover beside a ground effect): later terms must also
            # remove a share of the whole flight's residual
            least = options.min_improvement if kept else options.min_share
            threshold = max(least, options.null_margin * max(null.get(candidate.effect, 0.0), 0.0))
            against = reference if reference is not None else current
            local = _local_score(y, predicted, against, scale, candidate.outputs)
            if not kept:
                screened[candidate.effect] = round(score, 4)
                screened[f"{candidate.effect}_threshold"] = round(threshold, 4)
                screened[f"{candidate.effect}_where_it_acts"] = round(local, 4)
            if score > threshold and local > options.min_improvement:
                fit = fit_term(trial, y, base, adds, scale)
                if candidate.kind == "transform" and fit.value >= candidate.grid[-1]:
                    continue  # at the end of the range searched: a bound, not a measured delay or lag
                prediction = fit.prediction(base, adds)
                if not _sustained(_support(prediction, current, scale), flown["t_flight"]):
                    continue  # a moment of flight (a touchdown, a spike) is no physical effect
                change = _bic_change(fit, y, prediction, current, len(candidate.coefficients))
                scores.append((change, score, fit, predicted, candidate, adds))
        _report(progress, "screening terms", len(kept) + 1, options.max_findings + 1)
        if not scores:
            break
        _, score, fit, predicted, candidate, adds = min(scores, key=lambda s: s[0])
        before = dict(held_out)
        for o in fit.candidate.outputs:
            held_out[o] = predicted[o]
        if candidate.kind == "transform":
            base = dict(candidate.build(fit.value))
            kept.append((fit, score, before, dict(held_out)))
            continue
        own, *refit = split_joined(fit, candidate, linear) if fit.candidate is not candidate else [fit]
        kept = [(refit.pop(0) if k.candidate.kind == "linear" and refit else k, sc, b, a) for k, sc, b, a in kept]
        kept.append((own, score, before, dict(held_out)))
        additions = dict(adds)
        built = fit.candidate.build(fit.value)
        for o, coefficients in fit.coefficients.items():
            additions[o] = additions[o] + built[o] @ coefficients
    gains = {id(fit): _thrust_gain(fit) for fit, *_ in kept}
    findings = sorted(
        (  # each term's thrust level: the trim and the other terms' gains (collinear: only their sum is known)
            _finding(
                fit,
                score,
                before,
                after,
                y,
                flown,
                scale,
                1.0 + gain + sum(gains.values()) - gains[id(fit)],
                options.rotor_radius_m,
            )
            for fit, score, before, after in kept
        ),
        key=lambda f: -f.improvement_percent,
    )
    _report(progress, "done", 3, 3)
    floor = {o: float(np.sqrt(scale[o])) for o in OUTPUTS}
    unexplained = {o: round(float(np.sqrt(np.mean((y[o] - held_out[o]) ** 2))) / floor[o], 2) for o in OUTPUTS}
    return DiscrepancyResult(
        verdict=findings[0].effect if findings else "none",
        findings=tuple(findings),
        summary=summary_of(findings, floor, unexplained),
        unexplained=unexplained,
        screened=screened,
        noise_floor=floor,
        sim=tuple(s.name for s in sim),
        real=tuple(s.name for s in real),
        thrust_scale=round(1.0 + gain, 5),
    )


def _thrust_gain(fit: TermFit) -> float:
    """The change of thrust per input a term fitted beside its shape (its ``gain`` on az), 0 if it has none."""
    if "gain" not in fit.candidate.coefficients or "az" not in fit.coefficients:
        return 0.0
    return float(fit.coefficients["az"][fit.candidate.coefficients.index("gain")])


def _without(additions: Mapping[str, np.ndarray], linear: Sequence[TermFit]) -> dict[str, np.ndarray]:
    """`additions` less the contributions of the kept `linear` terms (the thrust trim stays)."""
    out = {o: np.array(v, dtype=float) for o, v in additions.items()}
    for fit in linear:
        built = fit.candidate.build(fit.value)
        for o, coefficients in fit.coefficients.items():
            out[o] = out[o] - built[o] @ coefficients
    return out


def _report(progress: Progress | None, stage: str, done: int, total: int) -> None:
    if progress is not None:
        progress(stage, done, total)


def _bic_change(
    fit: TermFit,
    y: Mapping[str, np.ndarray],
    with_term: Mapping[str, np.ndarray],
    current: Mapping[str, np.ndarray],
    n_coefficients: int,
) -> float:
    """Change of the Bayesian information criterion on all of REAL when the term joins the model.

    Each output's likelihood counts its effective samples (its residual is correlated), and the term's
    parameters are its `n_coefficients` (a transform: none) plus the value inside its shape.
    """
    change, samples = 0.0, 0.0
    for o in fit.candidate.outputs:
        before, after = y[o] - current[o], y[o] - with_term[o]
        n_effective = effective_samples(before)
        change += n_effective * float(np.log(max(np.sum(after**2), 1e-300) / max(np.sum(before**2), 1e-300)))
        samples += n_effective
    k = n_coefficients + (1 if fit.candidate.grid_parameter else 0)
    return change + k * float(np.log(max(samples, 2.0)))


def _support(
    prediction: Mapping[str, np.ndarray], current: Mapping[str, np.ndarray], scale: Mapping[str, float]
) -> np.ndarray:
    """The samples holding 80 % of a term's weighted contribution (its change to the prediction), indices."""
    energy = sum(((prediction[o] - current[o]) ** 2 / scale[o] for o in OUTPUTS), np.zeros(len(current[OUTPUTS[0]])))
    order = np.argsort(energy)[::-1]
    total = float(energy.sum())
    if total <= 0.0:
        return order[:0]
    return order[: int(np.searchsorted(np.cumsum(energy[order]), _SUPPORT_SHARE * total)) + 1]


def _sustained(rows: np.ndarray, clock: np.ndarray) -> bool:
    """Whether a term's support (sample indices) spans 2 s of flight, or recurs in episodes 10 s apart.

    A spike at one touchdown is an event; an effect that comes back whenever its regime does (near
    the ground at take-off and at landing) is physics, however short each visit.
    """
    if rows.size == 0:
        return False
    times = np.sort(clock[rows])
    step = float(np.median(np.diff(clock))) if clock.size > 1 else 0.0
    if times.size * step >= _MIN_SUPPORT_S:
        return True
    breaks = np.flatnonzero(np.diff(times) > 1.0) + 1  # episodes: support samples less than 1 s apart
    episodes = [(e[0], e[-1]) for e in np.split(times, breaks) if e[-1] - e[0] + step >= _EPISODE_S]
    return len(episodes) > 1 and episodes[-1][0] - episodes[0][1] >= _APART_S


def _local_score(
    y: Mapping[str, np.ndarray],
    predicted: Mapping[str, np.ndarray],
    current: Mapping[str, np.ndarray],
    scale: Mapping[str, float],
    outputs: Sequence[str],
) -> float:
    """The held-out share of the weighted residual a term removes where it acts (its support, from `predicted`).

    The share of the whole flight's residual says how much of the flight a term explains; an effect that
    acts on a part of it (20 s near the ground in 4 minutes) removes little of the whole however sure it
    is. Its floor is judged where it acts; what it gains over noise, on the whole flight against the null.
    """
    rows = _support({o: predicted.get(o, current[o]) for o in OUTPUTS}, current, scale)
    if rows.size == 0:
        return 0.0
    before = sum(float(np.sum((y[o][rows] - current[o][rows]) ** 2)) / scale[o] for o in outputs)
    after = sum(float(np.sum((y[o][rows] - predicted[o][rows]) ** 2)) / scale[o] for o in outputs)
    return 1.0 - after / before if before > 0 else 0.0


def _noise_floor(sim: FlightSeries) -> tuple[dict[str, float], dict[str, float]]:
    """Each output's held-out residual variance on SIM, and every term's held-out score there (its null score).

    Two folds of alternate 4 s blocks: the model fitted on one half is judged on the other, and the other
    way round; both figures are the means of the two. With long blocks (25 s) the figures depended on
    where the flight's manoeuvres fell: a reposition held out from the fit made the model extrapolate
    along it, and a drag term gained on noise (0.077 on one split, 0.28 on another flight's).
    """
    parts = blocks(sim.n, max(8, int(sim.n / (_NULL_BLOCK_S * sim.rate_hz))))
    halves = (np.concatenate(parts[1::2]), np.concatenate(parts[0::2]))
    scales, nulls = [], []
    for fitting, held in (halves, halves[::-1]):
        model: BaselineModel = fit_baseline(sim, fitting)
        prediction = model.predict(sim)
        scale = {o: max(float(np.var((sim[o] - prediction[o])[held])), 1e-12) for o in OUTPUTS}
        y = {o: sim[o][held] for o in OUTPUTS}
        base = {o: prediction[o][held] for o in OUTPUTS}
        zeros = {o: np.zeros(held.size) for o in OUTPUTS}
        scales.append(scale)
        # the terms are built on the whole flight (a delay's inputs reach back across the blocks) and judged on the half
        terms = [_on_rows(c, held) for c in candidate_terms(sim, model, prediction)]
        nulls.append({c.effect: cross_validated(c, y, base, zeros, scale)[0] for c in terms})
    scale = {o: float(np.mean([s[o] for s in scales])) for o in OUTPUTS}
    null = {e: float(np.mean([n.get(e, 0.0) for n in nulls])) for e in set().union(*nulls)}
    return scale, null


def _on_rows(candidate: Candidate, rows: np.ndarray) -> Candidate:
    """`candidate` with its regressors or predictions taken at samples `rows` only."""
    build = candidate.build

    def built(value: float) -> dict[str, np.ndarray]:
        return {o: np.asarray(a)[rows] for o, a in build(value).items()}

    return replace(candidate, build=built)


def _joined(flights: Sequence[FlightSeries]) -> FlightSeries:
    if len(flights) == 1:
        return flights[0]
    common = set.intersection(*(set(f.signals) for f in flights))
    offset, pieces = 0, []
    for f in flights:
        pieces.append(f.piece + offset)
        offset = int(pieces[-1].max()) + 1
    return FlightSeries(
        name=" + ".join(f.name for f in flights),
        time_s=np.concatenate([f.time_s for f in flights]),
        piece=np.concatenate(pieces),
        signals={s: np.concatenate([f[s] for f in flights]) for s in sorted(common)},
        rate_hz=flights[0].rate_hz,
    )


def _finding(
    fit: TermFit,
    score: float,
    before: Mapping[str, np.ndarray],
    after: Mapping[str, np.ndarray],
    y: Mapping[str, np.ndarray],
    flown: FlightSeries,
    scale: Mapping[str, float],
    thrust_scale: float,
    rotor_radius_m: float | None,
) -> Finding:
    outputs = fit.candidate.outputs
    rms_before = {o: float(np.sqrt(np.mean((y[o] - before[o]) ** 2))) for o in outputs}
    rms_after = {o: float(np.sqrt(np.mean((y[o] - after[o]) ** 2))) for o in outputs}
    weighted_before = sum(rms_before[o] ** 2 / scale[o] for o in outputs)
    weighted_after = sum(rms_after[o] ** 2 / scale[o] for o in outputs)
    improvement = 100.0 * (1.0 - np.sqrt(weighted_after / weighted_before)) if weighted_before > 0 else 0.0
    contribution = {o: after[o] - before[o] for o in outputs}
    regime = _regime(contribution, flown, fit.candidate.regime)
    if fit.candidate.grid_parameter == "time_s":  # a change at an instant acts from then on
        regime = Regime(variable="time", unit="s", low=round(fit.value, 3), high=round(float(flown["t_flight"][-1]), 3))
    finding = Finding(
        effect=fit.candidate.effect,
        outputs=outputs,
        band_rad_s=_band(contribution, flown.rate_hz),
        regime=regime,
        explained_variance=round(max(score, 0.0), 4),
        parameters=parameters_of(fit, thrust_scale, rotor_radius_m),
        rmse_before=rms_before,
        rmse_after=rms_after,
        improvement_percent=round(float(improvement), 2),
        evidence="",
        traces=_traces(flown, regime, {o: y[o] - before[o] for o in outputs}, {o: y[o] - after[o] for o in outputs}),
    )
    return _with_evidence(finding, fit.candidate)


_MAX_POINTS = 1500  # samples kept for the report's figures (4000 took 3.5 s to draw as SVG)


def _traces(
    flown: FlightSeries, regime: Regime, before: Mapping[str, np.ndarray], after: Mapping[str, np.ndarray]
) -> FindingTraces:
    step = max(1, flown.n // _MAX_POINTS)
    variable = {"time": "t_flight"}.get(regime.variable, regime.variable)
    values = _regime_variables(flown).get(variable, flown["t_flight"])
    return FindingTraces(
        time_s=flown["t_flight"][::step],
        regime=values[::step],
        before={o: v[::step] for o, v in before.items()},
        after={o: v[::step] for o, v in after.items()},
    )


def _with_evidence(finding: Finding, candidate: Candidate) -> Finding:
    return replace(finding, evidence=describe_finding(finding, candidate))


def _band(contribution: Mapping[str, np.ndarray], rate_hz: float) -> tuple[float, float]:
    """Frequencies holding 5-95 % of the contribution's power (its mean included at the lowest bin), rad/s."""
    total = None
    for x in contribution.values():
        f, power = welch(x, fs=rate_hz, nperseg=min(x.size, int(64 * rate_hz)), detrend=False)
        total = power if total is None else total + power
    assert total is not None
    cumulative = np.cumsum(total) / max(float(np.sum(total)), 1e-300)
    lo = f[int(np.searchsorted(cumulative, 0.05))]
    hi = f[min(int(np.searchsorted(cumulative, 0.95)), f.size - 1)]
    return (round(float(2 * np.pi * lo), 3), round(float(2 * np.pi * hi), 3))


def _regime_variables(flown: FlightSeries) -> dict[str, np.ndarray]:
    """The flight variables a finding may be located by (time apart), each shape (n,)."""
    variables = {name: flown[name] for name, _ in _REGIMES if name in flown and name != "t_flight"}
    if "u" in flown and "v" in flown:
        variables["ground_speed"] = np.hypot(flown["u"], flown["v"])
    if "wind_lon" in flown and "wind_lat" in flown:
        variables["wind_speed"] = np.hypot(flown["wind_lon"], flown["wind_lat"])
    return variables


def _regime(contribution: Mapping[str, np.ndarray], flown: FlightSeries, own: str | None) -> Regime:
    """The range of a flight variable holding the contribution: the term's `own` variable, else the narrowest.

    The range holds 80 % of the contribution's energy (its departures from its median: a trim acts
    everywhere and locates nothing). Without a variable of its own (a delay, a lag), each flight
    variable's range is taken as a share of its whole range and the narrowest wins; time only when no
    flight variable varies: it follows anything.
    """
    size = np.sqrt(sum((np.asarray(c) - np.median(c)) ** 2 for c in contribution.values()))
    variables = _regime_variables(flown)
    units = dict(_REGIMES)
    if own is not None and (own in variables or own == "t_flight"):
        values = variables.get(own, flown["t_flight"])
        low, high = _energy_range(values, size)
        return Regime(
            variable="time" if own == "t_flight" else own, unit=units[own], low=round(low, 3), high=round(high, 3)
        )
    best: tuple[float, str, float, float] = (np.inf, "t_flight", 0.0, 0.0)
    for name, values in {**variables, "t_flight": flown["t_flight"]}.items():
        spread = float(np.ptp(values))
        if spread <= 0 or np.ptp(size) <= 0:
            continue
        low, high = _energy_range(values, size)
        share = (high - low) / spread if name != "t_flight" else np.inf
        if share < best[0] or best[1] == "t_flight" and name == "t_flight":
            best = (share, name, low, high)
    _, name, low, high = best
    return Regime(
        variable="time" if name == "t_flight" else name, unit=units[name], low=round(low, 3), high=round(high, 3)
    )


def _energy_range(values: np.ndarray, size: np.ndarray) -> tuple[float, float]:
    """The range of `values` holding the middle 80 % of ``size**2``."""
    order = np.argsort(values)
    energy = np.cumsum(size[order] ** 2) / max(float(np.sum(size**2)), 1e-300)
    low = float(values[order][int(np.searchsorted(energy, 0.1))])
    high = float(values[order][min(int(np.searchsorted(energy, 0.9)), values.size - 1)])
    return low, high

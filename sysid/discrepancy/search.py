"""Discrepancy discovery: where a real flight departs from its simulation, which physics explains it, by how much.

0. **Sensors.** A sensor's error that no model of the vehicle can tell from the physics it measures (a
   gyro's scale: a roll moment per command as strong) is measured first, against the kinematics of the
   flights' other signals (a term's ``calibrate``: :mod:`.catalogue.sensor_scale`); REAL is corrected
   where it is off, and the finding's cut is the residual of its outputs against the simulation's model
   as logged and as corrected.
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
   (a touchdown's spike is no physics), and, for a term whose mark is on some outputs (a rotor's drag on ax and
   ay), if it passes the same threshold on those alone; of those that pass, the one that lowers the Bayesian information
   criterion most (effective samples, the parameter inside its shape
   counted) is kept; its contribution joins the model and the others are
   screened again (forward selection), until none passes. A delay and a lag compete:
   once one is kept the other is not tried.
   Every term of the catalogue (:mod:`.catalogue`) is judged so; the best is named only when it explains
   about as much of its outputs' residual as the model of the unknown (:mod:`.generic`) does, else the
   finding is ``unexplained`` (and the term an alternative); terms whose scores come close to the named
   one's are listed as its alternatives. When nothing is named, the model of the unknown is tried on
   every output; a later term must cut its outputs' residual RMS by 10 %; an output whose residual
   stays 2.5 times over its floor with every finding modelled is ``unexplained`` (weak names on it are
   dropped); names that are all weak (each under 15 % of its outputs' residual) give way to the model of
   the unknown on every output when it removes more of the whole flight's residual than they do. A trim of the thrust per input beyond 5 %, with nothing else on az, is a control
   effectiveness. The folds are 4 s blocks dealt in turn to six (a manoeuvre's regime lives in one
   stretch of the flight), and a sensor's constant bias is a nuisance, never a finding.
3. **Model, locate and show.** Each kept term is fitted on all of REAL with
   its uncertainties; its band is where its contribution's power lies, its
   regime the flight variable its contribution follows; the residual RMS
   before and after is on held-out blocks.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from sysid._filters import welch_density
from sysid.discrepancy.baseline import BaselineModel, fit_baseline
from sysid.discrepancy.catalogue import (
    CATALOGUE,
    Calibration,
    Candidate,
    Derivation,
    FlightContext,
    Term,
    candidate_terms,
    term_of,
)
from sysid.discrepancy.catalogue._air import air_velocity, climb_rate
from sysid.discrepancy.corrected import UNEXPLAINED, CorrectedModel, ModelTerm
from sysid.discrepancy.describe import describe_finding, parameters_of, summary_of
from sysid.discrepancy.generic import GenericFit, Regressor, fit_generic, generic_library, generic_term
from sysid.discrepancy.result import (
    Alternative,
    DiscrepancyResult,
    Finding,
    FindingTraces,
    FittedParameter,
    Regime,
    Screening,
)
from sysid.discrepancy.selection import (
    TermFit,
    blocks,
    combined,
    cross_validated,
    effective_samples,
    fit_term,
    held_out_share,
    joined,
    narrowed,
    split_joined,
)
from sysid.discrepancy.series import OUTPUTS, FlightSeries

__all__ = ["DiscrepancyOptions", "discover"]

_REGIMES = (
    ("height_agl", "m"),
    ("ground_speed", "m/s"),
    ("airspeed", "m/s"),
    ("climb_rate", "m/s"),
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

_AMBIGUOUS_SCORE = 0.02  # another term within this held-out score of the winner's (or this share of it) ...
_AMBIGUOUS_SHARE = 0.1  # ... explains the same residual as well: the finding is ambiguous
_LEVEL_CHANGE = 0.05  # a trim further than this from 1, with nothing else on az, is a change of thrust per command
_LATE_SCORE = 0.19  # held-out share a later term must remove of its outputs' residual (a 10 % cut of their RMS)
_FAR_LEFT = 2.5  # an output's held-out residual this many times its floor with every finding modelled is unexplained
_OWNS = 0.3  # a finding that removed this share of its outputs' residual owns what is left there
_WEAK = 0.15  # a term that removed less of the residual of its outputs, one of them that far, is no finding
_NAMED_SHARE = 0.8  # a catalogue term explaining under this share of what the model of the unknown does is no name

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
    generic_margin : float
        Held-out score by which the model of the unknown must beat the best catalogue term on that term's
        outputs (and the term explain under 80 % of what it does) for the term not to be named.
    rotor_radius_m : float or None
        Propeller radius, m, if known: the ground effect's end is also given as Z/R.
    simulation_misfit : str or None
        Why the simulation is no close model of its own flights (:func:`~.model_files.simulation_misfit`):
        then finding nothing is the verdict ``not_judged``, not ``none``, and the summary says why.
    """

    min_improvement: float = 0.05
    min_share: float = 0.01
    null_margin: float = 3.0
    max_findings: int = 3
    generic_margin: float = 0.10
    rotor_radius_m: float | None = None
    simulation_misfit: str | None = None


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
    calibrations = []  # (the sensor's term, the flight it was measured on, its calibration)
    for sensor in CATALOGUE:  # a sensor's error, before any physics
        calibration = sensor.calibrate(simulated, flown) if sensor.calibrate is not None else None
        if calibration is not None:
            calibrations.append((sensor, flown, calibration))
            flown = calibration.corrected
    scale, null = _noise_floor(simulated)
    _report(progress, "simulation model", 1, 3)
    # the moments and side forces read the thrust command about the real vehicle's own hover (see recentred)
    shift = float(np.mean(flown["delta_thr"]) - np.mean(simulated["delta_thr"]))
    baseline = fit_baseline(simulated, read_on=flown).recentred(shift)
    y = {o: flown[o] for o in OUTPUTS}
    base = baseline.predict(flown)
    additions = {o: np.zeros(flown.n) for o in OUTPUTS}
    thrust = -base["az"]
    gain = float(np.dot(thrust, base["az"] - y["az"]) / max(float(np.dot(thrust, thrust)), 1e-300))
    additions["az"] = -gain * thrust  # the real thrust per input may differ by a constant factor: a trim
    trim = additions["az"]
    kept: list[_Kept] = []
    screened: list[Screening] = []
    terms: dict[int, Term] = {}
    held_out = combined(base, additions)  # the baseline is fitted on SIM: on REAL its prediction is held out already
    first = FlightContext(series=flown, baseline=baseline, thrust=-(base["az"] + trim))
    library = generic_library(first)
    search = _Search(y=y, scale=scale, library=library, options=options, held_out=held_out, terms=terms)
    # a delay's or lag's re-predictions read no thrust: built once, reused by every round of the selection
    transforms = {c.effect: c for c in candidate_terms(first) if c.kind == "transform"}
    generic_null = options.null_margin * max(null.get("unexplained", 0.0), 0.0)
    while len(kept) < options.max_findings:
        found = {k.fit.candidate.effect for k in kept}
        exclude = found | {r for e in found if e != "unexplained" for r in term_of(e).rivals}
        if "unexplained" in found:
            break  # what is left is the model of the unknown's: no catalogue term is named after it
        scores: list[_Scored] = []
        linear = [k.fit for k in kept if k.fit.candidate.kind == "linear"]
        without = _without(additions, linear)  # the kept linear terms refit with each linear newcomer
        current = combined(base, additions)
        # every term reads one thrust, the model's with the trim: two terms' thrust gains are then one column, whose
        # sum is measured, and not two near copies whose difference (the first term's contribution) a fit would use
        context = FlightContext(series=flown, baseline=baseline, thrust=-(base["az"] + trim))
        for candidate in (transforms.get(c.effect, c) for c in candidate_terms(context, exclude=tuple(exclude))):
            together = candidate.kind == "linear" and bool(linear)
            adds = without if together else additions
            reference = held_out if together else None  # judged against the kept terms' held-out prediction
            against = reference if reference is not None else current
            shown_on = term_of(candidate.effect).shown_on
            trial = joined(candidate, linear) if together else candidate
            score, predicted = cross_validated(trial, y, base, adds, scale, reference, candidate.outputs)
            # a companion output (a rotor drag's hub moment) stays only where it removes a share of its own
            # residual: columns that fit nothing would cost the term its score and criterion
            if shown_on:
                acting = _acting(candidate, y, predicted, against, scale, options.min_share, shown_on)
                if acting != candidate.outputs:
                    candidate = narrowed(candidate, acting)
                    trial = joined(candidate, linear) if together else candidate
                    score, predicted = cross_validated(trial, y, base, adds, scale, reference, candidate.outputs)
            # once a term is kept, the residual where it acts holds its shape's error, which another term acting
            # there fits as well (a mass step at the low hover beside a ground effect): later terms must also
            # remove a share of the whole flight's residual
            least = options.min_improvement if kept else options.min_share
            threshold = max(least, options.null_margin * max(null.get(candidate.effect, 0.0), 0.0))
            if kept:  # a later term takes up what the first one's shape left: it must cut its outputs' RMS by 10 %
                threshold = max(threshold, _LATE_SCORE)
            local = _local_score(y, predicted, against, scale, candidate.outputs)
            # a term whose own mark is missing (a rotor drag without a drag force) removes what it does with its
            # companion columns only (a hub moment): it is not that effect
            shown = not shown_on or held_out_share(y, predicted, against, scale, shown_on) > threshold
            if not kept:
                screened.append(
                    Screening(
                        effect=candidate.effect,
                        score=round(score, 4),
                        threshold=round(threshold, 4),
                        where_it_acts=round(local, 4),
                    )
                )
            if score > threshold and local > options.min_improvement and shown:
                # a term that passes on all its outputs is a finding on those where it acts only (worn roll and
                # pitch motors: not on the yaw and the thrust, whose residuals it leaves at the floor); judged on
                # all of them first, so that an idle term is not made to pass on its one best output (the null)
                acting = _acting(candidate, y, predicted, against, scale, options.min_share, shown_on)
                if acting and acting != candidate.outputs:
                    candidate = narrowed(candidate, acting)
                    trial = joined(candidate, linear) if together else candidate
                    score, predicted = cross_validated(trial, y, base, adds, scale, reference, candidate.outputs)
                fit = fit_term(trial, y, base, adds, scale)
                own = split_joined(fit, candidate, linear)[0] if together else fit
                if term_of(candidate.effect).against_physics(own.coefficient_values()):
                    continue  # its shape fitted the other way round is another effect's (the thrust's curvature)
                if candidate.kind == "transform" and fit.value >= candidate.grid[-1]:
                    continue  # at the end of the range searched: a bound, not a measured delay or lag
                prediction = fit.prediction(base, adds)
                if not _sustained(_support(prediction, current, scale), flown["t_flight"]):
                    continue  # a moment of flight (a touchdown, a spike) is no physical effect
                change = _bic_change(fit, y, prediction, current, len(candidate.coefficients))
                scores.append(_Scored(change, score, fit, predicted, candidate, adds))
        _report(progress, "screening terms", len(kept) + 1, options.max_findings + 1)
        if not scores:
            break
        best = min(scores, key=lambda s: s.bic_change)
        rivals = _alternatives(best, scores)
        generic = fit_generic(context, y, current, scale, outputs=best.candidate.outputs, library=library)
        if _generic_wins(best, generic, options):
            # the criterion's choice explains clearly less than the model of the unknown: a passing term that
            # explains about as much (a lag on six outputs beside a weaker gain change on four) is the answer
            close = [c for c in scores if c.score >= generic.score - options.generic_margin]
            if close:
                best = max(close, key=lambda c: c.score)
                rivals = _alternatives(best, scores)
                generic = fit_generic(context, y, current, scale, outputs=best.candidate.outputs, library=library)
        if _generic_wins(best, generic, options):
            # the best name explains clearly less than a generic model of the same outputs: it is not the answer;
            # after a named effect what is left holds its shape's error (a lag's first order against the real one):
            # only a residual that stays far above the floor is then unexplained (see _far_left)
            if not kept:
                rivals = (Alternative(effect=best.candidate.effect, explained_variance=round(best.score, 4)), *rivals)
                kept.append(_unexplained(search, generic, base, additions, rivals))
            break
        before = dict(held_out)
        for o in best.fit.candidate.outputs:
            held_out[o] = best.predicted[o]
        if best.candidate.kind == "transform":
            base = dict(best.candidate.build(best.fit.value))
            kept.append(_Kept(best.fit, best.score, before, dict(held_out), rivals))
            continue
        own, *refit = (
            split_joined(best.fit, best.candidate, linear) if best.fit.candidate is not best.candidate else [best.fit]
        )
        kept = [
            _Kept(refit.pop(0), k.score, k.before, k.after, k.alternatives)
            if k.fit.candidate.kind == "linear" and refit
            else k
            for k in kept
        ]
        kept.append(_Kept(own, best.score, before, dict(held_out), rivals))
        additions = dict(best.adds)
        built = best.fit.candidate.build(best.fit.value)
        for o, coefficients in best.fit.coefficients.items():
            additions[o] = additions[o] + built[o] @ coefficients
    context = FlightContext(series=flown, baseline=baseline, thrust=-(base["az"] + trim))
    first_floor = max(options.min_share, generic_null)
    if not kept:
        current = combined(base, additions)
        generic = fit_generic(context, y, current, scale, library=library)
        if _generic_passes(search, generic, current, first_floor, flown["t_flight"]):
            kept.append(_unexplained(search, generic, base, additions))
    kept, additions = _instead_of_weak(search, kept, base, additions, context, first_floor)
    kept = _far_left(search, kept, base, additions, context)
    level = _thrust_level(kept, gain, thrust, base, additions, y)
    corrected = CorrectedModel(
        baseline=baseline,
        thrust_trim=gain,
        terms=tuple(t for k in kept if (t := _model_term(k)) is not None),
        made_from=(*(s.name for s in sim), *(s.name for s in real)),
    )
    if level is not None and len(kept) < options.max_findings:
        kept.append(level)  # the trim itself, which the corrected model holds already
    _report(progress, "done", 3, 3)
    gains = {id(k.fit): _thrust_gain(k.fit) for k in kept}
    findings = sorted(
        (
            *(_calibrated(t, c, measured_on, flown, baseline, scale) for t, measured_on, c in calibrations),
            # each term's thrust level: the trim and the other terms' gains (collinear: only their sum is known)
            *(
                _finding(
                    k,
                    y,
                    flown,
                    scale,
                    terms.get(id(k.fit)) or term_of(k.fit.candidate.effect),
                    Derivation(
                        thrust_scale=1.0 + gain + sum(gains.values()) - gains[id(k.fit)],
                        rotor_radius_m=options.rotor_radius_m,
                    ),
                )
                for k in kept
            ),
        ),
        key=lambda f: -f.improvement_percent,
    )
    floor = {o: float(np.sqrt(scale[o])) for o in OUTPUTS}
    unexplained = {o: round(_spread(y[o] - held_out[o]) / floor[o], 2) for o in OUTPUTS}
    misfit = options.simulation_misfit
    return DiscrepancyResult(
        verdict=findings[0].effect if findings else ("not_judged" if misfit else "none"),
        findings=tuple(findings),
        summary=summary_of(findings, floor, unexplained, misfit=misfit),
        unexplained=unexplained,
        screened=tuple(screened),
        noise_floor=floor,
        sim=tuple(s.name for s in sim),
        real=tuple(s.name for s in real),
        thrust_scale=round(1.0 + gain, 5),
        corrected=corrected,
    )


def _model_term(kept: _Kept) -> ModelTerm | None:
    """A kept term as the corrected simulation holds it (None: a residual located, not modelled)."""
    fit = kept.fit
    if fit.candidate.kind == "linear" and not fit.coefficients:
        return None
    regressors: dict[str, tuple[str, ...]] = {}
    if fit.candidate.effect == UNEXPLAINED:  # its coefficients' keys are "output:regressor"
        for key in fit.candidate.coefficients:
            output, regressor = key.split(":", 1)
            regressors[output] = (*regressors.get(output, ()), regressor)
    coefficients = {o: np.asarray(c, dtype=float) for o, c in fit.coefficients.items()}
    return ModelTerm(effect=fit.candidate.effect, value=fit.value, coefficients=coefficients, regressors=regressors)


def _generic_passes(
    search: _Search, generic: GenericFit, current: Mapping[str, np.ndarray], threshold: float, clock: np.ndarray
) -> bool:
    """Whether the model of the unknown passes a first term's screen: `threshold` on the whole flight, the floor
    where it acts, and a sustained support (`clock`: the flight's time, s, shape (n,))."""
    if not generic.chosen or generic.score <= threshold:
        return False
    local = _local_score(search.y, generic.predicted, current, search.scale, generic.outputs)
    sustained = _sustained(_support(generic.predicted, current, search.scale), clock)
    return local > search.options.min_improvement and sustained


def _instead_of_weak(
    search: _Search,
    kept: list[_Kept],
    base: Mapping[str, np.ndarray],
    additions: dict[str, np.ndarray],
    context: FlightContext,
    threshold: float,
) -> tuple[list[_Kept], dict[str, np.ndarray]]:
    """`kept` and the additions, with the model of the unknown in the place of names that are all weak.

    Names that each removed under :data:`_WEAK` of their outputs' residual (a mass step's 0.2 % beside a
    roll command that also pitches) may be slivers of something no catalogue term describes, each judged
    on its own outputs only. The model of the unknown, fitted on every output to what was left before
    them, takes their place when it passes a first term's screen (`threshold`) and removes more of the
    weighted held-out residual of the whole flight than they do together; the names become its alternatives.
    """
    if not kept or any(
        k.score >= _WEAK or k.fit.candidate.kind != "linear" or k.fit.candidate.effect == UNEXPLAINED for k in kept
    ):
        return kept, additions
    without = _without(additions, [k.fit for k in kept])
    current = combined(base, without)
    generic = fit_generic(context, search.y, current, search.scale, library=search.library)
    if not _generic_passes(search, generic, current, threshold, context.series["t_flight"]):
        return kept, additions
    before = kept[0].before
    removed = _removed(search.y, generic.predicted, before, search.scale)
    if removed <= _removed(search.y, search.held_out, before, search.scale):
        return kept, additions
    search.held_out.update(before)  # the names' share goes back to the residual
    alternatives = tuple(Alternative(effect=k.fit.candidate.effect, explained_variance=round(k.score, 4)) for k in kept)
    return [_unexplained(search, generic, base, without, alternatives)], without


def _removed(
    y: Mapping[str, np.ndarray],
    after: Mapping[str, np.ndarray],
    before: Mapping[str, np.ndarray],
    scale: Mapping[str, float],
) -> float:
    """The weighted residual (each output over its floor's variance) a prediction removes from `before`'s, all outputs."""
    return sum(float(np.sum((y[o] - before[o]) ** 2) - np.sum((y[o] - after[o]) ** 2)) / scale[o] for o in OUTPUTS)


def _far_left(
    search: _Search,
    kept: list[_Kept],
    base: Mapping[str, np.ndarray],
    additions: Mapping[str, np.ndarray],
    context: FlightContext,
) -> list[_Kept]:
    """`kept`, with what stays far above the noise floor reported as ``unexplained`` and the weak names on it dropped.

    An output whose held-out residual stays over :data:`_FAR_LEFT` times its floor with every finding
    modelled (but an output a finding removed :data:`_OWNS` of the residual of: what is left there is that
    finding's shape's error, a first-order lag against the real actuator) holds something no term and no
    static model of the flight explains (a load swinging under
    the vehicle: dynamics of its own). A catalogue term that removed under :data:`_WEAK` of the residual of
    such an output took up a sliver of it: a guess, not a finding. The rest is located as ``unexplained``
    on those outputs, with what the model of the unknown can say of it (perhaps nothing).
    """
    y, held_out = search.y, search.held_out
    floor = {o: float(np.sqrt(search.scale[o])) for o in OUTPUTS}
    owned = {o for k in kept if k.score >= _OWNS for o in k.fit.candidate.outputs}  # a strong name's shape error
    far = tuple(o for o in OUTPUTS if o not in owned and _spread(y[o] - held_out[o]) > _FAR_LEFT * floor[o])
    if not far or any(k.fit.candidate.effect == "unexplained" for k in kept):
        return kept
    weak = [k for k in kept if k.score < _WEAK and set(k.fit.candidate.outputs) & set(far)]
    kept = [k for k in kept if not any(k is w for w in weak)]
    if weak:
        held_out.update(weak[0].before)  # the weak terms' share goes back to the residual
    current = {o: held_out[o] for o in OUTPUTS}
    generic = fit_generic(context, y, current, search.scale, outputs=far, library=search.library)
    kept.append(_unexplained(search, generic, base, additions, outputs=far))
    return kept


def _spread(residual: np.ndarray) -> float:
    """RMS of a residual about its mean: a sensor's constant bias is a nuisance, not something left unexplained."""
    return float(np.std(residual))


def _thrust_level(
    kept: Sequence[_Kept],
    gain: float,
    thrust: np.ndarray,
    base: Mapping[str, np.ndarray],
    additions: Mapping[str, np.ndarray],
    y: Mapping[str, np.ndarray],
) -> _Kept | None:
    """The thrust per command's change as a finding (``control_effectiveness``), when the trim itself is one.

    The trim fitted before any term is the real thrust per input over the simulated one: a trim while it is
    within :data:`_LEVEL_CHANGE` of 1, or while a term on az (a mass, the battery, the ground) holds its own
    level; beyond it, with nothing else on az, the real motors make another thrust per command (worn
    motors or props; a vehicle heavier by the same share needs the same command: a hover cannot tell them
    apart, and the sentence says so). Its uncertainty is the trim's least-squares spread, the residual's
    correlation counted.
    """
    if abs(gain) <= _LEVEL_CHANGE or any("az" in k.fit.candidate.outputs for k in kept):
        return None
    after = combined(base, additions)
    residual = y["az"] - after["az"]
    inflation = residual.size / max(effective_samples(residual), 1.0)
    sigma = float(np.sqrt(np.mean(residual**2) * inflation / max(float(np.dot(thrust, thrust)), 1e-300)))
    column = -thrust[:, None]
    candidate = Candidate(
        effect="control_effectiveness",
        outputs=("az",),
        kind="linear",
        grid=(float("nan"),),
        grid_parameter="",
        build=lambda _value: {"az": column},
        coefficients=("k_thrust",),
    )
    fit = TermFit(
        candidate=candidate,
        value=float("nan"),
        coefficients={"az": np.array([gain])},
        covariance={"az": np.array([[sigma**2]])},
        value_uncertainty=float("nan"),
    )
    before = {**after, "az": np.asarray(base["az"])}
    removed = 1.0 - float(np.sum((y["az"] - after["az"]) ** 2)) / max(
        float(np.sum((y["az"] - before["az"]) ** 2)), 1e-300
    )
    return _Kept(fit, removed, before, after, (Alternative(effect="mass", explained_variance=round(removed, 4)),))


@dataclass(frozen=True, slots=True)
class _Search:
    """What the steps of one search read: the real flight's outputs and noise floors, the model of the unknown's
    library and the thresholds; and what they write: the held-out prediction with every kept term (`held_out`,
    updated in place) and the model of the unknown's term per kept fit (`terms`, by ``id`` of the fit).
    """

    y: Mapping[str, np.ndarray]
    scale: Mapping[str, float]
    library: list[Regressor]
    options: DiscrepancyOptions
    held_out: dict[str, np.ndarray]
    terms: dict[int, Term]


@dataclass(frozen=True, slots=True)
class _Kept:
    """A kept term: its fit, held-out score, the held-out prediction before and after it, its rivals."""

    fit: TermFit
    score: float
    before: dict[str, np.ndarray]
    after: dict[str, np.ndarray]
    alternatives: tuple[Alternative, ...] = ()


@dataclass(frozen=True, slots=True)
class _Scored:
    """A candidate that passed the screen at one step."""

    bic_change: float
    score: float
    fit: TermFit
    predicted: dict[str, np.ndarray]
    candidate: Candidate
    adds: Mapping[str, np.ndarray]


def _alternatives(best: _Scored, scores: Sequence[_Scored]) -> tuple[Alternative, ...]:
    """The other passing terms that explain the winner's residual within its uncertainty (same outputs, close score)."""
    out = []
    for other in scores:
        if other is best or not set(other.candidate.outputs) & set(best.candidate.outputs):
            continue
        if other.score >= best.score - max(_AMBIGUOUS_SCORE, _AMBIGUOUS_SHARE * best.score):
            out.append(Alternative(effect=other.candidate.effect, explained_variance=round(other.score, 4)))
    return tuple(sorted(out, key=lambda a: -a.explained_variance))


def _generic_wins(best: _Scored, generic: GenericFit, options: DiscrepancyOptions) -> bool:
    """Whether the model of the unknown explains the best term's outputs clearly better than the term does."""
    return generic.score - best.score > options.generic_margin and best.score < _NAMED_SHARE * generic.score


def _unexplained(
    search: _Search,
    generic: GenericFit,
    base: Mapping[str, np.ndarray],
    additions: Mapping[str, np.ndarray],
    alternatives: tuple[Alternative, ...] = (),
    *,
    outputs: tuple[str, ...] = (),
) -> _Kept:
    """The model of the unknown as a kept term (fitted on all samples), the search's `held_out` updated with it.

    `outputs`: where it is located when the model of the unknown keeps no regressor there (it is then a
    residual located, not modelled).
    """
    candidate = generic.candidate(outputs)
    if generic.chosen:  # fitted where it keeps regressors; located besides on `outputs`
        fit = replace(fit_term(generic.candidate(), search.y, base, additions, search.scale), candidate=candidate)
    else:
        fit = TermFit(
            candidate=candidate, value=float("nan"), coefficients={}, covariance={}, value_uncertainty=float("nan")
        )
    search.terms[id(fit)] = generic_term(generic, outputs)
    before = dict(search.held_out)
    for o in generic.outputs:
        search.held_out[o] = generic.predicted[o]
    return _Kept(fit, generic.score, before, dict(search.held_out), alternatives)


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


def _acting(
    candidate: Candidate,
    y: Mapping[str, np.ndarray],
    predicted: Mapping[str, np.ndarray],
    current: Mapping[str, np.ndarray],
    scale: Mapping[str, float],
    min_share: float,
    always: tuple[str, ...],
) -> tuple[str, ...]:
    """The outputs of a linear `candidate` where it removes more than `min_share` of its own held-out residual.

    Each output's columns are fitted on their own, so the others' shares do not change once one is dropped.
    A transform (a delay, a lag) re-predicts every output: all are kept. So are the outputs in `always`.
    """
    if candidate.kind != "linear":
        return candidate.outputs
    return tuple(
        o for o in candidate.outputs if o in always or held_out_share(y, predicted, current, scale, (o,)) > min_share
    )


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
    return held_out_share(
        {o: y[o][rows] for o in outputs},
        {o: predicted[o][rows] for o in outputs},
        {o: current[o][rows] for o in outputs},
        scale,
        outputs,
    )


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
        context = FlightContext(series=sim, baseline=model, thrust=-prediction["az"])
        terms = [_on_rows(c, held) for c in candidate_terms(context)]
        nulls.append({c.effect: cross_validated(c, y, base, zeros, scale)[0] for c in terms})
        library = [replace(r, values=r.values[held]) for r in generic_library(context)]
        nulls[-1]["unexplained"] = fit_generic(context, y, base, scale, library=library).score
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
        specific_force_derived=flights[0].specific_force_derived,
    )


def _finding(
    kept: _Kept,
    y: Mapping[str, np.ndarray],
    flown: FlightSeries,
    scale: Mapping[str, float],
    term: Term,
    derivation: Derivation,
) -> Finding:
    fit, before, after = kept.fit, kept.before, kept.after
    outputs = fit.candidate.outputs
    contribution = {o: after[o] - before[o] for o in outputs}
    if not any(np.any(c) for c in contribution.values()):  # located, not modelled: the residual says where
        contribution = {o: y[o] - before[o] for o in outputs}
    regime = _regime(contribution, flown, fit.candidate.regime)
    if fit.candidate.grid_parameter == "time_s":  # a change at an instant acts from then on
        regime = Regime(variable="time", unit="s", low=round(fit.value, 3), high=round(float(flown["t_flight"][-1]), 3))
    return _described(
        term,
        _Residuals(before={o: y[o] - before[o] for o in outputs}, after={o: y[o] - after[o] for o in outputs}),
        contribution,
        regime,
        flown,
        scale,
        explained_variance=kept.score,
        parameters=parameters_of(fit, term, derivation),
        alternatives=kept.alternatives,
    )


def _calibrated(
    term: Term,
    calibration: Calibration,
    measured_on: FlightSeries,
    flown: FlightSeries,
    baseline: BaselineModel,
    scale: Mapping[str, float],
) -> Finding:
    """A sensor's error as a finding: the residual of its outputs against the simulation's model, as the flight
    it was `measured_on` has them and as corrected. Its parameters come from the flights' kinematics, not from
    that residual: the cut is held out of their measurement. `flown`: the flight the search read (its regime)."""
    outputs, corrected = calibration.outputs, calibration.corrected
    before, after = baseline.predict(measured_on), baseline.predict(corrected)
    residuals = _Residuals(
        before={o: measured_on[o] - before[o] for o in outputs}, after={o: corrected[o] - after[o] for o in outputs}
    )
    contribution = {o: residuals.before[o] - residuals.after[o] for o in outputs}
    weighted = [sum(float(np.mean(r[o] ** 2)) / scale[o] for o in outputs) for r in (residuals.before, residuals.after)]
    return _described(
        term,
        residuals,
        contribution,
        _regime(contribution, flown, None),
        flown,
        scale,
        explained_variance=1.0 - weighted[1] / weighted[0] if weighted[0] > 0 else 0.0,
        parameters=calibration.parameters,
    )


@dataclass(frozen=True, slots=True)
class _Residuals:
    """Each of a finding's outputs' held-out residual without (`before`) and with (`after`) it, shape (n,)."""

    before: dict[str, np.ndarray]
    after: dict[str, np.ndarray]


def _described(
    term: Term,
    residuals: _Residuals,
    contribution: Mapping[str, np.ndarray],
    regime: Regime,
    flown: FlightSeries,
    scale: Mapping[str, float],
    *,
    explained_variance: float,
    parameters: tuple[FittedParameter, ...],
    alternatives: tuple[Alternative, ...] = (),
) -> Finding:
    """The finding of `term` with its residuals' figures, band, traces and sentence."""
    outputs = tuple(residuals.before)
    rms_before = {o: float(np.sqrt(np.mean(residuals.before[o] ** 2))) for o in outputs}
    rms_after = {o: float(np.sqrt(np.mean(residuals.after[o] ** 2))) for o in outputs}
    weighted_before = sum(rms_before[o] ** 2 / scale[o] for o in outputs)
    weighted_after = sum(rms_after[o] ** 2 / scale[o] for o in outputs)
    improvement = 100.0 * (1.0 - np.sqrt(weighted_after / weighted_before)) if weighted_before > 0 else 0.0
    finding = Finding(
        effect=term.effect,
        outputs=outputs,
        band_rad_s=_band(contribution, flown.rate_hz),
        regime=regime,
        explained_variance=round(max(explained_variance, 0.0), 4),
        parameters=parameters,
        rmse_before=rms_before,
        rmse_after=rms_after,
        improvement_percent=round(float(improvement), 2),
        evidence="",
        alternatives=alternatives,
        traces=_traces(flown, regime, residuals.before, residuals.after),
    )
    return replace(finding, evidence=describe_finding(finding, term))


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


def _band(contribution: Mapping[str, np.ndarray], rate_hz: float) -> tuple[float, float]:
    """Frequencies holding 5-95 % of the contribution's power (its mean included at the lowest bin), rad/s."""
    total = None
    for x in contribution.values():
        f, power = welch_density(x, rate_hz, min(x.size, int(64 * rate_hz)))
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
    air = air_velocity(flown)
    if air is not None:
        variables["airspeed"] = np.hypot(air[0], air[1])
    climb = climb_rate(flown)
    if climb is not None:
        variables["climb_rate"] = climb
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

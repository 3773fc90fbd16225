"""``plansim diagnose-check``: the diagnosis run blind on recordings simulated with and without effects.

Recordings of one scenario are simulated by plansim (:func:`plansim.runner.simulate_and_record`, truth from
:func:`plansim.simulate.chunks.simulate_recording`):

- **null**: the scenario as it is (for ``jjf2003``: bias instability that does not average down, a 12-bit quantiser
  the noise does not dither, the Table 1 table errors);
- **catalogue effects**: one component of each effect at k × its noise-equivalent size (k = 2, 5, 10 by default),
  the size taken from the diagnosis of a null recording of the same schedule
  (:attr:`plansim.diagnose.scores.CandidateScore.noise_equivalent_size`), injected through the scenario's
  ``[mimu.effects]`` field so that the simulator makes it (``bias_drift`` has no field: a ramp in time is added to
  the samples before the acquisition, as below). The component is the first one the schedule identifies;
- **effects outside the catalogue**, added to the simulated samples before the acquisition (the same trial
  simulated without the quantiser, the effect added, then saturated and quantised as the scenario's acquisition
  does: :func:`_acquire`; added after the quantiser, they would leave samples off its codes that no sensor
  makes) (:func:`_add_out_of_catalogue`): a step in
  the x gyro's bias half-way through the recording; a sample clock that runs fast (the segment table, in nominal
  time, drifts off the data); a change of the x gyro's scale factor half-way through; one segment's gx off (the
  segment that holds the middle sample: a rate the table did not hold, a pose knocked) — each at k × its
  noise-equivalent size, the catalogue's yardstick: the size whose change of the reference null's segment means
  has non-centrality 1 on that recording's base fit (:func:`_noncentrality`,
  :func:`plansim.diagnose.scores.noncentrality`), found from the effect in its natural unit
  (:func:`_out_of_catalogue_size`: a gx segment mean's standard uncertainty, 100 ppm of clock error, the scale
  change that moves the largest rate's segment by that uncertainty) and quoted in it too; and a burst of extra
  white noise on gx over a tenth of the run, of k × its noise per sample (it changes the noise, not the means,
  so it has no noise-equivalent size). And a lever arm of 5 mm on the x accelerometer that the fit is not told
  (aliased with P in JJF 2003: it must never be attributed).

``diagnose`` is run on each without being told what was injected. Counted: false alarms (anything selected, the
base model's lack of fit, or anything unexplained after the refit, within segments included), detection
(anything flagged) and correct attribution (the injected effect selected, and only it), the confusion of
injected against selected, how often an out-of-catalogue effect is flagged as an unexplained residual, and the
parameters' error against the truth before and after the refit (r.m.s. of (estimate − truth)/u, and the 95 %
coverage of the after-fit). Each recording's seed is a hash of the root seed, the case and the index, so the
numbers do not depend on the order of the cases.
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.stats import binom

from plansim.config import parse_scenario
from plansim.diagnose.procedure import diagnose, scenario_diagnose_options
from plansim.diagnose.scores import noncentrality
from plansim.fit import resolve_site
from plansim.io.recording_data import segment_first_samples
from plansim.io.scenario_file import apply_overrides
from plansim.kernels.layout import ACQ_FULL_SCALE, ACQ_RANGE, ACQ_STEP
from plansim.kernels.quantiser import quantise
from plansim.model.parameters import PARAMETER_INDEX, PARAMETERS
from plansim.runner import simulate_and_record
from plansim.simulate.arguments import kernel_arguments
from plansim.simulate.chunks import simulate_recording
from plansim.uncertainty.metrology.propagation import coverage_factor

#: the scenario field of each catalogue effect's components (bias_drift is added to the samples)
FIELDS = {"gyro_scale_asymmetry": "gyro_asymmetry", "gyro_scale_nonlinearity": None, "gyro_g2_sensitivity":
          "gyro_g2_sensitivity", "accel_quadratic": "accel_second_order", "lever_arm": "accel_lever_arm"}
#: effects outside the catalogue, added to the samples (:func:`_add_out_of_catalogue`); the lever arm the fit is
#: not told is run with the catalogue effects
OUT_OF_CATALOGUE = ("bias_step", "clock_fast", "noise_burst", "scale_change", "segment_offset")
#: each parameter's group (Kg, Bg, G, Ka, Ba, P), in the order of the fit's estimates
PARAMETER_GROUP = tuple(spec.group for spec in PARAMETERS)
#: the catalogue effects injected (the lever arm at a fixed 5 mm, the others at each size)
CATALOGUE_CASES = ("gyro_scale_asymmetry", "gyro_scale_nonlinearity", "gyro_g2_sensitivity", "accel_quadratic",
                   "bias_drift", "lever_arm")


def case_seed(root: int, case: str, index: int) -> int:
    """The seed of one recording: a hash of the root seed, the case and its index."""
    hashed = hashlib.sha256(f"{root}/{case}/{index}".encode()).hexdigest()
    return int.from_bytes(bytes.fromhex(hashed[:8]), "little")


def _inject(scenario, effect: str, component: str, size: float):
    """The scenario with one component of a catalogue effect set to *size* (SI), or None for bias_drift."""
    e = scenario.effects
    axes = "xyz"
    if effect == "gyro_scale_asymmetry":
        value = np.array(e.gyro_asymmetry, dtype=float)
        value[axes.index(component)] += size
        return dataclasses.replace(scenario, effects=dataclasses.replace(e, gyro_asymmetry=value))
    if effect == "gyro_scale_nonlinearity":
        name = "gyro_nonlinearity_quadratic" if component.endswith("2") else "gyro_nonlinearity_cubic"
        value = np.array(getattr(e, name), dtype=float)
        value[axes.index(component[0])] += size
        return dataclasses.replace(scenario, effects=dataclasses.replace(e, **{name: value}))
    if effect == "gyro_g2_sensitivity":
        value = np.array(e.gyro_g2_sensitivity, dtype=float)
        value[axes.index(component[0]), axes.index(component[1])] += size
        return dataclasses.replace(scenario, effects=dataclasses.replace(e, gyro_g2_sensitivity=value))
    if effect == "accel_quadratic":
        value = np.array(e.accel_second_order, dtype=float)
        value[axes.index(component)] += size
        return dataclasses.replace(scenario, effects=dataclasses.replace(e, accel_second_order=value))
    if effect == "lever_arm":
        value = np.array(e.accel_lever_arm, dtype=float)
        value[axes.index(component[0]), axes.index(component[1])] += size
        return dataclasses.replace(scenario, effects=dataclasses.replace(e, accel_lever_arm=value))
    return None


@dataclass
class CheckReport:
    scenario: str
    alpha: float
    null: dict = field(default_factory=dict)
    effects: list = field(default_factory=list)
    out_of_catalogue: list = field(default_factory=list)
    #: recordings whose diagnosis raised: ``{case, index, seed, error}``; the check goes on without them, and the
    #: figures of each case count the recordings that ran (``recordings``)
    failures: list = field(default_factory=list)


def _attempt(report: CheckReport, case: str, index: int, scenario, recording, truth, alpha, null_draws, seed):
    """:func:`_run`, or None where it raises, the failure kept in ``report.failures``: a long check loses nothing to
    one recording, and says which one failed (its case and seed, to run it again) instead of stopping."""
    try:
        return _run(scenario, recording, truth, alpha, null_draws, seed)
    except Exception as exc:  # any failure of one diagnosis is reported with its seed, not fatal to the check
        report.failures.append({"case": case, "index": index, "seed": seed, "error": f"{type(exc).__name__}: {exc}"})
        return None


def _alarm(d) -> bool:
    """The diagnosis says something is there: an effect selected, the base model's lack of fit, or anything
    unexplained after the refit (segment level, within segments, beyond the stated noise): any of
    :func:`_families`."""
    return any(_families(d).values())


#: the families of tests a diagnosis reports on (:func:`_families`), in the order the null's ``by_family`` lists them
FAMILIES = ("selection", "lack_of_fit", "unexplained_segment_level", "within_segment", "stated_noise")


def _families(d) -> dict[str, bool]:
    """Which family of tests fired on a diagnosis (a recording can fire several): a selection, the base model's
    segment-level lack of fit, the final model's, a within-segment finding, the final model's means beyond the
    stated noise — so that a false-alarm rate above α says which share of α
    (plansim.diagnose.procedure.SELECTION_SHARE …) runs hot."""
    fired = (bool(d.selected), bool(d.lack_of_fit.flagged), bool(d.lack_of_fit_after.flagged),
             bool(d.within.any_flagged), bool(d.unexplained["stated_noise"]))
    return dict(zip(FAMILIES, fired, strict=True))


def _without_quantiser(scenario):
    """The scenario with its acquisition's quantiser off (bits = 0): the same trial's samples before it (the
    quantiser draws no random numbers, so everything else is the same)."""
    document = apply_overrides(scenario.document, ["acquisition.bits=0"])
    return parse_scenario(document, source=f"{scenario.source} without its quantiser")


def _acquire(scenario, samples: np.ndarray) -> np.ndarray:
    """Samples (n, 6) through the scenario's acquisition: saturation and quantiser, per channel
    (:func:`plansim.kernels.quantiser.quantise`, the sample path's own)."""
    acquisition = np.asarray(kernel_arguments(scenario)["acquisition"], dtype=float)
    out = np.empty_like(samples)
    for c in range(samples.shape[1]):
        kind = c // 3
        output_range, step = acquisition[ACQ_RANGE + kind], acquisition[ACQ_STEP + kind]
        full_scale = acquisition[ACQ_FULL_SCALE + kind]
        inverse = 1.0 / step if step > 0 else 0.0
        out[:, c] = [quantise(y, output_range, step, inverse, full_scale) for y in samples[:, c]]
    return out


def _run(scenario, recording, truth, alpha, null_draws, seed):
    """Diagnose *recording* as ``plansim diagnose REC --scenario`` would with the check's (un-injected) *scenario*:
    its site and options (:func:`plansim.diagnose.procedure.scenario_diagnose_options`: turntable, reduction, known
    lever arms, stated noise, the stated slow noise the segment means are tested against) — what the lab knows,
    never what was injected."""
    d = diagnose(recording, resolve_site(scenario=scenario), alpha=alpha, null_draws=null_draws, seed=seed,
                 **scenario_diagnose_options(scenario))
    z = {}
    for label, fit in (("before", d.before), ("after", d.after)):
        m = fit.joint
        ok = np.isfinite(m.estimate) & (m.u > 0)
        zz = (m.estimate[ok] - truth[ok]) / m.u[ok]
        k = np.array([coverage_factor(nu) for nu in m.dof[ok]])
        z[label] = (float(np.sqrt(np.mean(zz**2))), float(np.mean(np.abs(zz) <= k)))
        each = np.full((len(PARAMETER_GROUP), 2), np.nan)  # per parameter: z, and 1.0 where |z| ≤ k
        each[ok, 0], each[ok, 1] = zz, np.abs(zz) <= k
        z[f"{label}_each"] = each
    return d, z


def _share(count: int, of: int) -> float:
    """count / of, NaN where nothing ran."""
    return count / of if of else math.nan


def _mean(values: list) -> float:
    """The mean, NaN where nothing ran."""
    return float(np.mean(values)) if values else math.nan


def _by_group(each: list) -> dict:
    """The parameters' errors pooled over recordings, per group of eq. (1)/(2) (Kg, Bg, G, Ka, Ba, P): r.m.s. of
    z = (estimate − truth)/u, the fraction within the 95 % coverage interval, and the number of values (a group's
    values within one recording are correlated, so its binomial tolerance is wider than the count suggests)."""
    if not each:
        return {}
    each = np.asarray(each, dtype=float)  # (recordings, parameters, 2)
    out = {}
    for group in dict.fromkeys(PARAMETER_GROUP):
        cols = [k for k, g in enumerate(PARAMETER_GROUP) if g == group]
        z, covered = each[:, cols, 0], each[:, cols, 1]
        ok = np.isfinite(z)
        if np.any(ok):
            out[group] = {"rms_z": float(np.sqrt(np.mean(z[ok] ** 2))), "coverage_95": float(np.mean(covered[ok])),
                          "values": int(np.count_nonzero(ok))}
    return out


def run_diagnose_check(scenario, *, null: int = 100, per_effect: int = 10, sizes=(2.0, 5.0, 10.0),
                       alpha: float = 0.05, seed: int = 0, null_draws: int = 500, progress=None,
                       effects=None) -> CheckReport:
    """Run the check (module docstring) and return its figures. *effects*: the injected effects to run (names of
    :data:`CATALOGUE_CASES` and :data:`OUT_OF_CATALOGUE`; default all); the nulls always run."""
    allowed = CATALOGUE_CASES + OUT_OF_CATALOGUE
    effects = allowed if effects is None else tuple(effects)
    unknown = [e for e in effects if e not in allowed]
    if unknown or not effects:
        raise ValueError(f"effects = {list(effects)!r}: each must be one of {', '.join(allowed)}")
    for name, value, low in (("null", null, 1), ("per_effect", per_effect, 0), ("null_draws", null_draws, 19)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
            raise ValueError(f"{name} = {value!r}: must be a whole number >= {low}")
    if not 0 < alpha < 1:
        raise ValueError(f"alpha = {alpha!r}: must be between 0 and 1")
    sizes = tuple(float(k) for k in sizes)
    if not sizes or any(not k > 0 for k in sizes):
        raise ValueError(f"sizes = {sizes!r}: each must be > 0")
    report = CheckReport(scenario.name, alpha)
    sized = sum(e in effects for e in CATALOGUE_CASES if e != "lever_arm") + sum(e in effects for e in OUT_OF_CATALOGUE)
    total = null + per_effect * (len(sizes) * sized + ("lever_arm" in effects))  # the lever arm runs once
    done = 0

    def tick():
        nonlocal done
        done += 1
        if progress is not None:
            progress(done, total)

    # the null
    alarms, selections, z_before, each_before = 0, 0, [], []
    by_family = dict.fromkeys(FAMILIES, 0)
    falsely_selected: dict[str, int] = {}
    reference = None
    ran = 0
    for i in range(null):
        s = case_seed(seed, "null", i)
        recording = simulate_and_record(scenario, seed=s, trial=0)
        _, _, truth = simulate_recording(scenario, s, 0)
        result = _attempt(report, "null", i, scenario, recording, truth, alpha, null_draws, s)
        tick()
        if result is None:
            continue
        d, z = result
        ran += 1
        reference = reference or d
        sample_rate = recording.schedule.segments[0].sample_rate
        selections += bool(d.selected)
        alarms += _alarm(d)
        for family, fired in _families(d).items():
            by_family[family] += fired
        for effect in d.selected:
            falsely_selected[effect] = falsely_selected.get(effect, 0) + 1
        z_before.append(z["before"])
        each_before.append(z["before_each"])
    report.null = {"recordings": ran, "false_alarms": alarms, "rate": _share(alarms, ran),
                   "selections": selections, "selection_rate": _share(selections, ran),
                   "binomial_99_upper_count": int(binom.ppf(0.99, ran, alpha)),
                   "by_family": by_family, "falsely_selected": falsely_selected,
                   "rms_z": _mean([v[0] for v in z_before]),
                   "coverage_95": _mean([v[1] for v in z_before]),
                   "by_group": _by_group(each_before)}
    if reference is None or per_effect == 0:
        return report
    nes = {c.effect: c for c in reference.candidates}
    unquantised = _without_quantiser(scenario)  # effects added to the samples go in before the acquisition
    for effect in (e for e in CATALOGUE_CASES if e in effects):
        candidate = nes[effect]
        usable = np.flatnonzero(np.isfinite(candidate.noise_equivalent_size))
        if effect == "lever_arm" or not usable.size:
            component, base = ("xx", 5e-3) if effect == "lever_arm" else (candidate.components[0], math.nan)
        else:
            component, base = candidate.components[usable[0]], float(candidate.noise_equivalent_size[usable[0]])
        for k in (sizes if effect != "lever_arm" else (1.0,)):
            size = base * k if effect != "lever_arm" else base
            counts = {"ran": 0, "detected": 0, "attributed": 0, "selected": {}, "rms_z_before": [],
                      "rms_z_after": [], "coverage_after": []}
            for i in range(per_effect):
                s = case_seed(seed, f"{effect}/{k}", i)
                injected = _inject(scenario, effect, component, size) if effect != "bias_drift" else scenario
                if effect == "bias_drift":  # a ramp on the sensor, before the acquisition, as the others are
                    recording = simulate_and_record(unquantised, seed=s, trial=0)
                    c = "gx gy gz ax ay az".split().index(component)
                    rate = recording.schedule.segments[0].sample_rate
                    t = np.arange(recording.samples.shape[0]) / rate
                    samples = np.array(recording.samples, dtype=float)
                    samples[:, c] += size * (t - t.mean())
                    recording = type(recording)(_acquire(scenario, samples), recording.schedule,
                                                dict(recording.attrs))
                else:
                    recording = simulate_and_record(injected, seed=s, trial=0)
                _, _, truth = simulate_recording(injected, s, 0)
                result = _attempt(report, f"{effect} x{k:g}", i, scenario, recording, truth, alpha, null_draws, s)
                tick()
                if result is None:
                    continue
                d, z = result
                counts["ran"] += 1
                counts["detected"] += _alarm(d)
                counts["attributed"] += d.selected == (effect,)
                key = "+".join(d.selected) or "(none)"
                counts["selected"][key] = counts["selected"].get(key, 0) + 1
                counts["rms_z_before"].append(z["before"][0])
                counts["rms_z_after"].append(z["after"][0])
                counts["coverage_after"].append(z["after"][1])
            report.effects.append({
                "effect": effect, "component": component, "times_noise_equivalent": k if effect != "lever_arm"
                else None, "size": size, "identifiable": candidate.identifiable, "recordings": counts["ran"],
                "detection": _share(counts["detected"], counts["ran"]),
                "attribution": _share(counts["attributed"], counts["ran"]),
                "confusion": counts["selected"], "rms_z_before": _mean(counts["rms_z_before"]),
                "rms_z_after": _mean(counts["rms_z_after"]), "coverage_after": _mean(counts["coverage_after"])})
    # outside the catalogue, each added to the simulated samples of the null scenario (module docstring)
    u_mean = float(np.median(np.sqrt(np.diag(reference.before.covariance)).reshape(-1, 6)[:, 0]))
    white = reference.before.noise.channels[0].white
    sigma_sample = float(white * math.sqrt(sample_rate)) if math.isfinite(white) else u_mean
    max_rate = max(abs(seg.rate) for seg in scenario.schedule.segments if seg.rate_known)
    first_null = case_seed(seed, "null", 0)  # the reference diagnosis's recording, before the quantiser
    clean = simulate_and_record(unquantised, seed=first_null, trial=0)
    clean_bias = float(simulate_recording(scenario, first_null, 0)[2][PARAMETER_INDEX["Bgx"]])
    for effect in (e for e in OUT_OF_CATALOGUE if e in effects):
        # the yardstick of the catalogue's: k × the size whose change of the segment means has non-centrality 1 on
        # the reference fit (mean changes are linear in the size; the clock's nearly); a burst, which changes the
        # noise and not the means, in its noise per sample
        natural, unit, natural_scale = _out_of_catalogue_size(effect, 1.0, u_mean, sigma_sample, max_rate)
        nc = _noncentrality(effect, natural, reference.before, clean, clean_bias)
        equivalent = natural / math.sqrt(nc) if nc is not None and 0 < nc < math.inf else None
        for k in sizes:
            if effect == "noise_burst":
                size, scale = k * natural, natural_scale
            elif equivalent is None:
                raise ValueError(f"effect = {effect!r}: the base model spans its change of the segment means on "
                                 f"{scenario.name!r}'s schedule (non-centrality {nc}); it has no noise-equivalent size")
            else:
                size, scale = k * equivalent, "its noise-equivalent size"
            at = _noncentrality(effect, size, reference.before, clean, clean_bias)
            flagged, named, ran = 0, 0, 0
            for i in range(per_effect):
                s = case_seed(seed, f"{effect}/{k}", i)
                # the effect acts on the sensor, before the acquisition: added to the samples of the same trial
                # without the quantiser, then quantised as the scenario's acquisition does
                recording = simulate_and_record(unquantised, seed=s, trial=0)
                _, _, truth = simulate_recording(scenario, s, 0)
                samples = _add_out_of_catalogue(effect, np.array(recording.samples, dtype=float), size, s,
                                                bias=float(truth[PARAMETER_INDEX["Bgx"]]),
                                                span=_middle_segment(recording.schedule))
                recording = type(recording)(_acquire(scenario, samples), recording.schedule, dict(recording.attrs))
                result = _attempt(report, f"{effect} x{k:g}", i, scenario, recording, truth, alpha, null_draws, s)
                tick()
                if result is None:
                    continue
                d, _ = result
                ran += 1
                flagged += _alarm(d)
                named += bool(d.selected)
            report.out_of_catalogue.append({"effect": effect, "times": k, "scale": scale, "size": size,
                                            "unit": unit, "noncentrality": at,
                                            "in_natural_units": size / natural, "natural_unit": natural_scale,
                                            "recordings": ran, "flagged_unexplained": _share(flagged, ran),
                                            "named_after_a_candidate": _share(named, ran)})
    return report


#: the relative error of a sample clock that runs fast, per unit of k (k = 5: 500 ppm)
CLOCK_ERROR_PER_K = 1e-4


def _out_of_catalogue_size(effect: str, k: float, u_mean: float, sigma_sample: float,
                           max_rate: float = math.nan) -> tuple[float, str, str]:
    """(size, unit, what k multiplies) of an out-of-catalogue effect at multiple *k*."""
    if effect == "bias_step":
        return k * u_mean, "rad/s", "the standard uncertainty of a gx segment mean (the fit's V)"
    if effect == "clock_fast":
        return k * CLOCK_ERROR_PER_K, "1", f"{CLOCK_ERROR_PER_K:g} of relative clock error"
    if effect == "noise_burst":
        return k * sigma_sample, "rad/s", "the gx noise per sample"
    if effect == "scale_change":
        return (k * u_mean / max_rate, "1", "the change of the x gyro's scale factor that moves a segment at the "
                "schedule's largest rate by a gx segment mean's standard uncertainty")
    if effect == "segment_offset":
        return k * u_mean, "rad/s", "the standard uncertainty of a gx segment mean (the fit's V)"
    raise ValueError(f"effect = {effect!r}: must be one of {', '.join(OUT_OF_CATALOGUE)}")


def _noncentrality(effect: str, size: float, fit, clean, bias: float) -> float | None:
    """The non-centrality of an out-of-catalogue effect of *size* on the reference diagnosis's base *fit*
    (:func:`plansim.diagnose.scores.noncentrality`, the metric of the candidates' noise-equivalent size): the change
    it makes to the segment means of *clean*, that fit's recording before the quantiser (*bias*: its Bgx). None for
    ``noise_burst``, which changes the noise, not the means."""
    if effect == "noise_burst":
        return None
    samples = np.array(clean.samples, dtype=float)
    changed = _add_out_of_catalogue(effect, samples.copy(), size, 0, bias=bias, span=_middle_segment(clean.schedule))
    delta = type(clean)(changed, clean.schedule, dict(clean.attrs)).segment_means() - clean.segment_means()
    return noncentrality(fit, np.asarray(delta)[np.asarray(fit.used)])


def _middle_segment(schedule) -> tuple[int, int]:
    """The (first, end) sample of the segment that holds the recording's middle sample."""
    first = segment_first_samples(schedule)
    middle = (first[-1] + schedule.segments[-1].samples) // 2
    k = int(np.searchsorted(first, middle, side="right") - 1)
    return int(first[k]), int(first[k] + schedule.segments[k].samples)


def _add_out_of_catalogue(effect: str, samples: np.ndarray, size: float, seed: int, bias: float = 0.0,
                          span: tuple[int, int] | None = None) -> np.ndarray:
    """The samples (n, 6) with an out-of-catalogue effect of *size* (:func:`_out_of_catalogue_size`) added.

    ``bias_step``: gx + size from the middle sample on. ``clock_fast``: the sensor's clock runs fast by the
    relative error *size*, so sample i holds the signal of nominal sample i·(1 + size) (linear interpolation;
    the segment table, in nominal time, drifts off the data by up to size × the run). ``noise_burst``: white
    noise of sd *size* added to gx over a tenth of the run, from 40 % of it. ``scale_change``: the x gyro's scale
    factor grows by the relative *size* from the middle sample on (gx − *bias*, the unit's Bgx, times *size* added).
    ``segment_offset``: gx + size over one segment's samples, *span* = (first, end) (the segment that holds the
    middle sample: :func:`_middle_segment`) — a rate the table did not hold, a pose knocked.
    """
    n = samples.shape[0]
    if effect == "bias_step":
        samples[n // 2:, 0] += size
    elif effect == "clock_fast":
        index = np.arange(n, dtype=float)
        where = np.minimum(index * (1.0 + size), n - 1.0)
        samples = np.column_stack([np.interp(where, index, samples[:, c]) for c in range(samples.shape[1])])
    elif effect == "noise_burst":
        start, stop = int(0.4 * n), int(0.5 * n)
        samples[start:stop, 0] += size * np.random.default_rng(seed).standard_normal(stop - start)
    elif effect == "scale_change":
        samples[n // 2:, 0] += size * (samples[n // 2:, 0] - bias)
    elif effect == "segment_offset":
        if span is None or not 0 <= span[0] < span[1] <= n:
            raise ValueError(f"span = {span!r}: segment_offset needs the (first, end) sample of one segment, "
                             f"within the {n} samples")
        samples[span[0]:span[1], 0] += size
    else:
        raise ValueError(f"effect = {effect!r}: must be one of {', '.join(OUT_OF_CATALOGUE)}")
    return samples


def check_json(report: CheckReport) -> dict:
    return {"scenario": report.scenario, "alpha": report.alpha, "null": report.null, "effects": report.effects,
            "out_of_catalogue": report.out_of_catalogue, "failures": report.failures}

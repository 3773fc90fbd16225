"""Propagation of distributions by Monte Carlo (JCGM 101:2008) and several outputs at once (JCGM 102:2011).

The model is the simulator itself: each Monte Carlo trial is one simulated calibration
(:func:`plansim.runner.run`), whose inputs — the unit's true parameters, every table and fixture
error, noise, drift, quantisation — are drawn from the scenario's distributions, and whose output
is the error ``E = Ŷ − Y`` of each of the 39 JJF 2003 parameters (the output quantity of the GUM
budgets of :mod:`plansim.uncertainty.gum`).

- :func:`numerical_tolerance` — JCGM 101 7.9.2: ``δ = ½·10^l`` for a value written ``c·10^l`` with
  ``c`` an ``n_dig``-digit integer.
- :func:`coverage_intervals` — JCGM 101 7.7: probabilistically symmetric (7.7.1) and shortest
  (7.7.2) coverage intervals from the ordered values.
- :func:`adaptive_monte_carlo` — JCGM 101 7.9.4: blocks of ``M`` trials (distinct seeds derived
  from one :class:`numpy.random.SeedSequence`), stop when twice the standard deviation of the
  block averages of the estimate, the standard uncertainty and both interval ends is within the
  numerical tolerance for every output considered.
- :func:`validate_gum` — JCGM 101 8: ``d_low = |y − U_p − y_low|``, ``d_high = |y + U_p − y_high|``
  against ``δ`` of the GUM ``u(y)``.
- :func:`joint_region_check` — JCGM 102 7.7 and 6.5: the hyper-ellipsoidal coverage region of
  several outputs (e.g. the nine elements of Kg) against the box of their marginal ``k = 2``
  intervals.
- :func:`coverage_against_truth` — the fraction of trials whose interval ``estimate ± U`` contains
  the true value (the simulator knows it).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy import special  # the quantiles themselves: scipy.stats takes 1.4 s to import

from plansim.model.parameters import N_PARAMETERS, PARAMETER_INDEX, PARAMETER_NAMES
from plansim.config import Scenario

__all__ = [
    "DEFAULT_DIGITS",
    "DEFAULT_TRIALS_PER_BLOCK",
    "JointRegionCheck",
    "MonteCarloResult",
    "ValidationOutcome",
    "adaptive_monte_carlo",
    "block_seeds",
    "correlation_matrix",
    "coverage_against_truth",
    "coverage_intervals",
    "coverage_tolerance",
    "joint_region_check",
    "minimum_block_size",
    "numerical_tolerance",
    "validate_gum",
]

#: JCGM 101 7.9.2: n_dig is "usually 1 or 2"; 1 keeps the run affordable (see docs/uncertainty.md).
DEFAULT_DIGITS = 1
#: JCGM 101 7.9.4 b): M = max(J, 10⁴) with J = ⌈100/(1 − p)⌉ (2000 for p = 0.95).
DEFAULT_TRIALS_PER_BLOCK = 10_000

ProgressCallback = Callable[[int, int, float], None]


# ----------------------------------------------------------------------------- JCGM 101 building blocks


def numerical_tolerance(value, digits: int = DEFAULT_DIGITS):
    """Numerical tolerance of a value, JCGM 101 7.9.2.

    Write ``|value| = c × 10^l`` with ``c`` an integer of *digits* decimal digits (n_dig); then
    ``δ = ½ × 10^l``. Example (7.9.2): ``u = 0.002 26`` with n_dig = 2 gives ``c = 23``,
    ``l = −4``, ``δ = 0.000 05``.

    Parameters
    ----------
    value : float or array_like
        The value (an uncertainty, usually).
    digits : int
        n_dig ≥ 1.

    Returns
    -------
    float or ndarray
        ``δ``; 0 for a zero value.
    """
    if isinstance(digits, bool) or not isinstance(digits, (int, np.integer)) or digits < 1:
        raise ValueError(f"digits = {digits!r}: n_dig must be a whole number >= 1 (JCGM 101 7.9.2)")
    z = np.abs(np.asarray(value, dtype=float))
    if not np.all(np.isfinite(z)):
        raise ValueError(f"value = {value!r}: must be finite")
    with np.errstate(divide="ignore"):
        exponent = np.floor(np.log10(np.where(z > 0, z, 1.0))) - digits + 1
    c = np.round(z / 10.0**exponent)
    exponent = np.where(c >= 10.0**digits, exponent + 1, exponent)  # 9.96 -> 10.0: one more digit
    delta = np.where(z > 0, 0.5 * 10.0**exponent, 0.0)
    return float(delta) if np.ndim(delta) == 0 else delta


def _check_probability(p) -> float:
    if isinstance(p, bool) or not isinstance(p, (int, float)) or not 0.0 < p < 1.0:
        raise ValueError(f"coverage_probability = {p!r}: must lie strictly between 0 and 1")
    return float(p)


def coverage_intervals(values, coverage_probability: float = 0.95) -> dict[str, np.ndarray]:
    """Probabilistically symmetric and shortest coverage intervals, JCGM 101 7.7.

    With the ``M`` values sorted, ``q = pM`` if that is an integer, else ``⌊pM + ½⌋``. The
    probabilistically symmetric interval (7.7.1) is ``[y_(r), y_(r+q)]`` with ``r = (M − q)/2`` if
    that is an integer, else ``⌊(M − q + 1)/2⌋``; the shortest (7.7.2) is the ``[y_(r), y_(r+q)]``
    of least length over ``r = 1 … M − q`` (1-based order statistics).

    Parameters
    ----------
    values : (M,) or (M, n) array_like
        Monte Carlo values of one or several outputs (columns).
    coverage_probability : float
        ``p``.

    Returns
    -------
    dict
        ``low``, ``high`` (symmetric) and ``shortest_low``, ``shortest_high``, each of shape (n,)
        (or scalars for 1-D input).
    """
    p = _check_probability(coverage_probability)
    y = np.asarray(values, dtype=float)
    one = y.ndim == 1
    if one:
        y = y[:, None]
    if y.ndim != 2 or y.shape[0] < 2:
        raise ValueError(f"values: shape {np.shape(values)}; expected (M,) or (M, n) with M >= 2")
    m = y.shape[0]
    pm = p * m
    q = int(round(pm)) if abs(pm - round(pm)) < 1e-9 else int(math.floor(pm + 0.5))
    if q >= m:
        raise ValueError(f"{m} values are too few for a {p:.0%} coverage interval (JCGM 101 7.2.2: M >> 1/(1 − p))")
    rest = m - q
    r = rest // 2 if rest % 2 == 0 else (rest + 1) // 2
    ordered = np.sort(y, axis=0)
    low, high = ordered[r - 1], ordered[r - 1 + q]
    lengths = ordered[q:] - ordered[:-q]  # r = 1 … M − q: y_(r+q) − y_(r)
    best = np.argmin(lengths, axis=0)
    cols = np.arange(y.shape[1])
    short_low, short_high = ordered[best, cols], ordered[best + q, cols]
    out = {"low": low, "high": high, "shortest_low": short_low, "shortest_high": short_high}
    if one:
        out = {k: float(v[0]) for k, v in out.items()}
    return out


def minimum_block_size(coverage_probability: float = 0.95) -> int:
    """JCGM 101 7.9.4 b): ``M = max(J, 10⁴)``, ``J`` the smallest integer ≥ ``100/(1 − p)``."""
    p = _check_probability(coverage_probability)
    return max(int(math.ceil(100.0 / (1.0 - p) - 1e-9)), 10_000)


def block_seeds(seed: int, count: int, start: int = 0) -> list[int]:
    """Seeds of blocks ``start … start + count − 1``: one child of ``SeedSequence(seed)`` per block.

    ``SeedSequence(seed).spawn`` gives statistically independent streams; each block's seed is
    the first 64-bit word of its child's state, so block *h* has the same seed however many blocks
    run.
    """
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed = {seed!r}: expected a whole number >= 0")
    children = np.random.SeedSequence(int(seed)).spawn(start + count)[start:]
    return [int(child.generate_state(1, dtype=np.uint64)[0]) for child in children]


def coverage_tolerance(n: int, coverage_probability: float = 0.95, z: float = 4.0) -> float:
    """``z·sqrt(p(1 − p)/n)``: *z* binomial standard deviations of an observed coverage of *n* trials."""
    p = _check_probability(coverage_probability)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError(f"n = {n!r}: expected a whole number >= 1")
    return z * math.sqrt(p * (1.0 - p) / n)


def coverage_against_truth(errors, half_width) -> np.ndarray:
    """Fraction of trials whose interval ``estimate ± half_width`` contains the truth (``|E| ≤ U``).

    Parameters
    ----------
    errors : (M, n) array_like
        ``estimate − truth`` per trial and output.
    half_width : (n,) array_like
        The expanded uncertainty ``U`` claimed for each output (``nan``: no claim → ``nan``).
    """
    e = np.asarray(errors, dtype=float)
    u = np.asarray(half_width, dtype=float)
    if e.ndim != 2 or u.shape != (e.shape[1],):
        raise ValueError(f"errors shape {e.shape} and half_width shape {u.shape}: expected (M, n) and (n,)")
    covered = np.mean(np.abs(e) <= np.where(np.isnan(u), 0.0, u)[None, :], axis=0)
    return np.where(np.isnan(u), np.nan, covered)


def correlation_matrix(values) -> np.ndarray:
    """Correlation matrix of the outputs from the Monte Carlo values (JCGM 102 7); 0 where an output is constant."""
    v = np.asarray(values, dtype=float)
    if v.ndim != 2 or v.shape[0] < 2:
        raise ValueError(f"values: shape {v.shape}; expected (M, n) with M >= 2")
    cov = np.cov(v, rowvar=False)
    s = np.sqrt(np.diag(cov))
    scale = np.where(s > 0, s, np.inf)
    r = cov / np.outer(scale, scale)
    np.fill_diagonal(r, np.where(s > 0, 1.0, 0.0))
    return r


# ----------------------------------------------------------------------------- adaptive Monte Carlo


@dataclass(frozen=True)
class MonteCarloResult:
    """The result of the adaptive Monte Carlo procedure, JCGM 101 7.9.4 (output: errors, SI).

    Attributes
    ----------
    scenario : str
        Scenario name.
    seed : int
        Root seed of the block seeds.
    trials_per_block : int
        ``M``.
    blocks : int
        ``h`` at the stop.
    digits : int
        ``n_dig``.
    coverage_probability : float
        ``p``.
    converged : bool
        True if the 7.9.4 rule stopped the run; False if ``max_trials`` did.
    monitored : tuple of str
        The outputs whose numerical tolerance decided the stop.
    estimate, standard_uncertainty : (39,) ndarray
        ``y`` and ``u(y)`` from all ``h·M`` values (7.6).
    low, high : (39,) ndarray
        Probabilistically symmetric coverage interval (7.7.1).
    shortest_low, shortest_high : (39,) ndarray
        Shortest coverage interval (7.7.2).
    tolerance : (39,) ndarray
        ``δ`` at the stop: from ``u(y)`` by 7.9.2, or as given (validation, 8.2).
    block_sd : (4, 39) ndarray
        ``s_y, s_u, s_low, s_high``: standard deviations of the block averages (7.9.4 f-g).
    history : (h, 4, 39) ndarray
        Each block's ``y, u, y_low, y_high``.
    skewness, excess_kurtosis : (39,) ndarray
        Shape of the output distributions (0, 0 for a Gaussian; −1.2 excess for a rectangular).
    errors : (h·M, 39) ndarray
        Every Monte Carlo value (estimate − truth, SI).
    path : str
        Simulation path of the runs.
    """

    scenario: str
    seed: int
    trials_per_block: int
    blocks: int
    digits: int
    coverage_probability: float
    converged: bool
    monitored: tuple[str, ...]
    estimate: np.ndarray
    standard_uncertainty: np.ndarray
    low: np.ndarray
    high: np.ndarray
    shortest_low: np.ndarray
    shortest_high: np.ndarray
    tolerance: np.ndarray
    block_sd: np.ndarray
    history: np.ndarray
    skewness: np.ndarray
    excess_kurtosis: np.ndarray
    errors: np.ndarray = dataclasses.field(repr=False)
    path: str = ""

    @property
    def trials(self) -> int:
        """``h·M``."""
        return self.blocks * self.trials_per_block

    def tolerance_met(self) -> np.ndarray:
        """(39,) True where ``2·s ≤ δ`` for all four block quantities (7.9.4 j)."""
        return np.all(2.0 * self.block_sd <= self.tolerance[None, :], axis=0)

    def index(self, name: str) -> int:
        if name not in PARAMETER_INDEX:
            raise ValueError(f"unknown parameter {name!r}; known: {', '.join(PARAMETER_NAMES)}")
        return PARAMETER_INDEX[name]


def _block_statistics(values: np.ndarray, p: float) -> np.ndarray:
    """(4, n): y, u, y_low, y_high of one block (7.6, 7.7.1)."""
    intervals = coverage_intervals(values, p)
    return np.stack([values.mean(axis=0), values.std(axis=0, ddof=1), intervals["low"], intervals["high"]])


def _parameter_selection(parameters) -> np.ndarray:
    if parameters is None:
        return np.arange(N_PARAMETERS)
    if isinstance(parameters, str) or not isinstance(parameters, Sequence):
        raise TypeError(f"parameters = {parameters!r}: expected a sequence of parameter names")
    out = []
    for name in parameters:
        if name not in PARAMETER_INDEX:
            raise ValueError(f"parameters: unknown parameter {name!r}; known: {', '.join(PARAMETER_NAMES)}")
        out.append(PARAMETER_INDEX[name])
    if not out:
        raise ValueError("parameters: name at least one parameter to monitor")
    return np.array(sorted(set(out)))


def adaptive_monte_carlo(scenario: Scenario, *, digits: int = DEFAULT_DIGITS,
                         trials_per_block: int = DEFAULT_TRIALS_PER_BLOCK, max_trials: int = 1_000_000,
                         seed: int | None = None, tolerance=None, parameters: Sequence[str] | None = None,
                         coverage_probability: float = 0.95, path: str = "auto",
                         progress: ProgressCallback | None = None) -> MonteCarloResult:
    """Adaptive Monte Carlo procedure of JCGM 101 7.9.4 on the scenario's calibration.

    a) ``n_dig`` = *digits*; b) ``M`` = *trials_per_block* (7.9.4 b) asks ``max(J, 10⁴)``,
    :func:`minimum_block_size`; smaller blocks are allowed for tests); c)-d) run block *h* with its
    own seed (:func:`block_seeds`) and form its ``y, u, y_low, y_high``; e) at least two blocks;
    f)-g) the standard deviation of each average, ``s² = Σ(x_r − x̄)²/(h(h − 1))``; h)-i) ``δ`` from
    ``u(y)`` of all ``h·M`` values by 7.9.2 (or *tolerance*, e.g. ``δ/5`` of the GUM u for
    validation, JCGM 101 8.2); j) stop when ``2s ≤ δ`` for the four quantities of every monitored
    output, else next block; k) results from all ``h·M`` values.

    Parameters
    ----------
    scenario : Scenario
        The calibration to simulate.
    digits : int
        ``n_dig`` (7.9.2).
    trials_per_block : int
        ``M`` (≥ 2/(1 − p) so that a block has a 95 % interval).
    max_trials : int
        Stop here even if the tolerance is not met (``converged`` is then False).
    seed : int, optional
        Root seed; default the scenario's.
    tolerance : float or (39,) array_like, optional
        Fixed numerical tolerances instead of the 7.9.2 ``δ`` of the MCM's own ``u``.
    parameters : sequence of str, optional
        The outputs whose tolerance decides the stop (default all 39).
    coverage_probability : float
        ``p``.
    path : {"auto", "sample", "segment"}
        Simulation path (:func:`plansim.runner.run`).
    progress : callable, optional
        ``progress(trials_done, blocks, worst)`` after each block, ``worst`` = max ``2s/δ``.

    Returns
    -------
    MonteCarloResult
    """
    from plansim.runner import run

    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario = {scenario!r}: expected a plansim.scenario.Scenario")
    p = _check_probability(coverage_probability)
    numerical_tolerance(1.0, digits)  # validates digits
    for name, value in (("trials_per_block", trials_per_block), ("max_trials", max_trials)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
            raise ValueError(f"{name} = {value!r}: expected a whole number >= 1")
    if trials_per_block * (1.0 - p) < 2.0:
        raise ValueError(f"trials_per_block = {trials_per_block}: a block needs at least 2/(1 − p) = "
                         f"{math.ceil(2.0 / (1.0 - p))} trials for its {p:.0%} coverage interval")
    if max_trials < 2 * trials_per_block:
        raise ValueError(f"max_trials = {max_trials}: the adaptive procedure needs at least two blocks "
                         f"(2 × {trials_per_block}); JCGM 101 7.9.4 e)")
    seed = scenario.seed if seed is None else seed
    monitored = _parameter_selection(parameters)
    fixed = None
    if tolerance is not None:
        fixed = np.broadcast_to(np.asarray(tolerance, dtype=float), (N_PARAMETERS,)).copy()
        if np.any(~np.isfinite(fixed)) or np.any(fixed < 0):
            raise ValueError(f"tolerance = {tolerance!r}: must be finite and >= 0")
    blocks: list[np.ndarray] = []
    history: list[np.ndarray] = []
    max_blocks = max_trials // trials_per_block
    converged = False
    used_path = ""
    delta = np.zeros(N_PARAMETERS)
    sd = np.zeros((4, N_PARAMETERS))
    h = 0
    while h < max_blocks:
        (block_seed,) = block_seeds(seed, 1, start=h)
        results = run(scenario, trials=trials_per_block, seed=block_seed, path=path)
        used_path = results.attrs["simulation_path"]
        values = np.ascontiguousarray(results["error"].values)
        blocks.append(values)
        history.append(_block_statistics(values, p))
        h += 1
        if h < 2:
            continue
        stacked = np.stack(history)  # (h, 4, 39)
        sd = stacked.std(axis=0, ddof=1) / math.sqrt(h)
        if fixed is not None:
            delta = fixed
        else:
            u_all = np.concatenate(blocks).std(axis=0, ddof=1)
            delta = numerical_tolerance(u_all, digits)
        twice = 2.0 * sd[:, monitored]
        d = np.broadcast_to(delta[monitored], twice.shape)
        ratio = np.where(d > 0, twice / np.where(d > 0, d, 1.0), np.where(twice > 0, np.inf, 0.0))
        worst = float(np.max(ratio))
        if progress is not None:
            progress(h * trials_per_block, h, worst)
        if worst <= 1.0:
            converged = True
            break
    errors = np.concatenate(blocks)
    intervals = coverage_intervals(errors, p)
    centred = errors - errors.mean(axis=0)
    u = errors.std(axis=0, ddof=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        skew = np.where(u > 0, np.mean(centred**3, axis=0) / u**3, 0.0)
        kurt = np.where(u > 0, np.mean(centred**4, axis=0) / u**4 - 3.0, 0.0)
    if fixed is None:
        delta = numerical_tolerance(u, digits)
    return MonteCarloResult(
        scenario=scenario.name, seed=int(seed), trials_per_block=int(trials_per_block), blocks=h, digits=int(digits),
        coverage_probability=p, converged=converged, monitored=tuple(PARAMETER_NAMES[i] for i in monitored),
        estimate=errors.mean(axis=0), standard_uncertainty=u, low=intervals["low"], high=intervals["high"],
        shortest_low=intervals["shortest_low"], shortest_high=intervals["shortest_high"], tolerance=np.asarray(delta),
        block_sd=sd, history=np.stack(history), skewness=skew, excess_kurtosis=kurt, errors=errors, path=used_path)


# ----------------------------------------------------------------------------- validation of the GUM (JCGM 101 8)


@dataclass(frozen=True)
class ValidationOutcome:
    """JCGM 101 8.1 comparison of the GUM interval ``y ± U_p`` with the MCM interval, per output.

    Attributes
    ----------
    delta : (n,) ndarray
        ``δ`` of the GUM ``u(y)`` (7.9.2, 8.1.1).
    d_low, d_high : (n,) ndarray
        ``|y − U_p − y_low|`` and ``|y + U_p − y_high|`` (8.1.2).
    validated : (n,) ndarray of bool
        ``d_low ≤ δ`` and ``d_high ≤ δ`` (8.1.3).
    """

    delta: np.ndarray
    d_low: np.ndarray
    d_high: np.ndarray
    validated: np.ndarray


def validate_gum(gum_estimate, gum_expanded, gum_standard_uncertainty, mcm_low, mcm_high,
                 digits: int = DEFAULT_DIGITS) -> ValidationOutcome:
    """Validation of the GUM uncertainty framework using MCM, JCGM 101 8.

    Parameters
    ----------
    gum_estimate, gum_expanded, gum_standard_uncertainty : array_like
        ``y``, ``U_p`` and ``u(y)`` from the GUM.
    mcm_low, mcm_high : array_like
        The MCM coverage interval (probabilistically symmetric, 7.7.1).
    digits : int
        ``n_dig`` of ``δ``.

    Returns
    -------
    ValidationOutcome
    """
    y, U, u, low, high = (np.atleast_1d(np.asarray(x, dtype=float))
                          for x in (gum_estimate, gum_expanded, gum_standard_uncertainty, mcm_low, mcm_high))
    shapes = {x.shape for x in (y, U, u, low, high)}
    if len(shapes) != 1:
        raise ValueError(f"validate_gum: the arrays have different shapes {sorted(shapes)}")
    delta = np.atleast_1d(numerical_tolerance(u, digits))
    d_low = np.abs(y - U - low)
    d_high = np.abs(y + U - high)
    return ValidationOutcome(delta=delta, d_low=d_low, d_high=d_high, validated=(d_low <= delta) & (d_high <= delta))


# ----------------------------------------------------------------------------- several outputs (JCGM 102)


@dataclass(frozen=True)
class JointRegionCheck:
    """The joint coverage region of several outputs against their marginal intervals (JCGM 102).

    Attributes
    ----------
    parameters : tuple of str
        The outputs (e.g. the nine elements of Kg).
    trials : int
        Monte Carlo values used.
    coverage_probability : float
        ``p``.
    dimension : int
        Rank of the outputs' covariance (degrees of freedom of the χ² quantile).
    chi2_quantile : float
        ``χ²_n(p)``: ``k_p²`` of the hyper-ellipsoid of a multivariate Gaussian (JCGM 102 6.5).
    mc_k : float
        ``k_p`` from the Monte Carlo (JCGM 102 7.7): square root of the p-quantile of the
        Mahalanobis distances ``(e − ē)ᵀ V⁻¹ (e − ē)`` with the MCM mean and covariance.
    fraction_in_ellipsoid : float
        Fraction of trials inside the ellipsoid ``χ²_n(p)`` (≈ p when the outputs are Gaussian).
    marginal_k : float
        Coverage factor of the marginal intervals (2).
    fraction_all_marginal : float
        Fraction of trials with *all* outputs inside ``ē_i ± k·s_i`` at once.
    box_k : float
        The ``k`` of a box ``ē_i ± k·s_i`` that holds the fraction p of the trials jointly.
    gum_fraction_in_ellipsoid : float
        Fraction of trials whose error lies inside the GUM ellipsoid ``eᵀ V_gum⁻¹ e ≤ χ²_n(p)``
        about the truth (coverage of the truth by the GUM joint region); ``nan`` if not given.
    tolerance : float
        ``4·sqrt(p(1 − p)/trials)``.
    misleading : bool
        True if the marginal ``k = 2`` intervals jointly cover less than ``p − tolerance``.
    message : str
        The finding in words.
    """

    parameters: tuple[str, ...]
    trials: int
    coverage_probability: float
    dimension: int
    chi2_quantile: float
    mc_k: float
    fraction_in_ellipsoid: float
    marginal_k: float
    fraction_all_marginal: float
    box_k: float
    gum_fraction_in_ellipsoid: float
    tolerance: float
    misleading: bool
    message: str

    def as_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["parameters"] = list(self.parameters)
        return d


def _mahalanobis(centred: np.ndarray, covariance: np.ndarray) -> tuple[np.ndarray, int]:
    """Squared Mahalanobis distances with the pseudo-inverse (rank-deficient covariance allowed)."""
    w, v = np.linalg.eigh(0.5 * (covariance + covariance.T))
    keep = w > max(w.max(), 0.0) * 1e-12
    z = centred @ v[:, keep] / np.sqrt(w[keep])
    return np.sum(z**2, axis=1), int(np.count_nonzero(keep))


def joint_region_check(values, parameters: Sequence[str], coverage_probability: float = 0.95,
                       gum_covariance=None, marginal_k: float = 2.0) -> JointRegionCheck:
    """Check several outputs jointly (JCGM 102 7.7, 6.5): ellipsoid versus the box of marginal intervals.

    Parameters
    ----------
    values : (M, 39) array_like
        Monte Carlo errors of all parameters.
    parameters : sequence of str
        The outputs considered together (e.g. the nine ``Kg**``).
    coverage_probability : float
        ``p``.
    gum_covariance : (39, 39) array_like, optional
        The GUM covariance of the errors, for the coverage of the truth by the GUM ellipsoid.
    marginal_k : float
        ``k`` of the marginal intervals a certificate prints (2).
    """
    p = _check_probability(coverage_probability)
    idx = _parameter_selection(list(parameters))
    names = tuple(PARAMETER_NAMES[i] for i in idx)
    v = np.asarray(values, dtype=float)
    if v.ndim != 2 or v.shape[1] != N_PARAMETERS or v.shape[0] < 2 * len(idx):
        raise ValueError(f"values: shape {v.shape}; expected (M, {N_PARAMETERS}) with M >= {2 * len(idx)}")
    e = v[:, idx]
    mean = e.mean(axis=0)
    cov = np.cov(e, rowvar=False)
    d2, rank = _mahalanobis(e - mean, cov)
    chi2 = float(special.chdtri(rank, 1.0 - p))  # the χ² quantile p
    inside = float(np.mean(d2 <= chi2))
    s = np.sqrt(np.diag(cov))
    s_safe = np.where(s > 0, s, np.inf)
    scaled = np.max(np.abs(e - mean) / s_safe, axis=1)
    all_marginal = float(np.mean(scaled <= marginal_k))
    box_k = float(np.quantile(scaled, p))
    mc_k = float(math.sqrt(np.quantile(d2, p)))
    gum_inside = math.nan
    if gum_covariance is not None:
        g = np.asarray(gum_covariance, dtype=float)
        if g.shape != (N_PARAMETERS, N_PARAMETERS):
            raise ValueError(f"gum_covariance: shape {g.shape}; expected ({N_PARAMETERS}, {N_PARAMETERS})")
        gd2, grank = _mahalanobis(e, g[np.ix_(idx, idx)])
        gum_inside = float(np.mean(gd2 <= special.chdtri(grank, 1.0 - p)))
    n = e.shape[0]
    tol = coverage_tolerance(n, p)
    misleading = all_marginal < p - tol
    if misleading:
        message = (f"marginal k = {marginal_k:g} intervals of the {len(idx)} outputs hold all of them at once in only "
                   f"{all_marginal:.1%} of the trials (not {p:.0%}); a joint {p:.0%} statement needs the "
                   f"ellipsoid (k_p = {mc_k:.3g}, JCGM 102 7.7) or a box with k = {box_k:.3g}")
    else:
        message = (f"marginal k = {marginal_k:g} intervals hold all {len(idx)} outputs at once in {all_marginal:.1%} "
                   f"of the trials")
    return JointRegionCheck(parameters=names, trials=n, coverage_probability=p, dimension=rank, chi2_quantile=chi2,
                            mc_k=mc_k, fraction_in_ellipsoid=inside, marginal_k=float(marginal_k),
                            fraction_all_marginal=all_marginal, box_k=box_k, gum_fraction_in_ellipsoid=gum_inside,
                            tolerance=tol, misleading=misleading, message=message)

"""JCGM 101:2008 7.9: the adaptive Monte Carlo procedure, its numerical tolerance and block seeds.

The model is passed in as a callable ``simulate(trials, seed) -> (trials, m) array`` of output
values (JCGM 101 7.5: the model evaluated at ``trials`` draws from the inputs' distributions),
so this module knows nothing of what is simulated.

- :func:`numerical_tolerance` — 7.9.2: ``δ = ½·10^l`` for a value written ``c·10^l`` with ``c`` an
  ``n_dig``-digit integer.
- :func:`minimum_block_size` — 7.9.4 b): ``M = max(J, 10⁴)``.
- :func:`block_seeds` — one independent seed per block, from one :class:`numpy.random.SeedSequence`.
- :func:`adaptive_monte_carlo` — 7.9.4: blocks of ``M`` values until twice the standard deviation
  of the block averages of the estimate, the standard uncertainty and both interval ends is within
  the numerical tolerance for every monitored output.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from plansim.uncertainty.metrology.checks import check_count, check_probability
from plansim.uncertainty.metrology.intervals import coverage_intervals

__all__ = [
    "DEFAULT_DIGITS",
    "DEFAULT_TRIALS_PER_BLOCK",
    "MonteCarloResult",
    "ProgressCallback",
    "Simulate",
    "adaptive_monte_carlo",
    "block_seeds",
    "minimum_block_size",
    "numerical_tolerance",
    "select_outputs",
]

#: JCGM 101 7.9.2: n_dig is "usually 1 or 2"; 1 keeps the run affordable.
DEFAULT_DIGITS = 1
#: JCGM 101 7.9.4 b): M = max(J, 10⁴) with J = ⌈100/(1 − p)⌉ (2000 for p = 0.95).
DEFAULT_TRIALS_PER_BLOCK = 10_000

#: ``simulate(trials, seed)``: the output values of *trials* Monte Carlo trials, shape (trials, m).
Simulate = Callable[[int, int], np.ndarray]
#: ``progress(trials_done, blocks, worst)``, ``worst`` = the largest ``2s/δ`` over the monitored outputs.
ProgressCallback = Callable[[int, int, float], None]


def numerical_tolerance(value, digits: int = DEFAULT_DIGITS):
    """Numerical tolerance of a value, JCGM 101 7.9.2.

    Write ``|value| = c × 10^l`` with ``c`` an integer of *digits* decimal digits (n_dig); then
    ``δ = ½ × 10^l``. Example (7.9.2): ``u = 0.002 26`` with n_dig = 2 gives ``c = 23``,
    ``l = −4``, ``δ = 0.000 05``.

    Parameters
    ----------
    value : float or array_like
        The value (an uncertainty, usually); finite.
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


def minimum_block_size(coverage_probability: float = 0.95) -> int:
    """JCGM 101 7.9.4 b): ``M = max(J, 10⁴)``, ``J`` the smallest integer ≥ ``100/(1 − p)``."""
    p = check_probability(coverage_probability)
    return max(int(math.ceil(100.0 / (1.0 - p) - 1e-9)), 10_000)


def block_seeds(seed: int, count: int, start: int = 0) -> list[int]:
    """Seeds of blocks ``start … start + count − 1``: one child of ``SeedSequence(seed)`` per block.

    ``SeedSequence(seed).spawn`` gives statistically independent streams (JCGM 101 C.3 asks for
    independent pseudo-random sequences); each block's seed is the first 64-bit word of its
    child's state, so block *h* has the same seed however many blocks run.

    Parameters
    ----------
    seed : int
        Root seed, a whole number >= 0.
    count, start : int
        Which blocks.

    Returns
    -------
    list of int
    """
    check_count(seed, "seed", 0)
    children = np.random.SeedSequence(int(seed)).spawn(start + count)[start:]
    return [int(child.generate_state(1, dtype=np.uint64)[0]) for child in children]


def select_outputs(selection, names: Sequence[str], argument: str = "monitor") -> np.ndarray:
    """Sorted column indices of the outputs named in *selection* (all of *names* if None).

    Raises
    ------
    TypeError
        *selection* is a string or not a sequence.
    ValueError
        An unknown name (the message lists the known ones), or an empty selection.
    """
    if selection is None:
        return np.arange(len(names))
    if isinstance(selection, str) or not isinstance(selection, Sequence):
        raise TypeError(f"{argument} = {selection!r}: expected a sequence of output names")
    index = {name: k for k, name in enumerate(names)}
    out = []
    for name in selection:
        if name not in index:
            raise ValueError(f"{argument}: unknown output {name!r}; known: {', '.join(names)}")
        out.append(index[name])
    if not out:
        raise ValueError(f"{argument}: name at least one output")
    return np.array(sorted(set(out)))


@dataclass(frozen=True)
class MonteCarloResult:
    """The result of the adaptive Monte Carlo procedure, JCGM 101 7.9.4.

    Attributes
    ----------
    names : tuple of str
        The outputs, in the order of the columns.
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
        True if the 7.9.4 j) rule stopped the run; False if ``max_trials`` did.
    monitored : tuple of str
        The outputs whose numerical tolerance decided the stop.
    estimate, standard_uncertainty : (m,) ndarray
        ``y`` and ``u(y)`` from all ``h·M`` values (7.6).
    low, high : (m,) ndarray
        Probabilistically symmetric coverage interval (7.7.1).
    shortest_low, shortest_high : (m,) ndarray
        Shortest coverage interval (7.7.2).
    tolerance : (m,) ndarray
        ``δ`` at the stop: from ``u(y)`` by 7.9.2, or as given (e.g. for validation, 8.2).
    block_sd : (4, m) ndarray
        ``s_y, s_u, s_low, s_high``: standard deviations of the block averages (7.9.4 f)-g)).
    history : (h, 4, m) ndarray
        Each block's ``y, u, y_low, y_high``.
    skewness, excess_kurtosis : (m,) ndarray
        Shape of the output distributions (0, 0 for a Gaussian; −1.2 excess for a rectangular).
    values : (h·M, m) ndarray
        Every Monte Carlo value of the outputs (7.5).
    """

    names: tuple[str, ...]
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
    values: np.ndarray = dataclasses.field(repr=False)

    @property
    def trials(self) -> int:
        """``h·M``."""
        return self.blocks * self.trials_per_block

    def tolerance_met(self) -> np.ndarray:
        """(m,) True where ``2·s ≤ δ`` for all four block quantities (7.9.4 j))."""
        return np.all(2.0 * self.block_sd <= self.tolerance[None, :], axis=0)

    def index(self, name: str) -> int:
        """Column of the output *name*."""
        if name not in self.names:
            raise ValueError(f"unknown output {name!r}; known: {', '.join(self.names)}")
        return self.names.index(name)


def _block_statistics(values: np.ndarray, p: float) -> np.ndarray:
    """(4, m): y, u, y_low, y_high of one block (7.6, 7.7.1)."""
    intervals = coverage_intervals(values, p)
    return np.stack([values.mean(axis=0), values.std(axis=0, ddof=1), intervals["low"], intervals["high"]])


def adaptive_monte_carlo(simulate: Simulate, names: Sequence[str], *, seed: int, digits: int = DEFAULT_DIGITS,
                         trials_per_block: int = DEFAULT_TRIALS_PER_BLOCK, max_trials: int = 1_000_000,
                         tolerance=None, monitor: Sequence[str] | None = None, coverage_probability: float = 0.95,
                         progress: ProgressCallback | None = None) -> MonteCarloResult:
    """Adaptive Monte Carlo procedure of JCGM 101 7.9.4.

    a) ``n_dig`` = *digits*; b) ``M`` = *trials_per_block* (7.9.4 b) asks ``max(J, 10⁴)``,
    :func:`minimum_block_size`; smaller blocks are allowed for tests); c)-d) run block *h* with its
    own seed (:func:`block_seeds`) and form its ``y, u, y_low, y_high``; e) at least two blocks;
    f)-g) the standard deviation of each average, ``s² = Σ(x_r − x̄)²/(h(h − 1))``; h)-i) ``δ`` from
    ``u(y)`` of all ``h·M`` values by 7.9.2 (or *tolerance*, e.g. a fraction of ``δ`` of the GUM u
    for validation, JCGM 101 8.2); j) stop when ``2s ≤ δ`` for the four quantities of every
    monitored output, else next block; k) results from all ``h·M`` values.

    Parameters
    ----------
    simulate : callable
        ``simulate(trials, seed) -> (trials, m)`` array of output values; called once per block.
    names : sequence of str
        The ``m`` outputs, in the order of the columns.
    seed : int
        Root seed of the block seeds (whole number >= 0).
    digits : int
        ``n_dig`` (7.9.2).
    trials_per_block : int
        ``M`` (≥ 2/(1 − p) so that a block has a p coverage interval).
    max_trials : int
        Stop here even if the tolerance is not met (``converged`` is then False).
    tolerance : float or (m,) array_like, optional
        Fixed numerical tolerances instead of the 7.9.2 ``δ`` of the MCM's own ``u``.
    monitor : sequence of str, optional
        The outputs whose tolerance decides the stop (default all).
    coverage_probability : float
        ``p``.
    progress : callable, optional
        ``progress(trials_done, blocks, worst)`` after each block from the second on, ``worst`` =
        the largest ``2s/δ``.

    Returns
    -------
    MonteCarloResult

    Raises
    ------
    TypeError
        *simulate* is not callable, or *monitor* is not a sequence of names.
    ValueError
        Bad counts, digits, probability, tolerance or names; a block of the wrong shape.
    """
    if not callable(simulate):
        raise TypeError(f"simulate = {simulate!r}: expected a callable simulate(trials, seed) -> (trials, m) array")
    names = tuple(names)
    if not names or not all(isinstance(n, str) for n in names):
        raise TypeError(f"names = {names!r}: expected a non-empty sequence of output names")
    m = len(names)
    p = check_probability(coverage_probability)
    numerical_tolerance(1.0, digits)  # validates digits
    check_count(trials_per_block, "trials_per_block")
    check_count(max_trials, "max_trials")
    check_count(seed, "seed", 0)
    if trials_per_block * (1.0 - p) < 2.0:
        raise ValueError(f"trials_per_block = {trials_per_block}: a block needs at least 2/(1 − p) = "
                         f"{math.ceil(2.0 / (1.0 - p))} trials for its {p:.0%} coverage interval")
    if max_trials < 2 * trials_per_block:
        raise ValueError(f"max_trials = {max_trials}: the adaptive procedure needs at least two blocks "
                         f"(2 × {trials_per_block}); JCGM 101 7.9.4 e)")
    monitored = select_outputs(monitor, names)
    fixed = None
    if tolerance is not None:
        fixed = np.broadcast_to(np.asarray(tolerance, dtype=float), (m,)).copy()
        if np.any(~np.isfinite(fixed)) or np.any(fixed < 0):
            raise ValueError(f"tolerance = {tolerance!r}: must be finite and >= 0")
    blocks: list[np.ndarray] = []
    history: list[np.ndarray] = []
    max_blocks = max_trials // trials_per_block
    converged = False
    delta = np.zeros(m)
    sd = np.zeros((4, m))
    h = 0
    while h < max_blocks:
        (block_seed,) = block_seeds(seed, 1, start=h)
        values = np.ascontiguousarray(simulate(trials_per_block, block_seed), dtype=float)
        if values.shape != (trials_per_block, m):
            raise ValueError(f"simulate({trials_per_block}, {block_seed}) returned shape {values.shape}; "
                             f"expected ({trials_per_block}, {m}): one row per trial, one column per output")
        blocks.append(values)
        history.append(_block_statistics(values, p))
        h += 1
        if h < 2:
            continue
        stacked = np.stack(history)  # (h, 4, m)
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
    values = np.concatenate(blocks)
    intervals = coverage_intervals(values, p)
    centred = values - values.mean(axis=0)
    u = values.std(axis=0, ddof=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        skew = np.where(u > 0, np.mean(centred**3, axis=0) / u**3, 0.0)
        kurt = np.where(u > 0, np.mean(centred**4, axis=0) / u**4 - 3.0, 0.0)
    if fixed is None:
        delta = numerical_tolerance(u, digits)
    return MonteCarloResult(
        names=names, seed=int(seed), trials_per_block=int(trials_per_block), blocks=h, digits=int(digits),
        coverage_probability=p, converged=converged, monitored=tuple(names[i] for i in monitored),
        estimate=values.mean(axis=0), standard_uncertainty=u, low=intervals["low"], high=intervals["high"],
        shortest_low=intervals["shortest_low"], shortest_high=intervals["shortest_high"], tolerance=np.asarray(delta),
        block_sd=sd, history=np.stack(history), skewness=skew, excess_kurtosis=kurt, values=values)

"""Optimal designs: approximate by the multiplicative algorithm, certified by the equivalence theorem; exact by
rounding and exchange; support points on a continuous variable refined to the variance function's maxima.

The criteria and the equivalence theorem are in :mod:`plansim.design.criteria`. With costs ``c_i`` (table
time of one segment, settling included) the weights are *fractions of the total cost*: the algorithm works
on the information per unit cost ``M_i / c_i``, and a design of total cost T records ``w_i T / c_i``
segments of candidate *i* (Fedorov 1972, §2.8; Atkinson et al. 2007, §10.9).

References
----------
Silvey, S. D., Titterington, D. M., Torsney, B. (1978). An algorithm for optimal designs on a finite design
space. Commun. Statist. A7, 1379–1389. (the multiplicative algorithm, power 1 for D)
Yu, Y. (2010). Monotonic convergence of a general algorithm for computing optimal designs. Ann. Statist. 38,
1593–1606. (power 1/2 for A and c, monotone)
Pukelsheim, F., Rieder, S. (1992). Efficient rounding of approximate designs. Biometrika 79, 763–770.
Fedorov, V. V. (1972). Theory of Optimal Experiments. Academic Press. (the exchange algorithm)
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np
from scipy.optimize import minimize, root

from plansim.design.criteria import Criterion, check_blocks, information

__all__ = ["ApproximateDesign", "Certificate", "certificate", "multiplicative", "efficient_rounding", "exchange",
           "refine_support"]

#: default stopping rule of the multiplicative algorithm: the equivalence-theorem efficiency bound b/max φ ≥ 1 − this
EFFICIENCY_TOLERANCE = 1e-9
#: weights below this fraction of the largest are reported as off the support
SUPPORT_THRESHOLD = 1e-6


@dataclasses.dataclass(frozen=True)
class Certificate:
    """What the Kiefer–Wolfowitz equivalence theorem says of a design.

    ``derivatives`` φ_i (n,) and ``bound`` b; ``efficiency_bound`` = b / max φ (≤ 1; the design's efficiency
    against the optimum is at least this); ``support_gap`` = max over the support of |φ_i/b − 1| (0 at the
    optimum: equality on the support).
    """

    derivatives: np.ndarray
    bound: float
    efficiency_bound: float
    support_gap: float

    @property
    def optimal(self) -> bool:
        """True when the bound certifies the design optimal to :data:`EFFICIENCY_TOLERANCE` (tenfold)."""
        return self.efficiency_bound >= 1.0 - 10 * EFFICIENCY_TOLERANCE


@dataclasses.dataclass(frozen=True)
class ApproximateDesign:
    """An approximate (continuous) design: weights over the candidates, as fractions of the total cost.

    ``weights`` (n,) sum to 1; ``costs`` (n,) the cost of one unit of each candidate (1 without costs);
    ``information`` the information matrix per unit cost; ``criterion`` and its ``value`` there;
    ``certificate`` (:class:`Certificate`); ``iterations`` of the algorithm.
    """

    weights: np.ndarray
    costs: np.ndarray
    information: np.ndarray
    criterion: Criterion
    value: float
    certificate: Certificate
    iterations: int

    @property
    def support(self) -> np.ndarray:
        """Indices of the candidates with weight above :data:`SUPPORT_THRESHOLD` of the largest."""
        return np.flatnonzero(self.weights > SUPPORT_THRESHOLD * self.weights.max())

    def units(self, total_cost: float) -> np.ndarray:
        """Number of units (segments) of each candidate, not rounded, in a design of *total_cost*."""
        return self.weights * float(total_cost) / self.costs


def _per_cost(blocks, costs) -> tuple[np.ndarray, np.ndarray]:
    blocks = check_blocks(blocks)
    if costs is None:
        return blocks, np.ones(blocks.shape[0])
    costs = np.asarray(costs, dtype=float)
    if costs.shape != blocks.shape[:1] or not np.all(np.isfinite(costs)) or not np.all(costs > 0):
        raise ValueError(f"costs: expected {blocks.shape[0]} finite costs > 0 (one per candidate), got {costs!r}")
    return blocks / costs[:, None, None], costs


def certificate(blocks: np.ndarray, weights: np.ndarray, criterion: Criterion) -> Certificate:
    """The equivalence-theorem check of the design *weights* over candidate information matrices *blocks*."""
    M = information(blocks, weights)
    phi, bound = criterion.derivatives(blocks, M)
    on = weights > SUPPORT_THRESHOLD * weights.max()
    gap = float(np.max(np.abs(phi[on] / bound - 1.0)))
    return Certificate(phi, bound, float(bound / phi.max()), gap)


def multiplicative(blocks, criterion: Criterion | str = "D", costs=None, start=None,
                   tolerance: float = EFFICIENCY_TOLERANCE, max_iterations: int = 100_000) -> ApproximateDesign:
    """The optimal approximate design over a finite set of candidates, by the multiplicative algorithm.

    ``w_i ← w_i (φ_i / b)^λ``, normalised, with λ = 1 for D (Silvey, Titterington & Torsney 1978; then Σ w_i φ_i
    = p keeps the weights summing to one) and λ = 1/2 for A and c (Yu 2010), from equal weights; stops when the
    equivalence theorem certifies efficiency ≥ 1 − *tolerance* (:func:`certificate`).

    Parameters
    ----------
    blocks : (n, p, p) array_like
        Information matrix of one unit of each candidate (:mod:`plansim.design.catalogue` builds them for a
        MIMU; any linear model's ``f fᵀ/σ²`` will do).
    criterion : Criterion or {"D", "A"}
        What to optimise (a c-criterion needs its vector: ``Criterion("c", c=…)``).
    costs : (n,) array_like, optional
        Cost of one unit of each candidate (table time, s); the weights are then fractions of the total cost.
    start : (n,) array_like, optional
        Starting weights (> 0 where the candidate may enter); default equal.
    tolerance, max_iterations
        Stopping rule; reaching *max_iterations* first raises ``RuntimeError`` naming the bound reached.

    Raises
    ------
    ValueError
        Bad blocks or costs, or the candidates together cannot identify the parameters (singular information
        at equal weights; for c, cᵀθ not estimable).
    """
    if isinstance(criterion, str):
        criterion = Criterion(criterion)
    per_cost, costs = _per_cost(blocks, costs)
    n = per_cost.shape[0]
    w = np.full(n, 1.0 / n) if start is None else np.asarray(start, dtype=float) / np.sum(start)
    if w.shape != (n,) or not np.all(w >= 0) or not np.isfinite(w).all():
        raise ValueError(f"start: expected {n} weights ≥ 0 with a positive sum, got {start!r}")
    M = information(per_cost, w)
    if not np.isfinite(criterion.value(M)):
        raise ValueError("the candidates cannot identify the parameters: the information matrix is singular at "
                         "equal weights (for c: the combination is not estimable); add candidates or drop parameters")
    power = 1.0 if criterion.kind == "D" else 0.5
    active = np.flatnonzero(w > 0)
    iterations = 0
    while True:
        phi, bound = criterion.derivatives(per_cost[active], M)
        if bound / phi.max() >= 1.0 - tolerance:
            break
        iterations += 1
        if iterations > max_iterations:
            raise RuntimeError(f"multiplicative algorithm: efficiency bound {bound / phi.max():.12f} after "
                               f"{max_iterations} iterations (asked ≥ {1 - tolerance:.12f})")
        w[active] *= (np.maximum(phi, 0.0) / bound) ** power
        if criterion.kind == "D":
            active, w = _harman_pronzato(active, w, phi, bound)
        w /= w.sum()
        M = information(per_cost[active], w[active])
    return ApproximateDesign(w, costs, M, criterion, criterion.value(M), certificate(per_cost, w, criterion),
                             iterations)


def _harman_pronzato(active: np.ndarray, w: np.ndarray, phi: np.ndarray, p: float) -> tuple[np.ndarray, np.ndarray]:
    """Drop the candidates that cannot support a D-optimal design (Harman & Pronzato 2007, Theorem 1): with
    ε = max φ/p − 1 at the current design, any candidate with φ_i < p(1 + ε/2 − √(ε(4 + ε − 4/p))/2) has weight 0
    in every D-optimal design. Exact: it only speeds the multiplicative algorithm up.

    Harman, R., Pronzato, L. (2007). Improvements on removing nonoptimal support points in D-optimum design
    algorithms. Statist. Probab. Lett. 77, 90–94.
    """
    eps = phi.max() / p - 1.0
    threshold = p * (1.0 + eps / 2.0 - math.sqrt(max(eps * (4.0 + eps - 4.0 / p), 0.0)) / 2.0)
    keep = phi >= threshold
    w[active[~keep]] = 0.0
    return active[keep], w


def efficient_rounding(weights, n: int) -> np.ndarray:
    """Integer counts (summing to *n*) from approximate weights by efficient rounding (Pukelsheim & Rieder 1992).

    ``n_i = ⌈(n − ℓ/2) w_i⌉`` over the ℓ support points, then one unit at a time added where ``n_i / w_i`` is
    smallest or removed where ``(n_i − 1)/w_i`` is largest until the sum is *n*. With fewer units than support
    points (n < ℓ) the n heaviest points get one unit each; :func:`exchange` then improves the choice.
    """
    w = np.asarray(weights, dtype=float)
    if w.ndim != 1 or not np.all(np.isfinite(w)) or not np.all(w >= 0) or not w.sum() > 0:
        raise ValueError(f"weights: expected finite weights ≥ 0 with a positive sum, got {weights!r}")
    if not isinstance(n, (int, np.integer)) or isinstance(n, bool) or n < 1:
        raise ValueError(f"n = {n!r}: expected an integer ≥ 1")
    support = np.flatnonzero(w > SUPPORT_THRESHOLD * w.max())
    if n < len(support):  # fewer units than support points: the n heaviest (ties to the lowest index) …
        support = np.sort(support[np.argsort(-w[support], kind="stable")[:n]])
    counts = np.zeros(len(w), dtype=int)
    ws = w[support] / w[support].sum()
    ns = np.ceil((n - len(support) / 2.0) * ws).astype(int)
    while ns.sum() < n:
        ns[np.argmin(ns / ws)] += 1
    while ns.sum() > n:
        ns[np.argmax((ns - 1) / ws)] -= 1
    counts[support] = ns
    return counts


def exchange(blocks, counts, criterion: Criterion | str = "D", costs=None, budget: float | None = None,
             max_passes: int = 200) -> np.ndarray:
    """Improve an exact design by exchange (Fedorov 1972): move one unit from a candidate to another while that
    lowers the criterion, until no single move does.

    ``counts`` (n,) integer units of each candidate. Without *costs* the number of units stays the same; with
    *costs* a move is allowed when the total cost stays ≤ *budget* (default: the cost of *counts*). Returns the
    new counts. Deterministic: the best move of each pass, ties to the lowest index.
    """
    if isinstance(criterion, str):
        criterion = Criterion(criterion)
    blocks = check_blocks(blocks)
    counts = np.asarray(counts)
    if counts.shape != blocks.shape[:1] or not np.issubdtype(counts.dtype, np.integer) or np.any(counts < 0):
        raise ValueError(f"counts: expected {blocks.shape[0]} integers ≥ 0, got {counts!r}")
    counts = counts.astype(int).copy()
    costs = np.ones(len(counts)) if costs is None else np.asarray(costs, dtype=float)
    budget = float(costs @ counts) if budget is None else float(budget)
    current = criterion.value(information(blocks, counts.astype(float)))
    for _ in range(max_passes):
        best, move = current, None
        M, spent = information(blocks, counts.astype(float)), float(costs @ counts)  # fixed within a pass
        for i in np.flatnonzero(counts > 0):
            M_out = M - blocks[i]
            spare = budget - (spent - costs[i])
            for j in np.flatnonzero(costs <= spare + 1e-12 * budget):
                if j == i:
                    continue
                value = criterion.value(M_out + blocks[j])
                improves = value < best - 1e-12 * abs(best) if np.isfinite(best) else np.isfinite(value)
                if improves:
                    best, move = value, (i, j)
        if move is None:
            break
        counts[move[0]] -= 1
        counts[move[1]] += 1
        current = best
    return counts


def _merge_neighbours(grid: np.ndarray, design: ApproximateDesign, threshold: float) -> tuple[np.ndarray, np.ndarray]:
    """The grid points with weight above *threshold* of the largest, neighbours on the grid merged into one at their
    weighted mean, or at the end of the grid when they include it (the grid design splits a support point that
    falls between two grid points)."""
    support = np.flatnonzero(design.weights > threshold * design.weights.max())
    points, weights, run = [], [], [support[0]]
    for k in list(support[1:]) + [None]:
        if k is not None and k == run[-1] + 1:
            run.append(k)
            continue
        w = design.weights[run]
        ends = [i for i in (0, len(grid) - 1) if i in run]  # a point at an end of the interval stays there
        points.append(float(grid[ends[0]]) if ends else float(np.dot(w, grid[run]) / w.sum()))
        weights.append(float(w.sum()))
        if k is not None:
            run = [k]
    return np.array(points), np.array(weights)


#: the grid stage of :func:`refine_support` stops at this efficiency bound (the continuous stage does the rest) …
GRID_TOLERANCE = 1e-4
#: … and keeps the grid points with at least this fraction of the largest weight
GRID_SUPPORT = 1e-3
#: step of the central differences of φ(x) in :func:`refine_support`, relative to the interval's scale: truncation
#: ~h²/6 of φ''' and rounding ~ε·φ/h, both far below 1e-9 in the support points
SLOPE_STEP = 1e-5


def refine_support(regressor: Callable[[float], np.ndarray], grid, criterion: Criterion | str = "D",
                   tolerance: float = EFFICIENCY_TOLERANCE) -> tuple[np.ndarray, ApproximateDesign, Certificate]:
    """Optimal design on an interval: the grid's optimum, then its support points moved continuously.

    1. :func:`multiplicative` over the *grid* (increasing; its ends are the interval's) to efficiency
       1 − :data:`GRID_TOLERANCE`;
    2. the grid points with weight above :data:`GRID_SUPPORT` of the largest, neighbours merged
       (:func:`_merge_neighbours`); points at the ends stay there;
    3. the interior points x_k moved to minimise the criterion with the weights re-optimised at each x (to
       *tolerance*). By the envelope theorem its gradient is ``−w_k φ'(x_k)`` (φ the directional derivative,
       :mod:`plansim.design.criteria`), so the optimum is where every interior support point is a stationary
       point of φ, as the equivalence theorem asks: L-BFGS-B on that gradient, then ``scipy.optimize.root`` on
       ``φ'(x_k) = 0`` (φ' by central differences, step :data:`SLOPE_STEP`).

    ``regressor(x)`` gives the information matrix (p, p) of one unit at x. Returns the support points, the
    design over them and the equivalence-theorem certificate over the grid and the support together (its
    ``efficiency_bound`` certifies the design on the whole grid, not only on its own points).
    """
    if isinstance(criterion, str):
        criterion = Criterion(criterion)
    grid = np.asarray(grid, dtype=float)
    if grid.ndim != 1 or grid.size < 2 or not np.all(np.diff(grid) > 0) or not np.all(np.isfinite(grid)):
        raise ValueError(f"grid: expected an increasing 1-D array of at least 2 finite points, got {grid!r}")
    lo, hi = float(grid[0]), float(grid[-1])
    h = SLOPE_STEP * max(1.0, abs(lo), abs(hi))
    coarse = multiplicative(np.array([regressor(v) for v in grid]), criterion, tolerance=GRID_TOLERANCE)
    x0, w = _merge_neighbours(grid, coarse, GRID_SUPPORT)
    interior = (x0 > lo) & (x0 < hi)
    state = {"weights": w}

    def design_at(free):
        x = x0.copy()
        x[interior] = free
        design = multiplicative(np.array([regressor(v) for v in x]), criterion, start=state["weights"],
                                tolerance=tolerance)
        state["weights"] = design.weights
        return x, design

    def slopes(x, design):
        G, _ = criterion.gradient(design.information)
        return np.array([float(np.sum(G * (regressor(v + h) - regressor(v - h)))) / (2.0 * h) for v in x[interior]])

    def value_and_gradient(free):
        x, design = design_at(free)
        return design.value, -design.weights[interior] * slopes(x, design)

    free = x0[interior]
    if free.size:
        bounds = [(lo, hi)] * free.size
        free = minimize(value_and_gradient, free, jac=True, method="L-BFGS-B", bounds=bounds,
                        options={"ftol": 1e-15, "gtol": 1e-13, "maxiter": 1000}).x
        free = root(lambda f: slopes(*design_at(f)), free, method="hybr", options={"xtol": 1e-15}).x
    x, design = design_at(free)
    keep = np.sort(design.support)  # a point the continuous weights left empty goes
    order = keep[np.argsort(x[keep])]
    x = x[order]
    design = multiplicative(np.array([regressor(v) for v in x]), criterion, start=design.weights[order],
                            tolerance=tolerance)
    everywhere = np.concatenate([grid, x])
    weights = np.concatenate([np.zeros(grid.size), design.weights])
    return x, design, certificate(np.array([regressor(v) for v in everywhere]), weights, criterion)

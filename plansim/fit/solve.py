"""The joint fit's solver: generalised least squares on the whitened segment means, with or without the data
sheet's prior, and how it judges a search that stopped.

:func:`solve` minimises ‖W·(m − model(θ, tilts))‖² (+ the data sheet's prior rows) over the identified combinations
of the parameters and the hand-placed poses' tilts by scipy.optimize.least_squares (Levenberg–Marquardt), and
returns the gains the budget propagates through (:mod:`plansim.fit.budget`). :func:`whitening` is the W of a
covariance V; :func:`weak_directions` the directions of the design the data determine only weakly (a step of one u
along them moves some parameter beyond its data sheet's limit). docs/fitting.md, "The joint fit".
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from plansim.fit.budget import chi2_quantile
from plansim.fit.identify import UNINFORMATIVE_LIMITS
from plansim.fit.model import MeanModel, nominal_parameters

#: evaluations of the model the non-linear fit (poses placed by hand) may take before it gives up
MAX_EVALUATIONS = 400


#: a non-linear fit that has used its MAX_EVALUATIONS is taken where it stopped when one more Gauss–Newton step would
#: lower χ² along what the data determine by less than this — less than one degree of freedom's expected share, so no
#: test or u reads it — and along what they determine only weakly by less than the 99 % point of χ² for as many
#: degrees of freedom (:func:`_short`). It stops
#: short only in a direction the data barely determine (a curved valley, walked in ever smaller steps: poses placed
#: by hand whose gravity directions all lie in one cap leave the accelerometers' ellipsoid so), where the estimate's
#: u says as much (docs/fitting.md)
STALLED_CHI2 = 1.0


#: eigenvalues of the means' covariance V below this fraction of its largest are raised to it before V is
#: inverted: a channel that shows no noise at all (noise-free data) must not make V singular to rounding
EIGENVALUE_FLOOR = 1e-14


def whitening(V: np.ndarray) -> np.ndarray:
    """W with W·V·Wᵀ = I (V = U Λ Uᵀ, W = Λ^{-1/2} Uᵀ), eigenvalues floored at :data:`EIGENVALUE_FLOOR`·max."""
    values, vectors = np.linalg.eigh(V)
    values = np.maximum(values, EIGENVALUE_FLOOR * max(values.max(), 1e-300))
    return (vectors / np.sqrt(values)).T


def _gauss_newton_decrease(X: np.ndarray, residual: np.ndarray, theta_basis: np.ndarray,
                           limits: np.ndarray) -> tuple[float, float, int]:
    """What one more Gauss–Newton step would take off χ² where a search stopped: the whitened *residual*'s part in
    the column space of the whitened design *X* (its columns the fit's unknowns z, θ = θ0 + *theta_basis*·z),
    split by the design's singular directions into the part along directions the data determine and the part
    along directions they determine only weakly — where a step of one standard uncertainty moves some parameter
    beyond its group's *limits* ((39,), the fit's data sheet; the parameters
    :attr:`plansim.fit.joint.FitResult.weakly_determined` flags). Returns (determined part, weak part, number of
    weak directions)."""
    left, weak = weak_directions(X, theta_basis, limits)
    parts = (left.T @ residual) ** 2
    return float(parts[~weak].sum()), float(parts[weak].sum()), int(weak.sum())


def weak_directions(X: np.ndarray, theta_basis: np.ndarray, limits: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The whitened design *X*'s left singular vectors (those above lstsq's cut), and for each whether the data
    determine it only weakly: a step of one standard uncertainty along it (θ = θ0 + *theta_basis*·z) moves some
    parameter beyond its group's *limits* ((39,), the fit's data sheet: :attr:`plansim.fit.identify.HeldPriors.
    limits`)."""
    if X.shape[1] == 0:
        return np.zeros((X.shape[0], 0)), np.zeros(0, dtype=bool)
    left, singular, right = np.linalg.svd(X, full_matrices=False)
    kept = singular > np.finfo(float).eps * max(X.shape) * max(singular.max(initial=0.0), 1e-300)  # lstsq's cut
    one_sigma = (theta_basis @ right[kept].T) / singular[kept]  # (39, k): θ's step of 1 u along each direction
    weak = np.max(np.abs(one_sigma) / np.asarray(limits)[:, None], axis=0, initial=0.0) > 1.0
    return left[:, kept], weak


def _short(decrease: float, weak: float, n_weak: int) -> bool:
    """Whether a search that used up its evaluations stopped short of the minimum (:func:`_gauss_newton_decrease`):
    more than :data:`STALLED_CHI2` left along what the data determine, or, along the directions they determine
    only weakly, more than the 99 % point of χ² for as many degrees of freedom (what freeing them would have to
    take off to count, as for the combinations :func:`plansim.fit.joint.fit_recording` frees at the fitted tilts)."""
    return decrease > STALLED_CHI2 or (n_weak > 0 and weak > chi2_quantile(n_weak, 0.99))


def solve(model: MeanModel, basis: np.ndarray, theta0: np.ndarray, tilts0: np.ndarray, observed: np.ndarray,
          W: np.ndarray, J_linear: np.ndarray, linear_start: bool = True, extra: np.ndarray | None = None,
          stalled: list | None = None, prior: bool = False, limits: np.ndarray | None = None):
    """Generalised least squares by scipy.optimize.least_squares on the residuals whitened by W.

    The unknowns are z, with (θ, tilts) = (θ0, tilts0) + basis·z: the identified combinations of the 39
    parameters and of the tilts of the hand-placed poses. Without hand-placed poses the model is linear
    (``J_linear``·θ); with them it is evaluated by the kernel at each step.

    Returns θ̂ (39,), the tilts (n_placed, 2), the gain A (39, 6S) of θ̂ on the means, the design of the
    identified combinations D (6S, rank) at the solution and the gain G (rank, 6S) of z (the fit's hat matrix
    is D·G), χ² = ‖W·(m − model)‖², the sizes of the extra unknowns, and the data sheet's part (below).

    ``prior``: the data sheet as a prior of every parameter, θ_k ~ N(nominal_k, U_k²) with U the data sheet's
    *limits* ((39,), :attr:`plansim.fit.identify.HeldPriors.limits`; default the consumer MEMS data sheet's,
    :data:`plansim.fit.identify.UNINFORMATIVE_LIMITS`), also what judges a stopped search (:func:`_short`); as
    further whitened residuals (θ_k − nominal_k)/U_k (a ridge regression towards the nominal point; the tilts get
    none). Where the data determine a combination far better than a data sheet its pull is (u/U)² of the estimate's
    distance from nominal — 10⁻⁶ of it for a scale factor known to 10⁻⁴; along a direction they determine only
    weakly it holds the estimate and its u where the data sheet does. The last element is then (∂θ̂/∂nominal (39,
    39), ∂(D·z)/∂nominal (6S, 39), ∂z/∂nominal), the gains of the prior's mean, whose Type B u is U; otherwise None.
    χ² stays the data's.

    ``extra`` (6S, m): further unknowns c that add ``extra·c`` to the means (an effect beyond eq. (1)/(2),
    linear in its size); they are the last m entries of z, and the last m columns of D and rows of G.

    A non-linear fit that uses up :data:`MAX_EVALUATIONS` is taken where it stopped if one more Gauss–Newton
    step would lower χ² by at most :data:`STALLED_CHI2` along what the data determine, and by less than its
    99 % point along what they determine only weakly (:func:`_gauss_newton_decrease`, :func:`_short`), and
    ``(evaluations, the two decreases, the number of weak directions)`` is appended to *stalled*; otherwise a
    ``ValueError``.
    """
    n = len(theta0)
    n_rows = W.shape[0]
    limits = UNINFORMATIVE_LIMITS if limits is None else np.asarray(limits, dtype=float)
    extra = np.zeros((len(observed), 0)) if extra is None else np.asarray(extra, dtype=float)
    if extra.shape[1]:
        basis = np.block([[basis, np.zeros((basis.shape[0], extra.shape[1]))],
                          [np.zeros((extra.shape[1], basis.shape[1])), np.eye(extra.shape[1])]])
    if basis.shape[1] == 0:
        empty = np.zeros((len(observed), 0))
        chi2 = float(np.sum((W @ (observed - J_linear @ theta0)) ** 2)) if model.n_tilts == 0 else \
            float(np.sum((W @ (observed - model.means(theta0, tilts0).ravel())) ** 2))
        return theta0.copy(), tilts0.copy(), np.zeros((n, len(observed))), empty, empty.T, chi2, np.zeros(0), None

    m = extra.shape[1]
    nt = basis.shape[0] - m  # θ and the nuisance parameters

    def unpack(z):
        step = basis[:nt] @ z
        return theta0 + step[:n], tilts0 + step[n:].reshape(tilts0.shape)

    def shift(z):
        return extra @ z[basis.shape[1] - m:] if m else 0.0

    # the data sheet's prior: whitened rows P·(θ − nominal), P = diag(1/U); none (zero rows) without it
    P = np.diag(1.0 / limits) if prior else np.zeros((0, n))
    nominal = nominal_parameters()
    X_prior = P @ basis[:n]

    if model.n_tilts == 0:
        design = np.hstack([J_linear, extra]) @ basis
        X = np.vstack([W @ design, X_prior])
        y = np.concatenate([W @ (observed - J_linear @ theta0), P @ (nominal - theta0)])
        result = least_squares(lambda z: X @ z - y, np.zeros(basis.shape[1]), jac=lambda z: X, method="lm",
                               x_scale="jac", xtol=1e-15, ftol=1e-15, gtol=1e-15)
    else:
        def design_at(z):
            theta, tilts = unpack(z)
            return np.hstack([model.parameter_jacobian(tilts=tilts), model.tilt_jacobian(theta, tilts), extra]) @ basis

        def residual(z):
            theta, tilts = unpack(z)
            return np.concatenate([W @ (model.means(theta, tilts).ravel() + shift(z) - observed),
                                   P @ (theta - nominal)])

        def jacobian(z):
            return np.vstack([W @ design_at(z), X_prior])

        def run(z0):
            result = least_squares(residual, z0, jac=jacobian, method="lm", x_scale="jac",
                                   xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=MAX_EVALUATIONS)
            if result.success:
                return result, 0.0, 0.0, 0
            # it used up its evaluations: the χ² one more Gauss–Newton step would take off (the residual's part in
            # the design's column space)
            return (result, *_gauss_newton_decrease(jacobian(result.x), result.fun, basis[:n], limits))

        # start from the linear solution with the tilts held at their first guess, then free them together; where
        # that start leads the search astray (a near-null direction the linear step takes at full length: hand
        # poses whose gravity directions lie in one cap), from the first guess itself: where it stops short, or
        # ends above the first guess's own χ² (a minimum the linear step fell into)
        z0 = np.zeros(basis.shape[1])
        if linear_start:
            outcome = run(np.linalg.lstsq(jacobian(z0), -residual(z0), rcond=None)[0])
            if _short(*outcome[1:]) or outcome[0].cost > 0.5 * float(np.sum(residual(z0) ** 2)):
                outcome = min(outcome, run(z0), key=lambda r: r[0].cost)
        else:
            outcome = run(z0)
        result, decrease, weak, n_weak = outcome
        if _short(decrease, weak, n_weak):
            raise ValueError(f"the fit of the hand-placed poses did not converge in {MAX_EVALUATIONS} evaluations "
                             f"({result.message}; one more step would lower chi2 by {decrease + weak:.3g}, "
                             f"{decrease:.3g} of it along what the data determine); check the segment table's poses "
                             "(docs/fitting.md)")
        if not result.success and stalled is not None:
            stalled.append((int(result.nfev), decrease, weak, n_weak))
        design = design_at(result.x)
        X = jacobian(result.x)
    # the gain of z on (the means, the prior's mean): X's rows are W·(means) and P·(θ − nominal)
    inputs = np.zeros((X.shape[0], W.shape[1] + P.shape[0]))
    inputs[:n_rows, :W.shape[1]] = W
    if prior:
        inputs[n_rows:, W.shape[1]:] = P
    gain_all = np.linalg.lstsq(X, inputs, rcond=None)[0]
    gain_z, gain_prior = gain_all[:, :W.shape[1]], gain_all[:, W.shape[1]:]
    theta, tilts = unpack(result.x)
    chi2 = float(np.sum(result.fun[:n_rows] ** 2))
    prior_gains = (basis[:n] @ gain_prior, design @ gain_prior, gain_prior) if prior else None
    return theta, tilts, basis[:n] @ gain_z, design, gain_z, chi2, result.x[len(result.x) - m:], prior_gains

"""Optimality criteria of an experimental design: D, A and c (Pukelsheim 1993, ch. 6; Atkinson, Donev & Tobias 2007).

A design ξ puts weight ``w_i ≥ 0`` (Σ w_i = 1) on candidate *i*, whose information per unit weight is the
positive semi-definite matrix ``M_i = F_iᵀ Σ_i⁻¹ F_i`` (p × p): ``F_i`` the derivative of the candidate's
observations with respect to the p parameters, ``Σ_i`` their noise covariance. The design's information
matrix is

    M(ξ) = Σ_i w_i M_i,

and, for a linear model with uncorrelated candidates, ``M(ξ)⁻¹/N`` is the covariance of the least-squares
estimate from N units of the design. The criteria, each written as a quantity to **minimise**:

- **D**: ``−log det M`` (the volume of the confidence ellipsoid);
- **A**: ``tr M⁻¹`` (the sum of the parameters' variances; with a ``scale`` vector s, ``tr(S M⁻¹ S)``
  with S = diag(1/s), the sum of the squared relative uncertainties);
- **c**: ``cᵀ M⁻ c`` (the variance of one linear combination cᵀθ, e.g. one parameter; M⁻ a generalised
  inverse: a c-optimal design often leaves the other parameters unidentified, Pukelsheim 1993, §2.14).

Each has a *directional derivative* ``φ_i(ξ)`` towards candidate *i* and a *bound* ``b(ξ)`` with
``Σ_i w_i φ_i = b``; the **Kiefer–Wolfowitz equivalence theorem** (Kiefer & Wolfowitz 1960; Pukelsheim
1993, 7.20) says ξ is optimal if and only if ``φ_i(ξ) ≤ b(ξ)`` for every candidate, with equality on
the support:

============  ===============================  ==========================
criterion     φ_i(ξ)                           b(ξ)
============  ===============================  ==========================
D             tr(M⁻¹ M_i)                      p
A             tr(M⁻¹ S² M⁻¹ M_i)               tr(S M⁻¹ S)
c             cᵀ M⁻¹ M_i M⁻¹ c                 cᵀ M⁻¹ c
============  ===============================  ==========================

and any design's efficiency against the optimum is at least ``b / max_i φ_i`` (D: ``p / max φ`` bounds
the D-efficiency ``(det M / det M*)^{1/p}`` from below; Pukelsheim 1993, 5.15). For a single-response
candidate ``M_i = f_i f_iᵀ/σ²`` the D-derivative is the standardised prediction variance
``f_iᵀ M⁻¹ f_i/σ²``.

References
----------
Kiefer, J., Wolfowitz, J. (1960). The equivalence of two extremum problems. Canad. J. Math. 12, 363–366.
Pukelsheim, F. (1993). Optimal Design of Experiments. Wiley.
Atkinson, A. C., Donev, A. N., Tobias, R. D. (2007). Optimum Experimental Designs, with SAS. OUP, ch. 9–11.
"""

from __future__ import annotations

import dataclasses

import numpy as np

__all__ = ["CRITERIA", "Criterion", "information", "check_blocks"]

#: the criteria :class:`Criterion` knows
CRITERIA = ("D", "A", "c")


def check_blocks(blocks, name: str = "blocks") -> np.ndarray:
    """Candidate information matrices as a float array (n, p, p), checked: finite, symmetric, n ≥ 1, p ≥ 1."""
    blocks = np.asarray(blocks, dtype=float)
    if blocks.ndim != 3 or blocks.shape[1] != blocks.shape[2] or blocks.shape[0] < 1 or blocks.shape[1] < 1:
        raise ValueError(f"{name}: expected candidate information matrices of shape (n, p, p), got {blocks.shape}")
    if not np.all(np.isfinite(blocks)):
        raise ValueError(f"{name}: every entry must be finite")
    scale = np.abs(blocks).max() or 1.0
    if np.abs(blocks - blocks.transpose(0, 2, 1)).max() > 1e-9 * scale:
        raise ValueError(f"{name}: each candidate's information matrix must be symmetric")
    return blocks


def information(blocks: np.ndarray, weights) -> np.ndarray:
    """The design's information matrix ``M(ξ) = Σ_i w_i M_i`` (p, p) for weights (n,)."""
    weights = np.asarray(weights, dtype=float)
    if weights.shape != blocks.shape[:1]:
        raise ValueError(f"weights: expected shape ({blocks.shape[0]},), one per candidate, got {weights.shape}")
    return np.einsum("i,ijk->jk", weights, blocks)


@dataclasses.dataclass(frozen=True)
class Criterion:
    """An optimality criterion, to be minimised.

    Parameters
    ----------
    kind : {"D", "A", "c"}
        See the module's table.
    c : (p,) array_like, optional
        The linear combination of the c-criterion (required for ``"c"``, refused otherwise).
    scale : (p,) array_like, optional
        A-criterion only: the parameters' scales s (e.g. their target uncertainties), so that the criterion is
        the sum of squared *relative* variances ``Σ_j var(θ_j)/s_j²``. Default: all ones.
    """

    kind: str
    c: np.ndarray | None = None
    scale: np.ndarray | None = None

    def __post_init__(self):
        if self.kind not in CRITERIA:
            raise ValueError(f"criterion = {self.kind!r}; allowed: {', '.join(CRITERIA)}")
        if (self.kind == "c") != (self.c is not None):
            need = "required" if self.kind == "c" else "only for the c-criterion"
            raise ValueError(f"criterion {self.kind!r}: the vector c is {need}")
        if self.scale is not None and self.kind != "A":
            raise ValueError(f"criterion {self.kind!r}: scale is for the A-criterion only")
        for field in ("c", "scale"):
            value = getattr(self, field)
            if value is not None:
                value = np.asarray(value, dtype=float)
                if value.ndim != 1 or not np.all(np.isfinite(value)) or not np.any(value):
                    raise ValueError(f"criterion {field}: expected a finite, non-zero vector, got {value!r}")
                if field == "scale" and not np.all(value > 0):
                    raise ValueError(f"criterion scale: every scale must be > 0, got {value!r}")
                object.__setattr__(self, field, value)

    def _check(self, p: int) -> None:
        for field in ("c", "scale"):
            value = getattr(self, field)
            if value is not None and value.shape != (p,):
                raise ValueError(f"criterion {field}: expected {p} entries (one per parameter), got {value.shape[0]}")

    def _weight(self, p: int) -> np.ndarray:
        """The matrix W of the criterion tr(W M⁻¹) (A: S², c: c cᵀ)."""
        if self.kind == "c":
            return np.outer(self.c, self.c)
        s = np.ones(p) if self.scale is None else self.scale
        return np.diag(1.0 / s**2)

    def value(self, M: np.ndarray) -> float:
        """The criterion at information matrix *M* (p, p); ``inf`` when *M* is singular (for c: when cᵀθ is not
        estimable)."""
        M = np.asarray(M, dtype=float)
        p = M.shape[0]
        self._check(p)
        if self.kind == "D":
            sign, logdet = np.linalg.slogdet(M)
            return -logdet if sign > 0 else np.inf
        if self.kind == "c":
            x = self._solve_c(M)
            return np.inf if x is None else float(self.c @ x)
        try:
            inverse = np.linalg.inv(M)
        except np.linalg.LinAlgError:
            return np.inf
        value = float(np.trace(self._weight(p) @ inverse))
        return value if np.isfinite(value) and value >= 0 else np.inf

    def gradient(self, M: np.ndarray) -> tuple[np.ndarray, float]:
        """The symmetric matrix G (p, p) with φ_i = tr(G·M_i) for any candidate, and the bound b, at *M*: D
        ``M⁻¹`` and p; A ``M⁻¹ W M⁻¹`` and ``tr(W M⁻¹)``; c ``x xᵀ`` and ``cᵀx`` with ``M x = c`` (a generalised
        inverse: c-optimal information is often singular)."""
        p = M.shape[0]
        self._check(p)
        if self.kind == "c":
            x = self._solve_c(M)
            if x is None:
                raise ValueError("c-criterion: cᵀθ is not estimable at this design")
            return np.outer(x, x), float(self.c @ x)
        inverse = np.linalg.inv(M)
        if self.kind == "D":
            return inverse, float(p)
        W = self._weight(p)
        return inverse @ W @ inverse, float(np.trace(W @ inverse))

    def derivatives(self, blocks: np.ndarray, M: np.ndarray) -> tuple[np.ndarray, float]:
        """Directional derivatives φ_i (n,) towards each candidate and the bound b, at *M* (:meth:`gradient`)."""
        G, bound = self.gradient(M)
        return np.einsum("jk,ikj->i", G, blocks), bound

    def _solve_c(self, M: np.ndarray) -> np.ndarray | None:
        """x with M·x = c (a generalised-inverse solution; cᵀx does not depend on which), or None when c is not in
        the range of M (cᵀθ not estimable): the residual above 1e-9 of |c|."""
        x = np.linalg.lstsq(M, self.c, rcond=1e-13)[0]
        if np.linalg.norm(M @ x - self.c) > 1e-9 * np.linalg.norm(self.c):
            return None
        return x

    def efficiency(self, M: np.ndarray, M_best: np.ndarray) -> float:
        """Efficiency of a design of information *M* relative to one of *M_best* (1 when as good), per unit weight:
        D ``(det M / det M*)^{1/p}``, A and c the ratio of the criteria (Pukelsheim 1993, 5.15)."""
        a, b = self.value(M), self.value(M_best)
        if self.kind == "D":
            return float(np.exp((b - a) / M.shape[0])) if np.isfinite(a) else 0.0
        return float(b / a) if np.isfinite(a) else 0.0

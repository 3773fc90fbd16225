"""The estimators of the vibration paper's experiment (docs/dynamic.md): output shift, Welch PSD, compensation.

The paper (Fu, Hao, Zhao 2020; :mod:`plansim.model.vibration`) records a still IMU for 100 s, under
random vibration for 300 s and still again for 100 s, at 2.5 ms (its section 2), and

- reads the gyro output's change during vibration from the segment means (its Table 1: ≈ 60 °/h):
  :func:`output_shift`, the mean during vibration minus the mean of the still segments before and after;
- compares the Welch PSD of the gyro output with the vibration spectrum (its Figure 4):
  :func:`welch_psd` (``scipy.signal.welch``, Hann window, 50 % overlap);
- compensates with the static model of its eq. (2) (bias, scale factor, misalignment, g-sensitivity from
  a static calibration; :func:`compensate`) and with the dynamic model of its eq. (3), which adds the g²
  (and g³) terms (:func:`fit_dynamic`, linear least squares), and reports the gyro output before and
  after (its Table 2: 75.39 → 30.94 °/h): :func:`residual_errors`.

All inputs and results are SI: s, rad/s, m/s².
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.signal

from plansim.model.vibration import MONOMIALS, monomials


def _segment(name: str, mask) -> np.ndarray:
    m = np.asarray(mask, dtype=bool)
    if m.ndim != 1 or not m.any():
        raise ValueError(f"{name}: expected a non-empty boolean mask of the samples, got {m.sum()} samples selected")
    return m


def output_shift(y: np.ndarray, during, still) -> np.ndarray:
    """Mean of *y* over the samples *during* vibration minus its mean over the *still* samples (3,), unit of y.

    Parameters
    ----------
    y : ndarray, (n, 3)
        Gyro outputs.
    during, still : array_like of bool, (n,)
        The samples under vibration; the still samples (before and after).
    """
    y = np.asarray(y, dtype=float)
    during = _segment("during", during)
    still = _segment("still", still)
    if during.size != y.shape[0] or still.size != y.shape[0]:
        raise ValueError(f"during, still: expected masks of {y.shape[0]} samples, got {during.size} and {still.size}")
    return y[during].mean(axis=0) - y[still].mean(axis=0)


def welch_psd(x: np.ndarray, sample_rate: float, segment: int = 1024) -> tuple[np.ndarray, np.ndarray]:
    """One-sided Welch PSD of *x* (n,) or (n, k) along axis 0: (frequencies Hz, PSD (unit of x)²/Hz).

    ``scipy.signal.welch`` with a Hann window of *segment* samples, 50 % overlap, the mean removed per
    segment. Each bin averages K = ⌊(n − segment)/(segment/2)⌋ + 1 overlapping periodograms; its
    relative standard deviation is ≈ √((1 + 2c²)/K) with c = 0.167 the correlation of neighbouring Hann
    segments at 50 % overlap (Welch 1967), i.e. ν ≈ 2K/(1 + 2c²) degrees of freedom
    (:func:`welch_degrees_of_freedom`).
    """
    x = np.asarray(x, dtype=float)
    if x.shape[0] < segment:
        raise ValueError(f"segment: {segment} samples is longer than the record ({x.shape[0]} samples)")
    return scipy.signal.welch(x, fs=sample_rate, window="hann", nperseg=segment, noverlap=segment // 2,
                              detrend="constant", scaling="density", axis=0)


def welch_degrees_of_freedom(n: int, segment: int) -> float:
    """ν ≈ 2K/(1 + 2c²), c = 0.167 (Hann, 50 % overlap): the χ² degrees of freedom of one Welch bin."""
    k = (n - segment) // (segment // 2) + 1
    return 2.0 * k / (1.0 + 2.0 * 0.167**2)


@dataclass(frozen=True)
class StaticModel:
    """The static model of the paper's eq. (2) as a static calibration gives it: K (3×3, 1), B (3, rad/s),
    G (3×3, rad/s per m/s²)."""

    K: np.ndarray
    B: np.ndarray
    G: np.ndarray


def compensate(y: np.ndarray, f: np.ndarray, static: StaticModel, dynamic: np.ndarray | None = None) -> np.ndarray:
    """The rate estimate ω̂ = K⁻¹ (y − B − G f − C m(f)) (n, 3), rad/s.

    *y* (n, 3) gyro outputs, rad/s; *f* (n, 3) the measured specific force, m/s²; *dynamic* C (3, 9), the
    coefficients of :func:`plansim.model.vibration.monomials` (None: the static model alone, eq. (2)).
    """
    y = np.asarray(y, dtype=float)
    f = np.asarray(f, dtype=float)
    r = y - static.B - f @ np.asarray(static.G).T
    if dynamic is not None:
        r = r - monomials(f) @ np.asarray(dynamic).T
    return np.linalg.solve(np.asarray(static.K, dtype=float), r.T).T


def fit_dynamic(y: np.ndarray, f: np.ndarray, rate: np.ndarray, static: StaticModel,
                columns=("zz", "zzz")) -> np.ndarray:
    """The g² (and g³) coefficients C (3, 9) by linear least squares, the static model held fixed.

    The residual of the static model r = y − B − G f − K ω (ω the known table rate, here the Earth rate) is
    fitted by r ≈ Σ_c C_c m_c(f) over the monomials *columns* (names of
    :data:`plansim.model.vibration.MONOMIALS`; the others are 0), without an intercept: the bias is the
    static calibration's, as in the paper. Only the monomials the vibration excites can be told apart: a
    shaker along z excites f_z² and f_z³ (and f_z, which G holds).

    Returns
    -------
    ndarray, (3, 9)
        C, rad/s per (m/s²)² (squares, products) and per (m/s²)³ (cubes).
    """
    unknown = [c for c in columns if c not in MONOMIALS]
    if unknown or not columns:
        raise ValueError(f"columns: expected names among {', '.join(MONOMIALS)}, got {list(columns)!r}")
    idx = [MONOMIALS.index(c) for c in columns]
    y = np.asarray(y, dtype=float)
    f = np.asarray(f, dtype=float)
    rate = np.broadcast_to(np.asarray(rate, dtype=float), y.shape)
    r = y - static.B - f @ np.asarray(static.G).T - rate @ np.asarray(static.K).T
    M = monomials(f)[:, idx]
    scale = np.sqrt(np.mean(M * M, axis=0))  # columns of like size: f_z³ is ~10 m/s² times f_z²
    coef, *_ = scipy.linalg.lstsq(M / scale, r)
    out = np.zeros((3, len(MONOMIALS)))
    out[:, idx] = (coef / scale[:, None]).T
    return out


def block_means(x: np.ndarray, samples: int) -> np.ndarray:
    """Means of consecutive blocks of *samples* rows of *x* (the last partial block dropped)."""
    n = (x.shape[0] // samples) * samples
    return x[:n].reshape(-1, samples, *x.shape[1:]).mean(axis=1)


def residual_errors(rate_estimate: np.ndarray, rate: np.ndarray, during, average: int) -> dict[str, np.ndarray]:
    """The error of a rate estimate during vibration (3 each, rad/s).

    ``mean``: the mean of ω̂ − ω over the vibration (the figure the paper's Tables 1 and 2 compare, read
    as the mean output error); ``rms_averaged``: the r.m.s. of the means over blocks of *average*
    samples (1 s); ``rms``: the r.m.s. sample by sample (dominated by the white noise).
    """
    during = _segment("during", during)
    e = np.asarray(rate_estimate, dtype=float)[during] - np.broadcast_to(np.asarray(rate, dtype=float),
                                                                          np.shape(rate_estimate))[during]
    return {"mean": e.mean(axis=0), "rms_averaged": np.sqrt(np.mean(block_means(e, average) ** 2, axis=0)),
            "rms": np.sqrt(np.mean(e * e, axis=0))}

"""Random vibration and the gyro's error model under it (the vibration paper; docs/dynamic.md).

The vibration paper (Fu, Hao, Zhao, *Dynamic error compensation of MEMS gyros in a vibration
environment*, 2020) shakes a MEMS IMU with wide-band random vibration given as a one-sided
acceleration PSD (its Figure 2: a rising segment A1, a flat segment A2 at 0.04 g²/Hz, a falling
segment A3; 6.06 g r.m.s. in all, its section 2) and models the gyro output with, besides the static
terms of its eq. (2) (bias, scale factor, misalignment, g-sensitivity), g² terms S and g³ terms D
(its eq. (3)).

**The PSD.** :class:`PsdProfile` is a piecewise straight line on log–log axes between breakpoints
(f_k, P_k), zero outside [f_0, f_K]: the way vibration specifications write it ("+3 dB/octave from 20
to 80 Hz"). A segment P(f) = P_k (f/f_k)^b_k, b_k = ln(P_{k+1}/P_k)/ln(f_{k+1}/f_k), holds the power

    ∫ P df = P_k f_k ((f_{k+1}/f_k)^(b_k+1) − 1)/(b_k + 1)     (P_k f_k ln(f_{k+1}/f_k) for b_k = −1),

and the variance E[a²] is the sum over segments. The paper's Figure 2 is not given in numbers; the
profile with its 0.04 g²/Hz plateau that gives its 6.06 g r.m.s. is the usual one of the random
vibration standards: +3 dB/octave (P ∝ f) from 20 to 80 Hz, flat 0.04 g²/Hz from 80 to 350 Hz,
−3 dB/octave (P ∝ 1/f) from 350 to 2000 Hz, 36.70 g², 6.058 g r.m.s. (:func:`paper_profile`). A flat
profile alone gives 6.06 g over 918 Hz (36.72 g² / 0.04 g²/Hz), e.g. 20–938 Hz.

**The generator.** White noise through an FIR filter whose gain is √(P(f) f_s/2) (frequency sampling,
Hann-windowed, linear phase; :func:`shaping_filter`), with the white numbers drawn block by block
from streams derived from the seed (:mod:`plansim.kernels.vibration`): the same seed gives the same
record in chunks of any size. The filter's own PSD (:func:`filter_psd`) and variance Σh²
(:func:`filter_variance`) are the exact truth of the generated process; they differ from the profile
by the window's smoothing at the band edges (Σh² is 0.09 % short of ∫P df for the paper's profile at
4800 Hz and 1025 taps).

**The gyro model.** With the specific force f (m/s², body axes) and the true rate ω (rad/s),

    y = K ω + B + G f + S₂ (f∘f) + S× (f_x f_y, f_x f_z, f_y f_z) + D (f∘f∘f) + noise,

K (3×3, 1: scale factors on the diagonal, misalignment off it), B (3, rad/s), G (3×3, rad/s per m/s²)
are the paper's eq. (2) and JJF 2003-2022 eq. (1) (plansim's ``Kg``, ``Bg``, ``G``); S₂ (3×3,
rad/s per (m/s²)², row = gyro, column = axis of the squared component: plansim's
``gyro_g2_sensitivity``, the kernels' ``S2``) and S× (3×3, same unit, columns xy, xz, yz) are the g²
terms of eq. (3) (the paper's S_x, S_y, S_z are the squares' coefficients); D (3×3, rad/s per
(m/s²)³) the g³ terms (its D_x, D_y, D_z), which the paper found negligible. The monomials are
:func:`monomials`; the model and the least-squares fit of :mod:`plansim.estimate.vibration` share
them.

Under a zero-mean Gaussian vibration a (independent axes) on top of gravity's specific force g_b,
f = g_b + a, and the mean output shifts by (:func:`predicted_shift`)

    Δy_i = Σ_j S₂_ij E[a_j²] + Σ_{j<k} S×_i,jk E[a_j a_k] + 3 Σ_j D_ij g_b,j E[a_j²],

the rectification the paper measures (≈ 60 °/h): E[(g + a)²] − g² = E[a²], E[(g + a)³] − g³ = 3gE[a²]
(E[a] = E[a³] = 0). The linear terms G f and K ω average to nothing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from plansim.kernels.random import root_key
from plansim.kernels.vibration import shaped_noise
from plansim.model.dynamics import one_number, positive_number
from plansim.units import STANDARD_GRAVITY

#: one g² per Hz in SI, (m/s²)²/Hz
G2_PER_HZ = STANDARD_GRAVITY**2
#: white numbers per block of a generated record (fixed: the numbers never depend on the chunking)
WHITE_BLOCK = 4096
#: the monomials of :func:`monomials`, in column order
MONOMIALS = ("xx", "yy", "zz", "xy", "xz", "yz", "xxx", "yyy", "zzz")


@dataclass(frozen=True)
class PsdProfile:
    """A one-sided acceleration PSD, straight between breakpoints on log–log axes, zero outside.

    Attributes
    ----------
    frequencies : ndarray
        Breakpoints f_0 < f_1 < … < f_K, Hz, f_0 > 0.
    levels : ndarray
        P(f_k) > 0, (m/s²)²/Hz (one g²/Hz is :data:`G2_PER_HZ`).
    """

    frequencies: np.ndarray
    levels: np.ndarray

    def __post_init__(self):
        try:
            f = np.array(self.frequencies, dtype=float).ravel()
            p = np.array(self.levels, dtype=float).ravel()
        except (TypeError, ValueError) as exc:
            raise TypeError(f"PSD profile: expected numbers (Hz, (m/s^2)^2/Hz), got frequencies "
                            f"{self.frequencies!r}, levels {self.levels!r}") from exc
        if f.size < 2 or f.size != p.size:
            raise ValueError(f"PSD profile: expected as many levels as frequencies, at least 2; got {f.size} "
                             f"frequencies and {p.size} levels")
        if not (np.all(np.isfinite(f)) and f[0] > 0 and np.all(np.diff(f) > 0)):
            raise ValueError(f"PSD profile frequencies: expected finite values > 0 Hz, strictly increasing; got "
                             f"{f.tolist()}")
        if not (np.all(np.isfinite(p)) and np.all(p > 0)):
            raise ValueError(f"PSD profile levels: expected finite values > 0 (m/s^2)^2/Hz; got {p.tolist()}")
        f.flags.writeable = False
        p.flags.writeable = False
        object.__setattr__(self, "frequencies", f)
        object.__setattr__(self, "levels", p)

    @property
    def slopes(self) -> np.ndarray:
        """b_k = ln(P_{k+1}/P_k)/ln(f_{k+1}/f_k) per segment (1 = +3.01 dB/octave, 0 flat)."""
        return np.diff(np.log(self.levels)) / np.diff(np.log(self.frequencies))

    def level(self, frequencies) -> np.ndarray:
        """P(f), (m/s²)²/Hz: log–log interpolation between the breakpoints, 0 outside [f_0, f_K]."""
        f = np.asarray(frequencies, dtype=float)
        out = np.zeros(f.shape)
        inside = (f >= self.frequencies[0]) & (f <= self.frequencies[-1])
        out[inside] = np.exp(np.interp(np.log(f[inside]), np.log(self.frequencies), np.log(self.levels)))
        return out

    def variance(self) -> float:
        """E[a²] = ∫ P df, (m/s²)², summed in closed form over the power-law segments."""
        total = 0.0
        for f0, f1, p0, b in zip(self.frequencies[:-1], self.frequencies[1:], self.levels[:-1], self.slopes):
            if abs(b + 1.0) < 1e-12:
                total += p0 * f0 * math.log(f1 / f0)
            else:
                total += p0 * f0 * ((f1 / f0) ** (b + 1.0) - 1.0) / (b + 1.0)
        return float(total)

    def rms(self) -> float:
        """√E[a²], m/s²."""
        return math.sqrt(self.variance())


def flat_profile(level: float, low: float, high: float) -> PsdProfile:
    """P = *level* ((m/s²)²/Hz) from *low* to *high* (Hz): E[a²] = level · (high − low)."""
    level = positive_number("level", level, "(m/s^2)^2/Hz")
    return PsdProfile(np.array([positive_number("low", low, "Hz"), positive_number("high", high, "Hz")]),
                      np.array([level, level]))


def paper_profile(plateau: float = 0.04 * G2_PER_HZ) -> PsdProfile:
    """The vibration paper's profile (its Figure 2): P ∝ f from 20 to 80 Hz, *plateau* from 80 to 350 Hz,
    P ∝ 1/f from 350 to 2000 Hz (±3.01 dB/octave); 36.70 g² (6.058 g r.m.s.) at 0.04 g²/Hz."""
    p = positive_number("plateau", plateau, "(m/s^2)^2/Hz")
    f = np.array([20.0, 80.0, 350.0, 2000.0])
    return PsdProfile(f, p * np.array([20.0 / 80.0, 1.0, 1.0, 350.0 / 2000.0]))


def shaping_filter(profile: PsdProfile, sample_rate: float, taps: int = 1025) -> np.ndarray:
    """The FIR filter h (L = *taps*, odd) that turns unit white noise at *sample_rate* into the profile.

    Frequency sampling: the gain √(P(f) f_s/2) on the L-point grid f = k f_s/L (one-sided PSD of unit
    white noise sampled at f_s: 2/f_s per Hz), the zero-phase impulse response by the inverse real FFT,
    centred and multiplied by a Hann window. The window smooths |H|² over ≈ 2 f_s/L, so the profile's
    edges are rounded and its variance Σh² falls short of ∫P df by about that share of the band's
    edges (:func:`filter_variance`). Requires the profile below the Nyquist frequency f_s/2.

    Returns
    -------
    ndarray, (taps,)
        h in the profile's amplitude unit (m/s²) per unit white number.
    """
    fs = positive_number("sample_rate", sample_rate, "Hz")
    if isinstance(taps, bool) or not isinstance(taps, (int, np.integer)) or taps < 3 or taps % 2 == 0:
        raise ValueError(f"taps: expected an odd integer >= 3, got {taps!r}")
    if profile.frequencies[-1] >= fs / 2:
        raise ValueError(f"sample_rate: {fs} Hz puts the Nyquist frequency {fs / 2} Hz at or below the profile's "
                         f"top {profile.frequencies[-1]} Hz; allowed: > {2 * profile.frequencies[-1]} Hz")
    grid = np.arange(taps // 2 + 1) * fs / taps
    gain = np.sqrt(profile.level(grid) * fs / 2.0)
    h = np.fft.irfft(gain, n=taps)  # zero-phase, real, symmetric about index 0
    h = np.roll(h, taps // 2) * np.hanning(taps + 2)[1:-1]
    return h


def filter_psd(taps: np.ndarray, sample_rate: float, frequencies) -> np.ndarray:
    """The one-sided PSD |H(f)|² · 2/f_s of *taps* driven by unit white noise, (unit of h)²/Hz."""
    f = np.asarray(frequencies, dtype=float)
    m = np.arange(len(taps))
    H = np.exp(-2j * np.pi * np.multiply.outer(f / sample_rate, m)) @ np.asarray(taps, dtype=float)
    return np.abs(H) ** 2 * 2.0 / sample_rate


def filter_variance(taps: np.ndarray) -> float:
    """Σ h²: the variance of the generated process (exact, for unit white noise)."""
    return float(np.sum(np.square(taps)))


def seed_key(seed) -> np.ndarray:
    """The root key of a record's streams (:func:`plansim.kernels.random.root_key`); *seed* an integer ≥ 0."""
    return root_key(seed)


def shaped_samples(key: np.ndarray, stream: int, taps: np.ndarray, start: int, count: int,
                   chunk: int | None = None) -> np.ndarray:
    """Samples start … start + count − 1 of the process *taps* on *stream* (:mod:`plansim.kernels.vibration`).

    *chunk* (samples per kernel call; default all at once) changes nothing but the memory used.
    """
    taps = np.ascontiguousarray(taps, dtype=float)
    out = np.empty(count)
    step = count if chunk is None else int(chunk)
    if step < 1 and count > 0:
        raise ValueError(f"chunk: expected an integer >= 1, got {chunk!r}")
    white = np.empty(min(step, count) + len(taps) - 1) if count else np.empty(0)
    for first in range(0, count, max(step, 1)):
        n = min(step, count - first)
        shaped_noise(key, np.int64(stream), taps, np.int64(WHITE_BLOCK), np.int64(start + first), white,
                     out[first:first + n])
    return out


def monomials(f: np.ndarray) -> np.ndarray:
    """The g² and g³ regressors of specific forces *f* (n, 3), m/s²: columns :data:`MONOMIALS`,
    (n, 9) = (f_x², f_y², f_z², f_x f_y, f_x f_z, f_y f_z, f_x³, f_y³, f_z³)."""
    f = np.asarray(f, dtype=float)
    x, y, z = f[:, 0], f[:, 1], f[:, 2]
    return np.stack([x * x, y * y, z * z, x * y, x * z, y * z, x * x * x, y * y * y, z * z * z], axis=1)


@dataclass(frozen=True)
class VibrationGyro:
    """The gyro triad of the vibration paper's eq. (3), all SI (module docstring).

    Attributes
    ----------
    K : (3, 3) scale factor and misalignment, 1.
    B : (3,) bias, rad/s.
    G : (3, 3) g-sensitivity, rad/s per m/s².
    S2 : (3, 3) g² sensitivity to the squares f_j², rad/s per (m/s²)².
    Sx : (3, 3) g² sensitivity to the products (f_x f_y, f_x f_z, f_y f_z), rad/s per (m/s²)².
    D : (3, 3) g³ sensitivity to the cubes f_j³, rad/s per (m/s²)³.
    """

    K: np.ndarray
    B: np.ndarray
    G: np.ndarray
    S2: np.ndarray
    Sx: np.ndarray
    D: np.ndarray

    def __post_init__(self):
        for name, shape in (("K", (3, 3)), ("B", (3,)), ("G", (3, 3)), ("S2", (3, 3)), ("Sx", (3, 3)),
                            ("D", (3, 3))):
            value = getattr(self, name)
            try:
                arr = np.array(value, dtype=float)
            except (TypeError, ValueError) as exc:
                raise TypeError(f"gyro {name}: expected numbers of shape {shape}, got {value!r}") from exc
            if arr.shape != shape or not np.all(np.isfinite(arr)):
                raise ValueError(f"gyro {name}: expected finite numbers of shape {shape}, got shape {arr.shape}")
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)

    @property
    def dynamic(self) -> np.ndarray:
        """(3, 9) coefficients of :func:`monomials`: [S2 | Sx | D]."""
        return np.hstack([self.S2, self.Sx, self.D])

    def output(self, rate: np.ndarray, f: np.ndarray) -> np.ndarray:
        """Noise-free outputs (n, 3), rad/s, for true rates *rate* ((3,) or (n, 3), rad/s) and specific
        forces *f* (n, 3), m/s²."""
        f = np.asarray(f, dtype=float)
        # (n, 3) @ (3, 3) products of contiguous arrays: a broadcast (stride 0) operand is 10× slower
        return np.asarray(rate, dtype=float) @ self.K.T + self.B + f @ self.G.T + monomials(f) @ self.dynamic.T


def predicted_shift(gyro: VibrationGyro, gravity_body: np.ndarray, variances: np.ndarray) -> np.ndarray:
    """Δy (3,), rad/s: the mean output shift under independent zero-mean Gaussian vibration of variances
    E[a_j²] (3,), (m/s²)², on top of the specific force *gravity_body* (3,), m/s² (module docstring)."""
    v = np.asarray(variances, dtype=float)
    g = np.asarray(gravity_body, dtype=float)
    return gyro.S2 @ v + 3.0 * gyro.D @ (g * v)


def interval_moments(taps: np.ndarray, oversampling: int) -> tuple[float, float, float]:
    """(σ², s², m₄): the process *taps*'s variance E[a²], the variance E[ā²] of the mean ā of *oversampling*
    consecutive samples (an integrate-and-dump output sample), and E[ā² q] with q the mean of a² over the same
    samples; (unit of h)², (unit of h)², (unit of h)⁴.

    From the autocorrelation R(k) = Σ_m h[m] h[m + k]: σ² = R(0), s² = (1/n²) Σ_ij R(i − j), and, a being
    Gaussian (Isserlis), E[ā² q] = s²σ² + (2/n) Σ_i c_i² with c_i = E[ā a_i] = (1/n) Σ_j R(i − j).
    """
    n = check_count("oversampling", oversampling)
    h = np.asarray(taps, dtype=float)
    full = np.correlate(h, h, mode="full")  # R(k) for k = −(L − 1) … L − 1
    centre = len(h) - 1
    lags = np.subtract.outer(np.arange(n), np.arange(n))
    R = np.where(np.abs(lags) < len(h), full[np.clip(centre + lags, 0, len(full) - 1)], 0.0)
    c = R.mean(axis=1)
    s2 = float(c.mean())
    variance = float(full[centre])
    return variance, s2, s2 * variance + 2.0 * float(np.mean(c * c))


def g2_fit_ratio(gravity: float, taps: np.ndarray, oversampling: int, fraction: float) -> float:
    """Ŝ/S₂: what the least-squares g² coefficient comes out as, against the truth, when the accelerometer's
    integrate-and-dump samples see only part of the vibration (docs/dynamic.md, "The simulation against the
    paper").

    One axis shaken along gravity (f = g + a), the column f̄² = (g + ā)² fitted without an intercept over a
    record whose share *fraction* is under vibration, the gyro rectifying the full band: r = S₂(g² + 2gā + q),
    q the interval mean of a². Still samples give m = g², r = S₂g²; under vibration E[m²] = g⁴ + 6g²s² + 3s⁴
    and E[m r]/S₂ = g⁴ + g²(σ² + 5s²) + E[ā² q] (odd moments vanish), so with p = *fraction*

        Ŝ/S₂ = [(1 − p) g⁴ + p (g⁴ + g²(σ² + 5s²) + E[ā² q])] / [(1 − p) g⁴ + p (g⁴ + 6g²s² + 3s⁴)],

    the moments of :func:`interval_moments`. It is 1 when the accelerometer sees everything (s² = σ²,
    E[ā² q] = 3σ⁴). Left out: the noise, the static calibration's errors, the g³ and cross terms.
    """
    v, s2, m4 = interval_moments(taps, oversampling)
    g2, p = float(gravity) ** 2, float(fraction)
    numerator = (1 - p) * g2 * g2 + p * (g2 * g2 + g2 * (v + 5 * s2) + m4)
    return numerator / ((1 - p) * g2 * g2 + p * (g2 * g2 + 6 * g2 * s2 + 3 * s2 * s2))


def check_count(name: str, value, low: int = 1) -> int:
    """*value* as an int ≥ *low*, or a TypeError / ValueError naming *name*."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        number = one_number(name, value)
        if not float(number).is_integer():
            raise TypeError(f"{name}: expected an integer, got {value!r}")
        value = int(number)
    if value < low:
        raise ValueError(f"{name}: expected an integer >= {low}, got {value!r}")
    return int(value)

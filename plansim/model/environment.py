"""The laboratory: local gravity and the Earth-rate vector.

Frames: the local-level frame is East-North-Up (ENU). A resting accelerometer senses the
specific force ``+g·Up``; a resting gyro senses the Earth rate
``Ω_ie·[0, cos φ, sin φ]`` (ENU) at latitude φ.
"""

from __future__ import annotations

import math

import numpy as np

#: Earth rotation rate relative to inertial space, rad/s (WGS 84 / IERS: 7.292115e-5 rad/s,
#: i.e. 15.041 °/h; one sidereal day of 23 h 56 min 4.09 s).
EARTH_RATE = 7.292115e-5

# WGS 84 normal gravity (Somigliana closed form), NIMA TR8350.2 eq. (4-1) constants
_GAMMA_EQUATOR = 9.7803253359  # m/s²
_K_SOMIGLIANA = 0.00193185265241
_E2 = 0.00669437999013
# free-air gradient of normal gravity near the surface, m/s² per m (≈ −0.3086 mGal/m)
_FREE_AIR_GRADIENT = -3.086e-6


def normal_gravity(latitude: float, height: float = 0.0) -> float:
    """Magnitude of normal gravity at geodetic *latitude* (rad) and ellipsoidal *height* (m).

    Somigliana's formula on the WGS 84 ellipsoid (NIMA TR8350.2, eq. 4-1),

    .. math:: \\gamma(\\varphi) = \\gamma_e \\frac{1 + k \\sin^2\\varphi}{\\sqrt{1 - e^2 \\sin^2\\varphi}},

    with the linear free-air correction −3.086e-6 s⁻² · h, adequate for laboratory heights
    (error < 1e-7 relative below 2 km).

    Examples
    --------
    >>> round(normal_gravity(0.0), 7), round(normal_gravity(math.pi / 2), 7)
    (9.7803253, 9.8321849)
    """
    s2 = math.sin(latitude) ** 2
    gamma = _GAMMA_EQUATOR * (1.0 + _K_SOMIGLIANA * s2) / math.sqrt(1.0 - _E2 * s2)
    return gamma + _FREE_AIR_GRADIENT * height


def earth_rate_enu(latitude: float) -> np.ndarray:
    """Earth-rate vector in the local ENU frame, rad/s: ``Ω·[0, cos φ, sin φ]``."""
    return EARTH_RATE * np.array([0.0, math.cos(latitude), math.sin(latitude)])

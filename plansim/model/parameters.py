"""The calibration parameters of JJF 2003-2022 eq. (1) and (2), named by the specification's symbols.

Gyro model, eq. (1):          w' = Kg·w + Bg + G·a
Accelerometer model, eq. (2): a' = Ka·a + Ba + P·(w²)

``Kg`` (3×3, dimensionless; diagonal = scale factors, off-diagonal = cross-coupling), ``Bg``
(rad/s), ``G`` (rad/s per m/s², bias acceleration sensitivity), ``Ka`` (3×3, dimensionless),
``Ba`` (m/s²), ``P`` (3×3 with zero diagonal, m/s² per (rad/s)², angular-rate sensitivity).
Row = sensor (output) axis, column = input axis: ``Kgxy`` is the X gyro's response to a rate
about Y (JJF 2003 §7.2.3: column *j* is measured with axis *j* on the rate table).

The 39 parameters are held as one flat vector in the order of :data:`PARAMETER_NAMES`;
:func:`unpack` and :func:`pack` convert to and from the matrices.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from plansim.units import KINDS

AXES = "xyz"


@dataclass(frozen=True)
class ParameterSpec:
    """One calibration parameter: its symbol, place in the model, SI unit and display unit."""

    name: str
    group: str  # Kg, Bg, G, Ka, Ba, P
    row: int
    col: int  # -1 for vectors
    kind: str  # key of plansim.units.KINDS
    si_unit: str
    display_unit: str
    long_name: str

    @property
    def display_factor(self) -> float:
        """SI value × 1/display_factor = value in display unit."""
        return KINDS[self.kind][self.display_unit]

    @property
    def unit_suffix(self) -> str:
        """What follows a value in display units in a sentence: ' ug', or '' for a dimensionless one."""
        return "" if self.display_unit == "1" else f" {self.display_unit}"


def _build() -> list[ParameterSpec]:
    specs: list[ParameterSpec] = []
    for i, r in enumerate(AXES):
        for j, c in enumerate(AXES):
            what = "scale factor" if i == j else f"cross-coupling, {r} gyro to rate about {c}"
            specs.append(ParameterSpec(f"Kg{r}{c}", "Kg", i, j, "dimensionless", "1", "1", f"gyro {what}"))
    for i, r in enumerate(AXES):
        specs.append(ParameterSpec(f"Bg{r}", "Bg", i, -1, "angular_rate", "rad/s", "deg/h", f"{r} gyro bias"))
    for i, r in enumerate(AXES):
        for j, c in enumerate(AXES):
            specs.append(
                ParameterSpec(
                    f"g{r}{c}", "G", i, j, "rate_per_acceleration", "rad/s/(m/s^2)", "deg/h/g",
                    f"{r} gyro bias sensitivity to acceleration along {c}",
                )
            )
    for i, r in enumerate(AXES):
        for j, c in enumerate(AXES):
            what = "scale factor" if i == j else f"cross-coupling, {r} accelerometer to acceleration along {c}"
            specs.append(ParameterSpec(f"Ka{r}{c}", "Ka", i, j, "dimensionless", "1", "1", f"accelerometer {what}"))
    for i, r in enumerate(AXES):
        specs.append(ParameterSpec(f"Ba{r}", "Ba", i, -1, "acceleration", "m/s^2", "ug", f"{r} accelerometer bias"))
    for i, r in enumerate(AXES):
        for j, c in enumerate(AXES):
            if i != j:
                specs.append(
                    ParameterSpec(
                        f"p{r}{c}", "P", i, j, "acceleration_per_rate_squared", "(m/s^2)/(rad/s)^2",
                        "ug/(rad/s)^2", f"{r} accelerometer sensitivity to squared rate about {c}",
                    )
                )
    return specs


PARAMETERS: tuple[ParameterSpec, ...] = tuple(_build())
PARAMETER_NAMES: tuple[str, ...] = tuple(p.name for p in PARAMETERS)
PARAMETER_INDEX: dict[str, int] = {p.name: k for k, p in enumerate(PARAMETERS)}
N_PARAMETERS = len(PARAMETERS)
#: the parameter groups in parameter order: Kg, Bg, G, Ka, Ba, P
GROUPS: tuple[str, ...] = tuple(dict.fromkeys(p.group for p in PARAMETERS))


def parameter(name: str) -> ParameterSpec:
    """Look up a parameter by its specification symbol."""
    try:
        return PARAMETERS[PARAMETER_INDEX[name]]
    except KeyError:
        raise ValueError(f"unknown parameter {name!r}; known: {', '.join(PARAMETER_NAMES)}") from None


def group_spec(group: str) -> ParameterSpec:
    """The first parameter of *group* (:data:`GROUPS`): its units (SI and display) are the whole group's."""
    for p in PARAMETERS:
        if p.group == group:
            return p
    raise ValueError(f"unknown parameter group {group!r}; known: {', '.join(GROUPS)}")


@functools.cache
def _indices(group: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(parameter index, row, column) of each parameter of *group*, built once (read-only)."""
    sel = [(k, p.row, p.col) for k, p in enumerate(PARAMETERS) if p.group == group]
    k, r, c = (np.array(x) for x in zip(*sel))
    for x in (k, r, c):
        x.flags.writeable = False
    return k, r, c


def unpack(vector: np.ndarray) -> dict[str, np.ndarray]:
    """Flat parameter vector(s) ``(..., 39)`` -> matrices ``Kg, Bg, G, Ka, Ba, P`` with leading dims."""
    vector = np.asarray(vector, dtype=float)
    lead = vector.shape[:-1]
    out: dict[str, np.ndarray] = {}
    for group in ("Kg", "G", "Ka", "P"):
        k, r, c = _indices(group)
        m = np.zeros(lead + (3, 3))
        m[..., r, c] = vector[..., k]
        out[group] = m
    for group in ("Bg", "Ba"):
        k, r, _ = _indices(group)
        v = np.zeros(lead + (3,))
        v[..., r] = vector[..., k]
        out[group] = v
    return out


def pack(Kg, Bg, G, Ka, Ba, P) -> np.ndarray:
    """Matrices (with equal leading dims) -> flat vector(s) ``(..., 39)``. P's diagonal is dropped."""
    mats = {"Kg": Kg, "Bg": Bg, "G": G, "Ka": Ka, "Ba": Ba, "P": P}
    lead = np.shape(Kg)[:-2]
    out = np.zeros(lead + (N_PARAMETERS,))
    for group, m in mats.items():
        m = np.asarray(m, dtype=float)
        k, r, c = _indices(group)
        out[..., k] = m[..., r, c] if group in ("Kg", "G", "Ka", "P") else m[..., r]
    return out

"""JJF 2003-2022 Appendix A: the five published uncertainty budgets as data, their printed arithmetic and readings.

Appendix A ("MIMU 测量不确定度评定示例") evaluates five example budgets, all with coverage
factor k = 2:

- A.1 gyro scale factor K, eq. (A.1)-(A.2): Kgxx, Kgyy, Kgzz;
- A.2 gyro bias B, the mean of the 6 position groups, eq. (A.4)-(A.5): Bgx, Bgy, Bgz;
- A.3 gyro bias acceleration sensitivity, ``gxx = (U1 − U2)/2``, eq. (A.6)-(A.8): the nine g**
  (gxx is the example, "the others similar", A.3.1);
- A.4 gyro cross-coupling, eq. (A.9), propagated as A.1: the six off-diagonal Kg**;
- A.5 accelerometer angular-rate sensitivity, ``p_yx = (U7 − U8)/ω²``, eq. (A.10)-(A.12): the six
  p** (p_yx is the example, "the others similar", A.5.1).

Each budget combines three components by ``u_c = sqrt(u1² + u2² + u3²)`` (A.1.3, A.2.3, …):

- ``u1`` turntable: ``U = 2e-4, k = 2`` -> ``1.0e-4`` (A.1.2.1);
- ``u2`` acquisition: quantisation ``δ = 1/2^N`` (eq. (A.3)), ``N = 12``, uniform ->
  ``u2 = δ/√3 = 1.41e-4`` (A.1.2.2);
- ``u3`` repeatability: ``1.22e-4`` given directly (A.1.2.3, A.4.2.3); for A.2 six inputs of
  ``3.41e-5`` **added linearly** to ``2.046e-4`` (A.2.2.3); for A.3 and A.5 two inputs of
  ``2.51e-3`` added linearly to ``5.02e-3`` (A.3.2.3, A.5.2.3).

:data:`APPENDIX_A` stores every component's inputs (value per reading, number of readings, the
combination rule as printed, and the measurement model's sensitivity coefficient) together with the
printed ``u_c`` and ``U`` exactly as printed, so that the printed arithmetic can be checked
(:meth:`AppendixABudget.recomputed_combined_standard_uncertainty`) and a GUM evaluation can
recombine the same inputs (:attr:`UncertaintyComponent.gum_standard_uncertainty`).

Slips in the printed arithmetic (see ``tests/test_appendix_a.py``):

- A.3 and A.5: ``2 × 5.02e-3 = 1.00e-2``, printed ``1.1e-2``;
- A.1 and A.4: ``2 × 2.12e-4 = 4.23e-4``, printed ``4.3e-4`` (both are the arithmetic value
  rounded *up* to two significant digits, GUM 7.2.6; A.2's ``5.36e-4`` is rounded to nearest);
- A.2, A.3, A.5: the repeatability of the individual readings is added linearly, although the
  model is a mean (sensitivity 1/6, eq. (A.4)), a half-difference (1/2, eq. (A.6)) or a
  difference (1, eq. (A.10)); the GUM law of propagation for independent readings (GUM 5.1.2)
  gives ``√6·3.41e-5/6 = 1.39e-5``, ``√2·2.51e-3/2 = 1.77e-3`` and ``√2·2.51e-3 = 3.55e-3``.

Readings of the units
---------------------
Appendix A never states units: ``u1`` is a relative rate error (Table 1), ``u2`` a fraction of the
acquisition full-scale range (eq. (A.3)) and ``u3`` is in unstated output units, and they are added
without sensitivity coefficients. To compare a budget with simulated errors its number has to be
*read* in some unit, and more than one reading is defensible. Each budget carries a tuple of
:class:`Reading` (``AppendixABudget.readings``); the first is the **primary** reading, the one in
which the budget's three components are commensurable with the model (``reading_kind``):

``A.1`` — ``"relative"`` (primary), ``"absolute"``
    The relative error of the scale factor, ``(K̂ − K)/K``: ``u1`` is the relative rate error of
    the table and ``u2`` the quantisation relative to full scale, which the maximum rate point
    (required by §7.2.1.1 c)) approaches. The absolute error ``K̂ − K`` is the same number within
    ``|K| − 1`` (2·10⁻³ in the default unit); it is kept so that the report *shows* that no
    verdict hinges on the difference.
``A.2`` — ``"FS_g"`` (primary), ``"deg/s"``
    A fraction of the gyro full scale (``scenario.acquisition.gyro_full_scale``, rad/s): the
    outputs ``U_gxi``, and ``u2``, are fractions of the acquisition's full scale. Or °/s, the unit
    of the specification's rates (clause 1, §7.2.1.1).
``A.3`` — ``"FS_g/g"`` (primary), ``"deg/s/g"``, ``"deg/h/g"``
    A fraction of the gyro full scale per g, ``FS_g/g_ref`` (rad/s per m/s²), since eq. (A.6)
    divides outputs (fractions of FS_g) by the 2 g span of the matrix A of eq. (6); or °/s per g
    (outputs in °/s); or °/h per g, the unit of MEMS data sheets. ``g_ref`` is the value of 1 g
    the laboratory uses in matrix A (``scenario.reduction.reference_gravity``), in every reading.
``A.4`` — ``"absolute"``
    The absolute error of the dimensionless cross-coupling coefficient, ``K̂gxy − Kgxy``
    (A.4.1: "the same model as the scale factor"; a relative error of a coefficient near zero is
    meaningless). The only reading.
``A.5`` — ``"FS_a/omega^2"`` (primary), ``"g/(rad/s)^2"``, ``"(m/s^2)/(rad/s)^2"``
    A fraction of the accelerometer full scale per squared test rate, ``FS_a/ω²``
    ((m/s²)/(rad/s)²), since eq. (A.10) divides outputs (fractions of FS_a) by ω²; ω is the rate
    of the rotating ("U8") ``omega_squared`` segment of the schedule about the parameter's input
    axis (column *j* of P is measured with axis *j* up, §7.2.5). Or g per (rad/s)² (outputs in g,
    ``g = g_ref``), or the SI unit of p.

:func:`reading_unit_in_si` gives the SI size of one unit of a reading (the primary one unless
``reading=`` names another) and :func:`errors_in_reading_units` converts errors;
:func:`printed_arithmetic_slips` lists the slips in words.
:func:`plansim.uncertainty.appendix_a_comparison.compare_with_appendix_a` compares Monte Carlo errors
with each budget, under every reading.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import Decimal

import numpy as np

from plansim.model.parameters import PARAMETER_INDEX, PARAMETER_NAMES, parameter
from plansim.units import DEG, HOUR

__all__ = [
    "ACQUISITION_BITS",
    "APPENDIX_A",
    "COMBINATION_RULES",
    "READING_KINDS",
    "TABLE_COVERAGE_FACTOR",
    "TABLE_EXPANDED_UNCERTAINTY",
    "AppendixABudget",
    "Reading",
    "UncertaintyComponent",
    "acquisition_quantisation_uncertainty",
    "appendix_a_budget",
    "errors_in_reading_units",
    "expanded_uncertainty_in_si",
    "omega_squared_test_rate",
    "printed_arithmetic_slips",
    "reading_si_unit",
    "reading_unit_description",
    "reading_unit_in_si",
]

#: A.1.2.1: expanded uncertainty of the position and rate table, and its coverage factor.
TABLE_EXPANDED_UNCERTAINTY = 2e-4
TABLE_COVERAGE_FACTOR = 2.0
#: A.1.2.2: effective number of bits N of the acquisition system in eq. (A.3).
ACQUISITION_BITS = 12

#: How Appendix A combines the readings of one component, as printed.
#: ``"single"``: one value; ``"linear_sum"``: ``u = Σ u(U_i) = count × value`` (A.2.2.3, A.3.2.3, A.5.2.3).
COMBINATION_RULES = ("single", "linear_sum")

#: How the SI size of one unit of a reading is obtained (module docstring; :func:`reading_unit_in_si`):
#: ``|truth|``, 1, ``FS_g``, ``FS_g/g_ref``, ``FS_a/ω²``, 1 (the parameter's SI unit), ``π/180``,
#: ``(π/180)/g_ref``, ``(π/180/3600)/g_ref`` and ``g_ref``.
READING_KINDS = (
    "relative",
    "absolute",
    "gyro_full_scale",
    "gyro_full_scale_per_reference_gravity",
    "accel_full_scale_per_rate_squared",
    "si",
    "degree_per_second",
    "degree_per_second_per_reference_gravity",
    "degree_per_hour_per_reference_gravity",
    "reference_gravity_per_rate_squared",
)

#: SI unit of one reading unit, by kind (None: dimensionless).
_READING_SI_UNIT = {
    "relative": None,
    "absolute": None,
    "gyro_full_scale": "rad/s",
    "gyro_full_scale_per_reference_gravity": "rad/s per m/s^2",
    "accel_full_scale_per_rate_squared": "(m/s^2)/(rad/s)^2",
    "si": None,
    "degree_per_second": "rad/s",
    "degree_per_second_per_reference_gravity": "rad/s per m/s^2",
    "degree_per_hour_per_reference_gravity": "rad/s per m/s^2",
    "reference_gravity_per_rate_squared": "(m/s^2)/(rad/s)^2",
}


@dataclass(frozen=True)
class Reading:
    """One reading of the unit in which an Appendix A budget's numbers are taken.

    Attributes
    ----------
    name : str
        Short name used in reports and JSON: ``"relative"``, ``"FS_g"``, ``"deg/s"``, ``"deg/h/g"``, …
    kind : str
        How the SI size of one unit is obtained, one of :data:`READING_KINDS`.
    unit : str
        The unit in words, for reports.
    why : str
        Why the reading is defensible.
    """

    name: str
    kind: str
    unit: str
    why: str = ""

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"reading name = {self.name!r}: expected a non-empty string")
        if self.kind not in READING_KINDS:
            raise ValueError(f"reading {self.name!r}: kind = {self.kind!r}; "
                             f"allowed: {', '.join(map(repr, READING_KINDS))}")

    @property
    def constant(self) -> bool:
        """Whether one unit has the same SI size in every trial (all but ``"relative"``, which is ``|truth|``)."""
        return self.kind != "relative"


def acquisition_quantisation_uncertainty(bits: int = ACQUISITION_BITS) -> float:
    """Standard uncertainty of the acquisition quantisation, JJF 2003 eq. (A.3) and A.1.2.2.

    Parameters
    ----------
    bits : int
        Effective number of bits N of the acquisition system (A.1.2.2 takes N = 12).

    Returns
    -------
    float
        ``u2 = δ/√3`` with ``δ = 1/2^N`` (type B, uniform distribution), a fraction of full scale;
        ``1.4095e-4`` for N = 12, printed as ``1.41e-4``.
    """
    if isinstance(bits, bool) or not isinstance(bits, (int, np.integer)):
        raise TypeError(f"bits = {bits!r}: expected a whole number of bits")
    if bits < 1:
        raise ValueError(f"bits = {bits!r}: the acquisition system needs at least 1 effective bit")
    return (1.0 / 2.0 ** int(bits)) / math.sqrt(3.0)


# ----------------------------------------------------------------------------- the budgets as data


@dataclass(frozen=True)
class UncertaintyComponent:
    """One uncertainty component of an Appendix A budget, with its inputs as printed.

    Attributes
    ----------
    symbol : str
        ``"u1"``, ``"u2"`` or ``"u3"``.
    source : str
        What the component comes from (turntable, acquisition system, repeatability).
    clause : str
        The Appendix A clause that evaluates it, e.g. ``"A.2.2.3"``.
    value_per_reading : float
        The standard uncertainty of one input reading, as printed (e.g. ``u(U_gx1) = 3.41e-5``),
        in the budget's reading unit.
    count : int
        Number of input readings the component combines (1, 2 or 6).
    combination_as_printed : str
        How the text combines the readings, one of :data:`COMBINATION_RULES`.
    printed_value : float
        The component's value exactly as printed (``1.0e-4``, ``1.41e-4``, ``2.046e-4``, …).
    sensitivity_coefficient : float
        Magnitude of the sensitivity coefficient of each reading in the budget's measurement
        model, in the reading unit: 1/6 for the mean of eq. (A.4), 1/2 for the half-difference of
        eq. (A.6), 1 for the difference of eq. (A.10) read in FS_a/ω², and 1 where the text gives the
        component directly (u1, u2, and u3 of A.1/A.4). The printed budgets do not apply it.
    derivation : str
        How the text obtains the value.
    """

    symbol: str
    source: str
    clause: str
    value_per_reading: float
    count: int
    combination_as_printed: str
    printed_value: float
    sensitivity_coefficient: float = 1.0
    derivation: str = ""

    def __post_init__(self):
        where = f"component {self.symbol!r} ({self.clause})"
        if self.combination_as_printed not in COMBINATION_RULES:
            raise ValueError(f"{where}: combination_as_printed = {self.combination_as_printed!r}; "
                             f"allowed: {', '.join(map(repr, COMBINATION_RULES))}")
        if isinstance(self.count, bool) or not isinstance(self.count, int):
            raise TypeError(f"{where}: count = {self.count!r}; expected a whole number of readings")
        if self.count < 1:
            raise ValueError(f"{where}: count = {self.count!r}; it must be >= 1")
        if self.combination_as_printed == "single" and self.count != 1:
            raise ValueError(f"{where}: count = {self.count!r} with combination 'single'; "
                             "a single value has count 1 (use 'linear_sum' for several readings)")
        for name in ("value_per_reading", "printed_value", "sensitivity_coefficient"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise TypeError(f"{where}: {name} = {value!r}; expected a number")
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"{where}: {name} = {value!r}; it must be finite and >= 0")

    @property
    def combined_as_printed(self) -> float:
        """The component recomputed with the printed rule: ``value`` or ``count × value`` (linear sum)."""
        if self.combination_as_printed == "linear_sum":
            return self.count * self.value_per_reading
        return self.value_per_reading

    @property
    def gum_standard_uncertainty(self) -> float:
        """The component by the GUM law of propagation for independent readings (GUM 5.1.2, eq. (10)).

        ``c · sqrt(count) · value_per_reading``: ``√6·3.41e-5/6 = 1.39e-5`` for A.2,
        ``√2·2.51e-3/2 = 1.77e-3`` for A.3, ``√2·2.51e-3 = 3.55e-3`` for A.5 (read in FS_a/ω²).
        """
        return self.sensitivity_coefficient * math.sqrt(self.count) * self.value_per_reading


@dataclass(frozen=True)
class AppendixABudget:
    """One Appendix A uncertainty budget (JJF 2003-2022, A.1 … A.5), as printed.

    Attributes
    ----------
    item : str
        ``"A.1"`` … ``"A.5"``.
    quantity : str
        The quantity evaluated.
    measurement_model : str
        The model and the equations the clause cites.
    parameters : tuple of str
        The JJF 2003 parameters (names of :data:`plansim.model.parameters.PARAMETER_NAMES`) the
        budget applies to; the text treats one as an example and says the others are similar.
    components : tuple of UncertaintyComponent
        ``u1``, ``u2``, ``u3``.
    printed_combined_standard_uncertainty : float
        ``u_c`` exactly as printed (A.x.3).
    printed_expanded_uncertainty : float
        ``U`` exactly as printed (A.x.4).
    coverage_factor : float
        ``k`` (2 in every budget).
    reading_kind : str
        The kind of the primary reading (one of :data:`READING_KINDS`; module docstring): the one
        plansim's single-reading figures use.
    reading : str
        The primary reading in words.
    readings : tuple of Reading
        Every defensible reading of the budget's unit; the first is the primary one (its kind is
        ``reading_kind``). Names are unique.
    """

    item: str
    quantity: str
    measurement_model: str
    parameters: tuple[str, ...]
    components: tuple[UncertaintyComponent, ...]
    printed_combined_standard_uncertainty: float
    printed_expanded_uncertainty: float
    coverage_factor: float
    reading_kind: str
    reading: str
    readings: tuple[Reading, ...]

    def __post_init__(self):
        where = f"budget {self.item!r}"
        if not self.parameters:
            raise ValueError(f"{where}: parameters is empty; name at least one JJF 2003 parameter")
        for name in self.parameters:
            if name not in PARAMETER_INDEX:
                raise ValueError(f"{where}: unknown parameter {name!r}; known: {', '.join(PARAMETER_NAMES)}")
        if len(set(self.parameters)) != len(self.parameters):
            raise ValueError(f"{where}: parameters {self.parameters!r} lists a parameter twice")
        if not self.components or not all(isinstance(c, UncertaintyComponent) for c in self.components):
            raise TypeError(f"{where}: components must be a non-empty tuple of UncertaintyComponent")
        if self.reading_kind not in READING_KINDS:
            raise ValueError(f"{where}: reading_kind = {self.reading_kind!r}; "
                             f"allowed: {', '.join(map(repr, READING_KINDS))}")
        if not isinstance(self.readings, tuple) or not self.readings \
                or not all(isinstance(r, Reading) for r in self.readings):
            raise TypeError(f"{where}: readings = {self.readings!r}; expected a non-empty tuple of Reading")
        if self.readings[0].kind != self.reading_kind:
            raise ValueError(f"{where}: readings[0] is {self.readings[0].name!r} of kind {self.readings[0].kind!r}; "
                             f"the first reading is the primary one and must have reading_kind {self.reading_kind!r}")
        names = [r.name for r in self.readings]
        if len(set(names)) != len(names):
            raise ValueError(f"{where}: readings {names!r} repeat a name")
        for name in ("printed_combined_standard_uncertainty", "printed_expanded_uncertainty", "coverage_factor"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise TypeError(f"{where}: {name} = {value!r}; expected a number")
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{where}: {name} = {value!r}; it must be finite and > 0")

    def component(self, symbol: str) -> UncertaintyComponent:
        """The component named *symbol* (``"u1"``, ``"u2"`` or ``"u3"``)."""
        for c in self.components:
            if c.symbol == symbol:
                return c
        raise ValueError(f"budget {self.item!r} has no component {symbol!r}; "
                         f"it has {', '.join(repr(c.symbol) for c in self.components)}")

    @property
    def primary_reading(self) -> Reading:
        """The first of :attr:`readings`: the reading of ``reading_kind``."""
        return self.readings[0]

    def reading_named(self, name: str) -> Reading:
        """The reading called *name* (e.g. ``"deg/s"``); ValueError listing the budget's readings otherwise."""
        for r in self.readings:
            if r.name == name:
                return r
        raise ValueError(f"budget {self.item!r} has no reading {name!r}; "
                         f"its readings: {', '.join(repr(r.name) for r in self.readings)}")

    def recomputed_combined_standard_uncertainty(self) -> float:
        """``u_c = sqrt(u1² + u2² + u3²)`` from the printed components (A.1.3 … A.5.3).

        Each component is recombined from its inputs with the printed rule
        (:attr:`UncertaintyComponent.combined_as_printed`), so this is the text's own arithmetic.
        """
        return math.sqrt(sum(c.combined_as_printed ** 2 for c in self.components))

    def recomputed_expanded_uncertainty(self) -> float:
        """``U = k · u_c`` with :meth:`recomputed_combined_standard_uncertainty` (A.1.4 … A.5.4), unrounded."""
        return self.coverage_factor * self.recomputed_combined_standard_uncertainty()


def _table_component(clause: str) -> UncertaintyComponent:
    return UncertaintyComponent(
        symbol="u1", source="position and rate table", clause=clause,
        value_per_reading=TABLE_EXPANDED_UNCERTAINTY / TABLE_COVERAGE_FACTOR, count=1,
        combination_as_printed="single", printed_value=1.0e-4,
        derivation="table U = 2e-4 with k = 2, u1 = U/k (type B)",
    )


def _acquisition_component(clause: str) -> UncertaintyComponent:
    return UncertaintyComponent(
        symbol="u2", source="data acquisition system (quantisation)", clause=clause,
        value_per_reading=1.41e-4, count=1, combination_as_printed="single", printed_value=1.41e-4,
        derivation="eq. (A.3) δ = 1/2^N, N = 12, uniform: u2 = δ/√3 (type B)",
    )


def _scale_factor_repeatability_component(clause: str) -> UncertaintyComponent:
    """u3 of A.1 and A.4: the same printed type A value (A.1.2.3, A.4.2.3)."""
    return UncertaintyComponent(
        symbol="u3", source="measurement repeatability", clause=clause,
        value_per_reading=1.22e-4, count=1, combination_as_printed="single", printed_value=1.22e-4,
        derivation="from a large amount of experimental data on one MIMU type (type A)",
    )


_RELATIVE = Reading(
    "relative", "relative", "1 (relative error, error / true value)",
    "u1 is the table's relative rate error and u2 a fraction of full scale, which the maximum rate point "
    "(§7.2.1.1 c)) approaches: the three components are relative errors of K")
_K_ABSOLUTE = Reading(
    "absolute", "absolute", "1 (absolute error of the dimensionless scale factor)",
    "K is dimensionless and close to 1, so K̂ − K is the relative error times |K|; kept so that the report "
    "shows that no verdict hinges on |K| − 1")
_COEFFICIENT_ABSOLUTE = Reading(
    "absolute", "absolute", "1 (absolute error of the dimensionless coefficient)",
    "A.4.1 propagates as the scale factor; a relative error of a coefficient near 0 means nothing")
_GYRO_READINGS = {
    "FS_g": Reading("FS_g", "gyro_full_scale", "FS_g (gyro full scale)",
                    "the outputs U_gxi, and u2 of eq. (A.3), are fractions of the acquisition full scale"),
    "deg/s": Reading("deg/s", "degree_per_second", "°/s",
                     "the outputs in °/s, the unit of the specification's rates (clause 1, §7.2.1.1)"),
}
_G_SENSITIVITY_READINGS = (
    Reading("FS_g/g", "gyro_full_scale_per_reference_gravity", "FS_g/g_ref (gyro full scale per reference g)",
            "eq. (A.6) divides outputs (fractions of FS_g) by the 2 g span of matrix A, eq. (6)"),
    Reading("deg/s/g", "degree_per_second_per_reference_gravity", "°/s per g (g = g_ref)",
            "outputs in °/s divided by the 2 g span of matrix A"),
    Reading("deg/h/g", "degree_per_hour_per_reference_gravity", "°/h per g (g = g_ref)",
            "the unit in which MEMS data sheets (and plansim's tables) give a g-sensitivity"),
)
_RATE_SENSITIVITY_READINGS = (
    Reading("FS_a/omega^2", "accel_full_scale_per_rate_squared",
            "FS_a/ω² (accelerometer full scale per squared test rate)",
            "eq. (A.10) divides outputs (fractions of FS_a) by ω²"),
    Reading("g/(rad/s)^2", "reference_gravity_per_rate_squared", "g per (rad/s)² (g = g_ref)",
            "outputs in g divided by ω² in (rad/s)²"),
    Reading("(m/s^2)/(rad/s)^2", "si", "(m/s²)/(rad/s)² (the SI unit of p)",
            "outputs in m/s² divided by ω² in (rad/s)²"),
)


#: The five budgets of JJF 2003-2022 Appendix A, as printed.
APPENDIX_A: tuple[AppendixABudget, ...] = (
    AppendixABudget(
        item="A.1",
        quantity="gyro scale factor K",
        measurement_model="U = K X + b + ε, eq. (A.1) (from §7.2.1.2 eq. (4)); u_c²(K) by eq. (A.2)",
        parameters=("Kgxx", "Kgyy", "Kgzz"),
        components=(
            _table_component("A.1.2.1"),
            _acquisition_component("A.1.2.2"),
            _scale_factor_repeatability_component("A.1.2.3"),
        ),
        printed_combined_standard_uncertainty=2.12e-4,
        printed_expanded_uncertainty=4.3e-4,
        coverage_factor=2.0,
        reading_kind="relative",
        reading="relative error of the scale factor, (estimate − truth)/truth (dimensionless)",
        readings=(_RELATIVE, _K_ABSOLUTE),
    ),
    AppendixABudget(
        item="A.2",
        quantity="gyro bias B (mean of the 6 position groups)",
        measurement_model="B = (U_gx1 + … + U_gx6)/6, eq. (A.4) (from §7.2.2.2 eq. (7)); u_c²(B) by eq. (A.5)",
        parameters=("Bgx", "Bgy", "Bgz"),
        components=(
            _table_component("A.2.2.1"),
            _acquisition_component("A.2.2.2"),
            UncertaintyComponent(
                symbol="u3", source="repeatability of the 6 group outputs U_gx1 … U_gx6", clause="A.2.2.3",
                value_per_reading=3.41e-5, count=6, combination_as_printed="linear_sum", printed_value=2.046e-4,
                sensitivity_coefficient=1.0 / 6.0,
                derivation="u(U_gx1) = … = u(U_gx6) = 3.41e-5 (type A); printed u3 = Σ u(U_gxi) = 2.046e-4",
            ),
        ),
        printed_combined_standard_uncertainty=2.68e-4,
        printed_expanded_uncertainty=5.36e-4,
        coverage_factor=2.0,
        reading_kind="gyro_full_scale",
        reading="gyro bias error as a fraction of the gyro full scale (U_abs = U × FS_g, rad/s)",
        readings=(_GYRO_READINGS["FS_g"], _GYRO_READINGS["deg/s"]),
    ),
    AppendixABudget(
        item="A.3",
        quantity="gyro bias acceleration sensitivity g (gxx as the example, the others similar)",
        measurement_model="gxx = (U_gx1 − U_gx2)/2, eq. (A.6)-(A.7) (from §7.2.2.2 eq. (7)); u_c² by eq. (A.8)",
        parameters=("gxx", "gxy", "gxz", "gyx", "gyy", "gyz", "gzx", "gzy", "gzz"),
        components=(
            _table_component("A.3.2.1"),
            _acquisition_component("A.3.2.2"),
            UncertaintyComponent(
                symbol="u3", source="repeatability of the outputs U_gx1, U_gx2", clause="A.3.2.3",
                value_per_reading=2.51e-3, count=2, combination_as_printed="linear_sum", printed_value=5.02e-3,
                sensitivity_coefficient=0.5,
                derivation="u(U_gx1) = u(U_gx2) = 2.51e-3 (type A); printed u3 = u(U_gx1) + u(U_gx2) = 5.02e-3",
            ),
        ),
        printed_combined_standard_uncertainty=5.02e-3,
        printed_expanded_uncertainty=1.1e-2,
        coverage_factor=2.0,
        reading_kind="gyro_full_scale_per_reference_gravity",
        reading="g-sensitivity error as a fraction of the gyro full scale per g "
                "(U_abs = U × FS_g / g_ref, rad/s per m/s²)",
        readings=_G_SENSITIVITY_READINGS,
    ),
    AppendixABudget(
        item="A.4",
        quantity="gyro cross-coupling coefficient (Kgxy as the example, the others similar)",
        measurement_model="off-diagonal elements of Kg, eq. (A.9) (from §7.2.3.2); propagation as A.1, eq. (A.2)",
        parameters=("Kgxy", "Kgxz", "Kgyx", "Kgyz", "Kgzx", "Kgzy"),
        components=(
            _table_component("A.4.2.1"),
            _acquisition_component("A.4.2.2"),
            _scale_factor_repeatability_component("A.4.2.3"),
        ),
        printed_combined_standard_uncertainty=2.12e-4,
        printed_expanded_uncertainty=4.3e-4,
        coverage_factor=2.0,
        reading_kind="absolute",
        reading="absolute error of the dimensionless cross-coupling coefficient, estimate − truth",
        readings=(_COEFFICIENT_ABSOLUTE,),
    ),
    AppendixABudget(
        item="A.5",
        quantity="accelerometer angular-rate sensitivity p (p_yx as the example, the others similar)",
        measurement_model="p_yx = (U_ay7 − U_ay8)/ω², eq. (A.10)-(A.11) (from §7.2.5.2 eq. (12)-(13)); "
                          "u_c² by eq. (A.12)",
        parameters=("pxy", "pxz", "pyx", "pyz", "pzx", "pzy"),
        components=(
            _table_component("A.5.2.1"),
            _acquisition_component("A.5.2.2"),
            UncertaintyComponent(
                symbol="u3", source="repeatability of the outputs U_ay7, U_ay8", clause="A.5.2.3",
                value_per_reading=2.51e-3, count=2, combination_as_printed="linear_sum", printed_value=5.02e-3,
                sensitivity_coefficient=1.0,
                derivation="u(U_ay7) = u(U_ay8) = 2.51e-3 (type A); printed u3 = u(U_ay7) + u(U_ay8) = 5.02e-3",
            ),
        ),
        printed_combined_standard_uncertainty=5.02e-3,
        printed_expanded_uncertainty=1.1e-2,
        coverage_factor=2.0,
        reading_kind="accel_full_scale_per_rate_squared",
        reading="rate-sensitivity error as a fraction of the accelerometer full scale per squared test rate "
                "(U_abs = U × FS_a / ω², (m/s²)/(rad/s)²)",
        readings=_RATE_SENSITIVITY_READINGS,
    ),
)


def appendix_a_budget(item: str) -> AppendixABudget:
    """The Appendix A budget numbered *item* (``"A.1"`` … ``"A.5"``)."""
    for budget in APPENDIX_A:
        if budget.item == item:
            return budget
    raise ValueError(f"Appendix A item {item!r} does not exist; items: "
                     f"{', '.join(repr(b.item) for b in APPENDIX_A)}")


# ----------------------------------------------------------------------------- readings of the units


def omega_squared_test_rate(scenario, input_axis: int) -> float:
    """The table rate ω of the §7.2.5 test about body axis *input_axis*, rad/s.

    Parameters
    ----------
    scenario : plansim.config.Scenario
        Its schedule's ``omega_squared`` segments of group *input_axis* are searched.
    input_axis : int
        0, 1, 2 for x, y, z: the column *j* of P (p_ij is measured with axis *j* up, JJF 2003 §7.2.5).

    Returns
    -------
    float
        ``|rate|`` of the rotating (U8) segments, which must share one rate.
    """
    if input_axis not in (0, 1, 2):
        raise ValueError(f"input_axis = {input_axis!r}; allowed: 0, 1, 2 (x, y, z)")
    schedule = scenario.schedule
    rates = {abs(s.rate) for s in schedule.segments
             if s.test == "omega_squared" and s.group == input_axis and s.rate != 0.0}
    if len(rates) != 1:
        raise ValueError(f"scenario {scenario.name!r}: schedule has rotating omega_squared rates "
                         f"{sorted(rates)} rad/s about {'xyz'[input_axis]}; the A.5 reading U × FS_a/ω² "
                         "needs exactly one test rate (JJF 2003 §7.2.5)")
    return rates.pop()


def _positive(value: float, where: str, why: str) -> float:
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"{where} = {value!r}: must be finite and > 0 {why}")
    return float(value)


def _budget_for(budget: AppendixABudget, parameter_name: str) -> int:
    if not isinstance(budget, AppendixABudget):
        raise TypeError(f"budget = {budget!r}: expected an AppendixABudget (e.g. an element of APPENDIX_A)")
    if parameter_name not in budget.parameters:
        raise ValueError(f"parameter {parameter_name!r} is not covered by budget {budget.item}; "
                         f"it covers {', '.join(budget.parameters)}")
    return PARAMETER_INDEX[parameter_name]


def _reading_of(budget: AppendixABudget, reading) -> Reading:
    """*reading* of *budget*: None (the primary one), a :class:`Reading` of the budget, or its name."""
    if reading is None:
        return budget.primary_reading
    if isinstance(reading, Reading):
        if reading not in budget.readings:
            raise ValueError(f"reading {reading.name!r} is not a reading of budget {budget.item}; its readings: "
                             f"{', '.join(repr(r.name) for r in budget.readings)}")
        return reading
    if isinstance(reading, str):
        return budget.reading_named(reading)
    raise TypeError(f"reading = {reading!r}: expected None (the primary reading), a Reading of budget "
                    f"{budget.item} or its name ({', '.join(repr(r.name) for r in budget.readings)})")


def _reference_gravity(scenario, budget: AppendixABudget) -> float:
    return _positive(scenario.reduction.reference_gravity, "reduction.reference_gravity",
                     f"to read {budget.item} per g")


def reading_unit_in_si(budget: AppendixABudget, parameter_name: str, scenario, truth=None, reading=None):
    """The SI size of one unit of a reading of the budget, for one parameter.

    Parameters
    ----------
    budget : AppendixABudget
        The budget.
    parameter_name : str
        One of ``budget.parameters``.
    scenario : plansim.config.Scenario
        Supplies ``acquisition.gyro_full_scale`` (FS_g readings), ``reduction.reference_gravity``
        (readings per g or in g), ``acquisition.accel_full_scale`` and the ω² test rate (FS_a/ω²).
    truth : float or array, optional
        True value(s) of the parameter, needed only by the relative reading (A.1); default the
        scenario's nominal truth.
    reading : None, Reading or str, optional
        Which of ``budget.readings`` (default the primary one, ``budget.readings[0]``).

    Returns
    -------
    float or ndarray
        By the reading's kind: ``|truth|`` (relative), 1 (absolute, si), ``FS_g`` rad/s,
        ``FS_g/g_ref`` rad/s per m/s², ``FS_a/ω²`` (m/s²)/(rad/s)², ``π/180`` rad/s (°/s),
        ``(π/180)/g_ref`` and ``(π/180/3600)/g_ref`` rad/s per m/s² (°/s/g, °/h/g), ``g_ref``
        (m/s²)/(rad/s)² (g/(rad/s)²): an error of ``e`` reading units is ``e × this`` in SI.
    """
    index = _budget_for(budget, parameter_name)
    kind = _reading_of(budget, reading).kind
    if kind in ("absolute", "si"):
        return 1.0
    if kind == "relative":
        value = scenario.truth_nominal[index] if truth is None else truth
        magnitude = np.abs(np.asarray(value, dtype=float))
        if not np.all(np.isfinite(magnitude) & (magnitude > 0)):
            raise ValueError(f"truth of {parameter_name} = {value!r}: the relative reading of {budget.item} "
                             "divides by the true value, which must be finite and non-zero")
        return float(magnitude) if magnitude.ndim == 0 else magnitude
    if kind == "degree_per_second":
        return DEG
    if kind == "degree_per_second_per_reference_gravity":
        return DEG / _reference_gravity(scenario, budget)
    if kind == "degree_per_hour_per_reference_gravity":
        return DEG / HOUR / _reference_gravity(scenario, budget)
    if kind == "reference_gravity_per_rate_squared":
        return _reference_gravity(scenario, budget)
    if kind == "gyro_full_scale":
        return _positive(scenario.acquisition.gyro_full_scale, "acquisition.gyro_full_scale",
                         f"to read {budget.item} as a fraction of the gyro full scale")
    if kind == "gyro_full_scale_per_reference_gravity":
        fs = _positive(scenario.acquisition.gyro_full_scale, "acquisition.gyro_full_scale",
                       f"to read {budget.item} as a fraction of the gyro full scale per g")
        return fs / _reference_gravity(scenario, budget)
    # accel_full_scale_per_rate_squared
    fs = _positive(scenario.acquisition.accel_full_scale, "acquisition.accel_full_scale",
                   f"to read {budget.item} as a fraction of the accelerometer full scale per ω²")
    omega = omega_squared_test_rate(scenario, parameter(parameter_name).col)
    return fs / omega**2


def errors_in_reading_units(budget: AppendixABudget, parameter_name: str, error, scenario, truth=None,
                            reading=None) -> np.ndarray:
    """Convert SI errors ``estimate − truth`` of one parameter into the units of a reading of the budget.

    Parameters
    ----------
    budget, parameter_name, scenario, truth, reading
        As in :func:`reading_unit_in_si` (*truth* broadcasts against *error* for the relative reading).
    error : array_like
        Errors in SI (:mod:`plansim.model.parameters` units).

    Returns
    -------
    ndarray
        ``error / reading_unit_in_si(...)``: e.g. the relative error (A.1), a fraction of ``FS_g``
        (A.2, primary) or °/s (A.2, ``reading="deg/s"``).
    """
    error = np.asarray(error, dtype=float)
    return error / reading_unit_in_si(budget, parameter_name, scenario, truth, reading)


def expanded_uncertainty_in_si(budget: AppendixABudget, parameter_name: str, scenario, truth=None, reading=None):
    """The printed ``U`` of *budget* in SI for one parameter, in one reading: ``U × reading_unit_in_si``.

    For the relative reading (A.1) the result scales with the true scale factor (default: the
    scenario's nominal truth).
    """
    return budget.printed_expanded_uncertainty * reading_unit_in_si(budget, parameter_name, scenario, truth, reading)


def reading_si_unit(budget: AppendixABudget, reading=None) -> str | None:
    """The SI unit of one unit of a reading (``"rad/s"``, …), None for a dimensionless one (relative, absolute, si)."""
    if not isinstance(budget, AppendixABudget):
        raise TypeError(f"budget = {budget!r}: expected an AppendixABudget")
    return _READING_SI_UNIT[_reading_of(budget, reading).kind]


def reading_unit_description(budget: AppendixABudget, scenario, reading=None) -> str:
    """The unit of a reading in words (default the primary one), with its SI size in *scenario* where it has one."""
    if not isinstance(budget, AppendixABudget):
        raise TypeError(f"budget = {budget!r}: expected an AppendixABudget")
    chosen = _reading_of(budget, reading)
    si = _READING_SI_UNIT[chosen.kind]
    if si is None:
        return chosen.unit
    sizes = {reading_unit_in_si(budget, name, scenario, reading=chosen) for name in budget.parameters}
    if len(sizes) == 1:
        return f"{chosen.unit} = {sizes.pop():.6g} {si}"
    listing = ", ".join(f"{name}: {reading_unit_in_si(budget, name, scenario, reading=chosen):.6g}"
                        for name in budget.parameters)
    return f"{chosen.unit}, in {si} per parameter ({listing})"


# ----------------------------------------------------------------------------- the printed arithmetic, in words


def _significant_digits(value: float) -> int:
    return len(Decimal(repr(value)).normalize().as_tuple().digits)


def _round_to(value: float, digits: int, up: bool) -> float:
    exponent = math.floor(math.log10(abs(value))) - digits + 1
    scaled = value / 10.0**exponent
    return (math.ceil(scaled - 1e-9) if up else round(scaled)) * 10.0**exponent


def printed_arithmetic_slips(budget: AppendixABudget) -> tuple[str, ...]:
    """The slips in one budget's printed arithmetic, in words with their numbers.

    - a component whose readings the text adds linearly (A.2.2.3, A.3.2.3, A.5.2.3), against the
      GUM law of propagation for independent readings (JCGM 100 5.1.2): ``c·√n·u``;
    - an expanded uncertainty that is not ``k·u_c`` rounded to nearest: rounded up (JCGM 100 7.2.6
      allows it) or not explained by rounding;
    - in every budget, u1 (a relative rate error), u2 (a fraction of full scale) and u3 (output
      units) added without units or sensitivity coefficients (A.1.3 … A.5.3).

    Parameters
    ----------
    budget : AppendixABudget

    Returns
    -------
    tuple of str
    """
    if not isinstance(budget, AppendixABudget):
        raise TypeError(f"budget = {budget!r}: expected an AppendixABudget (e.g. an element of APPENDIX_A)")
    slips = []
    for c in budget.components:
        if c.combination_as_printed == "linear_sum":
            slips.append(
                f"linear-sum slip ({c.clause}): {c.symbol} = {c.count} × {c.value_per_reading:g} = "
                f"{c.printed_value:g} "
                f"adds the readings linearly; the model's sensitivity is {c.sensitivity_coefficient:.3g} per reading "
                f"and the GUM law of propagation (JCGM 100 5.1.2) gives c·√n·u = {c.gum_standard_uncertainty:.3g}")
    arithmetic = budget.recomputed_expanded_uncertainty()
    printed = budget.printed_expanded_uncertainty
    digits = _significant_digits(printed)
    if not math.isclose(_round_to(arithmetic, digits, up=False), printed, rel_tol=1e-9):
        if math.isclose(_round_to(arithmetic, digits, up=True), printed, rel_tol=1e-9):
            nearest = _round_to(arithmetic, digits, up=False)
            slips.append(f"rounding: k·u_c = {arithmetic:.5g} is printed as {printed:g}, rounded up to {digits} "
                         f"digits (GUM 7.2.6 allows rounding up; to nearest it is {nearest:g})")
        else:
            uc = budget.recomputed_combined_standard_uncertainty()
            slips.append(f"rounding slip: k·u_c = {budget.coverage_factor:g} × {uc:.4g} = {arithmetic:.4g}, "
                         f"printed {printed:g}")
    slips.append("u1 (relative rate error), u2 (fraction of full scale) and u3 (output units) are added without "
                 "units or sensitivity coefficients (JJF 2003-2022 A.1.3-A.5.3)")
    return tuple(slips)

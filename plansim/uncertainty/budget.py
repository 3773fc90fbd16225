"""The GUM budget of a schedule as result objects: lines, per-parameter budgets, the whole evaluation.

- :class:`InputContribution` — one line of a budget (JCGM 100 5.1.3: ``u_i(y) = |c_i| u(x_i)``);
- :class:`SystematicEffect` — an uncorrected effect as a bias (JCGM 100 3.2.4);
- :class:`AppendixAView` — the JJF 2003-2022 Appendix A budget of a parameter beside this one;
- :class:`ParameterBudget` — ``y``, the lines, ``u_c`` (5.1.2), ``ν_eff`` (G.4.1), ``k`` (G.3.4), ``U`` (6.2.1);
- :class:`GumEvaluation` — all 39 budgets and the covariance of the errors (5.2.2; JCGM 102 6.2);
- :class:`GumUncertainties` — its figures alone (``y``, ``u_c``, ``ν_eff``, ``k``, ``U``, the covariance).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from plansim.model.parameters import PARAMETER_INDEX, PARAMETER_NAMES

__all__ = ["CATEGORIES", "AppendixAView", "GumEvaluation", "GumUncertainties", "InputContribution", "ParameterBudget",
           "SystematicEffect"]

#: Appendix A's three components, and the budget lines that belong to each.
CATEGORIES = ("table", "acquisition", "repeatability", "unit")


@dataclass(frozen=True)
class InputContribution:
    """One line of a budget: an input quantity (or a group of independent components).

    Attributes
    ----------
    name : str
        The input, e.g. ``"position accuracy"``.
    category : str
        Appendix A's component it belongs to: ``"table"`` (u1), ``"acquisition"`` (u2),
        ``"repeatability"`` (u3) or ``"unit"`` (the unit under calibration).
    evaluation : str
        ``"A"`` or ``"B"`` (GUM 4.2, 4.3).
    distribution : str
        The distribution assigned to each component (rectangular ±a, normal, …).
    standard_uncertainty : float
        ``u(x_i)`` of one component, in ``input_unit`` (the RMS over the components if they differ);
        ``nan`` where the line is not linearised.
    input_unit : str
        SI unit of the input.
    sensitivity : float
        ``c_i`` (one component), or the group-equivalent ``contribution / standard_uncertainty``;
        ``nan`` where the line is not linearised (start angle, drift).
    contribution : float
        ``u_i(y)``: the line's contribution to the parameter's standard uncertainty, SI.
    dof : float
        Degrees of freedom ``ν_i`` (Welch–Satterthwaite within the group; ``inf`` for type B).
    components : int
        Number of independent components in the group.
    note : str
        How the line was evaluated.
    """

    name: str
    category: str
    evaluation: str
    distribution: str
    standard_uncertainty: float
    input_unit: str
    sensitivity: float
    contribution: float
    dof: float
    components: int
    note: str = ""

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class SystematicEffect:
    """An effect the JJF 2003 estimators do not correct, as a bias of one parameter (SI)."""

    name: str
    bias: float
    note: str = ""

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class AppendixAView:
    """The Appendix A budget that applies to a parameter, in its reading unit and in SI.

    Attributes
    ----------
    item : str
        ``"A.1"`` … ``"A.5"``.
    reading_unit_si : float
        SI size of one reading unit for this parameter
        (:func:`plansim.uncertainty.appendix_a.reading_unit_in_si`).
    printed_u : tuple of float
        ``(u1, u2, u3)`` as printed, reading units.
    printed_uc, printed_U : float
        ``u_c`` and ``U`` (k = 2) as printed, reading units.
    same_inputs_gum_uc, same_inputs_gum_U : float
        The printed inputs recombined by the GUM law of propagation (the linear sums of u3 replaced
        by ``c·√n·u``, :attr:`plansim.uncertainty.appendix_a.UncertaintyComponent.gum_standard_uncertainty`),
        reading units, k = 2.
    plansim_u : tuple of float
        This scenario's GUM budget grouped as Appendix A groups it: table (u1), acquisition (u2),
        repeatability (u3: white noise and drift), reading units.
    plansim_uc, plansim_U95 : float
        This scenario's ``u_c`` and ``U95``, reading units.
    """

    item: str
    reading_unit_si: float
    printed_u: tuple[float, float, float]
    printed_uc: float
    printed_U: float
    same_inputs_gum_uc: float
    same_inputs_gum_U: float
    plansim_u: tuple[float, float, float]
    plansim_uc: float
    plansim_U95: float

    def as_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["printed_u"] = list(self.printed_u)
        d["plansim_u"] = list(self.plansim_u)
        return d


@dataclass(frozen=True)
class ParameterBudget:
    """The GUM budget of one JJF 2003 parameter (output quantity: its error E = Ŷ − Y, SI).

    Attributes
    ----------
    name, unit : str
        Parameter symbol and SI unit.
    truth : float
        Nominal true value (the linearisation point).
    estimate : float
        ``y``: the error at the expectation of the inputs — the sum of the uncorrected systematic
        effects (GUM 4.1.4).
    inputs : tuple of InputContribution
        The budget lines, largest contribution first; lines with zero contribution are omitted.
    combined_standard_uncertainty : float
        ``u_c(y)`` (GUM 5.1.2, 5.2.2).
    effective_dof : float
        ``ν_eff`` (G.4.1).
    coverage_factor : float
        ``k_p`` for ``coverage_probability`` (G.3.4).
    expanded_uncertainty : float
        ``U_p = k_p·u_c`` (6.2.1).
    coverage_probability : float
        ``p``.
    systematic_effects : tuple of SystematicEffect
        Uncorrected effects, each as a bias (nonzero ones only).
    largest_second_order : float
        Largest ``½|∂²E/∂x_i²|·u(x_i)²`` of the linearised inputs, SI (GUM 5.1.2 note: a check of
        the first-order approximation; compare with ``u_c``).
    appendix_a : AppendixAView or None
        The Appendix A budget of the parameter, where one applies.
    """

    name: str
    unit: str
    truth: float
    estimate: float
    inputs: tuple[InputContribution, ...]
    combined_standard_uncertainty: float
    effective_dof: float
    coverage_factor: float
    expanded_uncertainty: float
    coverage_probability: float
    systematic_effects: tuple[SystematicEffect, ...]
    largest_second_order: float
    appendix_a: AppendixAView | None = None

    def contribution(self, name: str) -> float:
        """The contribution of the input *name* (0 if the budget has no such line)."""
        for line in self.inputs:
            if line.name == name:
                return line.contribution
        return 0.0

    def category_uncertainty(self, category: str) -> float:
        """The lines of one Appendix A category combined in quadrature (drift and noise are
        independent of each other and of the table errors)."""
        if category not in CATEGORIES:
            raise ValueError(f"category = {category!r}; allowed: {', '.join(map(repr, CATEGORIES))}")
        return math.sqrt(sum(line.contribution**2 for line in self.inputs if line.category == category))

    def as_dict(self) -> dict:
        return {
            "name": self.name, "unit": self.unit, "truth": self.truth, "estimate": self.estimate,
            "inputs": [line.as_dict() for line in self.inputs],
            "combined_standard_uncertainty": self.combined_standard_uncertainty,
            "effective_dof": _json_number(self.effective_dof), "coverage_factor": self.coverage_factor,
            "expanded_uncertainty": self.expanded_uncertainty, "coverage_probability": self.coverage_probability,
            "systematic_effects": [e.as_dict() for e in self.systematic_effects],
            "largest_second_order": self.largest_second_order,
            "appendix_a": None if self.appendix_a is None else self.appendix_a.as_dict(),
        }


def _json_number(value: float):
    """``inf`` as the string ``"inf"`` (JSON has no infinity)."""
    return "inf" if isinstance(value, float) and math.isinf(value) else value


@dataclass(frozen=True)
class GumEvaluation:
    """GUM budgets of all 39 parameters of a scenario, and the covariance of their errors.

    Attributes
    ----------
    scenario : str
        Scenario name.
    budgets : tuple of ParameterBudget
        In the order of :data:`plansim.model.parameters.PARAMETER_NAMES`.
    covariance : ndarray (39, 39)
        Covariance of the parameter errors from every input (GUM 5.2.2; JCGM 102 6.2 for the
        multivariate law of propagation ``U_y = C_x U_x C_xᵀ``), SI.
    coverage_probability : float
        ``p`` of the expanded uncertainties.
    """

    scenario: str
    budgets: tuple[ParameterBudget, ...]
    covariance: np.ndarray
    coverage_probability: float

    def budget(self, name: str) -> ParameterBudget:
        """The budget of parameter *name*."""
        if name not in PARAMETER_INDEX:
            raise ValueError(f"unknown parameter {name!r}; known: {', '.join(PARAMETER_NAMES)}")
        return self.budgets[PARAMETER_INDEX[name]]

    @property
    def estimate(self) -> np.ndarray:
        """``y`` of every parameter (39,)."""
        return np.array([b.estimate for b in self.budgets])

    @property
    def standard_uncertainty(self) -> np.ndarray:
        """``u_c`` of every parameter (39,)."""
        return np.array([b.combined_standard_uncertainty for b in self.budgets])

    @property
    def expanded_uncertainty(self) -> np.ndarray:
        """``U_p`` of every parameter (39,)."""
        return np.array([b.expanded_uncertainty for b in self.budgets])

    def correlation(self) -> np.ndarray:
        """Correlation matrix of the parameter errors (GUM 5.2.2, eq. (14)); 0 where a ``u_c`` is 0."""
        u = np.sqrt(np.diag(self.covariance))
        scale = np.where(u > 0, u, np.inf)
        r = self.covariance / np.outer(scale, scale)
        np.fill_diagonal(r, np.where(u > 0, 1.0, 0.0))
        return r


@dataclass(frozen=True)
class GumUncertainties:
    """The figures of a :class:`GumEvaluation` without the budgets: each an array over the 39 parameters, SI.

    Attributes
    ----------
    scenario : str
        Scenario name.
    estimate : ndarray (39,)
        ``y``: the error at the expectation of the inputs (the uncorrected systematic effects, GUM 4.1.4).
    standard_uncertainty : ndarray (39,)
        ``u_c`` (GUM 5.1.2, 5.2.2).
    effective_dof : ndarray (39,)
        ``ν_eff`` (G.4.1).
    coverage_factor : ndarray (39,)
        ``k_p`` (G.3.4).
    expanded_uncertainty : ndarray (39,)
        ``U_p = k_p·u_c`` (6.2.1).
    covariance : ndarray (39, 39)
        Covariance of the parameter errors (GUM 5.2.2; JCGM 102 6.2).
    coverage_probability : float
        ``p`` of the expanded uncertainties.
    """

    scenario: str
    estimate: np.ndarray
    standard_uncertainty: np.ndarray
    effective_dof: np.ndarray
    coverage_factor: np.ndarray
    expanded_uncertainty: np.ndarray
    covariance: np.ndarray
    coverage_probability: float

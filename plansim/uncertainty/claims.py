"""Claims: stated expanded uncertainties of the parameters, from Appendix A or from a parsed claims document.

A claims document (TOML, already parsed; :func:`plansim.io.claims.load_claims` reads a file)::

    [items."A.2"]          # an Appendix A item, U in the item's reading unit (docs/appendix-a.md)
    U = 5.36e-4
    k = 2

    [parameters.Bgx]       # one parameter, a quantity of its kind
    U = "10 deg/h"

``U`` is an expanded uncertainty, ``k`` its coverage factor (default 2). A parameter claim
overrides an item claim for that parameter. A claim with ``k = 2`` is read as a 95 % claim
(JCGM 100 6.3.3, as Appendix A reads it); another ``k`` as ``p = 2Φ(k) − 1`` (a normal output).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from scipy import special  # the normal CDF itself: scipy.stats takes 1.4 s to import

from plansim.config import Scenario
from plansim.model.parameters import PARAMETER_INDEX, PARAMETER_NAMES, parameter
from plansim.uncertainty.appendix_a import APPENDIX_A, appendix_a_budget, reading_unit_description, reading_unit_in_si
from plansim.units import parse_quantity

__all__ = ["Claim", "appendix_a_claims", "parse_claims"]


@dataclass(frozen=True)
class Claim:
    """A stated expanded uncertainty of one parameter, in SI.

    Attributes
    ----------
    parameter : str
        Parameter symbol.
    expanded_uncertainty : float
        ``U`` in the parameter's SI unit.
    coverage_factor : float
        ``k`` of the claim.
    coverage_probability : float
        The probability the claim stands for: 0.95 for ``k = 2`` (GUM 6.3.3), else ``2Φ(k) − 1``.
    source : str
        Where the claim comes from (``"Appendix A A.2 (printed)"``, a file and its table).
    """

    parameter: str
    expanded_uncertainty: float
    coverage_factor: float
    coverage_probability: float
    source: str


def _claim_probability(k: float) -> float:
    return 0.95 if k == 2.0 else float(2.0 * special.ndtr(k) - 1.0)


def appendix_a_claims(scenario: Scenario, budgets=APPENDIX_A) -> dict[str, Claim]:
    """The printed Appendix A expanded uncertainties as claims on the 27 parameters they cover (SI).

    Each item's ``U`` is converted from its reading unit with
    :func:`plansim.uncertainty.appendix_a.reading_unit_in_si`; ``k = 2`` stands for 95 %.
    """
    out = {}
    for budget in budgets:
        for name in budget.parameters:
            unit = float(reading_unit_in_si(budget, name, scenario))
            out[name] = Claim(name, budget.printed_expanded_uncertainty * unit, budget.coverage_factor,
                              _claim_probability(budget.coverage_factor), f"Appendix A {budget.item} (printed)")
    return out


def _claim_number(raw, where: str) -> float:
    if isinstance(raw, bool) or not isinstance(raw, (int, float, str)):
        raise TypeError(f"{where} = {raw!r}: expected a number")
    try:
        value = float(raw)
    except ValueError:
        raise ValueError(f"{where} = {raw!r}: an Appendix A item's U is a plain number in the item's reading "
                         "unit (e.g. 5.36e-4), not a quantity with a unit") from None
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"{where} = {raw!r}: must be finite and > 0")
    return value


def _check_claim_entry(entry, where: str) -> None:
    """A claim is a table with U (required) and k (optional)."""
    if not isinstance(entry, Mapping):
        raise TypeError(f"{where} must be a table with U (and k)")
    if set(entry) - {"U", "k"} or "U" not in entry:
        raise ValueError(f"{where}: keys {sorted(entry)}; expected U (required) and k (optional)")


def _claim_k(entry: Mapping, where: str) -> float:
    k = entry.get("k", 2)
    if isinstance(k, bool) or not isinstance(k, (int, float)) or not (math.isfinite(k) and k > 0):
        raise ValueError(f"{where}.k = {k!r}: the coverage factor must be a number > 0")
    return float(k)


def parse_claims(document: Mapping, scenario: Scenario, source: str = "claims") -> dict[str, Claim]:
    """Claims from a parsed claims document (module docstring), in SI.

    Parameters
    ----------
    document : mapping
        The parsed TOML: tables ``items`` and/or ``parameters``.
    scenario : Scenario
        Supplies the reading units of the Appendix A items.
    source : str
        Name of the document in messages and in each claim's ``source``.

    Returns
    -------
    dict of parameter name -> Claim

    Raises
    ------
    ValueError, TypeError
        Unknown section, item, parameter or key; a missing or non-positive ``U``; a wrong unit.
    """
    if not isinstance(document, Mapping):
        raise TypeError(f"{source}: expected a TOML table, got {type(document).__name__}")
    unknown = set(document) - {"items", "parameters"}
    if unknown:
        raise ValueError(f"{source}: unknown section(s) {', '.join(sorted(map(repr, unknown)))}; "
                         "allowed: 'items', 'parameters'")
    claims: dict[str, Claim] = {}
    items = document.get("items", {})
    if not isinstance(items, Mapping):
        raise TypeError(f"{source}: [items] must be a table of Appendix A items")
    for item, entry in items.items():
        where = f"{source}: items.{item!r}"
        budget = appendix_a_budget(item) if item in {b.item for b in APPENDIX_A} else None
        if budget is None:
            raise ValueError(f"{where}: unknown Appendix A item; allowed: {', '.join(b.item for b in APPENDIX_A)}")
        _check_claim_entry(entry, where)
        U = _claim_number(entry["U"], f"{where}.U")
        k = _claim_k(entry, where)
        for name in budget.parameters:
            unit = float(reading_unit_in_si(budget, name, scenario))
            claims[name] = Claim(name, U * unit, k, _claim_probability(k),
                                 f"{source} [items.{item}] U = {U:g} {reading_unit_description(budget, scenario)}")
    parameters = document.get("parameters", {})
    if not isinstance(parameters, Mapping):
        raise TypeError(f"{source}: [parameters] must be a table of parameters")
    for name, entry in parameters.items():
        where = f"{source}: parameters.{name}"
        if name not in PARAMETER_INDEX:
            raise ValueError(f"{where}: unknown parameter; known: {', '.join(PARAMETER_NAMES)}")
        _check_claim_entry(entry, where)
        U = parse_quantity(entry["U"], parameter(name).kind, f"{where}.U")
        if not (math.isfinite(U) and U > 0):
            raise ValueError(f"{where}.U = {entry['U']!r}: must be > 0")
        k = _claim_k(entry, where)
        claims[name] = Claim(name, U, k, _claim_probability(k), f"{source} [parameters.{name}] U = {entry['U']}")
    if not claims:
        raise ValueError(f"{source}: no claims; give [items.\"A.x\"] or [parameters.<name>] tables with U")
    return claims

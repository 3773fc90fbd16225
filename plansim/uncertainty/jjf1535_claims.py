"""Claims on JJF 1535-2015 items: a certificate's stated expanded uncertainties, checked by the Monte Carlo.

A lab's JJF 1535 certificate states U for the items it reports. ``plansim run jjf1535 --claims claims.toml``
reads them and judges each against the simulated procedure, as ``plansim validate --claims`` judges JJF 2003
claims: over the trials, the fraction whose error lies within ±U (its coverage of the truth), the half-width
the Monte Carlo needs for the claim's probability, and the verdict of
:func:`plansim.uncertainty.metrology.coverage_verdict` (``supported``, ``under-stated``, ``over-stated ×F``).

The document (TOML, parsed)::

    [jjf1535.scale_factor]   # an item of plansim run jjf1535 (docs/jjf1535.md)
    U = 1.1e-3               # in the item's unit as the report prints it, or relative:
    relative = true          # U relative to the item's value (Appendix A reads K and B0 so)
    k = 2                    # the coverage factor (default 2: 95 %, JCGM 100 6.3.3)

    [jjf1535.nonlinearity]
    U = 150                  # ppm

Only an item with a true value in the simulation can be checked (its error is reported − true); the bias
stability has none, and a claim on it is refused, saying so.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from scipy import special

from plansim.estimate.jjf1535_items import ITEMS
from plansim.uncertainty.metrology.coverage import coverage_verdict

#: the keys of a claim's table
CLAIM_KEYS = ("U", "relative", "k")


@dataclass(frozen=True)
class Jjf1535Claim:
    """A stated expanded uncertainty of one JJF 1535 item: ``U`` in SI (or relative), ``k`` and the probability it
    stands for (0.95 for k = 2, else 2Φ(k) − 1), and where it came from."""

    item: str
    expanded_uncertainty: float
    relative: bool
    coverage_factor: float
    coverage_probability: float
    source: str


def parse_jjf1535_claims(document: Mapping, source: str = "claims") -> dict[str, Jjf1535Claim]:
    """The claims of a parsed document (module docstring): item -> claim, U in SI (or relative).

    Raises
    ------
    ValueError, TypeError
        A section other than ``jjf1535``, an unknown item, an item without a true value, a key other than U,
        relative and k, a missing or non-positive U, a bad k — each naming the document, the item and the value.
    """
    if not isinstance(document, Mapping):
        raise TypeError(f"{source}: expected a TOML table, got {type(document).__name__}")
    unknown = set(document) - {"jjf1535"}
    if unknown:
        raise ValueError(f"{source}: unknown section(s) {', '.join(sorted(map(repr, unknown)))}; a claims file for "
                         "the procedure jjf1535 has [jjf1535.ITEM] tables (JJF 2003 claims, [items] and "
                         "[parameters], go to plansim validate --claims)")
    table = document.get("jjf1535", {})
    if not isinstance(table, Mapping) or not table:
        raise ValueError(f"{source}: no claim; expected [jjf1535.ITEM] tables with U = …")
    out = {}
    for item, entry in table.items():
        where = f"{source}: jjf1535.{item}"
        if item not in ITEMS:
            raise ValueError(f"{where}: unknown item; allowed: {', '.join(ITEMS)}")
        if item == "bias_stability":
            raise ValueError(f"{where}: the bias stability has no true value in the simulation (it is a standard "
                             "deviation of period means of the noise): its figure's spread is in the report, but a "
                             "claim on it cannot be checked against a truth")
        if not isinstance(entry, Mapping):
            raise TypeError(f"{where} must be a table with U (and relative, k)")
        if "U" not in entry or set(entry) - set(CLAIM_KEYS):
            raise ValueError(f"{where}: keys {sorted(entry)}; expected U (required), relative and k (optional)")
        U = entry["U"]
        if isinstance(U, bool) or not isinstance(U, (int, float)) or not (math.isfinite(U) and U > 0):
            raise ValueError(f"{where}.U = {U!r}: expected a number > 0 in {ITEMS[item][2]} (or relative)")
        relative = entry.get("relative", False)
        if not isinstance(relative, bool):
            raise TypeError(f"{where}.relative = {relative!r}: expected true or false")
        k = entry.get("k", 2)
        if isinstance(k, bool) or not isinstance(k, (int, float)) or not (math.isfinite(k) and k > 0):
            raise ValueError(f"{where}.k = {k!r}: the coverage factor must be a number > 0")
        probability = 0.95 if k == 2 else float(2.0 * special.ndtr(k) - 1.0)
        out[item] = Jjf1535Claim(item, float(U) if relative else float(U) * ITEMS[item][3], relative, float(k),
                                 probability, f"{source} [jjf1535.{item}]")
    return out


def judge_jjf1535_claims(mc, claims: dict) -> list[dict]:
    """Each claim against the Monte Carlo *mc* (:class:`~plansim.uncertainty.jjf1535_monte_carlo.Jjf1535MonteCarlo`):
    ``{item, U, relative, k, coverage_probability, trials, coverage, needed, overstatement_factor, verdict,
    source}``, U and needed in SI (or relative): coverage = the fraction of trials with |error| ≤ U (relative:
    |error/true|), needed = the claim's probability's quantile of |error|. Trials where the procedure could not
    determine the item are left out (and counted in ``trials``)."""
    rows = []
    for item, claim in claims.items():
        x, t = mc.column(item), mc.column(item, "truth")
        found = np.isfinite(x) & np.isfinite(t)
        error = (x - t)[found]
        if claim.relative:
            error = error / t[found]
        magnitude = np.abs(error)
        n = int(magnitude.size)
        coverage = float(np.mean(magnitude <= claim.expanded_uncertainty)) if n else math.nan
        needed = float(np.quantile(magnitude, claim.coverage_probability)) if n else math.nan
        verdict, factor = coverage_verdict(coverage, n, claim.coverage_probability, claim.expanded_uncertainty,
                                           needed) if n else ("no trial determined the item", math.nan)
        rows.append({"item": item, "U": claim.expanded_uncertainty, "relative": claim.relative,
                     "k": claim.coverage_factor, "coverage_probability": claim.coverage_probability, "trials": n,
                     "coverage": coverage, "needed": needed, "overstatement_factor": factor, "verdict": verdict,
                     "source": claim.source})
    return rows

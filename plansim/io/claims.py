"""Claims files: a TOML file of stated expanded uncertainties, read and handed to :mod:`plansim.uncertainty.claims`."""

from __future__ import annotations

import tomllib
from pathlib import Path

from plansim.config import Scenario
from plansim.uncertainty.claims import Claim, parse_claims
from plansim.uncertainty.jjf1535_claims import Jjf1535Claim, parse_jjf1535_claims

__all__ = ["load_claims", "load_jjf1535_claims"]


def _document(path) -> tuple[dict, str]:
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"--claims {str(path)!r}: no such file")
    try:
        with open(p, "rb") as fh:
            return tomllib.load(fh), p.name
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"claims file {str(path)!r} is not valid TOML: {exc}") from None


def load_jjf1535_claims(path) -> dict[str, Jjf1535Claim]:
    """Claims on JJF 1535 items from a TOML file (:mod:`plansim.uncertainty.jjf1535_claims`), U in SI or relative;
    errors name the file."""
    document, name = _document(path)
    return parse_jjf1535_claims(document, source=name)


def load_claims(path, scenario: Scenario) -> dict[str, Claim]:
    """Claims from a TOML file (format: :mod:`plansim.uncertainty.claims`), in SI.

    Parameters
    ----------
    path : str or os.PathLike
        The claims file.
    scenario : Scenario
        Supplies the reading units of Appendix A items.

    Returns
    -------
    dict of parameter name -> Claim

    Raises
    ------
    ValueError
        No such file, a file that is not valid TOML (naming the file), or a bad claim
        (:func:`plansim.uncertainty.claims.parse_claims`).
    """
    document, name = _document(path)
    return parse_claims(document, scenario, source=name)

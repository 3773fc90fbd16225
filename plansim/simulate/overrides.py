"""``--set KEY=VALUE`` on a built-in experiment's settings (``plansim run jjf1537``, ``plansim run vibration_g2``).

One parser for both: a key must be one of the experiment's fields; a quantity is read as '<number> <unit>'
(:func:`plansim.units.parse_quantity`, a bare number for a dimensionless one); a count as a whole number; a word
field as it is written (the settings' own checks then judge it). An error names the item, the key and what is
allowed.
"""

from __future__ import annotations

import dataclasses

from plansim.units import parse_quantity


def split_item(item, keys, option: str) -> tuple[str, str]:
    """``KEY=VALUE`` as (KEY, VALUE), both stripped and VALUE unquoted; a ValueError naming *option*, the item and
    the allowed keys unless it is one with KEY in *keys*."""
    key, sep, text = str(item).partition("=")
    key, text = key.strip(), text.strip().strip("'\"")
    if not sep or key not in keys:
        raise ValueError(f"{option} {item!r}: expected KEY=VALUE with KEY one of {', '.join(keys)}")
    return key, text


def apply_overrides(settings, overrides, kinds: dict, *, words=("choice",), count_minimum: dict | None = None,
                    option: str = "--set"):
    """*settings* (a frozen dataclass with an ``overrides`` tuple) with ``KEY=VALUE`` strings applied.

    Parameters
    ----------
    settings : dataclass
        The experiment's settings.
    overrides : iterable of str
        ``KEY=VALUE`` items, as ``--set`` gives them.
    kinds : dict
        field -> unit kind (:data:`plansim.units.KINDS`), ``"count"``, or one of *words*.
    words : tuple of str
        The kinds taken as written (a choice of names, a set of axes).
    count_minimum : dict, optional
        field -> the smallest count allowed, for the error message.
    option : str
        The command-line option the items came with, for the error message.

    Returns
    -------
    The settings with the changes and the items appended to ``overrides``.

    Raises
    ------
    ValueError
        An item that is not KEY=VALUE with a known key, a count that is not a whole number, or a quantity
        :func:`plansim.units.parse_quantity` refuses.
    """
    changes = {}
    for item in overrides:
        key, text = split_item(item, kinds, option)
        kind = kinds[key]
        if kind in words:
            changes[key] = text
        elif kind == "count":
            try:
                changes[key] = int(text)
            except ValueError:
                least = (count_minimum or {}).get(key)
                raise ValueError(f"{option} {item!r}: {key} expects an integer"
                                 + ("" if least is None else f" >= {least}")) from None
        else:
            try:  # a bare number is a dimensionless quantity with the unit ''
                changes[key] = parse_quantity(text, kind, key)
            except ValueError as exc:
                raise ValueError(f"{option} {item!r}: {exc}") from None
    return dataclasses.replace(settings, **changes, overrides=tuple(settings.overrides) + tuple(overrides))


def jjf1535_settings(overrides=()):
    """The JJF 1535 procedure's settings (:class:`plansim.schedule.jjf1535.Jjf1535Settings`) with ``KEY=VALUE`` items
    applied (``plansim run|validate|sweep jjf1535 --procedure``), checked by building the procedure once: an error
    names the item, the key and what is allowed."""
    from plansim.schedule.jjf1535 import SETTING_KINDS, Jjf1535Settings

    settings = apply_overrides(Jjf1535Settings(), tuple(overrides), SETTING_KINDS,
                               count_minimum={"points": 11, "repeats": 2, "bias_periods": 2, "warm_up_records": 1},
                               option="--procedure")
    try:
        settings.procedure()
    except (TypeError, ValueError) as exc:
        raise ValueError(f"--procedure {'; '.join(settings.overrides) or '(defaults)'}: {exc}") from None
    return settings

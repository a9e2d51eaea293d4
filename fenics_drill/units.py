"""Drilling units through pint: a scene value may be written with its unit, ``rotation_speed = "120 rpm"``,
``rate_of_penetration = "15 m/h"``, ``outer_diameter = "5 in"``, ``density = "10.4 ppg"``; it is converted to the SI
unit of its key (the ``[unit]`` of the key's meaning) when the scene is read.  A unit pint does not know, or one of
another dimension than the key's, is refused in one line naming the key.

Units besides pint's own: ``ppg`` (pound per US gallon, the mud weight's), ``sg`` (specific gravity, 1000 kg/m^3),
``usft`` (the US survey foot of older surveys, 1200/3937 m).
"""

from __future__ import annotations

import functools
import math
import re

#: The units the drilling world writes that pint's registry lacks.
DRILLING_UNITS = ("ppg = pound / gallon", "sg = 1000 * kilogram / meter ** 3 = SG", "usft = survey_foot")


class UnitError(ValueError):
    """A value whose unit is unknown, of the wrong dimension, or not a quantity at all."""


@functools.cache
def registry():
    """pint's unit registry with :data:`DRILLING_UNITS` (built once, on the first value written with a unit)."""
    import pint

    units = pint.UnitRegistry()
    for definition in DRILLING_UNITS:
        units.define(definition)
    return units


def si_unit(meaning: str) -> str | None:
    """The SI unit in a key's meaning (its last ``[...]``: ``"... [rad/s]"`` -> ``"rad/s"``; ``[-]`` ->
    dimensionless), or None where it gives none or one pint cannot read (a key that takes plain numbers only)."""
    found = re.findall(r"\[([^\[\]]*)\]", meaning)
    if not found:
        return None
    unit = found[-1].split(";")[0].strip()
    unit = "dimensionless" if unit in ("-", "") else unit
    try:
        registry().Unit(unit)
    except Exception:  # pint's own errors: a unit written for people (e.g. "N s^4/m^4 with ...")
        return None
    return unit


def to_si(text: str, unit: str) -> float:
    """The number ``text`` ("120 rpm") is in ``unit`` ("rad/s"); UnitError says why it is not."""
    import pint

    units = registry()
    if not re.search(r"\d", text):
        raise UnitError(f"expected a number, or a number with its unit (e.g. '120 rpm', '5 in'), got {text!r}")
    try:
        quantity = units.Quantity(text.strip())
    except pint.UndefinedUnitError as err:
        raise UnitError(f"unknown unit {', '.join(map(repr, err.args[0:1]))} in {text!r}") from None
    except Exception:  # a string pint cannot parse as a quantity at all
        raise UnitError(f"{text!r} is not a number with a unit (e.g. '120 rpm', '5 in')") from None
    try:
        value = float(quantity.to(unit).magnitude)
    except pint.DimensionalityError:
        raise UnitError(f"{text!r} is not a quantity in {unit} (it is in {quantity.units:~})") from None
    if not math.isfinite(value):
        raise UnitError(f"{text!r} is not a finite quantity")
    return value

"""The one reader of drilling quantities: a value written as drilling engineers write it, converted to the SI unit of
the key (or column) it is given for.  The scene, the surveys, the API and every measured file read through it.

What it reads, besides pint's own units:

* numbers as written in the field: mixed numbers (``8 1/2 in``, ``8-1/2 in``, ``8½ in``), fractions (``3/4 in``),
  thousands separated by spaces (``5 000 N m``, also the thin and no-break spaces) or by commas where that is
  unambiguous (``1,200.5``, ``1,234,567``), a decimal comma where it is unambiguous (``0,3``, ``12,25``), the
  Unicode minus; ``1,200`` alone (a thousand two hundred, or one point two) is refused;
* inch and foot marks (``4.25"``, ``4.25''``, ``12'``, ``12' 6"``);
* products written with a dot, a hyphen or a middle dot (``kN.m``, ``ft-lbf``, ``kft-lbf``, ``N·m``), ``Nm``,
  ``kNm``, powers written as digits (``g/cm3``, ``min-1``, ``m²``);
* oilfield units in any case (``RPM``, ``IN``, ``FT``, ``KLBF``, ``PPG``), ``rev/min``, ``r/min``, ``fph``, ``pcf``,
  ``ppg``, ``sg``, ``kip``, ``usft`` (the US survey foot);
* a unit of mass where a force is asked means its weight under standard gravity: ``40 klb`` of weight on bit is
  40 klbf, ``5 kft-lb`` of torque is 5 kft lbf, ``10 t`` is 10 tonne-force;
* a frequency where an angular speed is asked means revolutions: ``120 1/min``, ``120 min^-1``, ``2 Hz``.

What is ambiguous is refused with the reason, never guessed: ``1,200``, and ``ton``/``tonf`` (the short, long and
metric ton-force differ by 12 %: write ``tonf_us``, ``tonf_uk`` or ``tf``).  A dimensionless key takes a plain
number only (``"17 deg"`` for a friction coefficient is refused).
"""

from __future__ import annotations

import functools
import math
import re
import unicodedata

#: The units the drilling world writes that pint's registry lacks (or defines otherwise).
DRILLING_UNITS = (
    "ppg = pound / gallon", "sg = 1000 * kilogram / meter ** 3 = SG", "usft = survey_foot",
    "fph = foot / hour", "pcf = pound / foot ** 3", "rev = revolution", "tonf_us = 2000 * force_pound",
    "tonf_uk = 2240 * force_pound",
)

#: Depths that differ by less than this are the same depth [m]: the round-off of depths written in other units
#: (2952.76 ft is 900.0012 m; a depth in feet to two decimals is within 1.5 mm of the metre it was written from).
DEPTH_ROUND_OFF = 2e-3

#: Oilfield spellings, matched whatever their case, for the words pint does not know as written ("RPM", "IN",
#: "Nm"): word -> pint's expression.  Words pint knows as written keep their case ("MN" is not "mN").
OILFIELD_WORDS = {
    "rpm": "rpm", "rps": "rev/s", "rev": "rev", "revs": "rev", "revolution": "rev", "revolutions": "rev",
    "in": "inch", "inch": "inch", "inches": "inch", "ft": "foot", "feet": "foot", "foot": "foot",
    "hr": "hour", "hrs": "hour", "min": "minute", "mins": "minute", "sec": "second", "hz": "Hz",
    "lb": "pound", "lbs": "pound", "lbm": "pound", "klb": "kilopound", "klbs": "kilopound",
    "lbf": "force_pound", "klbf": "kip", "kip": "kip", "kips": "kip",
    "kn": "kilonewton", "dan": "decanewton", "nm": "newton*meter", "knm": "kilonewton*meter",
    "kgf": "force_kilogram", "tf": "force_metric_ton", "kg": "kilogram", "tonne": "metric_ton",
    "tonnes": "metric_ton", "psi": "psi", "ksi": "ksi", "pa": "pascal", "kpa": "kilopascal", "mpa": "megapascal",
    "gpa": "gigapascal", "bar": "bar", "ppg": "ppg", "sg": "sg", "pcf": "pcf", "fph": "fph", "gal": "gallon",
    "deg": "degree", "degs": "degree", "degree": "degree", "degrees": "degree", "rad": "radian",
    "usft": "usft", "tonf_us": "tonf_us", "tonf_uk": "tonf_uk",
}

#: Words whose meaning differs between the short, long and metric systems: refused with the choices.
AMBIGUOUS_WORDS = {
    "ton": "the short (2000 lb), long (2240 lb) and metric (1000 kg) ton differ by 12 %: write tonf_us, tonf_uk "
           "or tf for a force, t for a mass",
    "tons": "the short (2000 lb), long (2240 lb) and metric (1000 kg) ton differ by 12 %: write tonf_us, tonf_uk "
            "or tf for a force, t for a mass",
    "tonf": "'tonf' is the short ton-force (2000 lbf) in the US, the long one (2240 lbf) in the UK and often the "
            "metric tonne-force (1000 kgf) in the field: write tonf_us, tonf_uk or tf",
}

#: A unit of mass where a force is asked: its weight under standard gravity (pint's names).
MASS_AS_FORCE = {"pound": "force_pound", "kilopound": "kip", "kilogram": "force_kilogram",
                 "metric_ton": "force_metric_ton"}

#: Unicode characters that stand for ASCII in a written value.
_CHARACTERS = {
    "\u2212": "-", "\u2012": "-", "\u2013": "-", "\u2010": "-", "\u2011": "-",  # minus and dashes
    "\u00a0": " ", "\u2009": " ", "\u202f": " ", "\u2007": " ", "\u2002": " ", "\u2003": " ", "\t": " ",
    "\u00b7": "*", "\u22c5": "*", "\u00d7": "*", "\u2044": "/", "\u2215": "/",
    "\u201d": '"', "\u2033": '"', "\u201c": '"', "\u2019": "'", "\u2032": "'", "\u2018": "'",
    "\u00b0": " deg",
}
_SUPERSCRIPT_DIGITS = "\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079\u207b"
_SUPERSCRIPTS = str.maketrans(_SUPERSCRIPT_DIGITS, "0123456789-")


class UnitError(ValueError):
    """A value whose number cannot be read, whose unit is unknown or ambiguous, or of the wrong dimension."""


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


def _normalised(text: str) -> str:
    """``text`` with its Unicode stand-ins in ASCII: minus signs, spaces, products, primes, superscript powers
    (``m²`` -> ``m^2``), vulgar fractions (``8½`` -> ``8 1/2``)."""
    text = re.sub(f"[{_SUPERSCRIPT_DIGITS}]+", lambda m: "^" + m.group().translate(_SUPERSCRIPTS), text)
    out = []
    for c in text:
        if c in _CHARACTERS:
            out.append(_CHARACTERS[c])
        elif "\u2044" in unicodedata.normalize("NFKC", c):  # a vulgar fraction: ½ -> " 1/2"
            out.append(" " + unicodedata.normalize("NFKC", c).replace("\u2044", "/"))
        else:
            out.append(c)
    return " ".join("".join(out).split())


_DIGITS = re.compile(r"\d+")
_PLAIN_DECIMAL = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_EXPONENT = re.compile(r"[eE][+-]?\d+")
_MIXED = re.compile(r"(?P<whole>\d+)(?: +|-)(?P<num>\d+) */ *(?P<den>\d+)(?![\d.,/])")
_FRACTION = re.compile(r"(?P<num>\d+) */ *(?P<den>\d+)(?![\d.,/])")


def _number(text: str) -> tuple[float, str]:
    """(the number at the start of ``text``, the rest): mixed numbers, fractions, thousands and decimal commas as
    the module says; UnitError where the number is ambiguous or not one."""
    sign, rest = 1.0, text.lstrip()
    if rest[:1] in "+-":
        sign, rest = (-1.0 if rest[0] == "-" else 1.0), rest[1:].lstrip()
    for pattern, mixed in ((_MIXED, True), (_FRACTION, False)):
        m = pattern.match(rest)
        if m:
            num, den = int(m["num"]), int(m["den"])
            if den == 0:
                raise UnitError(f"{text!r}: a fraction with denominator 0")
            if mixed and num >= den:
                raise UnitError(f"{text!r} is not a mixed number (its fraction {num}/{den} is not below 1)")
            return sign * ((int(m["whole"]) if mixed else 0) + num / den), rest[m.end():]
    m = _DIGITS.match(rest)
    if not m and not re.match(r"\.\d", rest):
        raise UnitError(f"expected a number, or a number with its unit (e.g. '120 rpm', '8 1/2 in'), got {text!r}")
    integer, k = (m.group(), m.end()) if m else ("0", 0)
    groups, separator = [], None  # the thousands groups after the first, and what separates them
    while len(integer) <= 3 and rest[k:k + 1] in (" ", ",") and separator in (None, rest[k]) and re.match(
            r"\d{3}(?![\d/])", rest[k + 1:]):
        separator = rest[k]
        groups.append(rest[k + 1:k + 4])
        k += 4
    digits, decimal = integer + "".join(groups), ""
    if rest[k:k + 1] == ".":
        d = re.match(r"\.(\d*)", rest[k:])
        decimal, k = d.group(1), k + d.end()
    elif rest[k:k + 1] == "," and re.match(r",\d", rest[k:]):
        if separator == ",":
            raise UnitError(f"{text!r}: commas both as thousands separators and as a decimal comma")
        d = re.match(r",(\d+)", rest[k:])
        decimal, k = d.group(1), k + d.end()
        if rest[k:k + 1] == ".":
            raise UnitError(f"{text!r}: a decimal comma followed by a decimal point")
    if separator == "," and len(groups) == 1 and not decimal:
        if integer != "0":
            raise UnitError(f"{text!r} is ambiguous: {digits} with a thousands comma, or {integer}.{groups[0]} with "
                            "a decimal comma; write it without the comma, or with a decimal point")
        digits, decimal = "0", groups[0]  # 0,300: a thousands group never follows a lone 0
    e = _EXPONENT.match(rest[k:])
    exponent = e.group() if e else ""
    k += len(exponent)
    value = float(f"{digits}.{decimal or 0}{exponent}")
    rest = rest[k:]
    if re.match(r"\s*[\d.,]", rest) and not re.match(r"\s*1\s*/\s*[A-Za-z]", rest):
        raise UnitError(f"{text!r} is not a number with a unit: digits follow the number "
                        "(thousands are groups of three digits: '5 000')")
    return sign * value, rest


def _words(unit: str) -> str:
    """A written unit as pint's expression: marks, products, digit powers, oilfield words (:data:`OILFIELD_WORDS`)."""
    units = registry()
    unit = unit.strip()
    if unit.lower() in ('"', "''", "in."):
        return "inch"
    if unit == "'":
        return "foot"
    unit = re.sub(r"tonf\s*\[\s*(us|uk)\s*\]", lambda m: f"tonf_{m[1].lower()}", unit, flags=re.I)
    unit = re.sub(r"(?<=[A-Za-z])(-?\d+)(?![\d.])", r"^\1", unit)  # cm3 -> cm^3, min-1 -> min^-1
    unit = re.sub(r"(?<=[A-Za-z])[.\-](?=[A-Za-z])", "*", unit)  # kN.m, ft-lbf
    if re.fullmatch(r"(?i)r(ev)?\s*/\s*min", unit):
        return "rpm"

    def word(m: re.Match) -> str:
        name = m.group()
        lower = name.lower()
        if lower in AMBIGUOUS_WORDS:
            raise UnitError(AMBIGUOUS_WORDS[lower])
        if lower in ("lb", "lbs", "klb", "klbs", "lbm"):
            return OILFIELD_WORDS[lower]  # pint's names, so that a force may take their weight
        try:
            units.Unit(name)
            return name
        except Exception:  # pint's UndefinedUnitError and its parse errors
            if lower in OILFIELD_WORDS:
                return OILFIELD_WORDS[lower]
            raise UnitError(f"unknown unit {name!r}") from None

    return re.sub(r"[A-Za-z_]+", word, unit)


def read_number(text: str, decimal_comma: bool = False) -> float:
    """A plain number as written in the field (``"5 000"``, ``"0,3"``, ``"1/2"``, ``"-12.5"``); UnitError where
    it is ambiguous, not a number, or written with a unit.  ``decimal_comma``: a comma is the decimal separator (a
    file whose fields are separated by semicolons or tabs)."""
    if isinstance(text, str) and _PLAIN_DECIMAL.fullmatch(text.strip()):
        return float(text)  # the common case, read as Python reads it (a survey file's thousands of stations)
    written = _normalised(str(text))
    if decimal_comma and "." not in written:
        written = written.replace(",", ".")
    value, rest = _number(written)
    if rest.strip():
        raise UnitError(f"{text!r} is not a plain number (this takes no unit)")
    if not math.isfinite(value):
        raise UnitError(f"{text!r} is not a finite number")
    return value


def read_quantity(text: str, unit: str) -> float:
    """The value ``text`` (``"8 1/2 in"``, ``"120 1/min"``, ``"5 000 N m"``) in the SI ``unit`` of its key
    (``"m"``, ``"rad/s"``, ``"N m"``, ``"dimensionless"``); UnitError says why it cannot be read.  A plain number is
    in ``unit`` already."""
    import pint

    units = registry()
    written = _normalised(str(text))
    if not re.search(r"\d", written):
        raise UnitError(f"expected a number, or a number with its unit (e.g. '120 rpm', '8 1/2 in'), got {text!r}")
    value, rest = _number(written)
    rest = rest.strip()
    if not rest:
        if not math.isfinite(value):
            raise UnitError(f"{text!r} is not a finite number")
        return value
    if unit == "dimensionless":
        raise UnitError(f"{text!r}: this key takes a plain number (it has no unit)")
    feet = re.fullmatch(r"(?:'|ft|feet|foot)\s*(?P<inches>\d.*?)\s*(?:\"|''|in|inch|inches)", rest, flags=re.I)
    try:
        if feet:  # 12' 6": feet and inches
            inches, more = _number(feet["inches"])
            if more.strip():
                raise UnitError(f"{text!r} is not feet and inches (e.g. 12' 6\")")
            quantity = units.Quantity(value, "foot") + units.Quantity(inches, "inch")
        else:
            quantity = units.Quantity(value, _words(rest))
    except UnitError as err:
        raise UnitError(f"{err} in {text!r}" if "unknown unit" in str(err) else f"{text!r}: {err}") from None
    except Exception:  # pint cannot parse the expression at all
        raise UnitError(f"{text!r} is not a number with a unit (e.g. '120 rpm', '8 1/2 in')") from None
    target = units.Quantity(1.0, unit)
    quantity = _as_asked(quantity, target)
    try:
        result = float(quantity.to(unit).magnitude)
    except pint.DimensionalityError:
        raise UnitError(f"{text!r} is not a quantity in {unit} (it is in {quantity.units:~})") from None
    if not math.isfinite(result):
        raise UnitError(f"{text!r} is not a finite quantity")
    return result


def _as_asked(quantity, target):
    """``quantity`` read as the key asks: revolutions for a frequency given for an angular speed; the weight of a
    mass given for a force (:data:`MASS_AS_FORCE`)."""
    units = registry()
    root, asked = quantity.to_root_units(), target.to_root_units()
    angle = dict(asked.unit_items()).get("radian", 0)
    if angle == 1 and "radian" not in dict(root.unit_items()) and quantity.dimensionality == units.Hz.dimensionality:
        return quantity * units.Quantity(1.0, "rev")  # 120 1/min, 2 Hz of an angular speed: revolutions
    if quantity.dimensionality != target.dimensionality:
        items = dict(quantity.unit_items())
        if any(name in MASS_AS_FORCE for name in items):
            weight = units.Quantity(quantity.magnitude, units.Unit("*".join(
                f"{MASS_AS_FORCE.get(name, name)}**{power}" for name, power in items.items())))
            if weight.dimensionality == target.dimensionality:
                return weight
    return quantity

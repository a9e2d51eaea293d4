"""The rig's measured loads against bit depth, from a CSV file: ``bit_depth``, then any of ``pick_up``,
``slack_off``, ``rotating_off_bottom`` (hook loads), ``torque_off_bottom`` and ``torque_on_bottom``, each with its
unit in brackets in the header as surveys write them (``bit_depth (ft)``, ``pick_up (klbf)``,
``torque_off_bottom (kft*lbf)``); read through the one reader of drilling quantities (:mod:`fenics_drill.units`).
Blank cells are not measured; lines starting with # are comments; commas, semicolons or tabs separate the fields
(with semicolons or tabs, a decimal comma is read).  Every refusal names the file and the line or the column.
"""

from __future__ import annotations

import csv
import re
from pathlib import Path

import numpy as np

from fenics_drill.scene import SceneError, read_regular_file
from fenics_drill.units import DEPTH_ROUND_OFF, UnitError, read_number, read_quantity

#: Each measured column, its SI unit, and the names it goes by in a header (lowercase, spaces or underscores).
COLUMNS = {
    "bit_depth": ("m", ("bit_depth", "bit depth", "depth", "md", "bit md", "measured depth", "bit_md")),
    "pick_up": ("N", ("pick_up", "pick up", "pickup", "pick-up", "pu", "hook load pick up", "puw")),
    "slack_off": ("N", ("slack_off", "slack off", "slackoff", "slack-off", "so", "sow")),
    "rotating_off_bottom": ("N", ("rotating_off_bottom", "rotating off bottom", "rotating weight", "rotating",
                                 "rob", "rotw", "free rotating weight")),
    "torque_off_bottom": ("N m", ("torque_off_bottom", "torque off bottom", "off bottom torque", "off-bottom torque",
                                  "tob off", "free rotating torque")),
    "torque_on_bottom": ("N m", ("torque_on_bottom", "torque on bottom", "on bottom torque", "on-bottom torque",
                                 "drilling torque")),
}
#: The hook-load columns (the others but the depth are torques).
HOOK_LOADS = ("pick_up", "slack_off", "rotating_off_bottom")
#: The largest measured file read [bytes].
MAX_MEASURED_BYTES = 20_000_000
_UNIT = re.compile(r"^(?P<name>.*?)\s*[(\[]\s*(?P<unit>[^()\[\]]*?)\s*[)\]]\s*$")


def _column(cell: str, path: Path) -> tuple[str, float]:
    """(the column a header cell names, the factor of its unit to SI); SceneError for an unknown column or unit."""
    text = cell.strip().strip('"').strip()
    match = _UNIT.match(text)
    name, unit = (match["name"], match["unit"]) if match else (text, "")
    key = " ".join(name.lower().replace("_", " ").split())
    for column, (si, aliases) in COLUMNS.items():
        if key in {" ".join(a.replace("_", " ").split()) for a in aliases}:
            if not unit:
                return column, 1.0
            try:
                return column, read_quantity(f"1 {unit}", si)
            except UnitError as err:
                raise SceneError(f"measured file {path}: column {text!r}: {err}") from None
    known = ", ".join(COLUMNS)
    raise SceneError(f"measured file {path}: unknown column {text!r}; the columns are {known} (each with its unit "
                     "in brackets, e.g. 'pick_up (klbf)')")


def read_measured(path: str | Path, well_depth: float) -> dict[str, np.ndarray]:
    """The measured file's columns in SI (NaN where a cell is blank), sorted by bit depth; refused where a depth
    lies beyond the well's ``well_depth`` [m] (beyond the round-off of the file's units), a hook load or a torque is
    negative, or a cell is not a number."""
    path = Path(path)
    data = read_regular_file(path, "measured file", MAX_MEASURED_BYTES, "a CSV text of measured loads")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = data.decode("latin-1")
    lines = [(k, line) for k, line in enumerate(text.splitlines(), start=1)
             if line.strip() and not line.lstrip().startswith("#")]
    if len(lines) < 2:
        raise SceneError(f"measured file {path} holds {'no header' if not lines else 'a header but no points'}")
    header_line, header = lines[0]
    delimiter = next((d for d in (",", ";", "\t") if d in header), ",")
    cells = next(csv.reader([header], delimiter=delimiter))
    columns = [_column(cell, path) for cell in cells]
    names = [c for c, _ in columns]
    for name in set(names):
        if names.count(name) > 1:
            raise SceneError(f"measured file {path}, line {header_line}: two columns name {name}")
    if "bit_depth" not in names or len(names) < 2:
        raise SceneError(f"measured file {path}, line {header_line}: needs a bit_depth column and at least one of "
                         f"{', '.join(list(COLUMNS)[1:])}")
    values = {name: [] for name in names}
    for k, line in lines[1:]:
        fields = next(csv.reader([line], delimiter=delimiter))
        if len(fields) != len(columns):
            raise SceneError(f"measured file {path}, line {k}: {len(fields)} fields where the header names "
                             f"{len(columns)}")
        for (name, factor), field in zip(columns, fields):
            if not field.strip():
                if name == "bit_depth":
                    raise SceneError(f"measured file {path}, line {k}: no bit depth")
                values[name].append(np.nan)
                continue
            try:
                value = read_number(field, decimal_comma=delimiter != ",") * factor
            except UnitError:
                raise SceneError(f"measured file {path}, line {k}: {name} = {field.strip()!r} is not a number") \
                    from None
            if name == "bit_depth" and not 0.0 < value <= well_depth + DEPTH_ROUND_OFF:
                raise SceneError(f"measured file {path}, line {k}: bit_depth = {field.strip()} is {value:.6g} m, "
                                 f"{'beyond the well' if value > 0 else 'not below the surface'} (its bottom is at "
                                 f"{well_depth:.6g} m)")
            if name != "bit_depth" and value < 0:
                raise SceneError(f"measured file {path}, line {k}: {name} = {field.strip()} is negative: a hook load "
                                 "or a torque the rig reads is >= 0")
            values[name].append(min(value, well_depth) if name == "bit_depth" else value)
    order = np.argsort(values["bit_depth"], kind="stable")
    return {name: np.asarray(column, dtype=float)[order] for name, column in values.items()}

"""The well: its axis from a survey by the minimum-curvature method, and the hole's sections along it.

A survey lists stations (measured depth s, inclination I from the vertical, azimuth A from north, clockwise).
Between two stations the axis is the circular arc that joins their tangents (minimum curvature): with the
dogleg angle beta between the tangents t1, t2, the displacement is (t1 + t2) (s2 - s1) / 2 RF(beta) with
RF = tan(beta/2) / (beta/2), and the tangent turns in their plane at the constant curvature beta / (s2 - s1).
Coordinates: x north, y east, z up (true vertical depth is -z); the tangent points down-hole.
"""

from __future__ import annotations

import csv
import dataclasses
import functools
import math
import re
import weakref
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fenics_drill.model.string_sections import section_at, string_sections
from fenics_drill.scene import SceneError, read_regular_file
from fenics_drill.units import DEPTH_ROUND_OFF, UnitError, read_number, read_quantity

#: Largest dogleg a pipe can pass in a well [deg per 30 m]: beyond this a survey is refused as a typing error
#: (the tightest short-radius wells build at about 2-3 deg per metre).
MAX_DOGLEG_DEG_PER_30M = 90.0


class SurveyError(ValueError):
    """A survey that cannot describe a well; the message names the station or the column."""


def tangent(inclination: np.ndarray, azimuth: np.ndarray) -> np.ndarray:
    """Unit tangents (north, east, up) pointing down-hole, from inclination and azimuth [rad]."""
    inclination, azimuth = np.asarray(inclination, dtype=float), np.asarray(azimuth, dtype=float)
    return np.stack([np.sin(inclination) * np.cos(azimuth), np.sin(inclination) * np.sin(azimuth),
                     -np.cos(inclination)], axis=-1)


@dataclass(frozen=True)
class Survey:
    """Survey stations: measured depth [m], inclination and azimuth [rad]."""

    md: np.ndarray
    inclination: np.ndarray
    azimuth: np.ndarray
    notes: tuple[str, ...] = ()  # what the reader left out of the file, said once the survey is read

    @classmethod
    def of(cls, md, inclination_deg, azimuth_deg, where: str = "the survey") -> "Survey":
        """Checked stations from degrees: at least two, depths strictly increasing, angles finite, inclination in
        [0, 180], doglegs a pipe can pass."""
        md, inc, azi = (np.asarray(a, dtype=float) for a in (md, inclination_deg, azimuth_deg))
        if not (md.ndim == inc.ndim == azi.ndim == 1 and md.size == inc.size == azi.size):
            raise SurveyError(f"{where}: md, inclination and azimuth must be three lists of the same length "
                              f"(got {md.size}, {inc.size}, {azi.size})")
        if md.size < 2:
            raise SurveyError(f"{where}: at least two stations are needed, got {md.size}")
        for name, values in (("md", md), ("inclination", inc), ("azimuth", azi)):
            bad = np.flatnonzero(~np.isfinite(values))
            if bad.size:
                raise SurveyError(f"{where}, station {bad[0] + 1}: {name} = {values[bad[0]]!r} is not a number")
        step = np.diff(md)
        if np.any(step <= 0):
            k = int(np.flatnonzero(step <= 0)[0])
            raise SurveyError(f"{where}, station {k + 2}: md = {md[k + 1]:g} m does not exceed the station before "
                              f"({md[k]:g} m): a survey is sorted by measured depth, without repeats")
        bad = np.flatnonzero((inc < 0) | (inc > 180))
        if bad.size:
            raise SurveyError(f"{where}, station {bad[0] + 1}: inclination = {inc[bad[0]]:g} deg is not in [0, 180]")
        survey = cls(md, np.radians(inc), np.radians(azi))
        dls = np.degrees(survey.doglegs()) / step * 30.0
        if np.any(dls > MAX_DOGLEG_DEG_PER_30M):
            k = int(np.argmax(dls))
            raise SurveyError(f"{where}, stations {k + 1}-{k + 2}: a dogleg of {dls[k]:.3g} deg/30 m, more than any "
                              f"pipe can pass ({MAX_DOGLEG_DEG_PER_30M:g} deg/30 m): check the depths and angles")
        return survey

    def doglegs(self) -> np.ndarray:
        """The angle between consecutive stations' tangents [rad]: 2 arcsin(|t2 - t1| / 2), exact to round-off for
        small angles (arccos of the dot product loses half the digits there: 1.5e-8 rad on a hold)."""
        t = tangent(self.inclination, self.azimuth)
        return 2.0 * np.arcsin(np.clip(0.5 * np.linalg.norm(t[1:] - t[:-1], axis=1), 0.0, 1.0))


#: The largest survey file read [bytes] (100 000 stations take about 3 MB).
MAX_SURVEY_BYTES = 50_000_000
#: The names each survey column goes by in a header (lowercase, its unit and north reference left out).
SURVEY_COLUMNS = {"md": ("md", "measured depth", "measured_depth", "measureddepth", "depth", "mdepth"),
                  "inclination": ("inclination", "inc", "incl"),
                  "azimuth": ("azimuth", "azi", "az", "azim")}
#: What each survey column is read in: its header's unit (:mod:`fenics_drill.units`) converted to these.
SURVEY_UNITS = {"md": "m", "inclination": "degree", "azimuth": "degree"}
#: The north an azimuth column is referred to, by the words vendors write beside it (in its name or in brackets).
NORTH_REFERENCES = {"true": "true", "tn": "true", "t": "true", "grid": "grid", "gn": "grid", "g": "grid",
                    "mag": "magnetic", "magnetic": "magnetic", "mn": "magnetic", "m": "magnetic"}
_BRACKETS = re.compile(r"\s*[(\[]\s*([^()\[\]]*?)\s*[)\]]")


def _survey_text(path: Path) -> str:
    """The text of a survey file: a regular file of at most MAX_SURVEY_BYTES, in UTF-8 (with or without a byte
    order mark) or, failing that, Latin-1 (a degree sign written by an older exporter); a binary file is refused."""
    try:
        data = read_regular_file(path, "survey file", MAX_SURVEY_BYTES, "a CSV text of stations")
    except SceneError as err:
        raise SurveyError(str(err)) from None
    if b"\x00" in data:
        raise SurveyError(f"survey file {path} is a binary file, not a CSV text of stations (md, inclination, "
                          "azimuth)")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = data.decode("latin-1")
    if any(ord(c) < 32 and c not in "\t\r\n" for c in text):
        raise SurveyError(f"survey file {path} holds control characters: it is not a CSV text of stations")
    return text


@dataclass(frozen=True)
class SurveyColumn:
    """A header cell that names a survey column: which one, the factor of its unit to m or degrees, and (an
    azimuth) the north it is referred to ('true', 'grid', 'magnetic'; None where the header does not say)."""

    column: str
    factor: float
    north: str | None = None


def _survey_column(header: str, path: Path) -> SurveyColumn | None:
    """The survey column a header cell names (``MD (ft)``, ``Azim True (deg)``, ``Azi (grid)``), or None."""
    cell = header.strip().strip('"').strip()
    bracketed = _BRACKETS.findall(cell)
    words = _BRACKETS.sub(" ", cell).lower().replace("_", " ").split()
    north = None
    for word in list(words[1:]) + [b.lower() for b in bracketed]:
        if word in NORTH_REFERENCES:
            north = NORTH_REFERENCES[word]
    words = [w for w in words if not (w in NORTH_REFERENCES and w != words[0])]
    units = [b for b in bracketed if b.lower() not in NORTH_REFERENCES]
    name = " ".join(words)
    for column, aliases in SURVEY_COLUMNS.items():
        if name in aliases:
            if column != "azimuth":
                north = None
            if not units or not units[0].strip():
                return SurveyColumn(column, 1.0, north)
            unit = units[0].strip()
            try:
                return SurveyColumn(column, read_quantity(f"1 {'degree' if unit == '°' else unit}",
                                                          SURVEY_UNITS[column]), north)
            except UnitError as err:
                raise SurveyError(f"survey file {path}: column {cell!r}: {err}") from None
    return None


def _survey_columns(names: list[str], path: Path, header_line: int) -> tuple[dict[str, tuple[int, float]], list[str]]:
    """The index and unit factor of each survey column in a header, and notices of the columns left out: of
    several azimuths the true one (or the one that names no north) is read; a grid or magnetic azimuth alone is
    refused, since it needs the grid convergence or the declination, which a survey file does not carry."""
    found, azimuths, notes = {}, [], []
    for index, cell in enumerate(names):
        column = _survey_column(cell, path)
        if column is None:
            continue
        if column.column == "azimuth":
            azimuths.append((index, column, cell.strip()))
        elif column.column not in found:
            found[column.column] = (index, column.factor)
    if azimuths:
        rank = {"true": 0, None: 1}
        usable = sorted((a for a in azimuths if a[1].north in rank), key=lambda a: rank[a[1].north])
        if not usable:
            index, column, cell = azimuths[0]
            raise SurveyError(f"survey file {path}, line {header_line}: the only azimuth, {cell!r}, is referred to "
                              f"{column.north} north; give the azimuth to true north (a {column.north} azimuth needs "
                              f"the {'grid convergence' if column.north == 'grid' else 'magnetic declination'}, "
                              "which the file does not carry)")
        index, column, cell = usable[0]
        found["azimuth"] = (index, column.factor)
        notes += [f"survey file {path}: column {other!r} left out, {cell!r} read as the azimuth"
                  for i, _, other in azimuths if i != index]
    missing = [c for c in SURVEY_COLUMNS if c not in found]
    if missing:
        shown = ", ".join(repr(n.strip()) for n in names)
        raise SurveyError(f"survey file {path}, line {header_line}: no column {', '.join(missing)} (the header names "
                          f"{shown}); the columns are md [m or ft], inclination and azimuth [deg]")
    return found, notes


def read_survey_csv(path: Path) -> Survey:
    """A survey from a CSV file: a header naming the columns md, inclination and azimuth (or MD, Inc, Azi, Azim
    True, with their units in brackets: m or ft, deg or rad; other columns are ignored), then one station per
    line; commas, semicolons or tabs between the fields (with semicolons or tabs, a decimal comma is read); lines
    starting with # and blank lines are skipped.  Errors name the file and the line; the columns left out are in
    the survey's ``notes``."""
    return _parsed_survey(path, _survey_text(path))


@functools.lru_cache(maxsize=8)
def _parsed_survey(path: Path, text: str) -> Survey:
    """:func:`read_survey_csv` of ``text`` read from ``path`` (kept: a command reads its survey at every stage)."""
    lines = [(k, line) for k, line in enumerate(text.splitlines(), start=1)
             if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise SurveyError(f"survey file {path} holds no stations")
    header_line, header = lines[0]
    delimiter = next((d for d in (",", ";", "\t") if d in header), ",")
    names = next(csv.reader([header], delimiter=delimiter))
    found, notes = _survey_columns(names, path, header_line)
    values = {c: [] for c in SURVEY_COLUMNS}
    for k, line in lines[1:]:
        fields = next(csv.reader([line], delimiter=delimiter))
        if len(fields) != len(names):
            raise SurveyError(f"survey file {path}, line {k}: {len(fields)} fields where the header names "
                              f"{len(names)}")
        for column, (index, factor) in found.items():
            try:
                values[column].append(read_number(fields[index], decimal_comma=delimiter != ",") * factor)
            except UnitError:
                raise SurveyError(f"survey file {path}, line {k}: {column} = {fields[index].strip()!r} is not a "
                                  "number") from None
    if not values["md"]:
        raise SurveyError(f"survey file {path} holds a header but no stations")
    survey = Survey.of(values["md"], values["inclination"], values["azimuth"], where=f"survey file {path}")
    return dataclasses.replace(survey, notes=tuple(notes))


class Trajectory:
    """The well's axis by minimum curvature: position, tangent and curvature at any measured depth."""

    def __init__(self, survey: Survey):
        self.survey = survey
        self.md = survey.md
        self.t = tangent(survey.inclination, survey.azimuth)
        beta = survey.doglegs()
        self.beta = beta
        length = np.diff(self.md)
        ratio = np.where(beta > 0, np.tan(beta / 2) / np.where(beta > 0, beta / 2, 1.0), 1.0)
        steps = 0.5 * length[:, None] * ratio[:, None] * (self.t[:-1] + self.t[1:])
        self.stations = np.vstack([np.zeros(3), np.cumsum(steps, axis=0)])

    @property
    def length(self) -> float:
        return float(self.md[-1] - self.md[0])

    def _segment(self, s: np.ndarray) -> np.ndarray:
        return np.clip(np.searchsorted(self.md, s, side="right") - 1, 0, len(self.md) - 2)

    def tangents(self, s) -> np.ndarray:
        """Unit tangents (down-hole) at measured depths ``s``: the slerp of the stations' tangents along each arc."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        k = self._segment(s)
        share = np.clip((s - self.md[k]) / (self.md[k + 1] - self.md[k]), 0.0, 1.0)
        beta = self.beta[k]
        t1, t2 = self.t[k], self.t[k + 1]
        small = beta == 0  # a hold (the doglegs are exact): the ratios below are well conditioned for any beta > 0
        safe = np.where(small, 1.0, beta)
        a = np.where(small, 1.0 - share, np.sin((1 - share) * safe) / np.sin(safe))
        b = np.where(small, share, np.sin(share * safe) / np.sin(safe))
        out = a[:, None] * t1 + b[:, None] * t2
        return out / np.linalg.norm(out, axis=1)[:, None]

    def positions(self, s) -> np.ndarray:
        """Positions (north, east, up) [m] at measured depths ``s``, on the arcs of minimum curvature."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        k = self._segment(s)
        beta = self.beta[k]
        length = self.md[k + 1] - self.md[k]
        share = np.clip((s - self.md[k]) / length, 0.0, 1.0)
        t1, t2 = self.t[k], self.t[k + 1]
        small = beta == 0
        safe = np.where(small, 1.0, beta)
        # the slerp integrated from the station: r = L / (beta sin beta) [(cos((1-f) beta) - cos beta) t1 + (1 - cos f beta) t2],
        # the differences of cosines written as products of sines (no cancellation at small beta):
        # cos((1-f) b) - cos b = 2 sin((1 - f/2) b) sin(f b / 2), 1 - cos(f b) = 2 sin(f b / 2)^2
        denominator = safe * np.sin(safe)
        half = np.sin(0.5 * share * safe)
        c1 = np.where(small, share - share**2 / 2, 2.0 * np.sin((1 - 0.5 * share) * safe) * half / denominator)
        c2 = np.where(small, share**2 / 2, 2.0 * half**2 / denominator)
        return self.stations[k] + length[:, None] * (c1[:, None] * t1 + c2[:, None] * t2)

    def curvature(self, s) -> np.ndarray:
        """The axis' curvature [1/m] at measured depths ``s``: beta / length of the arc they lie on."""
        k = self._segment(np.atleast_1d(np.asarray(s, dtype=float)))
        return self.beta[k] / (self.md[k + 1] - self.md[k])

    def inclination(self, s) -> np.ndarray:
        """Inclination from the vertical [rad] at measured depths ``s``."""
        t = self.tangents(s)
        return np.arctan2(np.hypot(t[:, 0], t[:, 1]), -t[:, 2])

    def bishop_frames(self, s) -> "AxisFrames":
        """The twist-free (Bishop) frame of the axis at measured depths ``s``, and the axis' curvature in it.

        At the surface d3 is the high side (the azimuth's direction where the hole starts vertical) and
        d2 = d3 x t; down-hole the frame is carried by parallel transport: along each arc it turns with the
        tangent about the arc's binormal b, by beta s / length, so that t' = k2 d2 + k3 d3, d2' = -k2 t,
        d3' = -k3 t with (k2, k3) = kappa ((b x t).d2, (b x t).d3), constant along the arc."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        binormals = np.cross(self.t[:-1], self.t[1:])
        norms = np.linalg.norm(binormals, axis=1)
        binormals = np.where(norms[:, None] > 1e-12, binormals / np.where(norms > 1e-12, norms, 1.0)[:, None], 0.0)
        d3 = _carried(_high_side(self.t[0], self.survey.azimuth[0]), binormals, self.beta)
        k = self._segment(s)
        share = np.clip((s - self.md[k]) / (self.md[k + 1] - self.md[k]), 0.0, 1.0)
        t = self.tangents(s)
        d3_s = _rotated(d3[k], binormals[k], share * self.beta[k])
        d3_s -= np.einsum("ij,ij->i", d3_s, t)[:, None] * t  # round-off only: d3 is normal to t
        d3_s /= np.linalg.norm(d3_s, axis=1)[:, None]
        d2_s = np.cross(d3_s, t)
        normal = self.curvature(s)[:, None] * np.cross(binormals[k], t)
        return AxisFrames(t, d2_s, d3_s, np.einsum("ij,ij->i", normal, d2_s), np.einsum("ij,ij->i", normal, d3_s))


@dataclass(frozen=True)
class AxisFrames:
    """Bishop frames (t, d2, d3) of the axis at some measured depths (rows, in north-east-up), and the curvature
    components (k2, k3) [1/m] of the axis in them."""

    t: np.ndarray
    d2: np.ndarray
    d3: np.ndarray
    k2: np.ndarray
    k3: np.ndarray

    def down(self) -> np.ndarray:
        """The unit downward vertical in each frame: its components along (t, d2, d3), one row per depth."""
        return -np.stack([self.t[:, 2], self.d2[:, 2], self.d3[:, 2]], axis=1)


def _high_side(t: np.ndarray, azimuth: float) -> np.ndarray:
    """The unit vector normal to t toward the vertical's up (the hole's high side); where t is vertical, the
    horizontal direction of ``azimuth`` (the high side the hole will have once it builds that way)."""
    up = np.array([0.0, 0.0, 1.0]) - t[2] * t
    norm = np.linalg.norm(up)
    if norm > 1e-9:
        return up / norm
    return np.array([np.cos(azimuth), np.sin(azimuth), 0.0])


def _carried(start: np.ndarray, axes: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """``start`` and its images as each arc turns it in turn by ``angles`` about ``axes`` (rows): the frame's
    vector at every station (Rodrigues' rotation, one station after the other in plain floats: a survey may have
    tens of thousands)."""
    x, y, z = (float(c) for c in start)
    out = [(x, y, z)]
    for (a, b, c), angle in zip(axes.tolist(), np.asarray(angles, dtype=float).tolist()):
        cos, sin = math.cos(angle), math.sin(angle)
        along = (a * x + b * y + c * z) * (1.0 - cos)
        x, y, z = (x * cos + (b * z - c * y) * sin + a * along, y * cos + (c * x - a * z) * sin + b * along,
                   z * cos + (a * y - b * x) * sin + c * along)
        out.append((x, y, z))
    return np.array(out)


def _rotated(vectors: np.ndarray, axes: np.ndarray, angles) -> np.ndarray:
    """Rodrigues' rotation of ``vectors`` about the unit ``axes`` (zero: no rotation) by ``angles`` (rows)."""
    vectors, axes = np.atleast_2d(vectors), np.atleast_2d(axes)
    angles = np.broadcast_to(np.asarray(angles, dtype=float), (max(len(vectors), len(axes)),))[:, None]
    along = np.einsum("ij,ij->i", axes, vectors)[:, None] * axes
    return vectors * np.cos(angles) + np.cross(axes, vectors) * np.sin(angles) + along * (1 - np.cos(angles))


def straight_survey(length: float, inclination_deg: float = 90.0, azimuth_deg: float = 0.0) -> Survey:
    """A straight hole of ``length`` at a fixed inclination and azimuth (the paper's: horizontal)."""
    return Survey.of([0.0, length], [inclination_deg] * 2, [azimuth_deg] * 2)


def dogleg_severity_deg_per_30m(survey: Survey) -> np.ndarray:
    """Dogleg severity of each survey interval, in degrees per 30 m (the industry's unit)."""
    return np.degrees(survey.doglegs()) / np.diff(survey.md) * 30.0


@dataclass(frozen=True)
class HoleSections:
    """The hole along measured depth: section k spans down to ``bottoms[k]``, with its radius and whether it is
    cased (its friction coefficient is the cased hole's) or open."""

    bottoms: np.ndarray
    radii: np.ndarray
    cased: np.ndarray

    def at(self, s) -> np.ndarray:
        """The index of the hole section at measured depths ``s``."""
        index = np.searchsorted(self.bottoms, np.atleast_1d(np.asarray(s, dtype=float)), side="left")
        return np.clip(index, 0, len(self.radii) - 1)

    def radius(self, s) -> np.ndarray:
        return self.radii[self.at(s)]


@dataclass(frozen=True)
class Well:
    """A scene's well: its axis (from the survey) and its hole sections."""

    trajectory: Trajectory
    hole: HoleSections

    @property
    def depth(self) -> float:
        """Measured depth of the last survey station (total depth) [m]."""
        return float(self.trajectory.md[-1])

    @property
    def notes(self) -> tuple[str, ...]:
        """What the survey's reader left out of its file (a second azimuth column, ...)."""
        return self.trajectory.survey.notes


def well_of(scene, string_length: float) -> Well:
    """The well of a scene's ``[well]`` table (raises SceneError naming the key, the file or the station): the
    survey from ``well.survey`` or the inline stations, started at the surface (a first station below md 0 is
    reached by a straight hole at its own angles), and the hole sections (one open hole of ``borehole.radius``
    when none are given).  Without stations, the paper's straight horizontal hole of ``string_length``."""
    w = scene.well
    if w.survey and w.md:
        raise SceneError("well.survey and well.md are not admissible together: give the stations in a file or "
                         "inline, not both")
    try:
        if w.survey:
            survey = read_survey_csv(Path(w.survey))
        elif w.md:
            survey = Survey.of(w.md, w.inclination, w.azimuth, where="well.md/inclination/azimuth")
        else:
            survey = straight_survey(string_length)
    except SurveyError as err:
        raise SceneError(str(err)) from None
    if survey.md[0] < 0:
        raise SceneError(f"the survey's first station is at md = {survey.md[0]:g} m: measured depth is counted "
                         "from the surface, >= 0")
    if survey.md[0] > 0:
        survey = Survey(np.concatenate([[0.0], survey.md]), np.concatenate([survey.inclination[:1], survey.inclination]),
                        np.concatenate([survey.azimuth[:1], survey.azimuth]))
    depth = float(survey.md[-1])
    count = len(w.hole_radius)
    if len(w.hole_bottom) != count or (w.hole_cased and len(w.hole_cased) != count):
        raise SceneError(f"well.hole_bottom ({len(w.hole_bottom)}), well.hole_radius ({count}) and well.hole_cased "
                         f"({len(w.hole_cased)}) must list the same hole sections (hole_cased may be left out: open)")
    if count:
        bottoms, radii = np.asarray(w.hole_bottom, dtype=float), np.asarray(w.hole_radius, dtype=float)
        if np.any(np.diff(bottoms) <= 0) or bottoms[0] <= 0:
            raise SceneError(f"well.hole_bottom = {list(w.hole_bottom)} is not admissible: the sections' bottoms "
                             "must be > 0 and increasing")
        if bottoms[-1] < depth - DEPTH_ROUND_OFF:
            raise SceneError(f"well.hole_bottom = {list(w.hole_bottom)} is not admissible: the last section must "
                             f"reach the survey's last station at md = {depth:g} m")
        if np.any(radii <= 0):
            raise SceneError(f"well.hole_radius = {list(w.hole_radius)} is not admissible: every radius must be > 0")
        cased = np.asarray(w.hole_cased or [False] * count, dtype=bool)
    else:
        bottoms, radii, cased = np.array([depth]), np.array([scene.borehole.radius]), np.array([False])
    if string_length > depth + DEPTH_ROUND_OFF:
        raise SceneError(f"the string ({string_length:g} m) is longer than the well ({depth:g} m of measured depth): "
                         "shorten string.sections or extend the survey")
    trajectory = Trajectory(survey)
    above = np.flatnonzero(trajectory.stations[:, 2] > 1e-9 * max(depth, 1.0))
    if above.size:
        k = int(above[0])
        raise SceneError(f"the survey rises above the surface: at md = {survey.md[k]:g} m (station {k + 1}) the well "
                         f"is {trajectory.stations[k, 2]:.4g} m above the ground; check the inclinations (above 90 "
                         "deg the hole climbs)")
    return Well(trajectory, HoleSections(bottoms, radii, cased))


@dataclass(frozen=True)
class StringInWell:
    """A scene's string resolved once in its well: the sections from the surface down (the bit at the bottom of the
    last) and the well they hang in (:func:`well_of`)."""

    sections: tuple
    well: Well

    @property
    def length(self) -> float:
        """The string's length, the bit's measured depth [m]."""
        return self.sections[-1].bottom


#: The scenes resolved so far, by identity (a scene is immutable; each entry goes with its scene).
_RESOLVED: dict[int, tuple[weakref.ref, StringInWell]] = {}


def string_in_well(scene) -> StringInWell:
    """The scene's :class:`StringInWell`, resolved at the first call for this scene and read from then on (raises
    SceneError as :func:`well_of` does)."""
    key = id(scene)
    known = _RESOLVED.get(key)
    if known is not None and known[0]() is scene:
        return known[1]
    sections = tuple(string_sections(scene))
    resolved = StringInWell(sections, well_of(scene, sections[-1].bottom))
    _RESOLVED[key] = (weakref.ref(scene), resolved)
    weakref.finalize(scene, _RESOLVED.pop, key, None)
    return resolved


def hanging_tension(scene, md, weight_on_bit: float) -> np.ndarray:
    """The effective tension [N] at measured depths ``md`` of the scene's string hanging in its well with
    ``weight_on_bit`` on the bit: the buoyed weight below each point along the axis, less the weight on bit
    (Lubinski's effective tension, without wall friction).  In the straight horizontal hole, or without gravity, the
    weight has no share along the axis: -weight_on_bit."""
    md = np.asarray(md, dtype=float)
    if not (scene.well.survey or scene.well.md) or not scene.model.gravity:
        return np.full_like(md, -weight_on_bit)
    resolved = string_in_well(scene)
    sections, trajectory = resolved.sections, resolved.well.trajectory
    # intervals that break at every section end, so that each carries one section's weight: sampled across an end,
    # a 2000-point grid put 176 m of 8 in collars under 2416 m of 4 1/2 in pipe 659 N off (tests/model/test_wells.py)
    fine = np.union1d(np.linspace(0.0, resolved.length, max(2001, 4 * scene.beam.elements + 1)),
                      [s.bottom for s in sections if 0.0 < s.bottom < resolved.length])
    weight = np.array([s.buoyed_weight(scene.environment.gravity, scene.fluid.density, scene.inner_fluid_density)
                       for s in sections])[section_at(sections, 0.5 * (fine[1:] + fine[:-1]))]
    axis = np.cos(trajectory.inclination(fine))  # the axis' share of a weight along it
    below = np.concatenate([np.cumsum((weight * 0.5 * (axis[1:] + axis[:-1]) * np.diff(fine))[::-1])[::-1], [0.0]])
    return np.interp(md, fine, below) - weight_on_bit


def check_weight_on_bit(scene) -> None:
    """Refuse a weight on bit that a hook-load drive cannot set in a well (SceneError with the numbers): a drawworks
    only holds, and the weight on bit cannot exceed the string's buoyed weight along the axis.  Both the drive's and
    the modal analysis's (``modal.weight_on_bit``) are checked.  A velocity drive positions the top, and pushes where
    the weight on bit asks more than the string weighs (its static state reports the push); the paper's horizontal
    string is pushed by design.  Neither is checked."""
    if not (scene.well.survey or scene.well.md) or scene.drive.mode != "hook_load":
        return
    available = float(hanging_tension(scene, [0.0], 0.0)[0])
    for name, value in (("drive.weight_on_bit", scene.drive.weight_on_bit),
                        ("modal.weight_on_bit", scene.modal.weight_on_bit)):
        if value >= available:
            raise SceneError(f"{name} = {value:g} N is not admissible with drive.mode = 'hook_load': the string's "
                             f"buoyed weight along this well is {available:.6g} N, so the hook would have to push to "
                             "set it; lower the weight on bit, add collars or heavy-weight pipe, or drive the top "
                             "(drive.mode = 'velocity')")


def check_string_in_well(scene) -> Well | None:
    """Every check of a scene's string in its well that needs no solve (what ``fenics-drill scene`` runs, and every
    command before it computes): the survey and the hole sections (:func:`well_of`), the sections' buoyed weights
    (:func:`~fenics_drill.model.string_sections.string_sections`) and the weight on bit (:func:`check_weight_on_bit`).
    The well, or None for the paper's straight hole of one pipe."""
    if not (scene.well.survey or scene.well.md or scene.string.sections):
        return None
    well = string_in_well(scene).well
    check_weight_on_bit(scene)
    return well


def bit_above_bottom(scene) -> float:
    """How far the bit is above the well's bottom [m]: the well's measured depth less the string's length, 0 where
    they agree within DEPTH_ROUND_OFF and in the paper's straight hole (as long as its string)."""
    if not (scene.well.survey or scene.well.md):
        return 0.0
    resolved = string_in_well(scene)
    gap = resolved.well.depth - resolved.length
    return gap if gap > DEPTH_ROUND_OFF else 0.0


def well_notes(scene) -> list[str]:
    """What every command says of a scene's well besides its results: where the bit is when the string does not
    reach the well's bottom, and what the survey's reader left out of its file."""
    well = check_string_in_well(scene)
    if well is None:
        return []
    notes = list(well.notes)
    above = bit_above_bottom(scene)
    if above > 0:
        notes.insert(0, f"the bit is {above:.4g} m above the well's bottom (a {string_in_well(scene).length:.6g} m "
                        f"string in a {well.depth:.6g} m well): 'on bottom' means the bit on the rock there")
    return notes

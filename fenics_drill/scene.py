"""Scene files: a TOML document in SI units, validated before any computation.

A scene is read with :func:`load_scene` (file + ``--set section.key=value``
overrides), checked key by key against :data:`SCHEMA`, then checked for the
relations between keys (inner radius < outer radius < borehole radius, ...).
Every refusal is a :class:`SceneError` naming the key, the value and what is
admissible.
"""

from __future__ import annotations

import copy
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from fenics_drill.forms import BeamProperties


class SceneError(ValueError):
    """A scene value that cannot be used; the message names key, value and admissible set."""


@dataclass(frozen=True)
class Key:
    """One scene key: its type, default, admissible set and meaning (with unit)."""

    kind: type | tuple[type, ...]
    default: Any
    doc: str
    check: Callable[[Any], bool] | None = None
    admissible: str = ""
    choices: tuple[str, ...] | None = None


def _positive(x) -> bool:
    return x > 0


def _non_negative(x) -> bool:
    return x >= 0


def _pos(doc: str, default, kind=float) -> Key:
    return Key(kind, default, doc, _positive, "> 0")


def _gamma_dispersion(x: float) -> bool:
    return 0.0 <= x < 1.0 / math.sqrt(2.0)


def _nonneg(doc: str, default, kind=float) -> Key:
    return Key(kind, default, doc, _non_negative, ">= 0")


def _grid_axis(x) -> bool:
    """[min, max, n]: 0 <= min <= max and n a whole number >= 1 (n = 1 needs min = max)."""
    if not isinstance(x, list) or len(x) != 3 or not all(isinstance(v, (int, float)) for v in x):
        return False
    low, high, n = x
    return 0 <= low <= high and float(n).is_integer() and n >= 1 and (n > 1 or low == high)


def _flag(doc: str, default: bool = True) -> Key:
    return Key(bool, default, doc)


def _band_or_count(doc: str) -> Key:
    return Key(float, -1.0, doc, lambda x: x == -1.0 or x >= 0, ">= 0 (or -1 for 'not set')")


# Defaults are the paper's nominal scene (Tables 1-3, Section 6).
SCHEMA: dict[str, dict[str, Key]] = {
    "beam": {
        "length": _pos("beam length L [m]", 100.0),
        "elements": Key(int, 250, "number of finite elements [-]; 250 sits on the Pareto front of the modal "
                        "models (the paper's 500 gives the same drilling quantities to 5 digits at 1.7x the cost, "
                        "benchmarks/RESULTS.md); the full order needs 500-1000", lambda n: n >= 1, ">= 1"),
        "element_degree": Key(
            int, 2, "polynomial degree of v, w; u and the rotations use one degree less [-]",
            lambda k: 2 <= k <= 5, "an integer in [2, 5]",
        ),
        "outer_radius": _pos("outer radius R_ext [m]", 80e-3),
        "inner_radius": _nonneg("inner radius R_int [m]", 50e-3),
        "density": _pos("mass density rho [kg/m^3]", 7900.0),
        "young_modulus": _pos("elastic modulus E [Pa]", 203e9),
        "poisson_ratio": Key(float, 0.3, "Poisson ratio nu [-]", lambda x: -1.0 < x < 0.5, "in (-1, 0.5)"),
        "shear_factor": Key(float, 6.0 / 7.0, "shear factor kappa_s [-]", lambda x: 0 < x <= 1, "in (0, 1]"),
        "damping": _nonneg("viscous damping constant c of Eq. (38) [1/s]", 0.01),
    },
    "borehole": {
        "radius": _pos("borehole radius R_bh = R_ext + gap [m]", 95e-3),
    },
    "environment": {
        "gravity": _nonneg("gravitational acceleration g, along -z [m/s^2]", 9.81),
    },
    "contact": {
        "stiffness_linear": _nonneg("k_FS1 of Eq. (17) [N/m]", 1e10),
        "stiffness_cubic": _nonneg("k_FS2 of Eq. (17) [N/m^3]", 1e16),
        "damping": _nonneg("c_FS of Eq. (17) [N s/m^4]", 1e6),
        "friction": _nonneg("mu_FS of Eqs. (18)-(19) [-]", 0.25),
        "sliding_velocity_scale": _pos(
            "v_s of the regularised sgn(v) = tanh(v / v_s) in (18)-(19), applied to the axial velocity "
            "and to the surface speed R_bh theta_x_dot [m/s]", 1e-3,
        ),
    },
    "bit_rock": {
        "limit_force": _nonneg("Gamma_BR of Eq. (20) [N]", 30e3),
        "rate": _nonneg("alpha_BR of Eq. (20) [s/m]", 400.0),
        "friction": Key(float, 0.4, "mu_BR of Eq. (21) [-]", lambda x: 0 <= x <= 1, "in [0, 1]"),
    },
    "drive": {
        "axial_velocity": Key(float, 1.0 / 180.0, "V0, imposed axial velocity at x = 0 [m/s]"),
        "rotation_speed": Key(float, 2.0 * math.pi, "Omega, imposed rotation speed at x = 0 [rad/s]"),
    },
    "time": {
        "t_end": _pos("end of the simulated interval [s]", 10.0),
        "dt": Key(
            float, -1.0, "nominal time step [s]; -1: 1/(2 f_max) with f_max = f*_max c_L / L (Section 6.2)",
            lambda x: x == -1.0 or x > 0, "> 0 (or -1 for the paper's nominal step)",
        ),
        "newmark_alpha": Key(
            float, 0.015, "alpha of Newmark's gamma = 1/2 + alpha, beta = (1/2 + gamma)^2 / 4 (Section 4.3) [-]",
            lambda x: 0 <= x <= 0.5, "in [0, 0.5]",
        ),
        "adaptive": _flag("refine the step where the local error estimate exceeds time.error_tolerance"),
        "error_tolerance": _pos(
            "admissible local error of the lateral vertex displacements per step [m]", 1e-5
        ),
        "max_step_cuts": Key(
            int, 12, "the smallest step is dt / 2^max_step_cuts; a run needing less stops [-]",
            lambda n: 0 <= n <= 40, "an integer in [0, 40]",
        ),
    },
    "solver": {
        "newton_tolerance": _pos("relative residual at which Newton stops [-]", 1e-8),
        "newton_max_iterations": Key(int, 25, "Newton iterations before the step is cut [-]", _positive, ">= 1"),
        "tangent_reuse": Key(int, 20, "steps over which the assembled internal tangent is reused; 1: fresh at "
                             "every step (contact and bit tangents are always fresh) [-]", _positive, ">= 1"),
    },
    "output": {
        "section": Key(
            float, -1.0, "x of the cross-section whose lateral motion is recorded [m]; -1: mid-length L/2",
            lambda x: x == -1.0 or x >= 0, ">= 0 (or -1 for L/2)",
        ),
        "field_interval": _nonneg("simulated time between XDMF field snapshots [s]; 0: no fields", 0.1),
        "von_mises": _flag("record the maximum von Mises stress over the string at every step (Eq. 100)"),
    },
    "model": {
        "supports": Key(
            str, "paper",
            "'paper': v, w, theta_y, theta_z fixed at x=0 and v, w at x=L; "
            "'pinned': v, w fixed at both ends",
            choices=("paper", "pinned"),
        ),
        "gravity": _flag("assemble the gravity load (52)"),
        "contact": _flag("evaluate wall impacts (16)-(19)"),
        "bit_rock": _flag("evaluate the bit-rock force and torque (20)-(22)"),
        "geometric_nonlinearity": _flag("assemble the geometric nonlinear force F_SE (49)"),
        "inertial_nonlinearity": _flag("assemble the inertial nonlinear force F_KE (48)"),
        "kinematics": Key(
            str, "objective",
            "cross-section kinematics of the strain energy: 'objective' (strains unchanged by a rigid "
            "spin theta_x, docs/errata.md) or 'printed' (Eq. 14 as printed)",
            choices=("objective", "printed"),
        ),
    },
    "modal": {
        "f_star_max": _pos("upper end of the dimensionless band of analysis B = [0, f*_max], Eq. (95) [-]", 4.0),
    },
    "reduction": {
        "rule": Key(
            str, "paper",
            "'paper' (Section 6.3), 'band' (f* upper bounds per family), "
            "'count' (number of modes per family) or 'none' (full order)",
            choices=("paper", "band", "count", "none"),
        ),
        "flexural": _band_or_count("flexural f* upper bound ('band') or mode count ('count')"),
        "torsional": _band_or_count("torsional f* upper bound ('band') or mode count ('count')"),
        "axial": _band_or_count("axial f* upper bound ('band') or mode count ('count')"),
        "static_correction": _flag(
            "add the static responses to a unit bit force and torque to the modal basis "
            "(fenics_drill/static_correction.py); false: the paper's pure modal basis", False),
    },
    "uncertainty": {  # Section 5 and 6.11; the means are the bit_rock values
        "rate_dispersion": Key(float, 0.005, "dispersion sigma/m of alpha_BR, gamma law (81) [-]",
                               _gamma_dispersion, "in [0, 1/sqrt(2)) (Eq. 81)"),
        "limit_force_dispersion": Key(float, 0.01, "dispersion sigma/m of Gamma_BR, gamma law (86) [-]",
                                      _gamma_dispersion, "in [0, 1/sqrt(2)) (Eq. 86)"),
        "friction_dispersion": _nonneg(
            "dispersion sigma/m of mu_BR, beta law (90)-(92); with mean m it must be < sqrt((1 - m)/m) [-]", 0.005),
        "seed": Key(int, 20150101, "base seed: realisation k draws from numpy default_rng([seed, k])",
                    lambda n: n >= 0, ">= 0"),
        "output_interval": _pos("step of the common time grid of the Monte Carlo histories [s]", 0.01),
    },
    "optimize": {  # Sections 6.9, 6.10, 6.12: the operating window and the objective
        "axial_velocity": Key(list, [1.0 / 360.0, 1.0 / 90.0, 4], "grid of V0: [min, max, points] [m/s]",
                              _grid_axis, "[min, max, n] with 0 <= min <= max and n >= 1 whole"),
        "rotation_speed": Key(list, [1.5 * math.pi, 7.0 * math.pi / 3.0, 4], "grid of Omega: [min, max, points] "
                              "[rad/s]", _grid_axis, "[min, max, n] with 0 <= min <= max and n >= 1 whole"),
        "objective": Key(str, "rop", "what to maximise: 'rop' (99) or 'efficiency' (96)",
                         choices=("rop", "efficiency")),
        "ultimate_strength": _pos("UTS of the von Mises constraint (100), (103) [Pa]", 650e6),
        "samples": Key(int, 0, "realisations per grid point: 0 = deterministic (nominal bit-rock), "
                       "N > 0 = robust, E[objective] (102) under the chance constraint (103)-(104)",
                       _non_negative, ">= 0"),
        "risk": Key(float, 0.1, "P_risk of the chance constraint (104) [-]", lambda x: 0 < x < 1, "in (0, 1)"),
    },
}


def default_scene() -> dict[str, dict[str, Any]]:
    """The nominal scene of the paper as a nested dict."""
    return {sec: {k: copy.deepcopy(spec.default) for k, spec in keys.items()} for sec, keys in SCHEMA.items()}


def _describe_kind(kind) -> str:
    kinds = kind if isinstance(kind, tuple) else (kind,)
    names = {float: "a number", int: "an integer", bool: "true or false", str: "a string", list: "an array"}
    return " or ".join(names.get(k, k.__name__) for k in kinds)


def _coerce(name: str, value: Any, spec: Key) -> Any:
    """Return ``value`` converted to the key's type, or raise SceneError."""
    bad = SceneError(f"{name} = {value!r} is not admissible: expected {_describe_kind(spec.kind)}")
    if spec.kind is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise bad
        value = float(value)
        if not math.isfinite(value):
            raise SceneError(f"{name} = {value!r} is not admissible: expected a finite number")
    elif spec.kind is int:
        if isinstance(value, bool):
            raise bad
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        if not isinstance(value, int):
            raise bad
    elif not isinstance(value, spec.kind):
        raise bad
    if spec.choices is not None and value not in spec.choices:
        raise SceneError(f"{name} = {value!r} is not admissible: expected one of {', '.join(spec.choices)}")
    if spec.check is not None and not spec.check(value):
        raise SceneError(f"{name} = {value!r} is not admissible: must be {spec.admissible}")
    return value


def _check_relations(scene: dict[str, dict[str, Any]]) -> None:
    beam, hole = scene["beam"], scene["borehole"]
    if beam["inner_radius"] >= beam["outer_radius"]:
        raise SceneError(
            f"beam.inner_radius = {beam['inner_radius']!r} is not admissible: "
            f"must be < beam.outer_radius = {beam['outer_radius']!r}"
        )
    if hole["radius"] <= beam["outer_radius"]:
        raise SceneError(
            f"borehole.radius = {hole['radius']!r} is not admissible: "
            f"must be > beam.outer_radius = {beam['outer_radius']!r} (the string must fit in the hole)"
        )
    if scene["output"]["section"] == -1.0:
        scene["output"]["section"] = 0.5 * beam["length"]
    if scene["output"]["section"] > beam["length"]:
        raise SceneError(
            f"output.section = {scene['output']['section']!r} is not admissible: "
            f"must be in [0, beam.length = {beam['length']!r}]"
        )
    red = scene["reduction"]
    if red["rule"] in ("band", "count"):
        for family in ("flexural", "torsional", "axial"):
            if red[family] < 0:
                raise SceneError(
                    f"reduction.{family} = {red[family]!r} is not admissible: "
                    f"reduction.rule = '{red['rule']}' needs a value >= 0 for every family"
                )
            if red["rule"] == "count" and not float(red[family]).is_integer():
                raise SceneError(
                    f"reduction.{family} = {red[family]!r} is not admissible: "
                    "reduction.rule = 'count' needs a whole number of modes"
                )


def validate(raw: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Merge ``raw`` over the defaults, checking every key; return the complete scene."""
    scene = default_scene()
    for section, entries in raw.items():
        if section not in SCHEMA:
            raise SceneError(f"unknown section [{section}]; known sections: {', '.join(SCHEMA)}")
        if not isinstance(entries, dict):
            raise SceneError(f"[{section}] must be a table of keys, got {entries!r}")
        for key, value in entries.items():
            if key not in SCHEMA[section]:
                raise SceneError(
                    f"unknown key {section}.{key}; known keys of [{section}]: {', '.join(SCHEMA[section])}"
                )
            scene[section][key] = _coerce(f"{section}.{key}", value, SCHEMA[section][key])
    _check_relations(scene)
    return scene


def parse_override(text: str) -> tuple[str, str, Any]:
    """Parse ``section.key=value``; the value is read as TOML (bare words as strings)."""
    if "=" not in text:
        raise SceneError(f"override {text!r} is not of the form section.key=value")
    dotted, value_text = text.split("=", 1)
    parts = dotted.strip().split(".")
    if len(parts) != 2 or not all(parts):
        raise SceneError(f"override {text!r}: the key must be section.key, got {dotted.strip()!r}")
    try:
        value = tomllib.loads(f"v = {value_text.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = value_text.strip()
    return parts[0], parts[1], value


def load_scene(path: str | Path | None = None, overrides: list[str] | tuple[str, ...] = ()) -> dict:
    """Read a scene file (or the defaults when ``path`` is None), apply overrides, validate."""
    raw: dict[str, Any] = {}
    if path is not None:
        path = Path(path)
        if not path.is_file():
            raise SceneError(f"scene file {str(path)!r} does not exist")
        try:
            raw = tomllib.loads(path.read_text())
        except tomllib.TOMLDecodeError as err:
            raise SceneError(f"scene file {str(path)!r} is not valid TOML: {err}") from err
    for text in overrides:
        section, key, value = parse_override(text)
        raw.setdefault(section, {})
        if not isinstance(raw[section], dict):
            raise SceneError(f"[{section}] must be a table of keys")
        raw[section][key] = value
    return validate(raw)


def beam_properties(scene: dict) -> BeamProperties:
    """The parameter object the forms take, built from a validated scene."""
    b = scene["beam"]
    return BeamProperties(
        length=b["length"],
        outer_radius=b["outer_radius"],
        inner_radius=b["inner_radius"],
        density=b["density"],
        young_modulus=b["young_modulus"],
        poisson_ratio=b["poisson_ratio"],
        shear_factor=b["shear_factor"],
        damping=b["damping"],
        gravity=scene["environment"]["gravity"] if scene["model"]["gravity"] else 0.0,
    )

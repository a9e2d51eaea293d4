"""Scene files: a TOML document in SI units, validated once into a typed, immutable :class:`Scene`.

A scene is read with :func:`load_scene` (file + ``--set section.key=value``
overrides).  Each section is a frozen dataclass whose fields are the scene keys:
the annotation is the type, the default is the paper's nominal value (Tables 1-3,
Section 6), and :func:`key` attaches the meaning (with unit) and the admissible
set.  The dataclasses *are* the schema: nothing else lists the keys.  After the
keys, the relations between them are checked (inner radius < outer radius <
borehole radius, ...).  Every refusal is a :class:`SceneError` naming the key,
the value and what is admissible.  Modules receive the typed sections
(``scene.beam.length``); a changed scene is a new one (:meth:`Scene.with_changes`).
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
import stat
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, get_type_hints

from fenics_drill.forms import BeamProperties
from fenics_drill.units import DEPTH_ROUND_OFF


#: The longest string a scene may describe [m] (the longest wells drilled are about 15 km).
MAX_LENGTH = 20_000.0
#: Most points of the common time grid of a Monte Carlo study's histories (uncertainty.output_interval): each
#: realisation holds a few histories on it, so 1e6 points are some 50 MB a realisation.
MAX_GRID_POINTS = 1_000_000
#: Largest scene file read [bytes]: a scene is a few kB of TOML.
MAX_SCENE_BYTES = 10_000_000


class SceneError(ValueError):
    """A scene value that cannot be used; the message names key, value and admissible set."""


def key(default, doc: str, check: Callable[[Any], bool] | None = None, admissible: str = "",
        choices: tuple[str, ...] | None = None):
    """A scene key: its default, meaning (with unit), admissible set and, for strings, the choices."""
    return field(default=default, metadata={"doc": doc, "check": check, "admissible": admissible,
                                            "choices": choices})


def _positive(x) -> bool:
    return x > 0


def _non_negative(x) -> bool:
    return x >= 0


def _pos(doc: str, default):
    return key(default, doc, _positive, "> 0")


def _nonneg(doc: str, default):
    return key(default, doc, _non_negative, ">= 0")


def _gamma_dispersion(x: float) -> bool:
    return 0.0 <= x < 1.0 / math.sqrt(2.0)


def _grid_axis(x) -> bool:
    """[min, max, n]: 0 <= min <= max and n a whole number >= 1 (n = 1 needs min = max)."""
    if len(x) != 3 or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in x):
        return False
    low, high, n = x
    return 0 <= low <= high and float(n).is_integer() and 1 <= n <= 1000 and (n > 1 or low == high)


def _band_or_count(doc: str):
    return key(-1.0, doc, lambda x: x == -1.0 or x >= 0, ">= 0 (or -1 for 'not set')")


@dataclass(frozen=True)
class Beam:
    length: float = key(100.0, "beam length L [m]", lambda x: 0 < x <= MAX_LENGTH, f"in (0, {MAX_LENGTH:g}]")
    elements: int = key(250, "number of finite elements [-]", lambda n: n >= 2, ">= 2")
    element_degree: int = key(2, "polynomial degree of u, v, w; the rotations use one degree less [-]",
                              lambda k: 2 <= k <= 5, "an integer in [2, 5]")
    outer_radius: float = _pos("outer radius R_ext [m]", 80e-3)
    inner_radius: float = _nonneg("inner radius R_int [m]", 50e-3)
    density: float = key(7900.0, "mass density rho [kg/m^3]", lambda x: 500 <= x <= 25000, "in [500, 25000] (any "
                         "engineering solid)")
    young_modulus: float = key(203e9, "elastic modulus E [Pa]", lambda x: 1e9 <= x <= 1e12, "in [1e9, 1e12] (any "
                               "engineering solid)")
    poisson_ratio: float = key(0.3, "Poisson ratio nu [-]", lambda x: -1.0 < x < 0.5, "in (-1, 0.5)")
    shear_factor: float = key(6.0 / 7.0, "shear factor kappa_s [-]", lambda x: 0 < x <= 1, "in (0, 1]")
    damping: float = _nonneg("viscous damping constant c of Eq. (38) [1/s]", 0.01)


@dataclass(frozen=True)
class Borehole:
    radius: float = _pos("borehole radius R_bh = R_ext + gap [m]", 95e-3)


@dataclass(frozen=True)
class Environment:
    gravity: float = _nonneg("gravitational acceleration g, along -z [m/s^2]", 9.81)


@dataclass(frozen=True)
class Contact:
    stiffness_linear: float = _nonneg("k_FS1 of Eq. (17) [N/m]", 1e10)
    stiffness_cubic: float = _nonneg("k_FS2 of Eq. (17) [N/m^3]", 1e16)
    damping: float = _nonneg("c_FS of Eq. (17) [N s/m^4; N s^4/m^4 with damper_law = printed]", 1e6)
    friction: float = _nonneg("wall friction coefficient mu_FS [-]", 0.25)
    friction_model: str = key("coulomb", "'coulomb' (one force opposing the contact point's slip) or 'paper' "
                              "((18)-(19))", choices=("coulomb", "paper"))
    axial_friction_law: str = key("model", "the axial friction (18): 'consistent', 'printed', or 'model' "
                                  "(as model.laws says)", choices=("model", "consistent", "printed"))
    friction_torque_law: str = key("model", "the friction torque (19): 'consistent', 'printed', or 'model' "
                                   "(as model.laws says)", choices=("model", "consistent", "printed"))
    damper_law: str = key("consistent", "the damper of (17): 'consistent' (c |delta|^3 delta_dot), 'printed' or "
                          "'model'", choices=("model", "consistent", "printed"))
    sliding_velocity_scale: float = _pos("slip speed v_s of the regularised signs tanh(x / v_s) of the paper's "
                                         "friction laws (18)-(19) [m/s]", 1e-5)
    stick_stiffness: float = _pos("k_t, the tangential spring of a stuck contact (the Coulomb force below mu |F_n|) "
                                  "[N/m]", 1e8)
    culling: bool = key(True, "evaluate the wall law only where a vertex can reach the wall (exact)")
    static_friction: float = key(-1.0, "the wall's static friction factor (no lateral fields; it caps a run's step); "
                                 "-1: contact.friction [-]", lambda x: x == -1 or x >= 0, "-1 or >= 0")
    static_slip_speed: float = _nonneg("slip speed below which the static factor holds a sliding contact [m/s]", 0.0)
    normal_force: str = key("static", "the wall's normal force without lateral fields: 'static' (the soft string's) or "
                            "'dynamic' (tension)", choices=("static", "dynamic"))

    @property
    def static_factor(self) -> float:
        """The static friction factor: ``static_friction``, or ``friction`` where it is -1."""
        return self.friction if self.static_friction < 0 else self.static_friction

@dataclass(frozen=True)
class BitRock:
    limit_force: float = _nonneg("Gamma_BR of Eq. (20) [N]", 30e3)
    rate: float = _nonneg("alpha_BR of Eq. (20) [s/m]", 400.0)
    friction: float = key(0.4, "mu_BR of Eq. (21) [-]", lambda x: 0 <= x <= 1, "in [0, 1]")
    torque_law: str = key("model", "the bit torque (21): 'consistent', 'printed', or 'model' (as model.laws says)",
                          choices=("model", "consistent", "printed"))
    law: str = key("paper", "bit-rock law: 'paper' (velocity law (20)-(22)) or 'detournay' (cutting law)",
                   choices=("paper", "detournay"))
    bit_radius: float = _pos("'detournay': bit radius a [m]", 95e-3)
    blades: int = key(4, "'detournay': number of blades n [-]", _positive, ">= 1")
    specific_energy: float = _pos("'detournay': intrinsic specific energy epsilon of the rock [Pa]", 60e6)
    cutting_orientation: float = _pos("'detournay': orientation zeta of the cutting force [-]", 0.6)
    contact_strength: float = _nonneg("'detournay': contact strength sigma under the wear flats [Pa]", 60e6)
    wear_flat_length: float = _nonneg("'detournay': total wear-flat length l [m]", 1.2e-3)
    geometry_factor: float = _pos("'detournay': bit geometry factor gamma of the contact torque [-]", 1.0)
    contact_velocity: float = _pos("'detournay': velocity scale of the regularised wear-flat contact [m/s]", 1e-4)
    contact_depth: float = _pos("'detournay': depth of cut over which the wear-flat contact builds up [m]", 1e-5)
    backward_spin: str = key("free", "'detournay': a bit turned backwards: 'free' (the law resists it) or 'held' (a "
                             "damper holds it)", choices=("free", "held"))

@dataclass(frozen=True)
class Drive:
    axial_velocity: float = key(1.0 / 180.0, "V0, imposed axial velocity at x = 0 [m/s]")
    rotation_speed: float = key(2.0 * math.pi, "Omega, imposed rotation speed at x = 0 (the set speed of a "
                                "controller) [rad/s]")
    mode: str = key("velocity", "axial drive: 'velocity' (u(0) = V0 t) or 'hook_load' (push with drive.weight_on_bit)",
                    choices=("velocity", "hook_load"))
    weight_on_bit: float = _pos("set weight on bit: a hook-load drive's, and an on-bottom start's [N]", 25e3)
    start: str = key("auto", "initial state: 'off_bottom', 'on_bottom' (at weight_on_bit) or 'auto' (on bottom in a well)",
                     choices=("auto", "off_bottom", "on_bottom"))
    controller: str = key("stiff", "rotary drive: 'stiff' (theta_x(0) = Omega t), 'pi' or 'soft_torque' (top drive)",
                          choices=("stiff", "pi", "soft_torque"))
    top_drive_inertia: float = _pos("'pi', 'soft_torque': rotary inertia J_td of the top drive [kg m^2]", 500.0)
    proportional_gain: float = _nonneg("'pi': k_p of the speed controller [N m s/rad]", 5e4)
    integral_gain: float = _nonneg("'pi': k_i of the speed controller [N m/rad]", 5e5)
    torque_limit: float = _pos("'pi', 'soft_torque': largest motor torque |T_m| [N m]", 60e3)


@dataclass(frozen=True)
class Time:
    t_end: float = key(10.0, "end of the simulated interval [s]", lambda x: 1e-6 <= x <= 1e6, "in [1e-6, 1e6]")
    dt: float = key(-1.0, "time step; -1: 1/(time.band_steps f_max), f_max = f*_max c_L / L (maps: half an axial "
                    "transit) [s]",
                    lambda x: x == -1.0 or 1e-9 <= x <= 10.0, "in [1e-9, 10] (or -1 for the nominal step of "
                    "time.band_steps)")
    band_steps: float = key(8.0, "steps per period of f_max in the nominal step (2: the paper's 1/(2 f_max)) [-]",
                            lambda x: x >= 2.0, ">= 2 (Nyquist)")
    newmark_alpha: float = key(0.015, "alpha of Newmark's gamma = 1/2 + alpha, beta = (1/2 + gamma)^2 / 4 "
                               "(Section 4.3) [-]", lambda x: 0 <= x <= 0.5, "in [0, 0.5]")
    adaptive: bool = key(True, "refine the step where the local error estimate exceeds time.error_tolerance")
    error_tolerance: float = _pos("admissible local error per step of the displacements watched [m]", 1e-5)
    start_up_share: float = key(0.01, "share of time.error_tolerance admitted over the first nominal step [-]",
                                lambda x: 0 < x <= 1, "in (0, 1]")
    max_step_cuts: int = key(12, "the smallest step is dt / 2^max_step_cuts; a run needing less stops [-]",
                             lambda n: 0 <= n <= 40, "an integer in [0, 40]")
    max_steps: float = key(1e7, "most steps a run may need at its largest step (t_end / step) before it is refused [-]",
                           lambda x: x >= 1, ">= 1")


@dataclass(frozen=True)
class Solver:
    newton_tolerance: float = _pos("relative residual at which Newton stops [-]", 1e-8)
    newton_max_iterations: int = key(25, "Newton iterations before the step is cut [-]", _positive, ">= 1")
    tangent_reuse: int = key(20, "steps over which the assembled internal tangent is reused [-]", _positive, ">= 1")
    compiled_step: bool = key(True, "take a modal model's steps that keep their tangent in one compiled call")

@dataclass(frozen=True)
class Output:
    section: float = key(-1.0, "x of the section watched; -1: L/2, or 30 m above the bit of a string of sections [m]",
                         lambda x: x == -1.0 or x >= 0, ">= 0 (or -1 for L/2)")
    field_interval: float = _nonneg("simulated time between XDMF field snapshots; 0: no fields [s]", 0.1)
    von_mises: bool = key(True, "record the maximum von Mises stress over the string at every step (Eq. 100)")


#: The axial-torsional string's element length [m] where the scene leaves it to the program: the drill pipe above a
#: BHA's lateral length (``model.axial_torsional_element_length = 0``) and the stick-slip maps' string.  Its limit
#: cycle is within 0.7 % in severity and 0.2 % in period of finer meshes and of the exact wave-guide solution
#: (benchmarks/results/stick_slip.md, stick_slip_waves.md); the build-and-hold well's 150 m split within 0.7 % of its
#: 1.8 m mesh in period, severity, torque and rop (bha_split_10s_fine_pipe.md against bha_split_10s.md).
AXIAL_TORSIONAL_ELEMENT_LENGTH = 10.0


@dataclass(frozen=True)
class Model:
    supports: str = key("paper", "'paper': v, w, theta_y, theta_z fixed at x=0 and v, w at x=L; "
                        "'pinned': v, w fixed at both ends", choices=("paper", "pinned"))
    gravity: bool = key(True, "assemble the gravity load (52)")
    contact: bool = key(True, "evaluate wall impacts (16)-(19)")
    bit_rock: bool = key(True, "evaluate the bit-rock force and torque (20)-(22)")
    geometric_nonlinearity: bool = key(True, "assemble the geometric nonlinear force F_SE (49)")
    inertial_nonlinearity: bool = key(True, "assemble the inertial nonlinear force F_KE (48)")
    laws: str = key("consistent", "friction (18), (19) and bit torque (21): 'consistent' or 'printed'",
                    choices=("consistent", "printed"))
    kinematics: str = key("objective", "section kinematics of the strain energy: 'objective' or 'printed' (14)",
                          choices=("objective", "printed"))
    angular_velocity: str = key("consistent", "angular velocity in the kinetic energy (24): 'consistent' or "
                                "'printed' (13)", choices=("consistent", "printed"))
    torsion: str = key("st_venant", "torsional stiffness: 'st_venant' (G J) or 'printed' (kappa_s G J, Table 4's; "
                       "docs/errata.md)", choices=("st_venant", "printed"))
    lateral_length: float = key(-1.0, "length above the bit whose lateral fields are solved; -1: all, 0: none [m]",
                                lambda x: x == -1.0 or x >= 0, ">= 0 (or -1 for the whole string)")
    axial_torsional_element_length: float = key(
        0.0, "element length above the lateral length (u, theta_x); 0: auto "
        f"({AXIAL_TORSIONAL_ELEMENT_LENGTH:g} m above a BHA), -1: as below [m]",
        lambda x: x in (-1.0, 0.0) or x > 0, "> 0 (or 0 for auto, -1 for the lateral part's)")


def _positions(x) -> bool:
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in x)


@dataclass(frozen=True)
class Supports:
    """Lateral supports besides the ends of ``model.supports``."""

    stabilisers: tuple = key((), "x of pinned lateral supports (v = w = 0 at the nearest vertex) [m]",
                             _positions, "a list of numbers")


@dataclass(frozen=True)
class Modal:
    f_star_max: float = key(4.0, "upper end of the dimensionless band of analysis B = [0, f*_max], Eq. (95) [-]",
                            lambda x: 1.0 <= x <= 64.0, "in [1, 64] (the band holds the first axial and torsional "
                            "modes, near f* = 0.3-0.5)")
    state: str = key("auto", "modes about: 'unloaded', 'static' (tension, wall springs) or 'auto' (static in a well)",
                     choices=("auto", "unloaded", "static"))
    weight_on_bit: float = key(-1.0, "compression at the bit of that static state; -1: the run's start's [N]",
                               lambda x: x == -1.0 or x >= 0, ">= 0 (or -1 for the run's)")


@dataclass(frozen=True)
class Reduction:
    rule: str = key("auto", "reduced basis: 'auto', 'paper' (Table 4), 'band', 'count' or 'none' (full order)",
                    choices=("auto", "paper", "band", "count", "none"))
    flexural: float = _band_or_count("flexural f* upper bound ('band') or mode count ('count') [-]")
    torsional: float = _band_or_count("torsional f* upper bound ('band') or mode count ('count') [-]")
    axial: float = _band_or_count("axial f* upper bound ('band') or mode count ('count') [-]")
    enrich: bool = key(True, "add the static responses the basis misses; false: refuse such a basis")
    axial_companions: bool = key(False, "also add each load response's axial companion (static modal derivative)")
    hyper: bool = key(True, "evaluate the nonlinear forces (48)-(49) on an ECSW element sample")
    hyper_tolerance: float = key(1e-4, "relative error of the sampled projected nonlinear forces on the training "
                                 "states [-]", lambda x: 0 < x < 1, "in (0, 1)")
    hyper_training: float = _pos("simulated time of the training run of the element sample [s]", 0.1)
    out_of_band_damping: float = key(0.1, "damping ratio of the basis's directions above 2 f_max [-]",
                                     lambda x: 0 <= x <= 10, "in [0, 10]")
    guard_tolerance: float = key(0.03, "largest share of a load's static response the basis may miss [-]",
                                 lambda x: 0 < x <= 1, "in (0, 1]")
    rest_response_tolerance: float = key(0.01, "largest share of the responses at rest the basis may miss [-]",
                                         lambda x: 0 < x <= 1, "in (0, 1]")


@dataclass(frozen=True)
class Uncertainty:
    """Section 5 and 6.11; the means are the bit_rock values."""

    rate_dispersion: float = key(0.005, "dispersion sigma/m of alpha_BR, gamma law (81) [-]",
                                 _gamma_dispersion, "in [0, 1/sqrt(2)) (Eq. 81)")
    limit_force_dispersion: float = key(0.01, "dispersion sigma/m of Gamma_BR, gamma law (86) [-]",
                                        _gamma_dispersion, "in [0, 1/sqrt(2)) (Eq. 86)")
    friction_dispersion: float = _nonneg("dispersion sigma/m of mu_BR, beta law (90)-(92); with mean m it must "
                                         "be < sqrt((1 - m)/m) [-]", 0.005)
    seed: int = key(20150101, "base seed: realisation k draws from numpy default_rng([seed, k]) [-]",
                    _non_negative, ">= 0")
    output_interval: float = _pos("step of the common time grid of the Monte Carlo histories [s]", 0.01)


_GRID = "[min, max, n] with 0 <= min <= max and n a whole number in [1, 1000] (n = 1: min = max)"

#: Most realisations a study takes (per grid point for ``optimize``): each is a run and a file, and
#: the statistics (101) of 10^4 are converged far beyond what the bit-rock data support.
MAX_SAMPLES = 10_000


@dataclass(frozen=True)
class Optimize:
    """Sections 6.9, 6.10, 6.12: the operating window and the objective."""

    axial_velocity: tuple = key((1.0 / 360.0, 1.0 / 90.0, 4), "grid of V0: [min, max, points] [m/s]",
                                _grid_axis, _GRID)
    rotation_speed: tuple = key((1.5 * math.pi, 7.0 * math.pi / 3.0, 4), "grid of Omega: [min, max, points] "
                                "[rad/s]", _grid_axis, _GRID)
    objective: str = key("rop", "what to maximise: 'rop' (99) or 'efficiency' (96)", choices=("rop", "efficiency"))
    ultimate_strength: float = _pos("UTS of the von Mises constraint (100), (103) [Pa]", 650e6)
    samples: int = key(0, "realisations per grid point: 0 deterministic, N > 0 robust (102)-(104) [-]",
                       lambda n: 0 <= n <= MAX_SAMPLES, f"in [0, {MAX_SAMPLES}]")
    risk: float = key(0.1, "P_risk of the chance constraint (104) [-]", lambda x: 0 < x < 1, "in (0, 1)")


def _orders(x) -> bool:
    return len(x) >= 1 and _positions(x) and all(v > 0 for v in x)


@dataclass(frozen=True)
class Campbell:
    """Critical-speed analysis: the modes of the string linearised about a steady spin."""

    rotation_speed: tuple = key((0.0, 4.0 * math.pi, 25), "grid of the spin Omega: [min, max, points] [rad/s]",
                                _grid_axis, _GRID)
    modes: int = key(12, "lowest whirl frequencies followed at each speed [-]", lambda n: 1 <= n <= 500,
                     "in [1, 500]")
    state: str = key("straight", "linearised about: 'straight' (no gravity, no wall) or 'static' (on the wall)",
                     choices=("straight", "static"))
    axial_force: float = key(0.0, "axial compression at the bit before linearising [N]")
    weight_on_bit: bool = key(False, "compress with the steady bit force (20) at V0 instead of campbell.axial_force")
    excitation_orders: tuple = key((1.0, 3.0), "orders n of the excitation lines f = n Omega / 2 pi (1: unbalance, "
                                   "n: an n-bladed bit) [-]", _orders, "a non-empty list of numbers > 0")
    damping: bool = key(False, "include the dissipation (38): damped frequencies and damping ratios")


def _numbers(x) -> bool:
    return _positions(x)


@dataclass(frozen=True)
class Well:
    """The well from its survey (minimum curvature) and its hole sections; absent, the straight horizontal hole
    of ``beam.length`` and ``borehole.radius``."""

    survey: str = key("", "survey CSV file, relative to the scene file (given with --set: to the working directory)")
    md: tuple = key((), "measured depths of the survey stations, inline instead of a file [m]", _numbers,
                    "a list of numbers")
    inclination: tuple = key((), "inclination of each station from the vertical [deg]", _numbers, "a list of numbers")
    azimuth: tuple = key((), "azimuth of each station, clockwise from north [deg]", _numbers, "a list of numbers")
    hole_bottom: tuple = key((), "measured depth of the bottom of each hole section, increasing [m]", _numbers,
                             "a list of numbers")
    hole_radius: tuple = key((), "radius of each hole section [m]", _numbers, "a list of numbers")
    hole_cased: tuple = key((), "whether each hole section is cased (true) or open hole (false)",
                            lambda x: all(isinstance(v, bool) for v in x), "a list of true or false")


#: The keys of a string section (a table of ``string.sections``), with their meaning and unit.
SECTION_KEYS = {
    "name": "what the section is (drill pipe, heavy-weight, collar, stabiliser, ...)",
    "length": "length of the section [m]",
    "outer_radius": "outer radius of the pipe body [m]",
    "inner_radius": "inner radius [m]",
    "density": "steel density [kg/m^3] (default beam.density)",
    "young_modulus": "elastic modulus [Pa] (default beam.young_modulus)",
    "poisson_ratio": "Poisson ratio [-] (default beam.poisson_ratio)",
    "tool_joint_outer_radius": "outer radius of the tool joints, the contact radius where they touch the wall [m] "
                               "(0: none)",
    "tool_joint_inner_radius": "inner radius of the tool joints [m] (default the body's inner_radius)",
    "tool_joint_length": "length of one tool joint [m]",
    "tool_joint_spacing": "distance between tool joints, one joint of pipe [m]",
}



#: The material keys of a string section take the admissible values of their [beam] defaults.
SECTION_RANGES = {name: (Beam.__dataclass_fields__[name].metadata["check"],
                         Beam.__dataclass_fields__[name].metadata["admissible"])
                  for name in ("density", "young_modulus", "poisson_ratio")}


#: The diameters a section may give instead of its radii.
SECTION_DIAMETERS = {"outer_diameter": "outer_radius", "inner_diameter": "inner_radius",
                     "tool_joint_outer_diameter": "tool_joint_outer_radius",
                     "tool_joint_inner_diameter": "tool_joint_inner_radius"}


def _section_in_si(k: int, table, written: dict) -> Any:
    """A table of ``string.sections`` with its values written with units in SI (:func:`with_unit`) and its
    diameters as radii; anything else as it was (the checks of :func:`_string_sections` follow)."""
    if not isinstance(table, dict):
        return table
    where, out = f"string.sections[{k}]", {}
    for name, value in table.items():
        if isinstance(value, str) and name != "name":
            written[f"{where}.{name}"] = value
            meaning = SECTION_KEYS.get(name) or SECTION_KEYS.get(SECTION_DIAMETERS.get(name, ""), "")
            value = with_unit(f"{where}.{name}", value, meaning)
        if name in SECTION_DIAMETERS:
            radius = SECTION_DIAMETERS[name]
            if radius in table:
                raise SceneError(f"{where}: {name} and {radius} are not admissible together: give one")
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise SceneError(f"{where}.{name} = {value!r} is not admissible: must be a number >= 0")
            name, value = radius, 0.5 * value
        out[name] = value
    return out


def _string_sections(sections) -> bool:
    """Each section a table of SECTION_KEYS with positive lengths and radii; raises SceneError naming the section
    and the key."""
    for k, section in enumerate(sections, start=1):
        where = f"string.sections[{k}]"
        if not isinstance(section, dict):
            raise SceneError(f"{where} = {section!r} is not admissible: each section is a table of keys "
                             f"({', '.join(SECTION_KEYS)})")
        unknown = [name for name in section if name not in SECTION_KEYS]
        if unknown:
            raise SceneError(f"unknown key {where}.{unknown[0]}; known keys: {', '.join(SECTION_KEYS)}")
        for name in ("length", "outer_radius", "inner_radius"):
            if name not in section:
                raise SceneError(f"{where} has no {name}: give {SECTION_KEYS[name]}")
        for name, value in section.items():
            if name == "name":
                continue
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value < 0:
                raise SceneError(f"{where}.{name} = {value!r} is not admissible: must be a number >= 0")
            if name in SECTION_RANGES and not SECTION_RANGES[name][0](value):
                raise SceneError(f"{where}.{name} = {value!r} is not admissible: must be {SECTION_RANGES[name][1]}")
        if section["length"] <= 0 or section["outer_radius"] <= 0:
            raise SceneError(f"{where}: length and outer_radius must be > 0")
        if section["inner_radius"] >= section["outer_radius"]:
            raise SceneError(f"{where}.inner_radius = {section['inner_radius']!r} is not admissible: must be < "
                             f"outer_radius = {section['outer_radius']!r}")
        joint = section.get("tool_joint_outer_radius", 0.0)
        if joint and joint < section["outer_radius"]:
            raise SceneError(f"{where}.tool_joint_outer_radius = {joint!r} is not admissible: must be >= "
                             f"outer_radius = {section['outer_radius']!r} (or 0 for none)")
        if joint and not (section.get("tool_joint_length", 0) > 0 and section.get("tool_joint_spacing", 0) > 0):
            raise SceneError(f"{where}: a tool joint needs tool_joint_length > 0 and tool_joint_spacing > 0")
        if joint and section["tool_joint_length"] > section["tool_joint_spacing"]:
            raise SceneError(f"{where}.tool_joint_length = {section['tool_joint_length']!r} is not admissible: must be "
                             f"<= tool_joint_spacing = {section['tool_joint_spacing']!r} (a joint is part of its pipe)")
        joint_inner = section.get("tool_joint_inner_radius")
        if joint_inner is not None and not (joint and joint_inner < joint):
            raise SceneError(f"{where}.tool_joint_inner_radius = {joint_inner!r} is not admissible: needs a "
                             f"tool_joint_outer_radius above it")
    return True


@dataclass(frozen=True)
class String:
    """The drillstring from the bit up; absent, the one pipe of [beam]."""

    sections: tuple = key((), "the string's sections from the bit up: tables of name, length, outer_radius, "
                          "inner_radius, ...", _string_sections, "a list of tables")


@dataclass(frozen=True)
class Fluid:
    """The drilling fluid: buoyancy of the string (inside and outside); in the FE model also the lateral added
    mass and a viscous lateral damping."""

    density: float = _nonneg("density of the mud in the annulus, 0 for air [kg/m^3]", 0.0)
    inner_density: float = key(-1.0, "density of the fluid inside the pipe, -1 for the mud's [kg/m^3]",
                               lambda x: x == -1.0 or x >= 0, ">= 0 (or -1 for fluid.density)")
    added_mass_coefficient: float = key(-1.0, "lateral added mass of the mud over rho_m pi R^2, -1 for the annulus' "
                                        "[-]", lambda x: x == -1.0 or x >= 0, ">= 0 (or -1 for the confined annulus)")
    lateral_damping: float = _nonneg("the mud's viscous force per length and lateral velocity [N s/m^2]", 0.0)


_OPERATIONS = ("rotating_on_bottom", "rotating_off_bottom", "sliding", "tripping_in", "tripping_out")


@dataclass(frozen=True)
class TorqueDrag:
    """The soft-string torque-and-drag study (``fenics-drill torque-drag``)."""

    operations: tuple = key(_OPERATIONS, "operations to compute", lambda x: all(o in _OPERATIONS for o in x),
                            " and ".join(_OPERATIONS))
    friction_cased: float = _nonneg("friction coefficient in cased hole [-]", 0.25)
    friction_open: float = _nonneg("friction coefficient in open hole [-]", 0.30)
    weight_on_bit: float = key(-1.0, "weight on bit while drilling; -1: drive.weight_on_bit [N]",
                               lambda x: x == -1.0 or x >= 0, ">= 0 (or -1 for the drive's)")
    torque_on_bit: float = _nonneg("torque on bit while drilling on bottom [N m]", 5e3)
    rotation_speed: float = key(-1.0, "rotation speed while rotating; -1: drive.rotation_speed [rad/s]",
                                lambda x: x == -1.0 or x >= 0, ">= 0 (or -1 for the drive's)")
    trip_speed: float = _pos("axial speed while tripping [m/s]", 0.3)
    rate_of_penetration: float = key(-1.0, "axial speed while drilling; -1: drive.axial_velocity [m/s]",
                                     lambda x: x == -1.0 or x >= 0, ">= 0 (or -1 for the drive's)")
    element_length: float = _pos("length of the soft string's elements [m]", 10.0)


def _friction_factors(x) -> bool:
    return len(x) >= 1 and _positions(x) and all(0 <= v <= 1 for v in x)


def _friction_pairs(x) -> bool:
    return all(isinstance(p, (list, tuple)) and len(p) == 2 and _friction_factors(p) for p in x)


#: The operations of a broomstick chart: the soft string's, named as the rig reads them.
_CHART_OPERATIONS = ("tripping_in", "tripping_out", "rotating_off_bottom", "rotating_on_bottom", "sliding")


@dataclass(frozen=True)
class Broomstick:
    """Hook load and surface torque against bit depth (``fenics-drill broomstick``), and the rig that reads them."""

    depth_step: float = key(28.5, "bit depths every this many metres, a stand of three joints [m]",
                            lambda x: x > 0, "> 0")
    operations: tuple = key(_CHART_OPERATIONS, "operations drawn", lambda x: len(x) >= 1 and all(
        o in _CHART_OPERATIONS for o in x), "a non-empty list of " + ", ".join(_CHART_OPERATIONS))
    friction_cased: tuple = key((0.15, 0.2, 0.25, 0.3), "friction factors in cased hole [-]", _friction_factors,
                                "a non-empty list of numbers in [0, 1]")
    friction_open: tuple = key((0.2, 0.25, 0.3, 0.35), "friction factors in open hole [-]", _friction_factors,
                               "a non-empty list of numbers in [0, 1]")
    friction_pairs: tuple = key((), "(cased, open) pairs instead of every cased factor with every open one [-]",
                                _friction_pairs, "a list of [cased, open] pairs of numbers in [0, 1]")
    block_weight: float = _nonneg("weight of the travelling equipment, added to every hook load [N]", 0.0)
    lines: int = key(0, "lines strung between crown and block; 0: the weight indicator reads the hook load [-]",
                     lambda n: 0 <= n <= 24, "an integer in [0, 24]")
    sheave_efficiency: float = key(1.0, "efficiency of each sheave (with lines > 0) [-]", lambda x: 0.5 <= x <= 1.0,
                                   "in [0.5, 1]")
    hook_load_limit: float = key(-1.0, "the rig's hook-load limit, drawn as a line; -1: none [N]",
                                 lambda x: x == -1.0 or x > 0, "> 0 (or -1 for none)")
    torque_limit: float = key(-1.0, "the rig's torque limit, drawn as a line; -1: none [N m]",
                              lambda x: x == -1.0 or x > 0, "> 0 (or -1 for none)")
    yield_strength: float = _pos("minimum yield strength of the pipe, for the weight that yields it [Pa]", 931e6)


def _bounds(x) -> bool:
    return len(x) == 2 and _friction_factors(x) and x[0] <= x[1]


@dataclass(frozen=True)
class Risk:
    """Torque and drag under uncertainty (``fenics-drill torque-drag --samples N``): the friction factors' laws, the
    survey's errors and its tortuosity, drawn for each realisation k from numpy default_rng([seed, k])."""

    friction_cased: tuple = key((0.15, 0.35), "bounds of the cased-hole friction factor [-]", _bounds,
                                "[low, high] with 0 <= low <= high <= 1")
    friction_open: tuple = key((0.2, 0.4), "bounds of the open-hole friction factor [-]", _bounds,
                               "[low, high] with 0 <= low <= high <= 1")
    friction_cased_mean: float = key(-1.0, "mean of the cased factor; -1: none (uniform on its bounds) [-]",
                                     lambda x: x == -1.0 or 0 <= x <= 1, "in [0, 1] (or -1 for none)")
    friction_open_mean: float = key(-1.0, "mean of the open-hole factor; -1: none (uniform on its bounds) [-]",
                                    lambda x: x == -1.0 or 0 <= x <= 1, "in [0, 1] (or -1 for none)")
    friction_cased_dispersion: float = key(-1.0, "dispersion (std / mean) of the cased factor; -1: none [-]",
                                           lambda x: x == -1.0 or x > 0, "> 0 (or -1 for none)")
    friction_open_dispersion: float = key(-1.0, "dispersion (std / mean) of the open-hole factor; -1: none [-]",
                                          lambda x: x == -1.0 or x > 0, "> 0 (or -1 for none)")
    survey_error: str = key("none", "'none', or the ISCWSA error model moving the stations, e.g. 'ISCWSA MWD Rev5.11'")
    magnetic_field: tuple = key((50e-6, 72.0, 0.0), "total field [T], dip and declination [deg] of a magnetic model",
                                lambda x: len(x) == 3 and _positions(x) and x[0] > 0,
                                "[total > 0, dip, declination]")
    tortuosity_amplitude: float = _nonneg("amplitude of the sine on inclination and azimuth [deg]", 0.0)
    tortuosity_period: float = _pos("period of the tortuosity along measured depth [m]", 30.0)
    seed: int = key(20261202, "base seed: realisation k draws from numpy default_rng([seed, k]) [-]", _non_negative,
                    ">= 0")


def _controllers(x) -> bool:
    return len(x) >= 1 and len(set(x)) == len(x) and all(c in _CONTROLLERS for c in x)


_CONTROLLERS = ("stiff", "pi", "soft_torque")


@dataclass(frozen=True)
class StickSlipMap:
    """Stick-slip over weight on bit x rotation speed (``fenics-drill stick-slip-map``): each point the scene's
    axial-torsional string run to its limit cycle or steady rotation, or to ``time_limit``."""

    weight_on_bit: tuple = key((20e3, 80e3, 4), "grid of the weight on bit: [min, max, points] [N]", _grid_axis, _GRID)
    rotation_speed: tuple = key((2.0 * math.pi, 8.0 * math.pi, 4), "grid of the rotation speed: [min, max, points] "
                                "[rad/s]", _grid_axis, _GRID)
    controllers: tuple = key(("stiff",), "the rotary drives mapped (drive.controller's choices)", _controllers,
                             "a non-empty list of distinct names among " + ", ".join(_CONTROLLERS))
    time_limit: float = _pos("longest drilling time run at a point before its cycle has settled [s]", 200.0)
    element_length: float = _pos("the axial-torsional string's element length (beam.elements is the lateral "
                                 "fields') [m]", AXIAL_TORSIONAL_ELEMENT_LENGTH)
    mesh_viscosity: float = _nonneg("zeta of a viscosity zeta h c / 2 on the torsional wave, damping the mesh's "
                                    "shortest (1: upwind) [-]", 0.0)
    step_check: bool = key(False, "also run each point at half its step and flag a cycle that moves (3 times the cost)")


@dataclass(frozen=True)
class Scene:
    """A validated scene: one typed, immutable section per TOML table."""

    beam: Beam = field(default_factory=Beam)
    borehole: Borehole = field(default_factory=Borehole)
    environment: Environment = field(default_factory=Environment)
    contact: Contact = field(default_factory=Contact)
    bit_rock: BitRock = field(default_factory=BitRock)
    drive: Drive = field(default_factory=Drive)
    time: Time = field(default_factory=Time)
    solver: Solver = field(default_factory=Solver)
    output: Output = field(default_factory=Output)
    model: Model = field(default_factory=Model)
    supports: Supports = field(default_factory=Supports)
    modal: Modal = field(default_factory=Modal)
    reduction: Reduction = field(default_factory=Reduction)
    uncertainty: Uncertainty = field(default_factory=Uncertainty)
    optimize: Optimize = field(default_factory=Optimize)
    campbell: Campbell = field(default_factory=Campbell)
    well: Well = field(default_factory=Well)
    string: String = field(default_factory=String)
    fluid: Fluid = field(default_factory=Fluid)
    torque_drag: TorqueDrag = field(default_factory=TorqueDrag)
    broomstick: Broomstick = field(default_factory=Broomstick)
    risk: Risk = field(default_factory=Risk)
    stick_slip_map: StickSlipMap = field(default_factory=StickSlipMap)

    def to_dict(self) -> dict[str, dict[str, Any]]:
        """The scene as nested plain values (what summary files and study directories store)."""
        return {s.name: dataclasses.asdict(getattr(self, s.name)) for s in dataclasses.fields(self)}

    def with_changes(self, **sections: dict[str, Any]) -> "Scene":
        """A new validated scene with some keys changed: ``scene.with_changes(drive={"rotation_speed": 5.0})``."""
        raw = self.to_dict()
        if getattr(self, "watched_by_default", False):  # output.section = -1 follows the changed string
            raw["output"]["section"] = -1.0
        for section, entries in sections.items():
            if not isinstance(entries, dict):
                raise SceneError(f"with_changes({section}={entries!r}): give the keys of [{section}] as a dict, e.g. "
                                 f"with_changes({section}={{'key': value}})")
            raw.setdefault(section, {}).update(entries)
        return validate(raw)

    @property
    def set_points(self) -> dict:
        """The operation's set points, one place for ``torque-drag`` and ``run``: the weight on bit [N], rotation
        speed [rad/s] and rate of penetration [m/s] of [drive], unless [torque_drag] gives its own (-1: the drive's)."""
        td, drive = self.torque_drag, self.drive
        return {"weight_on_bit": td.weight_on_bit if td.weight_on_bit >= 0 else drive.weight_on_bit,
                "rotation_speed": td.rotation_speed if td.rotation_speed >= 0 else abs(drive.rotation_speed),
                "rate_of_penetration": td.rate_of_penetration if td.rate_of_penetration >= 0
                else abs(drive.axial_velocity)}

    @property
    def modal_weight_on_bit(self) -> float:
        """The weight on bit of the static state the modes are linearised about [N]: ``modal.weight_on_bit``, or
        (-1) the run's: ``drive.weight_on_bit`` for a run that starts on bottom, 0 off bottom."""
        if self.modal.weight_on_bit >= 0:
            return self.modal.weight_on_bit
        return self.drive.weight_on_bit if self.starts_on_bottom else 0.0

    @property
    def starts_on_bottom(self) -> bool:
        """Whether a run starts from the static state with ``drive.weight_on_bit`` on the bit: ``drive.start``, where
        'auto' is on bottom in a well, whatever drives the top (the paper's horizontal string starts off bottom)."""
        if self.drive.start != "auto":
            return self.drive.start == "on_bottom"
        return bool(self.well.survey or self.well.md)

    def law(self, choice: str) -> str:
        """'consistent' or 'printed' for a per-law switch (``contact.axial_friction_law``, ...)."""
        return self.model.laws if choice == "model" else choice

    @property
    def string_length(self) -> float:
        """The string's length [m]: its sections' (``string.sections``), or ``beam.length``."""
        sections = self.string.sections
        return float(sum(section["length"] for section in sections)) if sections else self.beam.length

    @property
    def axial_torsional_element_length(self) -> float:
        """The elements' length above the lateral length [m] (``model.axial_torsional_element_length``), or -1 where
        they are the lateral part's: 'auto' (0) takes :data:`AXIAL_TORSIONAL_ELEMENT_LENGTH` above a BHA's lateral
        length, or the lateral part's where those are longer (it never refines); over a whole axial-torsional string
        (``model.lateral_length = 0``) it keeps ``beam.elements``, whose bit and collars a 10 m mesh would coarsen (the
        VBH well's rop over 5-10 s of its start-up moves by 9 % there); a whole string (-1) has none."""
        chosen, lateral = self.model.axial_torsional_element_length, self.model.lateral_length
        if lateral < 0 or chosen == -1.0:
            return -1.0
        if chosen > 0:
            return chosen
        if lateral == 0:
            return -1.0
        lateral_part = self.string_length / self.beam.elements
        return AXIAL_TORSIONAL_ELEMENT_LENGTH if lateral_part < AXIAL_TORSIONAL_ELEMENT_LENGTH else -1.0

    @property
    def hole_at_bit(self) -> tuple[float, str]:
        """(radius [m], the key that gives it) of the hole the bit drills: the well's hole section at the string's
        bottom when the well gives its hole (``well.hole_radius``), else ``borehole.radius``.  The paper's bit
        torque (21) takes it as its arm, R_bh."""
        well = self.well
        if not (well.hole_radius and well.hole_bottom):
            return self.borehole.radius, "borehole.radius"
        bottoms = list(well.hole_bottom)
        k = next((i for i, b in enumerate(bottoms) if b >= self.string_length - DEPTH_ROUND_OFF), len(bottoms) - 1)
        k = min(k, len(well.hole_radius) - 1)
        return well.hole_radius[k], f"well.hole_radius[{k + 1}] (the hole at the bit)"

    @property
    def beam_properties(self) -> BeamProperties:
        """The parameter object the forms take (gravity 0 when ``model.gravity`` is off); its length is the
        string's (:attr:`string_length`)."""
        b = self.beam
        return BeamProperties(
            length=self.string_length, outer_radius=b.outer_radius, inner_radius=b.inner_radius, density=b.density,
            young_modulus=b.young_modulus, poisson_ratio=b.poisson_ratio, shear_factor=b.shear_factor,
            damping=b.damping, gravity=self.environment.gravity * self.buoyancy_factor if self.model.gravity else 0.0,
            lateral_added_mass=self.lateral_added_mass, lateral_fluid_damping=self.fluid.lateral_damping,
            torsion=self.model.torsion,
        )

    @property
    def inner_fluid_density(self) -> float:
        """The density of the fluid inside the pipe [kg/m^3] (``fluid.inner_density``, -1: the mud's)."""
        return self.fluid.density if self.fluid.inner_density == -1.0 else self.fluid.inner_density

    @property
    def lateral_added_mass(self) -> float:
        """The fluids' mass per length that moves with the pipe's lateral motion [kg/m]: the fluid inside,
        rho_i pi r^2, and the mud outside, C_a rho_m pi R^2, with C_a = (R_h^2 + R^2) / (R_h^2 - R^2) of a
        cylinder in a concentric annulus of radius R_h (potential flow; Chen, Wambsganss & Jendrzejczyk 1976)
        unless ``fluid.added_mass_coefficient`` gives it."""
        return self.lateral_added_mass_of(self.beam.outer_radius, self.beam.inner_radius, self.borehole.radius)

    def lateral_added_mass_of(self, outer_radius, inner_radius, hole_radius):
        """:attr:`lateral_added_mass` of a pipe of these radii in a hole of ``hole_radius`` (numbers or arrays)."""
        fluid = self.fluid
        hole2, pipe2 = hole_radius**2, outer_radius**2
        c_a = (hole2 + pipe2) / (hole2 - pipe2) if fluid.added_mass_coefficient == -1.0 else fluid.added_mass_coefficient
        return math.pi * (self.inner_fluid_density * inner_radius**2 + c_a * fluid.density * pipe2)

    @property
    def buoyancy_factor(self) -> float:
        """The pipe's weight in the fluids over its weight in air: 1 + (rho_i A_i - rho_o A_o) / (rho_s A) (Archimedes
        on the fluid outside and inside; 1 in air).  The FE model's gravity load (52) is scaled by it."""
        b = self.beam
        steel = b.outer_radius**2 - b.inner_radius**2
        return 1.0 + (self.inner_fluid_density * b.inner_radius**2 - self.fluid.density * b.outer_radius**2) / (
            b.density * steel)


#: The printed laws (18), (19), (21) are the consistent ones with mu replaced by -mu, since F_n, F_BR <= 0
#: (docs/errata.md): the sign each choice gives mu.
LAW_SIGN = {"consistent": 1.0, "printed": -1.0}

#: section name -> its dataclass, in the order of the TOML file.
SECTIONS: dict[str, type] = {s.name: s.default_factory for s in dataclasses.fields(Scene)}


def section_keys(section: str) -> dict[str, dataclasses.Field]:
    """The keys of one section: name -> dataclass field (``metadata`` holds doc, check, admissible, choices)."""
    return {f.name: f for f in dataclasses.fields(SECTIONS[section])}


def _describe_kind(kind) -> str:
    names = {float: "a number", int: "an integer", bool: "true or false", str: "a string", tuple: "an array"}
    return names.get(kind, getattr(kind, "__name__", str(kind)))


def with_unit(name: str, value: str, meaning: str) -> float:
    """A value written with its unit ("120 rpm") in the SI unit of the key's ``meaning`` (:mod:`fenics_drill.units`),
    or a SceneError naming the key."""
    from fenics_drill.units import UnitError, read_number, read_quantity, si_unit

    unit = si_unit(meaning)
    try:
        return read_number(value) if unit is None else read_quantity(value, unit)
    except UnitError as err:
        reason = "expected a number (this key takes no unit)" if unit is None else err
        raise SceneError(f"{name} = {value!r} is not admissible: {reason}") from None


def _coerce(name: str, value: Any, kind: type, meta) -> Any:
    """Return ``value`` converted to the key's type (a number written with its unit to the key's SI unit), or raise
    SceneError."""
    bad = SceneError(f"{name} = {value!r} is not admissible: expected {_describe_kind(kind)}")
    if kind is float and isinstance(value, str):
        value = with_unit(name, value, meta["doc"])
    if kind is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise bad
        value = float(value)
        if not math.isfinite(value):
            raise SceneError(f"{name} = {value!r} is not admissible: expected a finite number")
    elif kind is int:
        if isinstance(value, bool):
            raise bad
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        if not isinstance(value, int):
            raise bad
    elif kind is tuple:
        if not isinstance(value, (list, tuple)):
            raise bad
        if name != "string.sections" and re.search(r"\[[^\[\]]+\]", meta["doc"]):
            # a list of quantities may write each with its unit, e.g. ["12.25 in", ...]
            value = [with_unit(f"{name}[{k}]", v, meta["doc"]) if isinstance(v, str) else v
                     for k, v in enumerate(value, start=1)]
        value = tuple(value)
    elif not isinstance(value, kind):
        raise bad
    if meta["choices"] is not None and value not in meta["choices"]:
        raise SceneError(f"{name} = {value!r} is not admissible: expected one of {', '.join(meta['choices'])}")
    if meta["check"] is not None and not meta["check"](value):
        shown = list(value) if isinstance(value, tuple) else value
        raise SceneError(f"{name} = {shown!r} is not admissible: must be {meta['admissible']}")
    return value


def _check_relations(scene: Scene) -> Scene:
    """Checks between keys; resolves ``output.section = -1`` to L/2."""
    beam, hole = scene.beam, scene.borehole
    unused = unused_keys(scene)  # a well's own string and hole: the one pipe and hole of [beam], [borehole] unused
    if "beam.outer_radius" not in unused:
        if beam.inner_radius >= beam.outer_radius:
            raise SceneError(f"beam.inner_radius = {beam.inner_radius!r} is not admissible: "
                             f"must be < beam.outer_radius = {beam.outer_radius!r}")
        if beam.length < 10.0 * beam.outer_radius:
            raise SceneError(f"beam.length = {beam.length!r} is not admissible: must be >= 10 beam.outer_radius = "
                             f"{10.0 * beam.outer_radius:g} m (a beam model needs a slender string)")
    if not unused and hole.radius <= beam.outer_radius:
        raise SceneError(f"borehole.radius = {hole.radius!r} is not admissible: must be > beam.outer_radius = "
                         f"{beam.outer_radius!r} (the string must fit in the hole)")
    length = scene.string_length
    if scene.output.section == -1.0:  # the middle of the paper's string; the BHA of a string of sections
        watched = length - min(BHA_WATCH, 0.5 * length) if scene.string.sections else 0.5 * length
        scene = dataclasses.replace(scene, output=dataclasses.replace(scene.output, section=watched))
    if scene.output.section > length:
        what = "the string's length" if scene.string.sections else "beam.length"
        raise SceneError(f"output.section = {scene.output.section!r} is not admissible: "
                         f"must be in [0, {what} = {length!r}]")
    _check_stabilisers(scene)
    _check_well_keys(scene)
    if scene.model.lateral_length > length * (1 + 1e-12):
        raise SceneError(f"model.lateral_length = {scene.model.lateral_length!r} is not admissible: must be <= the "
                         f"string's length, {length!r} m (or -1 for the whole string)")
    if scene.model.axial_torsional_element_length > 0 and scene.model.lateral_length < 0:
        raise SceneError(f"model.axial_torsional_element_length = {scene.model.axial_torsional_element_length!r} is "
                         "not admissible with model.lateral_length = -1: the whole string carries its lateral fields "
                         "(set model.lateral_length to the length above the bit that needs them, or 0)")
    contact = scene.contact
    if contact.normal_force == "dynamic" and scene.model.lateral_length < 0:
        raise SceneError("contact.normal_force = 'dynamic' is not admissible with model.lateral_length = -1: it presses "
                         "the wall where no lateral fields are solved, and the whole string carries them here (set "
                         "model.lateral_length to the length above the bit that needs them, or 0)")
    if contact.static_friction >= 0:
        if contact.static_friction < contact.friction:
            raise SceneError(f"contact.static_friction = {contact.static_friction!r} is not admissible: must be >= "
                             f"contact.friction = {contact.friction!r} (the static factor holds a stuck contact)")
        if contact.static_friction != contact.friction and scene.model.lateral_length != 0:
            raise SceneError(f"contact.static_friction = {contact.static_friction!r} is not admissible with "
                             f"model.lateral_length = {scene.model.lateral_length!r}: the lateral wall has one "
                             "friction factor, contact.friction; the static one acts on the axial-torsional string "
                             "(model.lateral_length = 0)")
    if contact.friction_model == "coulomb":
        for name in ("axial_friction_law", "friction_torque_law"):
            if scene.law(getattr(contact, name)) == "printed":
                raise SceneError(f"contact.{name} = 'printed' (through model.laws or itself) is not admissible with "
                                 "contact.friction_model = 'coulomb': the printed signs belong to the paper's laws "
                                 "(18)-(19); set contact.friction_model = 'paper'")
    if scene.model.contact and scene.contact.stiffness_linear == 0:
        raise SceneError("contact.stiffness_linear = 0.0 is not admissible with model.contact = true: without "
                         "its linear spring the wall lets the string through (k_FS2 delta^3 is negligible at small "
                         "penetrations); give k_FS1 > 0, or set model.contact = false to leave the wall out")
    bit, drive = scene.bit_rock, scene.drive
    if bit.law == "detournay":
        hole_at_bit, which = scene.hole_at_bit
        if bit.bit_radius > hole_at_bit * (1 + 1e-9):
            raise SceneError(f"bit_rock.bit_radius = {bit.bit_radius!r} is not admissible: must be <= {which} = "
                             f"{hole_at_bit!r} (the bit cuts the hole)")
        _check_bit_passes_its_bha(scene)
    if drive.mode == "hook_load":
        if not scene.model.bit_rock:
            raise SceneError("drive.mode = 'hook_load' is not admissible with model.bit_rock = false: nothing "
                             "would hold the pushed string")
        if bit.law == "paper" and drive.weight_on_bit >= bit.limit_force:
            raise SceneError(f"drive.weight_on_bit = {drive.weight_on_bit!r} is not admissible with "
                             f"bit_rock.law = 'paper': must be < bit_rock.limit_force = {bit.limit_force!r}, the "
                             "largest force the law (20) can hold (beyond it the bit accelerates without bound)")
    red = scene.reduction
    if red.rule in ("band", "count"):
        for family in ("flexural", "torsional", "axial"):
            value = getattr(red, family)
            if value < 0:
                raise SceneError(f"reduction.{family} = {value!r} is not admissible: "
                                 f"reduction.rule = '{red.rule}' needs a value >= 0 for every family")
            if red.rule == "count" and not float(value).is_integer():
                raise SceneError(f"reduction.{family} = {value!r} is not admissible: "
                                 "reduction.rule = 'count' needs a whole number of modes")
    return scene


def check_history_grid(scene: Scene) -> None:
    """For the studies that keep histories on the grid of uncertainty.output_interval (``mc``, ``optimize``): a
    grid of at most MAX_GRID_POINTS points, refused before anything is allocated."""
    grid = scene.time.t_end / scene.uncertainty.output_interval
    if grid > MAX_GRID_POINTS:
        raise SceneError(f"uncertainty.output_interval = {scene.uncertainty.output_interval!r} is not admissible with "
                         f"time.t_end = {scene.time.t_end!r}: the histories' grid would have {grid:.3g} points (at "
                         f"most {MAX_GRID_POINTS:g}); use an interval >= {scene.time.t_end / MAX_GRID_POINTS:.3g} s")


#: The heaviest drilling fluid admitted [kg/m^3]: above the densest muds and brines (about 2.6 SG).
MAX_FLUID_DENSITY = 3000.0


#: How far above the bit a string of sections is watched by default (output.section = -1): in its BHA [m].
BHA_WATCH = 30.0


def _check_well_keys(scene: Scene) -> None:
    """The well's inline stations come as three lists with the depths; the fluids are fluids a string sinks in."""
    well = scene.well
    if (well.inclination or well.azimuth) and not well.md:
        raise SceneError("well.inclination and well.azimuth are not admissible without well.md: give the stations' "
                         "measured depths too (or a survey file in well.survey)")
    fluid = scene.fluid
    for name, value in (("fluid.density", fluid.density), ("fluid.inner_density", scene.inner_fluid_density)):
        if value > MAX_FLUID_DENSITY:
            raise SceneError(f"{name} = {value!r} is not admissible: must be <= {MAX_FLUID_DENSITY:g} kg/m^3 (the "
                             "densest muds are about 2600 kg/m^3, 21.7 ppg)")
    if not scene.torque_drag.operations:
        raise SceneError("torque_drag.operations = [] is not admissible: name at least one operation")


def _check_bit_passes_its_bha(scene: Scene) -> None:
    """The bit drills the hole its BHA runs in: a bit smaller than the largest outer radius (body or tool joint,
    stabiliser blade) of a section in the hole section at the bit is refused, with the numbers.  (A section above
    an under-reamer lies in a larger hole section of its own, and is not compared.)"""
    sections, bit = scene.string.sections, scene.bit_rock.bit_radius
    if not sections:
        return
    length = scene.string_length
    bottoms = sorted(scene.well.hole_bottom)
    top_of_bit_hole = max((b for b in bottoms if b < length - DEPTH_ROUND_OFF), default=0.0)
    below = 0.0  # the depth of a section's bottom above the bit
    for k, section in enumerate(sections, start=1):
        radius = max(section["outer_radius"], section.get("tool_joint_outer_radius", 0.0))
        if length - below <= top_of_bit_hole:
            break
        if bit < radius * (1 - 1e-9):
            name = f" ({section['name']})" if section.get("name") else ""
            raise SceneError(f"bit_rock.bit_radius = {bit!r} is not admissible: the bit must pass its BHA, and "
                             f"string.sections[{k}]{name} is {radius!r} m in radius ({2 * radius / 0.0254:.4g} in "
                             f"across) in the hole the bit drills; give the bit's radius (an 8 1/2 in bit: "
                             "bit_radius = \"4 1/4 in\")")
        below += section["length"]


def _check_stabilisers(scene: Scene) -> None:
    """Each stabiliser inside the string, on a vertex of its own that no end support holds (a stabiliser holds the
    vertex nearest its position: one that snaps onto a held end, or onto another's vertex, would do nothing)."""
    beam, positions = scene.beam, list(scene.supports.stabilisers)
    length, what = scene.string_length, ("the string's length" if scene.string.sections else "beam.length")
    h = length / beam.elements
    taken = {}
    for x in positions:
        if not 0 < x < length:
            raise SceneError(f"supports.stabilisers = {positions!r} is not admissible: every position must be in "
                             f"(0, {what} = {length!r})")
        vertex = round(x / h)
        if vertex in (0, beam.elements):
            raise SceneError(f"supports.stabilisers: x = {x!r} m is not admissible: it snaps onto the end vertex at "
                             f"x = {vertex * h:g} m, which the supports hold already; place it at least h/2 = "
                             f"{h / 2:g} m from the ends, or refine beam.elements")
        if vertex in taken:
            raise SceneError(f"supports.stabilisers: x = {taken[vertex]!r} m and x = {x!r} m are not admissible "
                             f"together: both snap onto the vertex at x = {vertex * h:g} m; refine beam.elements "
                             "or drop one")
        taken[vertex] = x


def validate(raw: dict[str, Any]) -> Scene:
    """Check every key of ``raw`` (sections of keys) and its relations; missing keys take their defaults."""
    sections, written = {}, {}
    for section, entries in raw.items():
        if section not in SECTIONS:
            raise SceneError(f"unknown section [{section}]; known sections: {', '.join(SECTIONS)}")
        if not isinstance(entries, dict):
            raise SceneError(f"[{section}] must be a table of keys, got {entries!r}")
        keys, kinds = section_keys(section), get_type_hints(SECTIONS[section])
        values = {}
        for name, value in entries.items():
            if name not in keys:
                raise SceneError(f"unknown key {section}.{name}; known keys of [{section}]: {', '.join(keys)}")
            if isinstance(value, str) and kinds[name] is float or (
                    isinstance(value, (list, tuple)) and any(isinstance(v, str) for v in value) and name != "sections"):
                written[f"{section}.{name}"] = value
            try:
                if section == "string" and name == "sections" and isinstance(value, (list, tuple)):
                    value = [_section_in_si(k, table, written) for k, table in enumerate(value, start=1)]
                values[name] = _coerce(f"{section}.{name}", value, kinds[name], keys[name].metadata)
            except SceneError as err:
                raise SceneError(quoting_written(str(err), written)) from None
        sections[section] = SECTIONS[section](**values)
    try:
        scene = _check_relations(Scene(**sections))
    except SceneError as err:
        raise SceneError(quoting_written(str(err), written)) from None
    object.__setattr__(scene, "written", written)
    # output.section = -1 was resolved to the string's own section: a changed string resolves it again
    object.__setattr__(scene, "watched_by_default", sections.get("output", Output()).section == -1.0)  # what the user wrote with a unit (``fenics-drill scene``)
    return scene


def quoting_written(message: str, written: dict[str, Any]) -> str:
    """``message`` with what the user wrote for each key it names that was written with a unit, so that a bound
    broken by a misread value names the text it was read from: ``... (string.sections[1].outer_diameter was
    written '6 3/4 in')``."""
    quoted = []
    for name, text in written.items():
        if repr(text) in message or (isinstance(text, (list, tuple)) and repr(list(text)) in message):
            continue  # the message quotes it already
        where, _, short = name.rpartition(".")
        named = re.search(rf"(?<![\w.]){re.escape(name)}(?!\w)", message)
        if not named and where.startswith("string.sections[") and message.startswith(where):
            shorts = {short, SECTION_DIAMETERS.get(short, short)}
            named = any(re.search(rf"(?<!\w){re.escape(n)}(?!\w)", message) for n in shorts)
        if named:
            quoted.append(f"{name} was written {text!r}")
    return f"{message} ({'; '.join(quoted)})" if quoted else message


def unused_keys(scene: Scene) -> set[str]:
    """The keys a scene's well leaves unused: with ``[string]`` sections, the one pipe of [beam] (its length and
    radii) and the straight hole of [borehole] when the well gives its hole sections."""
    unused = set()
    if scene.string.sections:
        unused |= {"beam.length", "beam.outer_radius", "beam.inner_radius"}
    if scene.well.hole_radius:
        unused |= {"borehole.radius"}
    return unused


def checked(scene) -> Scene:
    """``scene`` checked again as a scene file would be: one changed with ``dataclasses.replace`` (or built by
    hand) meets the same one-line refusals as the command line's."""
    if not isinstance(scene, Scene):
        raise SceneError(f"expected a Scene (fenics_drill.load_scene(...)), got {type(scene).__name__}")
    raw = {}
    for f in dataclasses.fields(scene):
        section = getattr(scene, f.name)
        if not isinstance(section, SECTIONS[f.name]):
            raise SceneError(f"scene.{f.name} = {section!r} is not admissible: it must be the [{f.name}] section "
                             f"({SECTIONS[f.name].__name__}); change keys with scene.with_changes({f.name}={{...}})")
        raw[f.name] = dataclasses.asdict(section)
    return validate(raw)


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


def read_regular_file(path: Path, what: str, limit: int, kind: str) -> bytes:
    """The bytes of ``path``, a regular file of at most ``limit`` bytes, or a SceneError naming ``what`` (e.g.
    "scene file") and the file: a directory, a device, a pipe or a socket (which could block, or never end), a
    missing, unreadable or larger file.  ``kind`` says what the file should be ("a TOML file")."""
    name = repr(str(path))
    if path.is_dir():
        raise SceneError(f"{what} {name} is a directory, not {kind}")
    if not path.exists():
        raise SceneError(f"{what} {name} does not exist")
    try:
        # O_NONBLOCK: opening a pipe must not wait for a writer; the check is on what was opened
        descriptor = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
        with os.fdopen(descriptor, "rb") as f:
            if not stat.S_ISREG(os.fstat(f.fileno()).st_mode):
                raise SceneError(f"{what} {name} is not a regular file (a device, a pipe or a socket); it must be "
                                 f"{kind}")
            data = f.read(limit + 1)
    except OSError as err:
        raise SceneError(f"{what} {name} cannot be read: {err.strerror}") from err
    if len(data) > limit:
        raise SceneError(f"{what} {name} is larger than {limit / 1e6:g} MB; it must be {kind}")
    return data


def _read_toml(path: Path) -> dict[str, Any]:
    """The TOML document of a scene file, or a SceneError that names the file and says what is wrong."""
    name = repr(str(path))
    data = read_regular_file(path, "scene file", MAX_SCENE_BYTES, "a TOML file of a few kB")
    if not data.strip():
        raise SceneError(f"scene file {name} is empty; give the keys to change, or leave SCENE out to run the "
                         "paper's nominal scene")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise SceneError(f"scene file {name} is not UTF-8 text (a binary or UTF-16 file?); a scene is a TOML "
                         f"file in UTF-8: {err.reason} at byte {err.start}") from err
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SceneError(f"scene file {name} is not valid TOML: {err}") from err


def load_scene(path: str | Path | None = None, overrides: list[str] | tuple[str, ...] = ()) -> Scene:
    """Read a scene file (or the defaults when ``path`` is None), apply overrides, validate."""
    if isinstance(overrides, str) or not isinstance(overrides, (list, tuple)):
        raise SceneError(f"overrides = {overrides!r} is not admissible: give a list of 'section.key=value' strings, "
                         f"e.g. [{overrides!r}]" if isinstance(overrides, str) else
                         f"overrides = {overrides!r} is not admissible: give a list of 'section.key=value' strings")
    for text in overrides:
        if not isinstance(text, str):
            raise SceneError(f"override {text!r} is not admissible: each override is a 'section.key=value' string")
    if path is not None and not isinstance(path, (str, Path)):
        raise SceneError(f"scene file {path!r} is not admissible: give a path (str or pathlib.Path), or None for the "
                         "paper's nominal scene")
    raw: dict[str, Any] = {}
    if path is not None:
        raw = _read_toml(Path(path))
        _anchor_files(raw, Path(os.path.abspath(path)).parent)  # a scene file's paths: relative to the file
    for text in overrides:
        section, name, value = parse_override(text)
        raw.setdefault(section, {})
        if not isinstance(raw[section], dict):
            raise SceneError(f"[{section}] must be a table of keys")
        raw[section][name] = value
        _anchor_files({section: {name: value}}, Path.cwd(), into=raw)  # a command line's: to where it runs
    return validate(raw)


#: The scene keys that name files: (section, key).
FILE_KEYS = (("well", "survey"),)


def _anchor_files(raw: dict, folder: Path, into: dict | None = None) -> None:
    """Make the relative paths of :data:`FILE_KEYS` in ``raw`` absolute from ``folder`` (written into ``into``,
    default ``raw``), so that no later reading depends on the working directory."""
    into = raw if into is None else into
    for section, name in FILE_KEYS:
        table = raw.get(section)
        value = table.get(name) if isinstance(table, dict) else None
        if isinstance(value, str) and value and not Path(value).is_absolute():
            into[section][name] = str(folder / value)


@dataclass(frozen=True)
class KeyDescription:
    """One scene key as the manual and ``fenics-drill scene`` show it."""

    section: str
    name: str
    kind: str
    default: Any
    unit: str
    admissible: str
    meaning: str


def describe_keys() -> list[KeyDescription]:
    """Every scene key in file order: its type, default, unit (the doc's trailing ``[...]``), admissible set, meaning."""
    rows = []
    for section in SECTIONS:
        kinds = get_type_hints(SECTIONS[section])
        for name, f in section_keys(section).items():
            meta, doc = f.metadata, f.metadata["doc"]
            unit = ""
            match = re.search(r"\s*\[([^\[\]]*)\]$", doc)
            if match:
                unit, doc = match.group(1), doc[: match.start()]
            admissible = meta["admissible"] or (" | ".join(repr(c) for c in meta["choices"]) if meta["choices"] else "")
            default = f.default if f.default is not dataclasses.MISSING else f.default_factory()
            rows.append(KeyDescription(section, name, _describe_kind(kinds[name]), default, unit, admissible, doc))
    return rows

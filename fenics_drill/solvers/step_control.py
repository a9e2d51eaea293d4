"""Time-step control: the nominal step (Section 6.2, finer by default), refined where the motion is rough.

The nominal step resolves the band's highest frequency f_max with ``time.band_steps`` steps per period:
8 by default, 2 in the paper (1/(2 f_max)).  At the paper's step Newmark misses part of the drive torque's
oscillation, which the input power (98) counts while the torque drives, and the efficiency (96) comes out
4-7 % high against the step-converged full order; at the default 0.3-0.6 % against the same model with the
bit's transitions resolved, or the full order over the same band (docs/verification.md).

The local error of a Newmark step is estimated as in Zienkiewicz & Xie (1991):
e = (beta - 1/6) dt^2 (qdd_{n+1} - qdd_n), measured against ``time.error_tolerance`` on
the lateral displacements of the vertices (where impacts act) and, at the bit, on the
axial displacement and the arc r theta_x of the pipe's surface (where the stiff
bit-rock laws (20)-(21) act: the start-up from rest onto the rock and each stick-slip
transition).  An impact or a bit transient makes the acceleration jump, the estimate
grows and the step shrinks; once the motion is smooth again the step relaxes back to
the nominal one.  Without the bit's rows a reduced model takes the start-up in one
nominal step, and its bit velocity rings (benchmarks/results/reduced_accuracy.md).  A Newton
failure halves the step; after ``time.max_step_cuts`` halvings the run stops.

Over the first nominal step the tolerance is ``time.start_up_share`` of ``time.error_tolerance``: the bit,
set moving at V0 and Omega at t = 0, is braked by the rock law's steep velocity dependence within
microseconds, and what error that transient leaves stays in the string as a lightly damped oscillation that
moves the efficiency of the whole run (docs/verification.md, "The reduced model against its full order").
"""

from __future__ import annotations

import math

import numpy as np

from fenics_drill.model.resolution import band_frequency
from fenics_drill.model.reduction.spaces import column_bound, stack_rows
from fenics_drill.scene import SceneError


class RunFailure(RuntimeError):
    """A run that cannot go on: it ends "failed" with this message (when and why)."""


class StepTooSmall(RunFailure):
    """The step would have to go below dt_nominal / 2^max_step_cuts."""


def torsional_transit(scene) -> float:
    """An element's torsional wave transit [s]: the axial-torsional elements' length
    (``model.axial_torsional_element_length``), or the string's length over beam.elements, at the fastest torsional
    wave speed sqrt(G / rho) of the string's sections (beam.* where a section or the string gives none)."""
    beam = scene.beam
    chosen = scene.axial_torsional_element_length
    length = chosen if chosen > 0 else scene.string_length / beam.elements
    speed = max(math.sqrt(section.get("young_modulus", beam.young_modulus) / (2.0 * (1.0 + beam.poisson_ratio))
                          / section.get("density", beam.density)) for section in (scene.string.sections or [{}]))
    return length / speed


def breaks_loose_in_waves(scene) -> bool:
    """Whether the wall holds the string at a static friction factor above the kinetic one
    (``contact.static_friction``): a string stuck along the wall then breaks loose in torsional waves, which a step
    longer than an element's torsional transit smooths away."""
    return scene.model.contact and scene.contact.static_factor > scene.contact.friction


def nominal_step(scene) -> float:
    """time.dt, or 1 / (n f_max) with n = time.band_steps steps per period of f_max (n = 2: the paper's step
    of Section 6.2), at most an element's torsional transit where the wall's static friction makes the string
    break loose in torsional waves (:func:`breaks_loose_in_waves`): on the 2000 m string at 60 degrees off bottom
    the adaptive steps grew to 7-12 ms over 3.2 ms of transit, and the first breakaway's torque peak came out 13.2
    kN m against 15.4 kN m at a fixed 1 ms step (docs/guide/stick_slip_maps.md)."""
    if scene.time.dt > 0:
        return scene.time.dt
    step = 1.0 / (scene.time.band_steps * band_frequency(scene))
    return min(step, torsional_transit(scene)) if breaks_loose_in_waves(scene) else step


def least_steps(scene) -> float:
    """The fewest steps a run of the scene takes: time.t_end over its largest step, the nominal one."""
    return scene.time.t_end / nominal_step(scene)


def check_run_length(scene) -> None:
    """Refuse, before any work, a run that needs more than ``time.max_steps`` steps at its largest step (a time.dt
    of 1e-9 s over 10 s is 1e10 steps: days), naming the keys."""
    steps = least_steps(scene)
    if steps > scene.time.max_steps:
        raise SceneError(f"time.t_end = {scene.time.t_end:g} s at a step of at most {nominal_step(scene):.3g} s needs at "
                         f"least {steps:.3g} steps, more than time.max_steps = {scene.time.max_steps:g} (about "
                         f"{steps * 1e-3 / 3600:.3g} h at 1 ms per step); raise time.dt or lower time.t_end, or raise "
                         "time.max_steps to run it")


def steps_per_band_period(scene) -> float:
    """How many nominal steps a period of f_max holds (time.band_steps, or what an explicit time.dt gives)."""
    return 1.0 / (nominal_step(scene) * band_frequency(scene))


class StepController:
    """Proposes the next step size and judges each finished step."""

    GROWTH_MAX, SHRINK_MIN, SAFETY = 2.0, 0.25, 0.9

    def __init__(self, scene, beta: float, error_rows):
        self.nominal = nominal_step(scene)
        self.minimum = self.nominal / 2 ** scene.time.max_step_cuts
        self.adaptive = scene.time.adaptive
        self.tolerance = scene.time.error_tolerance
        # the start-up transient (time.start_up_share): a tighter tolerance over the first nominal step
        self.start_up_end = self.nominal
        self.start_up_tolerance = scene.time.start_up_share * self.tolerance
        self.error_factor = abs(beta - 1.0 / 6.0)
        # the maps of q to the displacements [m] the error is measured on, stacked (one product per step)
        self.error_rows = stack_rows(error_rows)
        # max_i |(R e)_i| <= sum_j of it |e_j|, in N_red products
        self.column_bound = column_bound(self.error_rows)
        self.dt = self.nominal
        self.forced_steps = 0  # steps accepted at the minimum size although their error exceeded the tolerance
        self.worst_forced_ratio = 0.0

    def step_towards(self, t: float, t_end: float) -> float:
        """The next step from t: the proposal, except near t_end, where what is left is split into one or
        two equal steps.  A sliver of a step (t_end - t << dt) would scale the Newmark inertia by
        1/dt^2 and drown Newton's residual in round-off."""
        remaining = t_end - t
        if remaining > 2.0 * self.dt:
            return self.dt
        return remaining if remaining <= self.dt else 0.5 * remaining

    def error_ratio(self, t: float, dt: float, qdd_old: np.ndarray, qdd_new: np.ndarray) -> float:
        """Estimated local error of the step from t over the tolerance (<= 1: accept), the start-up's before
        :attr:`start_up_end`; or an upper bound of it where that bound already makes :meth:`judge` accept the
        step and propose the nominal one, as the estimate would: the estimate's product with every row is then
        saved (most steps of a smooth motion)."""
        tolerance = self.tolerance if t >= self.start_up_end else self.start_up_tolerance
        e = self.error_factor * dt * dt * (qdd_new - qdd_old)
        bound = float(self.column_bound @ np.abs(e)) / tolerance
        # (1 + 1e-9): the estimate may exceed the bound by the round-off of their sums
        if bound * (1.0 + 1e-9) <= self._nominal_ratio(dt):
            return bound
        return float(np.max(np.abs(self.error_rows @ e))) / tolerance

    def _nominal_ratio(self, dt: float) -> float:
        """The largest error ratio after a step of dt for which :meth:`judge` accepts and proposes the
        nominal step (-1 if none does: from dt the proposal cannot grow to it)."""
        if not self.adaptive:
            return np.inf
        if self.GROWTH_MAX * dt < self.nominal:
            return -1.0
        return min(1.0, (self.SAFETY * dt / self.nominal) ** 3)

    def judge(self, dt: float, ratio: float) -> bool:
        """Accept or reject a converged step and set the next proposal.  A step already at the minimum
        size is accepted whatever its error, and counted in :attr:`forced_steps` (a run with such steps
        is reported "suspect")."""
        if not self.adaptive:
            self.dt = self.nominal
            return True
        factor = self.SAFETY * max(ratio, 1e-12) ** (-1.0 / 3.0)
        accept = ratio <= 1.0 or dt <= self.minimum * (1 + 1e-9)
        if accept and ratio > 1.0:  # nothing smaller is allowed: taken, and counted against the run
            self.forced_steps += 1
            self.worst_forced_ratio = max(self.worst_forced_ratio, ratio)
        factor = min(self.GROWTH_MAX, max(self.SHRINK_MIN, factor))
        self.dt = min(self.nominal, max(self.minimum, dt * factor))
        return accept

    def cut(self, dt: float, reason: str, t: float) -> None:
        """Halve after a Newton failure, or stop with a message saying when and why."""
        if dt <= self.minimum * (1 + 1e-9):
            raise StepTooSmall(
                f"at t = {t:.6f} s: {reason}; the step is already at its minimum "
                f"{self.minimum:.3e} s (time.max_step_cuts halvings of {self.nominal:.3e} s)"
            )
        self.dt = max(self.minimum, 0.5 * dt)

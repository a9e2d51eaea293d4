"""Damping of what a reduced basis spans above its band: the radiation a truncated string cannot carry.

A modal basis holds the modes of the band B (up to f_max = f*_max c_L / L) and, for the statics, vectors that
are not modes: the torsional modes of the stuck bit, the static responses the guard adds, the string's state at
rest.  Together they span directions whose Ritz frequencies (the eigenvalues of the reduced pair K_r, M_r) lie far
above f_max, and one of them is local to the bit: a light, stiff twist of its last metres (on a 101 m string
1555 Hz, with 0.018 kg m^2 of inertia at the bit, where f_max = 201 Hz).  The bit law's torque falls with the
spin rate, a negative damping (about -190 N m s/rad); on the full string the torsional waves the bit sends up
carry that energy away (the pipe's wave impedance rho J c_T is about 220 N m s/rad), but the bit-local Ritz
direction has no waves, and it rang: the bit's angular velocity zig-zagged from step to step, the peak stress
at the bit came out 7-11 % high and short strings' stick-slip twice as violent as in their full order
(docs/verification.md, "The reduced model against its full order").

This force gives every Ritz direction above OUT_OF_BAND_FACTOR x f_max the modal damping ratio
``reduction.out_of_band_damping`` (0.1 by default): f = -C qd with C = M_r X diag(2 zeta omega) X^T M_r over the
mass-normalised Ritz vectors X above the cut.  A tenth of critical already stops the ringing; critical damping
stopped it too but moved the 1 s efficiency of two short strings that did not ring by 0.6-0.9 % from their full
order, against 0.1-0.2 % at 0.1.  It leaves every motion in the span of the Ritz directions below the cut
untouched, the rigid spin and feed among them, so the band's dynamics and the drive's work are what they were;
the energy budget books its work under ``out_of_band``.

A string resting on the wall has more of them: the wall's springs (k_FS1 = 1e10 N/m, about 10 nm of indentation
under the weight) stiffen the directions that press the resting vertices into it far above the band, where they
rang against the contact (a thin pipe between stabilisers lifted off the wall and bounced).
:meth:`~fenics_drill.model.drillstring.DrillstringModel.resting_at` gives the model whose damped directions are
those of the reduced stiffness with the wall's springs at its static state.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np
import scipy.linalg as sl

from fenics_drill.model.forces.protocol import ForceEvaluation

#: Ritz directions above this many times f_max are damped.  The nominal step resolves f_max with 8 steps per
#: period (time.band_steps), so 2 f_max has 4; the basis's other vectors put Ritz frequencies from just above
#: f_max (the stuck-bit modes, which a stick phase needs) to 5-8 f_max (the bit-local twist).  Measured on
#: stick-slip scenes against their full order over 1 s: at 1 x f_max the efficiency moved by up to 1.4 % and the
#: peak stress by 2.8 %; at the step's Nyquist frequency (4 f_max) a 22 m string's peak bit spin stayed 37 % high;
#: at 2 f_max all four scenes tried are within 0.7 % on efficiency and 1.4 % on the peak stress
#: (docs/verification.md).
OUT_OF_BAND_FACTOR = 2.0


class OutOfBandDamping:
    """f = -C qd on the Ritz directions of a modal basis above OUT_OF_BAND_FACTOR x f_max (module doc)."""

    name: ClassVar[str] = "out_of_band"
    switch: ClassVar[str] = ""
    conservative: ClassVar[bool] = False
    recorded: ClassVar[dict] = {}

    def __init__(self, damping: np.ndarray, frequencies_hz: np.ndarray):
        self.damping = damping  # C, N_red x N_red
        self.frequencies_hz = frequencies_hz  # of the damped Ritz directions

    @classmethod
    def of_basis(cls, mass: np.ndarray, stiffness: np.ndarray, band_top_hz: float,
                 damping_ratio: float) -> "OutOfBandDamping | None":
        """The damping of the basis whose reduced mass and stiffness are ``mass``, ``stiffness``; None if no
        Ritz direction lies above the cut (or ``damping_ratio`` is 0)."""
        if damping_ratio <= 0:
            return None
        eigenvalues, ritz = sl.eigh(stiffness, mass)
        omega = np.sqrt(np.maximum(eigenvalues, 0.0))
        above = omega > 2.0 * np.pi * OUT_OF_BAND_FACTOR * band_top_hz
        if not above.any():
            return None
        shapes = mass @ ritz[:, above]  # M_r X: the modal coordinates' rows
        damping = shapes @ (2.0 * damping_ratio * omega[above, None] * shapes.T)
        return cls(damping, omega[above] / (2.0 * np.pi))

    def evaluate(self, q: np.ndarray, qd: np.ndarray, with_tangent: bool = False) -> ForceEvaluation:
        force = -(self.damping @ qd)
        return ForceEvaluation(force, 0.0, {self.name: force})

    def tangent(self, evaluation: ForceEvaluation, c_u: float, c_v: float):
        return -c_v * self.damping

    def record(self, evaluation: ForceEvaluation) -> dict[str, float]:
        return {}

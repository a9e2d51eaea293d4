"""Wall impacts of a run (Section 6.7): contact onsets of vertices that had moved clear of the wall.

Where the string rests on the wall, the vertices at the edges of a contact zone leave and touch it again by
the scale of the wall springs' own indentation as the motion breathes (measured on a thin string resting in
a 20 mm gap: at most 1.2e-8 m over 1 s of a 100 m string, 9.2e-8 m over 0.3 s of a 20 m one), and now and
then lift by a few micrometres at micrometres per second.  Counted as impacts, those contacts made a resting
string report impacts at a rate set by the mesh and the time step (3 to 541 in one second of the same scene).
An onset counts as an impact only when the vertex had moved clear of the wall by more than IMPACT_CLEARANCE
of the gap since its last contact (docs/verification.md, "Observables").
"""

from __future__ import annotations

import numpy as np

from fenics_drill.model.kernels.compiled import kernel

#: The share of the gap a vertex must have moved away from the wall, since its last contact, for its next
#: contact to count as an impact: 15 um on the paper's string, 1.5 times the step control's displacement
#: tolerance (time.error_tolerance = 1e-5 m), so a lift the integrator does not resolve is no impact.  The
#: resting contact's flicker (< 0.1 um) and the slow lifts of a resting full order (3.4 um at 3 um/s on the thin
#: string) stay below it; 84 % of the printed kinematics' contact onsets come after a larger lift, up to the gap.
IMPACT_CLEARANCE = 1e-3


@kernel
def _impacts_at(vertices, delta, in_contact, clear, per_vertex, clearance):
    """The contacts of one accepted state at the evaluated ``vertices`` (indentations ``delta``): the vertices
    whose impact began, also counted in ``per_vertex``; ``in_contact`` and ``clear`` (per vertex) updated in
    place; ``clearance`` per vertex.  One pass over the evaluated vertices: it runs at every accepted step."""
    began = np.empty(vertices.size, dtype=np.int64)
    count = 0
    for k in range(vertices.size):
        i = vertices[k]
        touching = delta[k] > 0.0
        if touching and not in_contact[i] and clear[i]:
            began[count] = i
            count += 1
            per_vertex[i] += 1
        if touching:
            clear[i] = False
        elif delta[k] < -clearance[i]:
            clear[i] = True
        in_contact[i] = touching
    return began[:count]


class ImpactCounter:
    """The impacts at every vertex, from the wall's evaluations at the accepted states of a run (its
    :class:`~fenics_drill.model.forces.wall_contact.WallForces`, or None without a wall)."""

    def __init__(self, vertex_count: int, gap):
        self.per_vertex = np.zeros(vertex_count, dtype=np.int64)
        self.in_contact = np.zeros(vertex_count, dtype=bool)  # at the last accepted state
        self.clearance = IMPACT_CLEARANCE * np.broadcast_to(np.asarray(gap, dtype=float), (vertex_count,)).copy()
        # whether each vertex moved clear of the wall since its last contact (one never evaluated is far)
        self._clear = np.ones(vertex_count, dtype=bool)
        self._evaluated = None  # the vertices the wall evaluated at the last accepted state

    def start(self, wall) -> None:
        """The initial state: a vertex counts as clear if the wall left it out (farther than its near
        share of the gap) or it is more than the clearance away."""
        if wall is not None:
            self._clear[wall.vertices] = wall.delta < -self.clearance[wall.vertices]
            self.step(wall)

    def step(self, wall) -> np.ndarray:
        """The vertices whose impact began during the step that ended at this accepted state (their
        indices), counted in :attr:`per_vertex`."""
        if wall is None:
            return np.zeros(0, dtype=np.int64)
        if wall.vertices is not self._evaluated:
            if self._evaluated is not None:
                # the wall's culled set changed: the vertices it left out are more than half the gap away
                # (WallContact.NEAR), far beyond the clearance, and out of contact
                dropped = np.setdiff1d(self._evaluated, wall.vertices, assume_unique=True)
                self._clear[dropped], self.in_contact[dropped] = True, False
            self._evaluated = wall.vertices
        return _impacts_at(wall.vertices, wall.delta, self.in_contact, self._clear, self.per_vertex,
                           self.clearance)

"""The wall's laws, one module per law: the normal force (16)-(17), one Coulomb force at the contact point, the
paper's friction (18)-(19); and their compiled passes over the vertices.  :class:`~fenics_drill.model.forces.
wall_contact.WallContact` applies them to a solution space."""

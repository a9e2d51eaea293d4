"""Shared fixtures: small scenes built from the paper's defaults."""

import pytest

from pathlib import Path

from fenics_drill.scene import Scene, load_scene

#: The paper's nominal scene file.
PAPER = Path(__file__).parents[1] / "demos" / "scenes" / "paper.toml"


#: The paper's wall friction (18)-(19), with the regularisation the tests of the reduced model were set up with.
#: Under the default Coulomb force at the contact point a spinning string on the wall climbs it and the 'auto'
#: rule takes the full order (tests/model/test_coulomb_friction.py tests that law and that choice).
PAPER_FRICTION = ("contact.friction_model='paper'", "contact.sliding_velocity_scale=1e-3")


def scene_with(*overrides: str) -> Scene:
    """The paper scene with the paper's wall friction (:data:`PAPER_FRICTION`) and ``section.key=value``
    overrides applied (which may choose the Coulomb force again)."""
    return load_scene(None, [*PAPER_FRICTION, *overrides])


@pytest.fixture
def paper_properties():
    return scene_with().beam_properties


def expected_status(scene: Scene) -> str:
    """What a run of ``scene`` that goes well ends as: "finished", or "suspect" when the mesh or the step the
    scene chose cannot carry its band of analysis (small test scenes often choose so, to be fast)."""
    from fenics_drill.studies.run import discretisation_reasons

    return "suspect" if discretisation_reasons(scene, {"command": "run"}) else "finished"

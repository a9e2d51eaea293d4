"""Shared fixtures: small scenes built from the paper's defaults."""

import pytest

from pathlib import Path

from fenics_drill.scene import Scene, load_scene

#: The paper's nominal scene file.
PAPER = Path(__file__).parents[1] / "demos" / "scenes" / "paper.toml"


def scene_with(*overrides: str) -> Scene:
    """The paper scene with ``section.key=value`` overrides applied."""
    return load_scene(None, list(overrides))


@pytest.fixture
def paper_properties():
    return scene_with().beam_properties


def expected_status(scene: Scene) -> str:
    """What a run of ``scene`` that goes well ends as: "finished", or "suspect" when the mesh or the step the
    scene chose cannot carry its band of analysis (small test scenes often choose so, to be fast)."""
    from fenics_drill.studies.run import discretisation_reasons

    return "suspect" if discretisation_reasons(scene, {"command": "run"}) else "finished"

"""Shared fixtures: small scenes built from the paper's defaults."""

import pytest

from fenics_drill.scene import beam_properties, load_scene


def scene_with(*overrides: str) -> dict:
    """The paper scene with ``section.key=value`` overrides applied."""
    return load_scene(None, list(overrides))


@pytest.fixture
def paper_properties():
    return beam_properties(scene_with())

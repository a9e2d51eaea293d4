"""JSON files of the project (summaries, reports): one writer, floats from NumPy included."""

from __future__ import annotations

import json
from pathlib import Path


def write_json(path: Path, data: dict) -> None:
    """Write ``data`` as indented JSON (NumPy scalars as floats)."""
    Path(path).write_text(json.dumps(data, indent=1, default=float))

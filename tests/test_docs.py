"""The manual follows the code: the generated scene reference lists exactly the keys ``fenics-drill scene`` prints,
and each key's help is one line (the explanations live in the manual)."""

import contextlib
import io
import re
import sys
from pathlib import Path

from fenics_drill.cli import main
from fenics_drill.scene import describe_keys

sys.path.insert(0, str(Path(__file__).parents[1] / "docs" / "_ext"))
from generated_reference import scene_reference_markdown  # noqa: E402


def printed_keys() -> set[str]:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["scene"]) == 0
    keys, section = set(), None
    for line in out.getvalue().splitlines():
        if match := re.fullmatch(r"\[(\w+)\]", line):
            section = match.group(1)
        elif match := re.match(r"(\w+) = ", line):
            keys.add(f"{section}.{match.group(1)}")
    return keys


def test_the_scene_reference_lists_every_key_the_scene_command_prints_and_no_other():
    documented = set(re.findall(r"^\| `(\w+\.\w+)` \|", scene_reference_markdown(), flags=re.MULTILINE))
    assert documented == printed_keys()
    assert len(documented) == len(describe_keys())


def test_every_key_has_a_one_line_meaning_and_a_unit_where_it_has_a_dimension():
    for row in describe_keys():
        assert 0 < len(row.meaning) <= 100, f"{row.section}.{row.name}: {row.meaning!r}"
        if row.kind in ("a number", "an integer"):
            assert row.unit, f"{row.section}.{row.name} has no [unit]"

"""The package shows its layers: data flows scene -> model -> solvers -> observables -> io -> studies ->
plots -> API/CLI (docs/architecture.md), and no module imports from a layer above its own."""

import ast
from pathlib import Path

PACKAGE = Path(__file__).parents[1] / "fenics_drill"

#: Rank of each layer; a module may import from its own rank or lower ones only.
LAYERS = {
    "fenics_drill.forms": 0,
    "fenics_drill.scene": 1,
    "fenics_drill.model": 2,
    "fenics_drill.solvers": 3,
    "fenics_drill.observables": 4,
    "fenics_drill.io": 5,
    "fenics_drill.studies": 6,
    "fenics_drill.plots": 7,
    "fenics_drill.api": 8,
    "fenics_drill.cli": 9,
    "fenics_drill.supervisor": 9,
}


def layer(module: str) -> int:
    matches = [name for name in LAYERS if module == name or module.startswith(name + ".")]
    assert matches, f"{module} belongs to no layer of LAYERS"
    return LAYERS[max(matches, key=len)]


def modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        if path.name == "__init__.py" and path.parent == PACKAGE:
            continue  # the package root re-exports the API lazily
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        yield ".".join(p for p in parts if p != "__init__"), path


def test_no_module_imports_from_a_higher_layer():
    upward = []
    for module, path in modules():
        own = layer(module)
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("fenics_drill."):
                names = [node.module]
            elif isinstance(node, ast.Import):
                names = [a.name for a in node.names if a.name.startswith("fenics_drill.")]
            upward += [f"{module} imports {name}" for name in names if layer(name) > own]
    assert not upward, upward


def test_every_force_lives_in_its_own_module_and_is_registered():
    from fenics_drill.model.forces import FORCES

    modules_of = [force.__module__ for force in FORCES]
    assert len(set(modules_of)) == len(FORCES)
    # a name is shared only by alternative laws of one force, which each scene chooses between
    names = [force.name for force in FORCES]
    for name in set(names):
        alternatives = [force for force in FORCES if force.name == name]
        if len(alternatives) > 1:
            assert all(hasattr(force, "chosen") for force in alternatives), name

"""The package shows its layers: data flows scene -> model -> solvers -> observables -> io -> studies ->
plots -> API/CLI (docs/architecture.md), and no module imports from a layer above its own."""

import ast
from pathlib import Path

PACKAGE = Path(__file__).parents[1] / "fenics_drill"

#: Rank of each layer; a module may import from its own rank or lower ones only.
LAYERS = {
    "fenics_drill.forms": 0,
    "fenics_drill.scene": 1,
    "fenics_drill.units": 1,  # the units a scene's values are written in: read with the scene
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


def rank_in(table: dict[str, int], module: str) -> int:
    """The rank of the longest name of ``table`` that ``module`` is or lies under."""
    matches = [name for name in table if module == name or module.startswith(name + ".")]
    assert matches, f"{module} belongs to no entry of {sorted(table)}"
    return table[max(matches, key=len)]


def layer(module: str) -> int:
    return rank_in(LAYERS, module)


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
        upward += [f"{module} imports {name}" for name in imported_modules(path) if layer(name) > own]
    assert not upward, upward


#: Inside the model layer, the same rule between its concerns (fenics_drill/model/__init__.py).
MODEL_PARTS = {
    "fenics_drill.model.kernels": 0,
    "fenics_drill.model.discretization": 1,
    "fenics_drill.model.resources": 1,
    "fenics_drill.model.resolution": 1,
    "fenics_drill.model.operators": 1,
    "fenics_drill.model.internal_force": 1,
    "fenics_drill.model.forces": 1,
    "fenics_drill.model.top_drive": 1,
    "fenics_drill.model.well": 1,
    "fenics_drill.model.string_sections": 1,
    "fenics_drill.model.soft_string": 1,
    "fenics_drill.model.survey_errors": 1,
    "fenics_drill.model.reduction": 2,
    "fenics_drill.model.drillstring": 3,
    "fenics_drill.model.axial_torsional_string": 3,
    "fenics_drill.model.rotating_modes": 3,
}


def model_part(module: str) -> int:
    return rank_in(MODEL_PARTS, module)


def imported_modules(path: Path) -> list[str]:
    names = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("fenics_drill."):
            names.append(node.module)
        elif isinstance(node, ast.Import):
            names += [a.name for a in node.names if a.name.startswith("fenics_drill.")]
    return names


def test_inside_the_model_kernels_physics_and_reduction_import_only_downwards():
    upward = []
    for module, path in modules():
        if not module.startswith("fenics_drill.model.") or module == "fenics_drill.model":
            continue
        own = model_part(module)
        upward += [f"{module} imports {name}" for name in imported_modules(path)
                   if name.startswith("fenics_drill.model.") and model_part(name) > own]
    assert not upward, upward


def test_every_package_directory_ships_in_the_wheel():
    """pyproject.toml lists the packages explicitly (forms/ is mapped into fenics_drill.forms)."""
    import tomllib

    listed = set(tomllib.loads((PACKAGE.parent / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    found = {".".join(p.parent.relative_to(PACKAGE.parent).parts) for p in PACKAGE.rglob("__init__.py")}
    assert found | {"fenics_drill.forms"} == listed


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


def test_no_import_cycle():
    """Following every import between the package's modules never leads back to where it started."""
    graph = {module: set() for module, _ in modules()}
    for module, path in modules():
        for name in imported_modules(path):
            target = name if name in graph else next((m for m in graph if name.startswith(m + ".")), None)
            if target is not None and target != module:
                graph[module].add(target)
    state, cycles = {}, []

    def visit(module, trail):
        state[module] = "open"
        for target in graph[module]:
            if state.get(target) == "open":
                cycles.append(trail[trail.index(target):] + [target])
            elif target not in state:
                visit(target, trail + [target])
        state[module] = "done"

    for module in graph:
        if module not in state:
            visit(module, [module])
    assert not cycles, cycles


def test_a_scenes_string_and_well_are_resolved_once(monkeypatch):
    """The mesh, the axial-torsional wall's normal forces, the soft string's study and the static state's start all
    read the scene's string in its well from one object (:func:`~fenics_drill.model.well.string_in_well`): the well is
    resolved from the scene's survey once per scene, and again for a changed scene."""
    import fenics_drill as fd
    from fenics_drill.model import well as wells
    from fenics_drill.model.discretization import BeamDiscretization
    from fenics_drill.model.forces.axial_torsional_wall import vertex_normal_forces
    from fenics_drill.studies.torque_drag import torque_drag_study

    calls = []
    resolve = wells.well_of
    monkeypatch.setattr(wells, "well_of", lambda *args: calls.append(args) or resolve(*args))
    scene = fd.load_scene("demos/scenes/well_build_hold.toml", ["beam.elements=60", "model.lateral_length=0"])
    disc = BeamDiscretization.from_scene(scene)
    vertex_normal_forces(scene, disc.vertex_x)
    torque_drag_study(scene)
    assert wells.string_in_well(scene) is wells.string_in_well(scene)
    assert len(calls) == 1
    changed = scene.with_changes(beam={"elements": 70})
    assert wells.string_in_well(changed).well is not wells.string_in_well(scene).well
    assert len(calls) == 2

"""Writes the generated reference pages before Sphinx reads the sources: ``reference/scene_keys.md`` from the
Scene dataclasses and ``reference/api.md`` from the package's modules (autodoc fills it from the docstrings)."""

from pathlib import Path

from fenics_drill.scene import SECTIONS, describe_keys


def scene_reference_markdown() -> str:
    """Every scene key, section by section: default, unit, admissible values and meaning."""
    rows = describe_keys()
    lines = [
        "# Scene keys",
        "",
        "Every key of a scene file, generated from the Scene dataclasses (`fenics_drill/scene.py`) when the "
        "manual is built; `fenics-drill scene` prints the same keys with their values. Units are SI. A key left "
        "out takes its default; an unknown key, a wrong type or a value outside the admissible set is refused "
        "before any computation, with a message naming the key.",
        "",
    ]
    for section in SECTIONS:
        doc = SECTIONS[section].__doc__ or ""
        lines += [f"## `[{section}]`", ""]
        if doc and not doc.startswith(SECTIONS[section].__name__ + "("):
            lines += [doc.strip(), ""]
        lines += ["| key | default | unit | admissible | meaning |", "|---|---|---|---|---|"]
        for row in rows:
            if row.section != section:
                continue
            default = list(row.default) if isinstance(row.default, tuple) else row.default
            cells = [f"`{section}.{row.name}`", f"`{default!r}`", row.unit or "", row.admissible or row.kind,
                     row.meaning]
            lines.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
        lines.append("")
    return "\n".join(lines)


def _write(app) -> None:
    target = Path(app.srcdir) / "reference" / "scene_keys.md"
    text = scene_reference_markdown()
    if not target.exists() or target.read_text() != text:
        target.write_text(text)




#: The package's layers in the order data flows through them (docs/architecture.md), with a line each.
LAYERS = {
    "fenics_drill": "The public API (`import fenics_drill as fd`) and the scene.",
    "fenics_drill.forms": "The weak forms in pure UFL.",
    "fenics_drill.model": "The string, its forces, the reduced model and the compiled kernels.",
    "fenics_drill.solvers": "Static equilibrium, Newmark/Newton, step control, the time loop.",
    "fenics_drill.observables": "Quantities computed from states and series.",
    "fenics_drill.io": "Files: one writer and one reader each.",
    "fenics_drill.studies": "Commands as functions: run, modal report, Monte Carlo, windows, Campbell.",
    "fenics_drill.plots": "Figures from saved files.",
}


def api_reference_markdown(package_root: Path) -> str:
    """One section per layer, one ``automodule`` per module (documented members only)."""
    modules = []
    for path in sorted(package_root.rglob("*.py")):
        parts = path.relative_to(package_root.parent).with_suffix("").parts
        modules.append(".".join(p for p in parts if p != "__init__"))
    forms_root = package_root.parent / "forms"
    modules += ["fenics_drill.forms" + ("" if p.stem == "__init__" else "." + p.stem)
                for p in sorted(forms_root.glob("*.py"))]
    lines = ["# API reference", "",
             "Generated from the docstrings when the manual is built, layer by layer in the order data flows "
             "(scene, forms, model, solvers, observables, io, studies, plots). Start with `fenics_drill.api`: "
             "the functions a notebook calls.", ""]
    owner = {}
    for module in modules:
        layer = max((name for name in LAYERS if module == name or module.startswith(name + ".")), key=len)
        if module in ("fenics_drill", "fenics_drill.cli", "fenics_drill.supervisor"):
            continue
        owner.setdefault(layer, []).append(module)
    owner["fenics_drill"] = ["fenics_drill.api", "fenics_drill.scene"]
    for layer, line in LAYERS.items():
        lines += [f"## `{layer}`", "", line, ""]
        for module in owner.get(layer, []):
            lines += [f"### `{module}`", "", "```{eval-rst}", f".. automodule:: {module}", "```", ""]
    return "\n".join(lines)


def _write_api(app) -> None:
    target = Path(app.srcdir) / "reference" / "api.md"
    text = api_reference_markdown(Path(app.srcdir).parent / "fenics_drill")
    if not target.exists() or target.read_text() != text:
        target.write_text(text)


def setup(app):
    app.connect("builder-inited", _write)
    app.connect("builder-inited", _write_api)
    return {"parallel_read_safe": True}

"""The release: the wheel and sdist build with ``python -m build``, and the wheel installed in a fresh virtual
environment is the whole tool: ``fenics-drill --version`` and a 0.1 s run that gives the source tree's answer."""

import json
import subprocess
import sys
import venv
from pathlib import Path

import fenics_drill
from fenics_drill.scene import load_scene
from fenics_drill.studies.run import run_scene

from conftest import expected_status

ROOT = Path(__file__).parents[1]

#: A short string, so that the run costs little beyond the fresh installation's Numba compilation.
SHORT_RUN = ["time.t_end=0.1", "beam.length=10", "beam.elements=20", "output.field_interval=0"]


def test_the_wheel_installed_in_a_fresh_environment_runs_as_the_source_tree(tmp_path):
    dist = tmp_path / "dist"
    subprocess.run([sys.executable, "-m", "build", "--outdir", str(dist), str(ROOT)], check=True,
                   capture_output=True, timeout=600)
    wheels, sdists = sorted(dist.glob("*.whl")), sorted(dist.glob("*.tar.gz"))
    assert len(wheels) == 1 and len(sdists) == 1
    assert f"-{fenics_drill.__version__}-" in wheels[0].name

    env_dir = tmp_path / "venv"
    venv.EnvBuilder(with_pip=True).create(env_dir)
    python, tool = env_dir / "bin" / "python", env_dir / "bin" / "fenics-drill"
    # the dependencies are this environment's (its site-packages on the new one's path, its .pth files unread, so
    # that the source tree's editable install is not seen): the wheel alone is what is installed and tried; that
    # the dependencies install from nothing is the bootstrap's test (make setup on a clean machine)
    dependencies = next(Path(p) for p in sys.path if p.endswith("site-packages") and Path(p).is_dir())
    (next((env_dir / "lib").glob("python*/site-packages")) / "dependencies.pth").write_text(f"{dependencies}\n")
    subprocess.run([str(python), "-m", "pip", "install", "--quiet", "--no-deps", str(wheels[0])], check=True,
                   capture_output=True, timeout=900)
    for library in (Path(sys.prefix) / "lib").iterdir():  # the MPI library a wheel put beside them
        if not (env_dir / "lib" / library.name).exists():
            (env_dir / "lib" / library.name).symlink_to(library)

    version = subprocess.run([str(tool), "--version"], check=True, capture_output=True, text=True, cwd=tmp_path,
                             timeout=300)
    assert version.stdout.strip() == f"fenics-drill {fenics_drill.__version__}"

    # run from a directory without the source tree, so that only the installed package can be imported
    installed = tmp_path / "installed-run"
    command = [str(tool), "run", str(ROOT / "demos" / "scenes" / "paper.toml"), "--out", str(installed)]
    for override in SHORT_RUN:
        command += ["--set", override]
    subprocess.run(command, check=True, capture_output=True, cwd=tmp_path, timeout=900)
    summary = json.loads((installed / "summary.json").read_text())
    origin = subprocess.run([str(python), "-c", "import fenics_drill; print(fenics_drill.__file__)"],
                            check=True, capture_output=True, text=True, cwd=tmp_path).stdout
    assert str(env_dir) in origin

    reference = run_scene(load_scene(ROOT / "demos" / "scenes" / "paper.toml", SHORT_RUN), tmp_path / "tree-run")
    assert summary["status"] == reference["status"] == expected_status(load_scene(ROOT / "demos" / "scenes" / "paper.toml",
                                                                                SHORT_RUN))
    # The same code on the same machine: the same steps and, to round-off, the same answer.
    assert summary["steps"] == reference["steps"]
    assert abs(summary["rop"] - reference["rop"]) <= 1e-9 * abs(reference["rop"])
    assert abs(summary["efficiency"] - reference["efficiency"]) <= 1e-9 * abs(reference["efficiency"])

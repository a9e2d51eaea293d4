"""What a scene will cost in memory, checked before anything is allocated.

Measured with ``/usr/bin/time -f %M fenics-drill modal demos/scenes/paper.toml --set
beam.elements=N`` (the modal analysis is the largest step of every command): 1.93 GB at
N = 20 000 and 3.73 GB at N = 40 000 elements of degree 2 (160 006 and 320 006 dofs),
i.e. 11.2 kB per dof over a base of about 0.2 GB.  The estimate below rounds both up.
"""

from __future__ import annotations

import os

BYTES_PER_DOF = 12_000
BASE_BYTES = 0.3e9
#: Share of the available memory a run may plan to use.
USABLE_SHARE = 0.8


class ResourceError(ValueError):
    """A scene that does not fit the machine; the message names the key and what would fit."""


def dof_count(elements: int, element_degree: int) -> int:
    """Unknowns of the mixed space: u, v, w of degree k, the rotations of degree k - 1."""
    k = element_degree
    return 3 * (k * elements + 1) + 3 * ((k - 1) * elements + 1)


def estimated_memory(elements: int, element_degree: int) -> float:
    """Peak memory of a command on this mesh [bytes]."""
    return BASE_BYTES + BYTES_PER_DOF * dof_count(elements, element_degree)


def available_memory() -> float | None:
    """Memory available to a new process [bytes] (MemAvailable of /proc/meminfo), or None if unknown."""
    try:
        with open("/proc/meminfo") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except OSError:
        pass
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_AVPHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return None


def ranks_on_this_machine() -> int:
    """The MPI ranks this process shares the machine with, itself included, as the process manager tells them
    (MPICH's MPI_LOCALNRANKS, Open MPI's OMPI_COMM_WORLD_LOCAL_SIZE); 1 outside mpiexec.  Each rank of a run, of
    ``mc`` or of ``optimize`` holds a model of its own."""
    for name in ("MPI_LOCALNRANKS", "OMPI_COMM_WORLD_LOCAL_SIZE"):
        if os.environ.get(name, "").isdigit():
            return max(int(os.environ[name]), 1)
    return 1


def check_memory(elements: int, element_degree: int) -> None:
    """Refuse, before allocating, a mesh whose estimated memory, once per rank on this machine
    (:func:`ranks_on_this_machine`), exceeds what the machine has free."""
    available = available_memory()
    if available is None:
        return
    ranks = ranks_on_this_machine()
    need = ranks * estimated_memory(elements, element_degree)
    budget = USABLE_SHARE * available
    if need > budget:
        per_element = BYTES_PER_DOF * dof_count(1000, element_degree) / 1000
        fits = max(int((budget / ranks - BASE_BYTES) / per_element), 0)
        on_ranks = f" on each of {ranks} ranks" if ranks > 1 else ""
        raise ResourceError(f"beam.elements = {elements} (degree {element_degree}) needs about "
                            f"{need / ranks / 1e9:.1f} GB{on_ranks}, more than the {available / 1e9:.1f} GB this "
                            f"machine has available: at most beam.elements = {fits} fits")


def check_disk(directory, need_bytes: float, what: str) -> None:
    """Refuse, before computing, an output that cannot fit in the free space of ``directory``'s file system
    (``what`` says which file and from which keys its size follows)."""
    import shutil

    probe = os.path.abspath(directory)
    while not os.path.exists(probe):
        probe = os.path.dirname(probe)
    free = shutil.disk_usage(probe).free
    if need_bytes > free:
        raise ResourceError(f"{what}: at least {need_bytes / 1e9:.3g} GB, needed, more than the {free / 1e9:.3g} GB free "
                            f"where {directory} is: free space, choose another --out, or shorten the run")

"""Choice of the reduced basis (Section 6.3, Table 4) from a classified modal basis."""

from __future__ import annotations

import numpy as np

from fenics_drill.modal import ModalBasis

FAMILIES = ("flexural", "torsional", "axial")


def paper_bands(length: float, longitudinal_wave_speed: float) -> dict[str, float]:
    """Section 6.3 as printed: flexural f* <= 5 L / c_L, torsional and axial f* <= 4."""
    return {"flexural": 5.0 * length / longitudinal_wave_speed, "torsional": 4.0, "axial": 4.0}


def select_modes(basis: ModalBasis, reduction: dict, length: float, longitudinal_wave_speed: float) -> np.ndarray:
    """Indices of the modes kept by ``reduction.rule`` (always including the rigid modes).

    'paper': the printed Section 6.3 bands; 'band': ``reduction.<family>`` is
    the f* upper bound per family; 'count': ``reduction.<family>`` is the number of
    lowest modes kept per family; 'none': every mode (the full model uses no basis).
    """
    rule = reduction["rule"]
    kinds = np.array(basis.kinds)
    keep = kinds == "rigid"
    if rule == "none":
        return np.arange(len(basis))
    if rule in ("paper", "band"):
        bands = paper_bands(length, longitudinal_wave_speed) if rule == "paper" else {
            f: reduction[f] for f in FAMILIES
        }
        for family in FAMILIES:
            keep |= (kinds == family) & (basis.f_star > 0) & (basis.f_star <= bands[family])
    elif rule == "count":
        for family in FAMILIES:
            members = np.flatnonzero(kinds == family)[: int(reduction[family])]
            keep[members] = True
    else:
        raise ValueError(f"unknown reduction rule {rule!r}")
    return np.flatnonzero(keep)


def family_counts(kinds) -> dict[str, int]:
    """Number of modes of each kind."""
    kinds = list(kinds)
    return {k: kinds.count(k) for k in ("rigid", *FAMILIES)}

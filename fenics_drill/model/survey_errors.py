"""The survey's uncertainty, as perturbed surveys: the systematic and global terms of an ISCWSA error model (through
welleng, an optional dependency: ``pip install fenics-drill[survey]``), and a tortuosity model.

An ISCWSA error model (Williamson 2000; the MWD models of Rev 4 and Rev 5) gives, for each error source, the error it
makes in each station's measured depth, inclination and azimuth at one standard deviation (welleng's ``e_DIA``).  A
source that is systematic (the same error at every station of a run: sensor biases and scale factors, misalignments,
the depth scale) or global (the same for every well: the declination, the depth reference) is drawn once per
realisation, z ~ N(0, 1), and moves every station by z e_DIA; the random terms, drawn anew at each station, are left
out: they are not the hole's real tortuosity, and sampled at every station they would add doglegs that inflate the
drag.  The real tortuosity is a model of its own: a sine of a stated amplitude and period on the inclination and the
azimuth, with a random phase per realisation, on stations a sixteenth of the period apart.
"""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass

import numpy as np

from fenics_drill.model.well import Survey
from fenics_drill.scene import SceneError

#: The error propagations a realisation draws once (the random ones are left out: module doc).
DRAWN_ONCE = ("systematic", "global", "well")


def welleng_installed() -> bool:
    return importlib.util.find_spec("welleng") is not None


def _welleng_survey(survey: Survey, model: str, field: tuple[float, float, float]):
    """welleng's survey of ``survey`` with the error ``model`` and the magnetic ``field`` (total [T], dip and
    declination [deg]); SceneError for a model welleng does not have, or without welleng."""
    if not welleng_installed():
        raise SceneError(f"risk.survey_error = {model!r} needs welleng, the optional dependency that implements the "
                         "ISCWSA error models: pip install 'fenics-drill[survey]' (or risk.survey_error = 'none')")
    import welleng

    models = welleng.error.get_error_models()
    if model not in models:
        iscwsa = ", ".join(repr(m) for m in models if m.startswith("ISCWSA"))
        raise SceneError(f"risk.survey_error = {model!r} is not an error model welleng knows; the ISCWSA ones are "
                         f"{iscwsa} (welleng.error.get_error_models() lists all)")
    total, dip, declination = field
    header = welleng.survey.SurveyHeader(b_total=total * 1e9, dip=dip, declination=declination, convergence=0.0,
                                         azi_reference="true", deg=True)
    return welleng.survey.Survey(md=survey.md, inc=np.degrees(survey.inclination), azi=np.degrees(survey.azimuth),
                                 header=header, error_model=model, deg=True)


@dataclass(frozen=True)
class SurveyErrors:
    """The stations' errors (depth [m], inclination and azimuth [rad]) at one standard deviation of each source a
    realisation draws once: ``terms`` (sources, stations, 3), named by ``names``."""

    names: tuple[str, ...]
    terms: np.ndarray

    @classmethod
    def of(cls, survey: Survey, model: str, field: tuple[float, float, float]) -> "SurveyErrors":
        errors = _welleng_survey(survey, model, field).err.errors.errors
        kept = [(name, np.asarray(error.e_DIA, dtype=float)) for name, error in errors.items()
                if error.propagation in DRAWN_ONCE]
        return cls(tuple(n for n, _ in kept), np.array([e for _, e in kept]).reshape(len(kept), survey.md.size, 3))

    def drawn(self, survey: Survey, rng: np.random.Generator) -> Survey:
        """The survey moved by one draw of every source."""
        moved = np.einsum("s,snk->nk", rng.standard_normal(len(self.names)), self.terms)
        md = survey.md + moved[:, 0]
        return Survey(np.maximum.accumulate(md), np.clip(survey.inclination + moved[:, 1], 0.0, np.pi),
                      survey.azimuth + moved[:, 2])


def iscwsa_covariance(survey: Survey, model: str, field: tuple[float, float, float]) -> np.ndarray:
    """The position covariance (north, east, vertical) [m^2] at each station of every source of the error model
    (random ones included), as ISCWSA's example workbooks tabulate it (stations, 3, 3)."""
    return np.asarray(_welleng_survey(survey, model, field).err.errors.cov_NEVs, dtype=float)


def tortuous(survey: Survey, amplitude_deg: float, period: float, rng: np.random.Generator) -> Survey:
    """``survey`` with a sine of ``amplitude_deg`` and ``period`` [m] on its inclination and its azimuth (their
    phases drawn from ``rng``), on stations a sixteenth of the period apart (the survey's stations kept)."""
    if amplitude_deg == 0.0:
        return survey
    md = np.union1d(survey.md, np.arange(survey.md[0], survey.md[-1], period / 16.0))
    phase = rng.uniform(0.0, 2.0 * np.pi, 2)
    wave = np.radians(amplitude_deg) * np.sin(2.0 * np.pi * (md - survey.md[0]) / period + phase[:, None])
    inclination = np.interp(md, survey.md, survey.inclination) + wave[0]
    azimuth = np.interp(md, survey.md, np.unwrap(survey.azimuth)) + wave[1]
    return Survey(md, np.abs(inclination), azimuth)

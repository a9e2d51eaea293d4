"""Random bit-rock parameters (Section 5): maximum-entropy laws built from a mean and a dispersion.

* alpha_BR and Gamma_BR: gamma laws (81), (86), shape 1/delta^2 and scale m delta^2,
  admissible for 0 <= delta < 1/sqrt(2) (the inverse must be of second order).
* mu_BR: beta law (90) on [0, 1] with (91)-(92): a = (1 - m)/delta^2 - m, b = a (1/m - 1),
  admissible for 0 < m < 1 and a, b > 0, i.e. delta^2 < (1 - m)/m.

delta is the coefficient of variation sigma / m.  delta = 0 gives the mean itself.
Realisation k of a study draws from ``numpy.random.default_rng([seed, k])``, so it
does not depend on which process computes it or in which order.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import stats

#: scene key of each random parameter's dispersion -> the bit_rock key of its mean.
PARAMETERS = {"rate_dispersion": "rate", "limit_force_dispersion": "limit_force", "friction_dispersion": "friction"}
GAMMA_LIMIT = 1.0 / math.sqrt(2.0)


class InadmissibleLaw(ValueError):
    """A mean and dispersion that define no admissible law."""


def gamma_law(mean: float, dispersion: float, name: str):
    """Gamma law (81)/(86) of mean ``mean`` and coefficient of variation ``dispersion``."""
    if mean <= 0:
        raise InadmissibleLaw(f"the mean of {name} must be > 0 for its gamma law, got {mean!r}")
    if not 0 <= dispersion < GAMMA_LIMIT:
        raise InadmissibleLaw(f"the dispersion of {name} must be in [0, 1/sqrt(2)) = [0, {GAMMA_LIMIT:.4f}) "
                              f"for its gamma law (81)/(86), got {dispersion!r}")
    if dispersion == 0:
        return None
    return stats.gamma(a=1.0 / dispersion**2, scale=mean * dispersion**2)


def beta_law(mean: float, dispersion: float, name: str):
    """Beta law (90)-(92) on [0, 1] of mean ``mean`` and coefficient of variation ``dispersion``."""
    if not 0 < mean < 1:
        raise InadmissibleLaw(f"the mean of {name} must be in (0, 1) for its beta law (90), got {mean!r}")
    if dispersion < 0:
        raise InadmissibleLaw(f"the dispersion of {name} must be >= 0, got {dispersion!r}")
    if dispersion == 0:
        return None
    a = (1.0 - mean) / dispersion**2 - mean  # (91)
    b = a * (1.0 / mean - 1.0)  # (92)
    if a <= 0 or b <= 0:
        limit = math.sqrt((1.0 - mean) / mean)
        raise InadmissibleLaw(f"the dispersion of {name} must be < sqrt((1 - m)/m) = {limit:.4f} for mean "
                              f"m = {mean!r}, so that the beta parameters (91)-(92) are positive; got {dispersion!r}")
    return stats.beta(a, b)


class BitRockLaws:
    """The joint law of (alpha_BR, Gamma_BR, mu_BR), independent components."""

    def __init__(self, bit_rock, uncertainty):
        """``bit_rock``, ``uncertainty``: the scene's sections (means and dispersions)."""
        self.means = {key: getattr(bit_rock, key) for key in PARAMETERS.values()}
        self.laws = {
            "rate": gamma_law(bit_rock.rate, uncertainty.rate_dispersion, "bit_rock.rate"),
            "limit_force": gamma_law(bit_rock.limit_force, uncertainty.limit_force_dispersion, "bit_rock.limit_force"),
            "friction": beta_law(bit_rock.friction, uncertainty.friction_dispersion, "bit_rock.friction"),
        }
        self.seed = uncertainty.seed

    def sample(self, k: int) -> dict:
        """The bit_rock parameters of realisation k."""
        rng = np.random.default_rng([self.seed, k])
        return {key: float(law.rvs(random_state=rng)) if law is not None else self.means[key]
                for key, law in self.laws.items()}

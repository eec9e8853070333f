r"""The mechanism behind the findings, computed (``kicktimes reproduce --study science``).

Writes ``science.md`` (every statement with its number, interval and verdict), its
tables ``science_*.csv`` and its figure, from the paper study's stores (``family_a``,
``family_b``) and findings tables, and from simulations of its own:

1. **Stretching per perturbation** (`stretching`), radii 0.002-0.03: a dedicated FTLE
   sweep (the paper's family-A setup, 100 ICs). Per radius the stretching
   :math:`s = \bar\lambda / \hat\Gamma` of each system (mean FTLE over ICs over the
   pooled perturbation rate, in nats per perturbation), the kicked / two-disk ratio with
   its `kicktimes.stats.ratio_verdict`, and the trend of the ratio against
   :math:`\ln(1/r)` (a bootstrap CI of its least-squares slope against 0). The line
   :math:`s = a + b \ln(1/r)` is reported over its fitted range only.
2. **Twins with independent kick angles** (`independent_angle_twin`): the Benettin
   twin that draws its own kick angles, beside the estimate
   :math:`\Gamma \ln(\tau / d_0)` and the two-disk stretching.
3. **Decorrelation per single perturbation** (`decorrelation`) under both collision
   rules: the correlation :math:`c` of the boundary angle at the wall hits just before
   and just after one disk-disk collision, one uniform kick, one scatter kick; the
   ratio :math:`(1 - c_{kick}) / (1 - c_{coll})` it predicts for
   :math:`(1 - R_1)_{kicked} / (1 - R_1)_{two}`, beside the ratio measured by the paper
   study (`prediction_against_measurement`); which kick law comes closest
   (`closest_kick_law`).
4. **The collision rate over the run** (`rate_relaxation`) of the paper's ICs against
   the kinetic rate :math:`\Gamma(r)`, per window and per radius, from the stores.
5. **The sticky orbits** (`sticky_orbits`): runs above 5 :math:`\Gamma(r)` and their
   initial angular momenta.

Modules: `stretching` (the sweep and its statistics), `twins`, `decorrelation`, `rates`
(sections 4 and 5), `figures`, `page` (the Markdown sections) and `run` (`reproduce`,
the scales and the cache).

References
----------
Ranković, S. and Porter, M. A. (2013), "Two-particle circular billiards versus randomly
perturbed one-particle circular billiards", Chaos 23, 013123 (the systems and the FTLE
of its eq. (4)). Benettin, G. et al. (1980), Meccanica 15, 9 (the twin renormalisation).

Examples
--------
>>> from kicktimes.studies.science import SCALES, reproduce
>>> SCALES["paper"].n_ics, SCALES["paper"].radii[0]
(100, 0.002)
>>> reproduce("unused", scale="huge")
Traceback (most recent call last):
...
ValueError: scale must be one of 'paper', 'quick', got 'huge'
"""

from __future__ import annotations

from kicktimes.studies.science.decorrelation import (
    closest_kick_law,
    decorrelation,
    prediction_against_measurement,
)
from kicktimes.studies.science.figures import stretching_figure
from kicktimes.studies.science.rates import rate_relaxation, sticky_orbits
from kicktimes.studies.science.run import SCALES, ScienceScale, find_stores, reproduce
from kicktimes.studies.science.stretching import stretching, stretching_experiment
from kicktimes.studies.science.twins import independent_angle_twin, twin_table, twins_raw

__all__ = ["SCALES", "ScienceScale", "closest_kick_law", "decorrelation", "find_stores",
           "independent_angle_twin", "prediction_against_measurement", "rate_relaxation",
           "reproduce", "stretching", "stretching_experiment", "stretching_figure",
           "sticky_orbits", "twin_table", "twins_raw"]

r"""Why the collision times are not Poisson (``kicktimes reproduce --study mechanism``).

Between collisions each disk's angular momentum about the table's centre,
:math:`L = x v_y - y v_x`, is conserved, so the pair collides at a rate
:math:`\Gamma(r; L_0, L_1)` (`kicktimes.stats.conditional_kinetic_rate`) that is reset at
every collision; under the elastic rule it depends on the speeds as well. The study
simulates two-disk runs with their collision logs (radii 0.01 and 0.02, paper ICs and
invariant-measure ICs, the same ICs at both radii) under the mirror and the elastic rule
and measures, per group (`analysis.analyse`):

1. the hazard of the interval to the next collision against the time since the last,
   in raw time, in each run's own time unit and in the time rescaled by the predicted
   rate (`kicktimes.stats.interval_hazard`): a flat hazard is a Poisson process;
2. the share of re-collisions (at most one wall hit of each disk since the previous
   collision) against randomly placed events at the same rate;
3. each IC's predicted rate against its observed rate, the pooled interval law as a
   mixture over the post-collision angular momenta against the fitted hyperexponential;
4. the Poisson battery on Cox twins (the rate redrawn at every event from the run's own
   states, or from a Markov chain of the rate fitted on the other half of the ICs), and
   the share of the observed excess over a Poisson process each reproduces.

It writes ``mechanism.md`` with, per rule, ``mechanism_numbers.csv`` (every number the
page quotes) and the figures in ``mechanism/`` and ``mechanism/elastic/``. Definitions:
docs/mechanism.md.

Modules: `simulate` (the runs), `twins` (the rate, the twin processes, the battery),
`analysis` (the numbers of a group), `figures`, `page`, `run` (`reproduce`, the scales
and the cache).

References
----------
Ranković, S. and Porter, M. A. (2013), "Two-particle circular billiards versus randomly
perturbed one-particle circular billiards", Chaos 23, 013123. Cox, D. R. (1955), "Some
statistical methods connected with series of events", J. R. Stat. Soc. B 17, 129 (doubly
stochastic Poisson processes).

Examples
--------
>>> from kicktimes.studies.mechanism import SCALES, reproduce
>>> SCALES["paper"].n_ics, SCALES["paper"].t_max, SCALES["paper"].twins
(200, 2000.0, 20)
>>> reproduce("unused", workers=0)
Traceback (most recent call last):
...
ValueError: workers must be an integer >= 1, got 0
"""

from __future__ import annotations

from kicktimes.studies.mechanism.analysis import analyse, cell_rows, state_rates
from kicktimes.studies.mechanism.page import write_page
from kicktimes.studies.mechanism.run import RULES, SCALES, MechanismScale, reproduce, run_rule
from kicktimes.studies.mechanism.simulate import METHODS, RADII, simulate
from kicktimes.studies.mechanism.twins import draw_rate_chains, fit_rate_chain, rate

__all__ = ["METHODS", "RADII", "RULES", "SCALES", "MechanismScale", "analyse", "cell_rows",
           "draw_rate_chains", "fit_rate_chain", "rate", "reproduce", "run_rule", "simulate",
           "state_rates", "write_page"]

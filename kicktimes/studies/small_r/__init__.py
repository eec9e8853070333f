r"""The paper's premise at its limit r -> 0 (``kicktimes reproduce --study small_r``).

Ranković & Porter expect a kicked disk to stand in for the second disk of a two-disk
billiard when the disks are small. This study settles what happens as r -> 0, by theory
and by simulation, and writes ``small_r.md`` with its tables ``small_r_*.csv`` and its
figure:

1. **The theory** (`kicktimes.diagnostics.low_density`): the stretching per perturbation
   :math:`\lambda/\Gamma = b\ln(1/r) + a + o(1)`, with b = 2 for a disk-disk collision or a
   scattering kick (the contact normal's :math:`1/\sigma` and the flight time
   :math:`\sim 1/\Gamma`) and b = 1 for a uniform kick (no :math:`1/\sigma`), and a from a
   Monte Carlo of the product of the rank-one maps; so the kicked / two-disk FTLE ratio
   tends to 1/2 for uniform kicks and to 1 for scattering kicks.
2. **The sweep** (`sweep`): the tangent-space FTLE of the two disks and of four kicked
   systems (uniform or scattering kicks, at the IC's two-disk rate or at the disk's own
   kinetic rate) at r = 1e-4 ... 3e-2, 100 invariant-measure ICs per radius and rule,
   each run over 10^4 collisions (horizon 10^4 / Γ(r)), both collision rules; one
   resumable store per (rule, radius), on a local pool or Dask.
3. **The comparison** (`tables`): measured against predicted λ/Γ per cell, the ratio
   against r beside the theory's ratio and its limit, and the ratio under its controls.

Modules: `sweep`, `tables`, `figures`, `page` and `run` (`reproduce`, the scales).

Examples
--------
>>> from kicktimes.studies.small_r import SCALES
>>> SCALES["paper"].radii[0], SCALES["paper"].n_ics, SCALES["paper"].collisions
(0.0001, 100, 10000)
"""

from __future__ import annotations

from kicktimes.studies.small_r.figures import small_r_figure
from kicktimes.studies.small_r.run import RULES, SCALES, SmallRScale, reproduce
from kicktimes.studies.small_r.sweep import (
    load_sweep,
    run_sweep,
    seconds_per_ic,
    small_r_experiment,
)
from kicktimes.studies.small_r.tables import (
    against_theory,
    findings,
    measured,
    per_ic,
    ratio_table,
    theory_table,
)

__all__ = ["RULES", "SCALES", "SmallRScale", "against_theory", "findings", "load_sweep",
           "measured", "per_ic", "ratio_table", "reproduce", "run_sweep", "seconds_per_ic",
           "small_r_experiment", "small_r_figure", "theory_table"]

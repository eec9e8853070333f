r"""The N-disk engine's equation of state as its standing check (``kicktimes reproduce
--study eos``).

Hard disks in the periodic box under the elastic rule, at area fractions 0.05 to 0.68 (the
dense fluid, below the liquid-hexatic transition), N = 10^4 with N = 10^3 as the
finite-size control. It writes ``eos.md`` with its tables ``eos_*.csv`` and its figure:

* **Z** from the collisional virial against the virial series to :math:`B_{10}` at
  :math:`\varphi \le 0.4` and against Kolafa & Rottner's equation of state above
  (`kicktimes.stats.eos`), each within 0.1 % (plus the reference's own accuracy), read on
  3-standard-error intervals over independent states;
* **the collision frequency** against Enskog's with :math:`g(\sigma) = (Z - 1)/(2\varphi)`
  from the same run's Z: an identity of equilibrium, so the engine checked against itself;
* **finite size and equilibration**, measured: Z at N = 10^3 over Z at 10^4, the second
  half of each run over its first.

Modules: `run` (`reproduce`, `run_cell`, the scales), `tables`, `page` (and the figure).

Examples
--------
>>> from kicktimes.studies.eos import SCALES
>>> SCALES["paper"].sizes, SCALES["paper"].packings[-1]
((10000, 1000), 0.68)
"""

from __future__ import annotations

from kicktimes.studies.eos.page import eos_figure
from kicktimes.studies.eos.run import PACKINGS, SCALES, EosScale, reproduce, run_cell
from kicktimes.studies.eos.tables import (
    eos_table,
    finite_size,
    frequency_table,
    halves_table,
    reference_margin,
)

__all__ = ["PACKINGS", "SCALES", "EosScale", "eos_figure", "eos_table", "finite_size",
           "frequency_table", "halves_table", "reference_margin", "reproduce", "run_cell"]

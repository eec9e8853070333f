"""From two disks to a gas (``kicktimes reproduce --study disks``).

The tagged disk's collision times among N equal hard disks in the circular table, from
N = 2 to 1000 (`kicktimes.experiment.DISKS_PRESETS`, their controls and the two-disk
references): `tables` (the per-N tables: Poisson battery, dispersion, hazard, Enskog's
rate, the kicked comparison), `controls` (every finding under the controls), `renewal`
(renewal models by AIC), `kicked` (the kicked comparison's sections), `ftle_check` (the
gas's FTLE: tangent vectors against a twin, the engine's N = 2 against the two-disk
simulator), `density` (the gas's FTLE against density, the kinetic-theory form), `null`
(null streams shaped like the runs: Poisson and the dilute tagged disk, the gas rows of
``null_calibration.csv``), `readings` (the one reading of "Poisson", `stats.poisson_verdict`
against the calibrated level, and the page's first screen), `figures`,
`page` (``disks.md``) and `run` (`reproduce_disks`: the sweeps and the FTLE computations,
run or resumed from the work folder, then the page; `reproduce` at the quick or the paper
scale).

Examples
--------
>>> from kicktimes.studies.disks import disks_table, reproduce_disks
>>> callable(disks_table) and callable(reproduce_disks)
True
"""

from __future__ import annotations

from kicktimes.studies.disks.figures import (
    controls_figure,
    hazard_figure,
    rates_figure,
    rejection_figure,
)
from kicktimes.studies.disks.page import write_disks_page
from kicktimes.studies.disks.run import QUICK_N, quick_experiment, reproduce, reproduce_disks
from kicktimes.studies.disks.tables import (
    disks_hazard,
    disks_table,
    kicked_table,
    rescale_by_speed,
    two_disk_check,
)

__all__ = ["QUICK_N", "controls_figure", "disks_hazard", "disks_table", "hazard_figure",
           "kicked_table", "quick_experiment", "rates_figure", "rejection_figure",
           "rescale_by_speed", "reproduce", "reproduce_disks",
           "two_disk_check", "write_disks_page"]

r"""The paper's comparison beyond the circle (``kicktimes reproduce --study tables``).

Ranković & Porter's premise is that a kicked disk stands in for the second disk of a
two-disk billiard whose wall is integrable (the circle), where only the disk-disk
collisions scatter. This study asks whether the kicked disk's FTLE deficit depends on
that integrability: it runs the paper's comparison (two disks; one disk kicked uniformly
at Poisson times, at the two disks' collision times, or by scattering kicks) in the
circle, in an ellipse (integrable for a point, nearly so for a disk) and in Bunimovich's
stadium (chaotic), under both collision rules, and writes ``tables.md`` with its tables
``tables_*.csv`` and its figure:

1. **The sweep** (`sweep`): one store per (table, rule), the paper's family A protocol
   with 200 invariant-measure ICs at r = 0.01, 0.02, 0.03, and its sweep report.
2. **The comparisons** (`compare`): the report's findings per table (FTLE, recurrence,
   1 − R₁, the Poisson question, the counts) under their controls, each table's FTLE
   ratio over the circle's, each system's FTLE over the free disk's.
3. **The free disk** (`one_disk`): its own FTLE in each table and the drift of the
   ellipse's focal integral.

Modules: `sweep`, `one_disk`, `compare`, `figures`, `page` and `run` (`reproduce`, the
scales).

Examples
--------
>>> from kicktimes.studies.tables import SCALES, TABLES
>>> SCALES["paper"].n_ics, sorted(TABLES)
(200, ['circle', 'ellipse', 'stadium'])
"""

from __future__ import annotations

from kicktimes.studies.tables.compare import (
    against_circle,
    against_free,
    elastic_speeds,
    findings,
    mean_ftle,
    null_levels,
    per_ic,
)
from kicktimes.studies.tables.figures import tables_figure
from kicktimes.studies.tables.one_disk import focal_drift, focal_product, free_ftle, free_runs
from kicktimes.studies.tables.run import SCALES, TablesScale, reproduce
from kicktimes.studies.tables.sweep import (
    RADII,
    RULES,
    TABLES,
    family_name,
    run_stores,
    tables_experiment,
)

__all__ = ["RADII", "RULES", "SCALES", "TABLES", "TablesScale", "against_circle",
           "against_free", "elastic_speeds", "family_name", "findings", "focal_drift",
           "focal_product", "free_ftle", "free_runs", "mean_ftle", "null_levels", "per_ic",
           "reproduce", "run_stores", "tables_experiment", "tables_figure"]

"""Billiard tables beyond the circle: ``kicktimes.tables.Circle()``, ``Stadium(a)``,
``Ellipse(a, b)``, and the free one-disk billiard in any of them.

The public home of `kicktimes.billiard.tables` (docs/tables.md); see there.
"""

from kicktimes.billiard.tables import (
    Circle,
    Ellipse,
    Stadium,
    TableLyapunov,
    TableRun,
    free_run,
    table_lyapunov,
    uniform_state,
)

__all__ = ["Circle", "Ellipse", "Stadium", "TableLyapunov", "TableRun", "free_run",
           "table_lyapunov", "uniform_state"]

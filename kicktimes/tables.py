"""Billiard tables beyond the circle: ``kicktimes.tables.Circle()``, ``Stadium(a)``,
``Ellipse(a, b)``, and the free one-disk billiard in any of them.

The public home of `kicktimes.billiard.tables` (docs/tables.md); see there.
"""

from kicktimes.billiard.tables import (
    TABLE_KINDS,
    Circle,
    Ellipse,
    Stadium,
    TableLyapunov,
    TableRun,
    check_table,
    free_run,
    parse_table,
    table_lyapunov,
    table_spec,
    uniform_state,
)

__all__ = ["TABLE_KINDS", "Circle", "Ellipse", "Stadium", "TableLyapunov", "TableRun",
           "check_table", "free_run", "parse_table", "table_lyapunov", "table_spec",
           "uniform_state"]

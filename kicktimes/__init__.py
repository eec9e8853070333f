"""kicktimes: statistics of collision-time processes in circular billiards.

Two equal hard disks in the unit circular table, the times of their mutual
collisions, and randomly kicked one-disk billiards driven by those times
(Ranković & Porter, Chaos 2013).

The main entry points::

    from kicktimes import simulate_two_particle, simulate_one_particle, initial_conditions
    from kicktimes import KickLaw                         # a kicked disk's kick law
    from kicktimes import simulate_disks, initial_state   # N disks (docs/disks.md)
    from kicktimes import schedules, stats, diagnostics
    from kicktimes.tables import Stadium, Ellipse, free_run   # tables beyond the circle

Subpackages are imported lazily, so ``import kicktimes`` stays cheap.
"""

from __future__ import annotations

import importlib

__version__ = "0.1.0"

_LAZY_ATTRS = {
    "simulate_two_particle": ("kicktimes.billiard.two_particle", "simulate_two_particle"),
    "simulate_one_particle": ("kicktimes.billiard.one_particle", "simulate_one_particle"),
    "initial_conditions": ("kicktimes.billiard.initial", "initial_conditions"),
    "TwoParticleRun": ("kicktimes.billiard.runs", "TwoParticleRun"),
    "OneParticleRun": ("kicktimes.billiard.runs", "OneParticleRun"),
    "read_run": ("kicktimes.billiard.runs", "read_run"),
    "simulate_disks": ("kicktimes.billiard.many_disks", "simulate_disks"),
    "initial_state": ("kicktimes.billiard.disk_states", "initial_state"),
    "DisksRun": ("kicktimes.billiard.disks_run", "DisksRun"),
    "DisksPressure": ("kicktimes.billiard.disks_run", "DisksPressure"),
    "box_side": ("kicktimes.billiard.disk_states", "box_side"),
    "KickLaw": ("kicktimes.billiard.kick_law", "KickLaw"),
}
_LAZY_MODULES = {"billiard", "schedules", "stats", "diagnostics", "experiment", "plots", "report",
                 "tables"}

__all__ = sorted([*_LAZY_ATTRS, *_LAZY_MODULES, "__version__"])


def __getattr__(name: str):
    if name in _LAZY_ATTRS:
        module, attr = _LAZY_ATTRS[name]
        value = getattr(importlib.import_module(module), attr)
    elif name in _LAZY_MODULES:
        value = importlib.import_module(f"kicktimes.{name}")
    else:
        raise AttributeError(f"module 'kicktimes' has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__():
    return __all__

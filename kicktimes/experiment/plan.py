"""The plan of a sweep: its tasks (one radius x one block of ICs), from the experiment's
fields alone.

Apart from :mod:`kicktimes.experiment.tasks` (which runs a task) and from
:mod:`kicktimes.experiment.config` (which defines the experiment), so that the experiment
can list its tasks without the two importing each other.
"""

from __future__ import annotations

from dataclasses import dataclass

from kicktimes._results import Result

__all__ = ["Task", "make_tasks"]


@dataclass(frozen=True)
class Task(Result):
    """One unit of work: radius ``radii[radius_index]`` and ICs ``ic_start .. ic_stop - 1``."""

    _title = "One task of a sweep"

    radius_index: int
    radius: float
    ic_start: int
    ic_stop: int

    def _summary_extra(self) -> list[str]:
        return [f"id: {self.id}, {self.n_ics} IC(s)"]

    @property
    def id(self) -> str:
        """Stable name, e.g. ``"r003-ic000050-000100"`` (used for part files)."""
        return f"r{self.radius_index:03d}-ic{self.ic_start:06d}-{self.ic_stop:06d}"

    @property
    def n_ics(self) -> int:
        return self.ic_stop - self.ic_start


def make_tasks(experiment) -> list[Task]:
    """Every task of ``experiment`` (an `Experiment`), radius-major then by IC block."""
    out = []
    for ri, r in enumerate(experiment.radii):
        for start in range(0, experiment.n_ics, experiment.block_size):
            out.append(Task(ri, r, start, min(start + experiment.block_size, experiment.n_ics)))
    return out

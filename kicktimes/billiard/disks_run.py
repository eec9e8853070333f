"""The record of an N-disk run (`kicktimes.simulate_disks`): `DisksRun`."""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import pandas as pd

from kicktimes import __version__
from kicktimes.fileio import atomic_write

__all__ = ["DisksRun"]


@dataclass(frozen=True, repr=False)
class DisksRun:
    """N hard disks in the unit circular table: their collision log and final state.

    Attributes
    ----------
    radii : ndarray, shape (n_disks,)
        The disks' radii.
    rule : str
        ``"mirror"`` or ``"elastic"``.
    t_max : float
        The run's end; every collision in ``[0, t_max]`` is logged.
    state, final_state : ndarray, shape (n_disks, 4)
        Rows ``(x, y, vx, vy)`` at time 0 and at ``t_max`` (an escaped disk: at its escape,
        on the wall).
    pp_times, pp_i, pp_j : ndarray
        The disk-disk collisions: time (increasing), the two disks (``i < j``); as a
        table, `collisions`.
    n_events : int
        All collisions, disk-disk and wall.
    n_wall : int
        Wall collisions (escapes included).
    masses : ndarray or None
        The masses (elastic rule), ``None``: equal.
    holes : ndarray or None
        Rows ``(centre angle, half-width)`` of the holes in the wall.
    escape_times : ndarray, shape (n_disks,)
        When each disk left through a hole (``inf``: it did not).
    sample : ndarray or None
        The disks whose positions are sampled (``tau``) and wall hits logged (``log_walls``).
    tau : float or None
        Sampling step; ``sample_times`` (``k tau``) and ``samples`` (shape
        ``(n_samples, len(sample), 2)``, NaN after an escape).
    wall_log : tuple or None
        ``(time, disk, x, y, sin_theta)`` of the wall hits of ``sample`` (``log_walls``); as
        a table, `walls`.
    engine : dict
        The engine's counts: cell crossings, stale events, cells per side.
    """

    radii: np.ndarray
    rule: str
    t_max: float
    state: np.ndarray
    final_state: np.ndarray
    pp_times: np.ndarray
    pp_i: np.ndarray
    pp_j: np.ndarray
    n_events: int
    n_wall: int
    masses: np.ndarray | None = None
    holes: np.ndarray | None = None
    escape_times: np.ndarray | None = None
    sample: np.ndarray | None = None
    tau: float | None = None
    sample_times: np.ndarray | None = None
    samples: np.ndarray | None = None
    wall_log: tuple | None = None
    engine: dict = field(default_factory=dict)
    version: str = field(default=__version__)

    @property
    def n_disks(self) -> int:
        return int(self.radii.shape[0])

    @property
    def n_pp(self) -> int:
        """Number of disk-disk collisions in ``[0, t_max]``."""
        return int(self.pp_times.shape[0])

    @property
    def collision_frequency(self) -> float:
        """Disk-disk collisions per disk per unit time, ``2 n_pp / (n_disks t_max)`` (each
        collision counts for both disks; escaped disks count for their whole run)."""
        return 2.0 * self.n_pp / (self.n_disks * self.t_max) if self.t_max > 0 else math.nan

    @cached_property
    def collisions(self) -> pd.DataFrame:
        """The disk-disk collisions: columns ``time``, ``i``, ``j`` (``i < j``), by time."""
        return pd.DataFrame({"time": self.pp_times, "i": self.pp_i, "j": self.pp_j})

    def collision_times(self, k: int) -> np.ndarray:
        """The times of disk ``k``'s collisions with other disks, increasing."""
        if isinstance(k, bool) or not isinstance(k, int | np.integer):
            raise TypeError(f"k must be an integer disk index, got {type(k).__name__}")
        if not 0 <= k < self.n_disks:
            raise ValueError(f"k must lie in [0, {self.n_disks - 1}], got {k}")
        return self.pp_times[(self.pp_i == k) | (self.pp_j == k)]

    @cached_property
    def walls(self) -> pd.DataFrame | None:
        """Wall hits of the sampled disks (``log_walls=True``): ``time``, ``disk``, ``s``
        (the contact's polar angle in ``[0, 2 pi)``), ``sin_theta`` (the incoming velocity's
        tangential component over its speed); ``None`` if not logged."""
        if self.wall_log is None:
            return None
        t, d, x, y, st = self.wall_log
        s = np.arctan2(y, x)
        s[s < 0.0] += 2.0 * np.pi
        s[s >= 2.0 * np.pi] = 0.0
        return pd.DataFrame({"time": t, "disk": d, "s": s, "sin_theta": st})

    @property
    def escaped(self) -> np.ndarray:
        """The disks that left the table, in order of their escape."""
        if self.escape_times is None:
            return np.empty(0, dtype=np.int64)
        out = np.flatnonzero(np.isfinite(self.escape_times))
        return out[np.argsort(self.escape_times[out], kind="stable")]

    @property
    def meta(self) -> dict:
        """The run's parameters, JSON-serialisable."""
        return {"kind": "disks", "n_disks": self.n_disks, "rule": self.rule,
                "t_max": self.t_max, "n_pp": self.n_pp, "n_events": self.n_events,
                "n_wall": self.n_wall, "r": self.radii.tolist() if np.ptp(self.radii) > 0
                else float(self.radii[0]), "masses": None if self.masses is None
                else self.masses.tolist(), "holes": None if self.holes is None
                else self.holes.tolist(), "version": self.version}

    def to_parquet(self, path: str | os.PathLike) -> None:
        """Write the collision log (``time, i, j``) to a Parquet file, atomically, with the
        run's parameters (`meta`) in the schema's metadata under ``kicktimes``."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        table = pa.table({"time": self.pp_times, "i": self.pp_i, "j": self.pp_j})
        table = table.replace_schema_metadata({b"kicktimes": json.dumps(self.meta).encode()})
        atomic_write(path, lambda tmp: pq.write_table(table, tmp))

    def __repr__(self) -> str:
        r = (f"r={float(self.radii[0])!r}" if np.ptp(self.radii) == 0
             else f"r in [{self.radii.min():.4g}, {self.radii.max():.4g}]")
        esc = f", escaped={int(np.isfinite(self.escape_times).sum())}" if self.holes is not None \
            else ""
        return (f"DisksRun(n_disks={self.n_disks}, {r}, rule={self.rule!r}, t_max={self.t_max!r}, "
                f"n_pp={self.n_pp}, n_events={self.n_events}{esc})")

"""The record of an N-disk run (`kicktimes.simulate_disks`): `DisksRun`, and its pressure,
`DisksPressure`."""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import pandas as pd

from kicktimes import __version__
from kicktimes._results import TableResult, nan_reason
from kicktimes.billiard.tables import Circle, table_spec
from kicktimes.fileio import atomic_write

__all__ = ["DisksPressure", "DisksRun"]


@dataclass(frozen=True)
class DisksPressure:
    r"""Compressibility factors :math:`Z = P A / (N kT)` of an N-disk run (`DisksRun.pressure`).

    Attributes
    ----------
    z_wall, z_virial, z_bulk : float
        From the wall's impulse (the table only, else NaN), the collisional virial, and the
        central region's collisions and density.
    se_wall, se_virial, se_bulk : float
        Their standard errors from ``blocks`` consecutive blocks of the run
        (:math:`s / \sqrt{B}`, ``s`` the blocks' standard deviation).
    packing : float
        The area fraction of the whole: ``sum r^2`` in the unit table (area pi), ``pi sum
        r^2 / L^2`` in the box.
    bulk_packing : float
        The central region's own time-averaged area fraction :math:`n_b \pi r^2`.
    henderson : float
        Henderson's :math:`Z` at ``bulk_packing`` (`kicktimes.stats.henderson_z`), for
        comparison.
    kT : float
        The mean kinetic energy per disk, :math:`\sum m |v|^2 / (2N)`.
    blocks : int
        The blocks of the standard errors.
    """

    z_wall: float
    z_virial: float
    z_bulk: float
    se_wall: float
    se_virial: float
    se_bulk: float
    packing: float
    bulk_packing: float
    henderson: float
    kT: float
    blocks: int

    @property
    def reason(self) -> str | None:
        """Why an estimate is NaN (None when all are defined): the wall's needs a wall."""
        if math.isfinite(self.z_wall):
            return nan_reason([self.z_virial, self.z_bulk])
        return "the periodic box has no wall: z_wall is undefined"

    def summary(self) -> str:
        """One line per estimate, with its standard error and Henderson's beside it."""
        def row(name, z, se):
            return f"Z {name:<7} {z:.5f} +- {se:.5f}"
        lines = [row("wall", self.z_wall, self.se_wall)] if math.isfinite(self.z_wall) else []
        lines += [row("virial", self.z_virial, self.se_virial),
                  row("bulk", self.z_bulk, self.se_bulk)
                  + f"  (bulk packing {self.bulk_packing:.5f})",
                  f"Z Henderson {self.henderson:.5f} at the bulk packing; kT = {self.kT:.6g}, "
                  f"{self.blocks} blocks"]
        return "\n".join(lines)


@dataclass(frozen=True, repr=False)
class DisksRun(TableResult):
    """N hard disks in a table (the unit circle, a stadium, an ellipse) or a periodic box:
    their collision log and final state.

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
    box : float or None
        The side ``L`` of the periodic square box ``[0, L)^2``; ``None``: the unit table.
    bulk_radius : float or None
        The table's central region (centres within ``bulk_radius``) of `pressure`'s bulk
        estimate; ``None`` in the box (the whole box).
    pressure_log : ndarray, shape (n_samples, 5) or None
        Rows ``(t, centres in the central region, wall impulse, virial, region's virial)``:
        the engine's running sums at ``t`` (`pressure`).
    table : Circle, Stadium, Ellipse or None
        The table (`kicktimes.tables`); ``None`` in the periodic box.
    """

    _title = "N hard disks (simulate_disks): the collision log"
    _summary_fields = ("n_disks", "radii", "rule", "t_max", "n_pp", "n_events", "n_wall", "box",
                       "table", "tau")
    _frame = "collisions"

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
    box: float | None = None
    bulk_radius: float | None = None
    pressure_log: np.ndarray | None = None
    table: object = None
    version: str = field(default=__version__)

    def _summary_extra(self) -> list[str]:
        if self.holes is None:
            return []
        return [f"escaped: {int(np.isfinite(self.escape_times).sum())} of {self.n_disks} "
                f"through {len(self.holes)} hole(s)"]

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

    @property
    def kT(self) -> float:
        r"""The mean kinetic energy per disk at the end, :math:`\sum_i m_i |v_i|^2 / (2N)`
        (masses 1 unless given; conserved by both rules)."""
        m = np.ones(self.n_disks) if self.masses is None else self.masses
        v2 = self.final_state[:, 2] ** 2 + self.final_state[:, 3] ** 2
        return float(np.sum(m * v2) / (2.0 * self.n_disks))

    def pressure(self, *, blocks: int = 10) -> DisksPressure:
        r"""The compressibility factor :math:`Z = P A / (N kT)` three ways, with errors.

        Parameters
        ----------
        blocks : int
            Consecutive blocks of the run for the standard errors (``2 <= blocks``, at most
            the rows of ``pressure_log`` less one).

        Returns
        -------
        DisksPressure
            ``z_wall``, ``z_virial``, ``z_bulk`` with standard errors, ``bulk_packing``,
            Henderson's :math:`Z` there.

        Raises
        ------
        ValueError
            For the pressure of a mirror run in the box (no momentum conservation: below),
            of a table with unequal radii (each disk's centre has its own room), of a run
            whose disks escaped, or of a run without a pressure log (``blocks``: too few
            rows).

        Notes
        -----
        With :math:`kT = \sum m|v|^2/(2N)` (two dimensions), :math:`T` = ``t_max`` and the
        engine's sums over the run (`kicktimes.billiard.kernels.disks.collide`):

        * **wall** (the table): the wall's force per unit length of the circle of radius
          :math:`\rho = 1 - r` the centres reach, :math:`P = \sum|\Delta p_{wall}| / (2\pi
          \rho T)`, over the area the centres reach, :math:`A_c = \pi\rho^2`:
          :math:`Z = \rho \sum|\Delta p_{wall}| / (2 T N kT)`. In a stadium or an ellipse
          the same with the centre's curve's length :math:`L_c` and area :math:`A_c`
          (``table.perimeter(r)``, ``table.area(r)``): :math:`Z = A_c \sum|\Delta
          p_{wall}| / (L_c T N kT)`, the wall's mean pressure (on a curved wall of a dense
          gas the contact density, so the local pressure, varies along the wall).
        * **virial** (Allen & Tildesley, *Computer Simulation of Liquids*, 2nd ed. 2017,
          sec. 2.4; the collisional form, sec. 3.7.2): :math:`P A = N kT + \frac{1}{2T}
          \sum_{coll} r_{ij}\cdot\Delta p_i` (:math:`= \sigma |\Delta p|` elastic,
          :math:`\sigma = r_i + r_j`). In the table, :math:`A = A_c` and the sum is
          :math:`\sum (r_i\cdot\Delta p_i + r_j\cdot\Delta p_j)` over both disks: the
          virial theorem with the wall as an external force (:math:`r\cdot\Delta p = -
ho
          |\Delta p|` at the wall) makes it equal to the wall's pressure, up to the
          boundary term :math:`[\sum r\cdot p]_0^T / (2T)`, for either rule. In the box,
          :math:`A = L^2`, minimum images, and this *is* the pressure. The mirror rule does
          not conserve momentum, so a pair's virial depends on the origin; in the box
          there is none: a ValueError. A stadium's or an ellipse's virial takes
          :math:`A = A_c` and the same sum (:math:`\sum_{wall} r\cdot\Delta p = -2 P A_c T`
          for a uniform wall pressure on any convex curve, :math:`\oint r\cdot n\,ds =
          2A_c`).
        * **bulk**: the collisions whose contact point lies within ``bulk_radius`` of the
          centre (in any table) (:math:`A_b = \pi R_b^2`) and the region's time-averaged
          number of centres
          :math:`N_b` (counted at the rows of ``pressure_log``, trapezoidal rule):
          :math:`Z_b = 1 + \sum_{region} \tfrac12 r_{ij}\cdot(\Delta p_i - \Delta p_j) / (2
          T N_b kT)`, the local virial of a homogeneous region away from the wall, to be
          compared with the equation of state at its own packing
          :math:`\varphi_b = N_b \pi r^2 / A_b` (the wall's layer takes disks from the
          bulk). The box's region is the whole box: :math:`Z_b = Z_{virial}`.

        Henderson's equation of state (Mol. Phys. 30, 971 (1975)),
        :math:`Z = (1 + \varphi^2/8)/(1 - \varphi)^2`, differs from the virial series of
        Clisby & McCoy (J. Stat. Phys. 122, 15 (2006)) by less than 0.1 % at
        :math:`\varphi = 0.3` (`kicktimes.stats.henderson_z`).

        Examples
        --------
        >>> import kicktimes as kt
        >>> s = kt.initial_state(300, None, packing=0.2, rule="elastic", rng=3)
        >>> run = kt.simulate_disks(s, (0.2 / 300) ** 0.5, t_max=2.0, rule="elastic")
        >>> p = run.pressure(blocks=4)
        >>> bool(abs(p.z_wall / p.z_virial - 1) < 0.05)
        True
        """
        from kicktimes.stats.enskog import henderson_z

        log = self.pressure_log
        if isinstance(blocks, bool) or not isinstance(blocks, int | np.integer):
            raise TypeError(f"blocks must be an integer, got {type(blocks).__name__}")
        rows = 0 if log is None else log.shape[0]
        if not 2 <= blocks <= rows - 1:
            raise ValueError(f"blocks must lie in [2, {rows - 1}] (the pressure log has {rows} "
                             f"rows), got {blocks}")
        if self.box is not None and self.rule == "mirror":
            raise ValueError("rule: the pressure of a mirror-rule run in the periodic box is "
                             "not defined (the mirror rule does not conserve momentum, and "
                             "the box has no origin for the virial); use rule='elastic'")
        if self.escape_times is not None and np.isfinite(self.escape_times).any():
            raise ValueError("holes: disks escaped during the run; the pressure needs a "
                             "closed table")
        if self.box is None and np.ptp(self.radii) > 0:
            raise ValueError("r: the table's pressure needs equal radii (each disk's centre "
                             "has its own room 1 - r_i, so no one area A_c)")
        n = self.n_disks
        kT = self.kT
        t, c, wall, vir, vir_b = (log[:, k] for k in range(5))
        edges = np.linspace(0, rows - 1, blocks + 1).round().astype(int)
        # the region's count integrated over each block (trapezoids between rows)
        area_c = np.concatenate([[0.0], np.cumsum(0.5 * (c[1:] + c[:-1]) * np.diff(t))])
        s0, s1 = edges[:-1], edges[1:]

        other = self.table is not None and not isinstance(self.table, Circle)
        r0 = float(self.radii[0])

        def z_of(a, b):
            dt = t[b] - t[a]
            n_b = (area_c[b] - area_c[a]) / dt if self.box is None else n
            if other:
                z_w = (self.table.area(r0) * (wall[b] - wall[a])
                       / (self.table.perimeter(r0) * dt * n * kT))
            else:
                z_w = (1.0 - r0) * (wall[b] - wall[a]) / (2.0 * dt * n * kT)
            z_v = 1.0 + (vir[b] - vir[a]) / (2.0 * dt * n * kT)
            z_b = 1.0 + (vir_b[b] - vir_b[a]) / (2.0 * dt * n_b * kT)
            return z_w, z_v, z_b, n_b

        z_w, z_v, z_b, n_b = z_of(0, rows - 1)
        per = np.array([z_of(a, b)[:3] for a, b in zip(s0, s1, strict=True)])
        se = per.std(axis=0, ddof=1) / math.sqrt(blocks)
        r2 = float(np.mean(self.radii ** 2))
        if other:
            packing = n * math.pi * r2 / self.table.area(0.0)
            bulk = n_b * r2 / self.bulk_radius ** 2
        elif self.box is None:
            packing = n * r2
            bulk = n_b * r2 / self.bulk_radius ** 2
        else:
            packing = bulk = n * math.pi * r2 / self.box ** 2
            z_w, se[0] = math.nan, math.nan
        return DisksPressure(z_wall=float(z_w), z_virial=float(z_v), z_bulk=float(z_b),
                             se_wall=float(se[0]), se_virial=float(se[1]),
                             se_bulk=float(se[2]), packing=float(packing),
                             bulk_packing=float(bulk), henderson=float(henderson_z(bulk)),
                             kT=kT, blocks=int(blocks))

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
        (the circle: the contact's polar angle in ``[0, 2 pi)``; a stadium or an ellipse:
        the arc length along the centre's curve from its rightmost point,
        `kicktimes.billiard.kernels.tables.boundary_coordinates`), ``sin_theta`` (the
        incoming velocity's tangential component over its speed: with ``s``, Birkhoff's
        coordinates); ``None`` if not logged."""
        if self.wall_log is None:
            return None
        t, d, x, y, st = self.wall_log
        if self.table is not None and not isinstance(self.table, Circle):
            from kicktimes.billiard.kernels.disk_walls import arc_lengths

            s = arc_lengths(*self.table.kernel(float(self.radii[0])),
                            np.ascontiguousarray(x), np.ascontiguousarray(y))
            return pd.DataFrame({"time": t, "disk": d, "s": s, "sin_theta": st})
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
                else self.holes.tolist(), "box": self.box, "bulk_radius": self.bulk_radius,
                "table": None if self.table is None else table_spec(self.table),
                "version": self.version}

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
        box = "" if self.box is None else f", box={self.box!r}"
        if self.table is not None and not isinstance(self.table, Circle):
            box = f", table={self.table!r}"
        return (f"DisksRun(n_disks={self.n_disks}, {r}, rule={self.rule!r}, t_max={self.t_max!r}, "
                f"n_pp={self.n_pp}, n_events={self.n_events}{esc}{box})")

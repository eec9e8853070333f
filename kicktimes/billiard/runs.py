"""Run records of the billiard simulators and their Parquet I/O.

A run is a frozen dataclass of plain arrays plus the parameters that produced it. The
boundary-collision table is built lazily (the kernels return contact coordinates; the
DataFrame with the arclength ``s`` is made on first access), so a sweep that only needs
``pp_times`` pays nothing for it.

On disk a run is one Parquet file holding a single row whose columns are the arrays
(Arrow list columns) and whose schema metadata holds the parameters as JSON. Files are
written atomically: a temporary file in the same folder, then ``os.replace``.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field, fields
from functools import cached_property
from typing import ClassVar, NamedTuple

import numpy as np
import pandas as pd

from kicktimes import __version__
from kicktimes._results import TableResult
from kicktimes.billiard.scatter import KICK_LOG_COLUMNS as _KICK_LOG_COLUMNS
from kicktimes.billiard.tables import Circle, Ellipse, Stadium
from kicktimes.fileio import atomic_write

TWO_PI = 2.0 * np.pi

#: Columns of a two-disk collision log (``log_collisions=True``): contact centres,
#: pre-collision velocities, post-collision velocities.
PP_LOG_COLUMNS = ("x0", "y0", "x1", "y1", "vx0", "vy0", "vx1", "vy1",
                  "vx0_post", "vy0_post", "vx1_post", "vy1_post")
#: Columns of a scattering-kick log (defined beside the kick, in kicktimes.billiard.scatter)
KICK_LOG_COLUMNS = _KICK_LOG_COLUMNS


class BoundaryLog(NamedTuple):
    """Raw boundary-collision log: contact centre ``(x, y)``, time, disk, ``sin_theta``."""

    time: np.ndarray
    particle: np.ndarray  # int8; all zeros for a one-particle run
    x: np.ndarray
    y: np.ndarray
    sin_theta: np.ndarray


def _arclength(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Polar angle of the contact point in ``[0, 2 pi)`` (= arclength on the unit table)."""
    s = np.arctan2(y, x)
    s[s < 0.0] += TWO_PI
    # arctan2 of a tiny negative y gives -0.0 + 2 pi = 2 pi exactly; keep the half-open range
    s[s >= TWO_PI] = 0.0
    return s


#: the tables a run's record can name (its ``meta["table"]``: the class name and its sizes)
_TABLES = {cls.__name__: cls for cls in (Circle, Stadium, Ellipse)}


def table_meta(table) -> dict:
    """A table as JSON: ``{"name": "Stadium", "a": 1.0}`` (`table_from_meta` reads it)."""
    return {"name": type(table).__name__,
            **{f.name: float(getattr(table, f.name)) for f in fields(table)}}


def table_from_meta(meta: dict):
    """The table of `table_meta`'s record."""
    meta = dict(meta)
    return _TABLES[meta.pop("name")](**meta)


def sampling_fields(t_end, mode, sampling, tau, n_steps, sample_times, samples) -> dict:
    """A run's fields that describe its horizon and samples, from a kernel's output (``mode``
    0: no samples, then ``sampling`` is recorded as ``None``)."""
    return {"t_max": float(t_end), "sampling": sampling if mode > 0 else None, "tau": tau,
            "n_steps": n_steps, "sample_times": sample_times, "samples": samples}


@dataclass(frozen=True, repr=False)
class _Run(TableResult):
    r: float
    t_max: float
    sampling: str | None
    tau: float | None
    n_steps: int | None
    ic: np.ndarray
    final_state: np.ndarray
    boundary_log: BoundaryLog
    sample_times: np.ndarray
    samples: np.ndarray
    seed: int | None = None
    version: str = field(default=__version__)
    #: the time a disk escaped through a hole of the table (``inf``: it did not, or the
    #: table has none); the run ends there
    escape_time: float = math.inf
    #: the disk that escaped (0 or 1; -1: none)
    escaped: int = -1

    kind: ClassVar[str] = "run"
    _array_fields: ClassVar[tuple[str, ...]] = ()
    #: 2-D array fields and their column count (stored flat in Parquet)
    _array_columns: ClassVar[dict[str, int]] = {}
    _scalar_fields: ClassVar[tuple[str, ...]] = ()
    #: scalar fields recorded only when not None (added later: older records lack them)
    _optional_fields: ClassVar[tuple[str, ...]] = ()

    _frame = "boundary"

    def _summary_extra(self) -> list[str]:
        if self.escaped < 0:
            return []
        return [f"escaped: disk {self.escaped} at t = {self.escape_time:.6g}"]

    @property
    def n_boundary(self) -> int:
        """Number of disk-boundary collisions in ``[0, t_max]``."""
        return int(self.boundary_log.time.shape[0])

    def theta(self, particle: int | None = None) -> np.ndarray:
        """Boundary-collision angles ``arcsin(sin_theta)`` of one disk, in time order."""
        log = self.boundary_log
        st = log.sin_theta
        if particle is not None:
            st = st[log.particle == particle]
        return np.arcsin(np.clip(st, -1.0, 1.0))

    @property
    def meta(self) -> dict:
        """The parameters of the run as a JSON-serialisable dict."""
        out = {"kind": self.kind}
        for name in self._scalar_fields:
            value = getattr(self, name)
            if value is None and name in self._optional_fields:
                continue
            out[name] = value.item() if isinstance(value, np.generic) else value
        if self.escaped >= 0:
            out["escape_time"] = float(self.escape_time)
            out["escaped"] = int(self.escaped)
        return out

    def _arrays(self) -> dict[str, np.ndarray]:
        arrays = {name: np.asarray(getattr(self, name)).ravel() for name in self._array_fields}
        arrays["ic"] = np.asarray(self.ic).ravel()
        arrays["final_state"] = np.asarray(self.final_state).ravel()
        for name, arr in self.boundary_log._asdict().items():
            arrays[f"boundary_{name}"] = arr
        arrays["sample_times"] = self.sample_times
        arrays["samples"] = np.asarray(self.samples).ravel()
        return arrays

    def to_parquet(self, path: str | os.PathLike) -> None:
        """Write the run to one Parquet file (atomically). Read it back with `read_run`."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        columns = {
            name: pa.array([arr], type=pa.list_(pa.from_numpy_dtype(arr.dtype)))
            for name, arr in self._arrays().items()
        }
        meta = {b"kicktimes": json.dumps(self.meta).encode()}
        table = pa.table(columns).replace_schema_metadata(meta)
        atomic_write(path, lambda tmp: pq.write_table(table, tmp))

    def __repr__(self) -> str:
        params = ", ".join(f"{k}={v!r}" for k, v in self.meta.items() if k != "kind")
        return f"{type(self).__name__}({params}, {self._summary_counts()})"

    def _summary_counts(self) -> str:
        return f"n_boundary={self.n_boundary}, n_samples={self.sample_times.shape[0]}"


@dataclass(frozen=True, repr=False)
class TwoParticleRun(_Run):
    """Result of `simulate_two_particle`.

    Attributes
    ----------
    r, rule, t_max, sampling, tau, n_steps, track, seed, version
        The parameters of the run (``seed`` is ``None`` unless the caller recorded it).
    ic, final_state : ndarray, shape (2, 4)
        Rows ``(x, y, vx, vy)`` of each disk at ``t = 0`` and at ``t = t_max``.
    pp_times : ndarray
        Every disk-disk collision time, increasing, in ``(0, t_max]``.
    boundary : DataFrame
        Columns ``time, particle, s, sin_theta`` (docs/architecture.md conventions), time
        order: ``s`` the contact's polar angle in ``[0, 2 pi)``, ``sin_theta`` the incoming
        velocity's tangential component. In another table (``table`` not the circle) the
        Birkhoff coordinates of `kicktimes.billiard.kernels.tables.boundary_coordinates`:
        columns ``time, particle, arc, s, sin_theta``, ``arc`` the arc length along the
        centre's curve counter-clockwise from its rightmost point, in ``[0, L(r))``, and
        ``s = 2 pi arc / L(r)`` the same as an angle (in the circle that is the polar angle,
        so ``s`` keeps its range and meaning of "where on the wall").
    table : Circle, Stadium or Ellipse
        The table (docs/tables.md); ``Circle()`` for the unit circle, the default, which
        the run's record (``meta``, Parquet) leaves out.
    sample_times, samples : ndarray, shapes (n,) and (n, 2)
        Sample times and the tracked disk's centre at them (empty without sampling).
    pp_log : ndarray, shape (n_pp, 12) or (0, 12)
        With ``log_collisions=True``, one row per disk-disk collision (`PP_LOG_COLUMNS`):
        both centres at contact and both velocities before and after; `collisions` is
        the same as a DataFrame with the time and the contact normal.
    """

    _title = "Two disks in a billiard table (simulate_two_particle)"
    _summary_fields = ("table", "r", "rule", "t_max", "n_pp", "n_boundary", "masses",
                       "sampling", "tau", "n_steps", "seed")

    rule: str = "mirror"
    track: int = 0
    pp_times: np.ndarray = field(default_factory=lambda: np.empty(0))
    pp_log: np.ndarray = field(default_factory=lambda: np.empty((0, 12)))
    #: the elastic rule's masses, normalised to ``(m0, m1) * 2 / (m0 + m1)`` (None: equal)
    masses: tuple | None = None
    #: the table (`kicktimes.tables`); the circle's runs leave it out of their record
    table: object = Circle()

    kind = "two_particle"
    _array_fields = ("pp_times", "pp_log")
    _array_columns = {"pp_log": 12}
    _scalar_fields = ("r", "rule", "t_max", "sampling", "tau", "n_steps", "track", "seed",
                      "version")

    @property
    def meta(self) -> dict:
        out = super().meta
        if self.table != Circle():
            out["table"] = table_meta(self.table)
        return out

    @cached_property
    def boundary(self) -> pd.DataFrame:
        log = self.boundary_log
        if self.table == Circle():
            return pd.DataFrame(
                {
                    "time": log.time,
                    "particle": log.particle,
                    "s": _arclength(log.x, log.y),
                    "sin_theta": log.sin_theta,
                }
            )
        from kicktimes.billiard.kernels.two import table_arc_lengths

        arc = table_arc_lengths(*self.table.kernel(self.r), np.ascontiguousarray(log.x),
                                np.ascontiguousarray(log.y))
        length = self.table.perimeter(self.r)
        return pd.DataFrame(
            {
                "time": log.time,
                "particle": log.particle,
                "arc": arc,
                "s": np.minimum(arc * (TWO_PI / length), np.nextafter(TWO_PI, 0.0)),
                "sin_theta": log.sin_theta,
            }
        )

    @cached_property
    def collisions(self) -> pd.DataFrame:
        """The disk-disk collision log (needs ``log_collisions=True``).

        Columns ``time``, `PP_LOG_COLUMNS` and the unit contact normal ``nx, ny`` from
        disk 0's centre towards disk 1's.
        """
        if self.pp_log.shape[0] != self.n_pp:
            raise ValueError(
                "this run has no collision log; simulate with log_collisions=True"
            )
        df = pd.DataFrame(self.pp_log, columns=list(PP_LOG_COLUMNS))
        df.insert(0, "time", self.pp_times)
        dx = df["x1"] - df["x0"]
        dy = df["y1"] - df["y0"]
        dd = np.hypot(dx, dy)
        df["nx"] = dx / dd
        df["ny"] = dy / dd
        return df

    @property
    def n_pp(self) -> int:
        """Number of disk-disk collisions in ``(0, t_max]``."""
        return int(self.pp_times.shape[0])

    def _summary_counts(self) -> str:
        return f"n_pp={self.n_pp}, " + super()._summary_counts()


@dataclass(frozen=True, repr=False)
class OneParticleRun(_Run):
    """Result of `simulate_one_particle`.

    Attributes
    ----------
    r, t_max, sampling, tau, n_steps, kick_angle, sigma, seed, version
        The parameters of the run.
    ic, final_state : ndarray, shape (4,)
        ``(x, y, vx, vy)`` at ``t = 0`` and ``t = t_max``.
    kick_times, kick_angles : ndarray
        The kicks applied, so that a twin run can reuse them (common random numbers).
        For ``kick_angle="uniform"`` or ``"normal"`` the angle is the new velocity
        direction; for
        ``"gaussian"`` it is the rotation applied to the current direction; for
        ``"scatter"`` it is an array of shape (n_kicks, 2), the two uniform numbers on
        (-1, 1) that fix each kick's partner and contact normal.
    rule, e0, partner : str, float, str or None
        Scattering kicks only: the collision rule, the pair's kinetic energy (elastic)
        and the partner law (docs/scatter.md).
    partner_radius, partner_mass : float or None
        Scattering kicks with a partner of another radius / mass ratio ``m1 / m0``
        (docs/unequal.md); ``None``: the disk's own radius, equal masses (and left out
        of ``meta``, so that runs without them keep their records).
    kick_log : DataFrame
        Scattering kicks only: per kick the time, the velocity before and after, the
        contact normal ``n``, the partner's velocity ``u`` and whether the partner's
        centre lay outside the table.
    boundary : DataFrame
        Columns ``time, s, sin_theta``: in the circle ``s`` is the contact's polar angle
        (the arc length on the unit table); in a stadium or an ellipse the arc length along
        the centre's curve, counter-clockwise from its rightmost point, and ``sin_theta``
        the incoming ``v.t / |v|`` (`kicktimes.billiard.kernels.tables.boundary_coordinates`).
    sample_times, samples : ndarray
        Sample times and the disk's centre at them.
    table : Circle, Stadium or Ellipse
        The table of the run (``Circle()`` unless ``simulate_one_particle(table=...)``;
        recorded in ``meta`` only for another table, so circle records are unchanged).
    """

    _title = "One kicked disk in a table (simulate_one_particle)"
    _summary_fields = ("r", "table", "t_max", "kick_angle", "sigma", "n_kicks", "n_boundary",
                       "rule", "sampling", "tau", "n_steps", "seed")

    kick_angle: str = "uniform"
    sigma: float | None = None
    kick_times: np.ndarray = field(default_factory=lambda: np.empty(0))
    kick_angles: np.ndarray = field(default_factory=lambda: np.empty(0))
    rule: str | None = None
    e0: float | None = None
    partner: str | None = None
    partner_radius: float | None = None
    partner_mass: float | None = None
    kick_log_array: np.ndarray = field(default_factory=lambda: np.empty((0, 9)))
    table: object = field(default_factory=Circle)

    kind = "one_particle"
    _array_fields = ("kick_times", "kick_angles", "kick_log_array")
    _array_columns = {"kick_log_array": 9}
    _scalar_fields = ("r", "t_max", "sampling", "tau", "n_steps", "kick_angle", "sigma", "seed",
                      "version", "rule", "e0", "partner", "partner_radius", "partner_mass")
    _optional_fields = ("partner_radius", "partner_mass")

    @cached_property
    def kick_log(self) -> pd.DataFrame:
        """Per scattering kick: ``time`` and `KICK_LOG_COLUMNS` (empty for other kicks)."""
        df = pd.DataFrame(self.kick_log_array, columns=list(KICK_LOG_COLUMNS))
        df["outside"] = df["outside"].astype(bool)
        df.insert(0, "time", self.kick_times[: df.shape[0]])
        return df

    @property
    def meta(self) -> dict:
        out = super().meta
        if self.table != Circle():
            out["table"] = table_meta(self.table)
        return out

    @cached_property
    def boundary(self) -> pd.DataFrame:
        log = self.boundary_log
        if self.table == Circle():
            s = _arclength(log.x, log.y)
        else:
            from kicktimes.billiard.kernels.one import table_arc_lengths

            s = table_arc_lengths(*self.table.kernel(self.r), log.x, log.y)
        return pd.DataFrame({"time": log.time, "s": s, "sin_theta": log.sin_theta})

    @property
    def n_kicks(self) -> int:
        return int(self.kick_times.shape[0])

    def _summary_counts(self) -> str:
        return f"n_kicks={self.n_kicks}, " + super()._summary_counts()


_KINDS = {cls.kind: cls for cls in (TwoParticleRun, OneParticleRun)}


def read_run(path: str | os.PathLike) -> TwoParticleRun | OneParticleRun:
    """Read a run written by ``run.to_parquet(path)``.

    Raises
    ------
    ValueError
        If the file is not a kicktimes run.
    """
    import pyarrow.parquet as pq

    table = pq.read_table(path)
    raw = (table.schema.metadata or {}).get(b"kicktimes")
    if raw is None:
        raise ValueError(f"path: {os.fspath(path)!r} is not a kicktimes run file")
    meta = json.loads(raw)
    cls = _KINDS.get(meta.pop("kind", None))
    if cls is None:
        raise ValueError(f"path: {os.fspath(path)!r} holds an unknown run kind")
    arr = {name: table.column(name)[0].values.to_numpy(zero_copy_only=False)
           for name in table.column_names}
    ic_shape = (2, 4) if cls is TwoParticleRun else (4,)
    log = BoundaryLog(*(arr[f"boundary_{name}"] for name in BoundaryLog._fields))
    kwargs = dict(meta)
    kwargs.update(
        ic=arr["ic"].reshape(ic_shape),
        final_state=arr["final_state"].reshape(ic_shape),
        boundary_log=log,
        sample_times=arr["sample_times"],
        samples=arr["samples"].reshape(-1, 2),
    )
    for name in cls._array_fields:
        if name not in arr:
            continue  # written by an older version without this field
        kwargs[name] = arr[name]
        if name in cls._array_columns:
            kwargs[name] = arr[name].reshape(-1, cls._array_columns[name])
    if isinstance(kwargs.get("table"), dict):
        kwargs["table"] = table_from_meta(kwargs["table"])
    if meta.get("kick_angle") == "scatter":
        kwargs["kick_angles"] = kwargs["kick_angles"].reshape(-1, 2)
    known = {f.name for f in fields(cls)}
    return cls(**{k: v for k, v in kwargs.items() if k in known})

"""An experiment: the parameters of one ensemble sweep, as a frozen dataclass and a TOML file.

The TOML file is flat (one key per field, see docs/experiments.md)::

    name = "family_a"
    radii = [0.008, 0.010, 0.012]
    n_ics = 200
    n_steps = 25000
    tau = 0.2
    sampling = "paper"

Unknown keys are refused (a typo must not silently fall back to a default). The
experiment's identity is `Experiment.hash`, a SHA-256 of its canonical JSON; a store
records it and refuses to mix results of two experiments.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
from dataclasses import asdict, dataclass, field, fields

from kicktimes.validation import (
    check_choice,
    check_distinct,
    check_file_name,
    check_int,
    check_real,
)

__all__ = ["DEFAULT_SYSTEMS", "DIAGNOSTICS", "SYSTEMS", "Experiment"]

SYSTEMS = ("two_particle", "poisson", "actual", "poisson_scatter", "actual_scatter",
           "poisson_kinetic", "mmpp", "uniform_kinetic")
#: the systems kicked at the kinetic rate of the disk's own angular momentum (and, under the
#: elastic rule, speed): equal disks of equal masses only
KINETIC_SYSTEMS = ("poisson_kinetic", "uniform_kinetic")
#: The paper's systems, run when an experiment names none (scattering kicks are opt-in)
DEFAULT_SYSTEMS = ("two_particle", "poisson", "actual")
DIAGNOSTICS = ("lyapunov", "recurrence_rate", "autocorrelation")
IC_METHODS = ("paper", "uniform")
SAMPLINGS = ("uniform", "paper")
RULES = ("mirror", "elastic")
LYAPUNOV_VARIANTS = ("norm", "paper")
LYAPUNOV_METHODS = ("tangent", "twin")
KICK_ANGLES = ("uniform", "gaussian", "normal")
RR_SAMPLINGS = ("run", "uniform", "run+uniform")

#: Fields added after the first store layout, with the value that reproduces the earlier
#: results: `Experiment.hash` leaves a field out while it has that value (and writes a
#: single ``eps`` as a float, as before), so stores written before the field existed keep
#: their hash and still load. Their results simply lack the rows added since.
_LATER_FIELDS = {"acf_max_lag": 20, "rr_sampling": "run", "lyapunov_method": "twin",
                 "holes": [], "partner_ratio": 1.0, "partner_mass": 1.0, "log_events": True,
                 "table": "circle"}
#: the systems an FTLE-only sweep without event logs (``log_events = false``) can run: those
#: whose kicks need no two-disk collision times beyond their rate
LOG_FREE_SYSTEMS = ("two_particle", "poisson", "poisson_scatter", "poisson_kinetic",
                    "uniform_kinetic")

_REQUIRED = ("name", "radii", "n_ics", "n_steps", "tau")



def _eps_tuple(value):
    """A positive threshold or a non-empty list of distinct ones, as a tuple (order kept)."""
    if isinstance(value, (str, bytes)):
        raise TypeError(f"eps: expected a float or a list of floats, got {value!r}")
    if not hasattr(value, "__iter__"):
        return (check_real("eps", value, low=0.0),)
    items = [check_real(f"eps[{k}]", e, low=0.0) for k, e in enumerate(value)]
    if not items:
        raise ValueError("eps: must contain at least one recurrence threshold, got []")
    if len(set(items)) != len(items):
        raise ValueError(f"eps: thresholds must be distinct, got {items}")
    return tuple(items)


def _subset(name, value, choices):
    if isinstance(value, str) or not hasattr(value, "__iter__"):
        raise TypeError(f"{name}: expected a list of names from {list(choices)}, got {value!r}")
    items = list(value)
    if not items:
        raise ValueError(f"{name}: must name at least one of {list(choices)}, got []")
    for item in items:
        check_choice(f"{name} entry", item, choices)
    if len(set(items)) != len(items):
        raise ValueError(f"{name}: duplicate entries in {items}")
    # canonical order, so that the same set always hashes the same
    return tuple(c for c in choices if c in items)


@dataclass(frozen=True)
class Experiment:
    """The parameters of an ensemble sweep over radii (the same object as a TOML file).

    Parameters
    ----------
    name : str
        Identifier (letters, digits, ``_ . -``), used in store and report names.
    radii : sequence of float
        Disk radii ``0 < r < 0.5``, distinct; stored sorted increasingly.
    n_ics : int
        Number of initial conditions (``>= 1``), drawn once at ``max(radii)`` and used
        unchanged for every radius (the paper's procedure).
    n_steps : int
        Sampling steps per run (``>= 1``).
    tau : float
        Step length (``> 0``).
    ic_method : {"paper", "uniform"}
        See `kicktimes.initial_conditions`.
    seed : int
        Root seed (``>= 0``) of the ICs and of every kick schedule and kick angle.
    sampling : {"uniform", "paper"}
        ``"paper"``: collision-truncated steps (the paper's algorithm, so ``n_steps``
        steps cover less than ``n_steps * tau``); ``"uniform"``: samples at ``k tau``.
    rule : {"mirror", "elastic"}
        Disk-disk collision rule.
    eps : float or sequence of float
        Recurrence thresholds ``> 0``, distinct (a single float is stored as a 1-tuple).
        ``eps[0]`` is the threshold of the ``recurrence_rate`` row (the paper: 0.001);
        every threshold gets the ``rr@``/``rr_offdiag@``/``det@``/``l_mean@``/``l_max@``
        rows (docs/experiments.md).
    rr_sampling : {"run", "uniform"}
        The samples the recurrence rows use. ``"run"``: the run's own samples (under
        ``sampling="paper"`` the paper's collision-truncated steps); ``"uniform"``: samples
        at ``k tau`` over the run's duration, from a uniformly sampled re-run of the same
        trajectory with the same kicks (identical to ``"run"`` when
        ``sampling="uniform"``); ``"run+uniform"``: both, the uniform rows prefixed
        ``uniform_`` (``uniform_rr_offdiag@e``, ``uniform_det@e``, ...): the
        uniform-sampling control of the recurrence findings.
    lag : int
        Autocorrelation lag ``>= 1`` of the ``autocorrelation`` row.
    acf_max_lag : int
        Largest lag ``>= 1`` of the autocorrelation curve (rows ``acf@1..acf@L``).
    d0 : float
        Initial separation of the Lyapunov twins, ``1e-10 <= d0 <= 1e-2`` (the paper:
        1/5000); used only with ``lyapunov_method = "twin"``.
    lyapunov_method : {"tangent", "twin"}
        ``"tangent"``: exact tangent vectors (no ``d0``); ``"twin"``: Benettin twins at
        distance ``d0`` (the paper's method). See `kicktimes.diagnostics.lyapunov`.
    lyapunov_variant : {"norm", "paper"}
        ``"paper"``: ``max(lambda_x, lambda_y)`` (also stores both); ``"norm"``: 2-norm.
    kick_angle : {"uniform", "gaussian", "normal"}
        Kick law of the one-particle billiards (`simulate_one_particle`): a new direction
        uniform on [0, 2 pi), a rotation by N(0, sigma^2), or a new direction from
        N(0, sigma^2); ``sigma`` (``> 0``) is unused for ``"uniform"``.
    systems : sequence of str
        Subset of ``("two_particle", "poisson", "actual", "poisson_scatter",
        "actual_scatter", "poisson_kinetic", "mmpp", "uniform_kinetic")`` whose diagnostics are
        stored (default the
        first three, the paper's). The two-particle run is always simulated (its collision
        times are stored and drive the others). The ``*_scatter`` systems are kicked at the
        same kinds of times but by scattering kicks (a collision with a virtual partner under
        ``rule``, docs/scatter.md) instead of ``kick_angle``. ``"poisson_kinetic"``: scattering
        kicks at the kinetic rate of the disk's own angular momentum, redrawn after every
        kick (`kicktimes.schedules.KineticRate`; under ``rule = "elastic"`` the rate of
        its angular momentum and speed, and elastic kicks with the IC's energy ``e0``);
        ``"uniform_kinetic"``: the kicks of ``kick_angle`` at that kinetic rate (with
        ``poisson``, ``poisson_scatter`` and ``poisson_kinetic`` the 2 x 2 factorial of
        deflection law and timing, `kicktimes.report.decomposition`). ``"mmpp"``: the
        kicks of ``kick_angle`` at the times of a two-state Markov-modulated Poisson
        process fitted to the IC's own collision times (`kicktimes.stats.fit_mmpp`;
        Poisson at the IC's rate when the run has too few collisions for a fit).
    diagnostics : sequence of str
        Subset of ``("lyapunov", "recurrence_rate", "autocorrelation")``.
    block_size : int
        Initial conditions per task (``>= 1``); a task is one radius times one block.
    holes : sequence of (float, float)
        Holes in the table's wall, rows ``(centre angle, half-width)`` in radians (default
        none): every run ends when a disk escapes (docs/escape.md), its ``escape_time``
        row is stored (``inf``: none by the end) and, for the two-disk run, its
        ``escaped_disk`` row (0, 1, or -1 for none), and the disk kicked at actual times gets
        the two-disk run's collision times up to its end (no continuation). Needs
        ``lyapunov_method = "tangent"``.
    partner_ratio : float
        Unequal disks (docs/unequal.md, "In sweeps"): disk 1 has the radius
        ``partner_ratio * r`` for the sweep radius ``r`` of disk 0 (default 1, equal
        disks). Disk 0 is the disk the one-disk systems simulate and kick, so a ratio
        ``> 1`` studies the small disk of the pair and a ratio ``< 1`` the large one. The
        two-disk system runs with ``r = (r, partner_ratio * r)``, the scattering kicks meet
        a partner of radius ``partner_ratio * r``, the actual-time kicks are disk 0's
        collisions with disk 1, and the report's kinetic rate is the pair's
        (`kicktimes.stats.kinetic_rate`). Disk 1 of the largest radius must fit:
        ``partner_ratio * max(radii) < 0.5`` (at most 1/3 for each disk with
        ``ic_method = "uniform"``). Not with ``"poisson_kinetic"`` or
        ``"uniform_kinetic"`` (their rate table, `kicktimes.schedules.KineticRate`, is for
        equal disks).
    table : str or table
        The billiard table (default ``"circle"``, the unit circle): ``"stadium a=..."``
        (Bunimovich's stadium, `kicktimes.tables.Stadium`) or ``"ellipse a=... b=..."``
        (`kicktimes.tables.Ellipse`), as `kicktimes.tables.parse_table` reads it, or a
        table value. Beyond the circle: ``ic_method = "uniform"``, equal disks, no holes and
        no kinetic-rate systems.
    partner_mass : float
        Disk 1's mass in units of disk 0's, ``m1 / m0 > 0`` (default 1). Only the elastic
        rule has masses (``rule = "elastic"``), and only the invariant ICs draw their
        speeds (``ic_method = "uniform"``). Not with the kinetic systems (equal masses).
    description : str
        Free text for the report.

    Examples
    --------
    >>> exp = Experiment(name="demo", radii=[0.02, 0.01], n_ics=4, n_steps=500, tau=0.3)
    >>> exp.radii
    (0.01, 0.02)
    >>> Experiment.from_toml_string(exp.to_toml()) == exp
    True
    >>> len(exp.hash())
    16
    """

    name: str
    radii: tuple
    n_ics: int
    n_steps: int
    tau: float
    ic_method: str = "paper"
    seed: int = 0
    sampling: str = "uniform"
    rule: str = "mirror"
    eps: tuple = (1e-3, 1e-2)
    rr_sampling: str = "run"
    lag: int = 1
    acf_max_lag: int = 20
    d0: float = 1.0 / 5000.0
    lyapunov_variant: str = "norm"
    lyapunov_method: str = "tangent"
    kick_angle: str = "uniform"
    sigma: float = 1.0
    systems: tuple = DEFAULT_SYSTEMS
    diagnostics: tuple = DIAGNOSTICS
    block_size: int = 25
    description: str = field(default="")
    holes: tuple = ()
    partner_ratio: float = 1.0
    partner_mass: float = 1.0
    log_events: bool = True
    table: str = "circle"

    def __post_init__(self):
        put = functools.partial(object.__setattr__, self)  # (the dataclass is frozen)
        check_file_name("name", self.name)
        put("radii", check_distinct("radii", self.radii, what="radii",
                                    check_item=lambda n, r: check_real(n, r, low=0.0, high=0.5)))
        put("n_ics", check_int("n_ics", self.n_ics, low=1))
        put("n_steps", check_int("n_steps", self.n_steps, low=1))
        put("tau", check_real("tau", self.tau, low=0.0))
        check_choice("ic_method", self.ic_method, IC_METHODS)
        put("seed", check_int("seed", self.seed, low=0))
        check_choice("sampling", self.sampling, SAMPLINGS)
        check_choice("rule", self.rule, RULES)
        put("eps", _eps_tuple(self.eps))
        check_choice("rr_sampling", self.rr_sampling, RR_SAMPLINGS)
        put("lag", check_int("lag", self.lag, low=1))
        put("acf_max_lag", check_int("acf_max_lag", self.acf_max_lag, low=1))
        put("d0", check_real("d0", self.d0, low=1e-10, high=1e-2, low_open=False, high_open=False))
        check_choice("lyapunov_variant", self.lyapunov_variant, LYAPUNOV_VARIANTS)
        check_choice("lyapunov_method", self.lyapunov_method, LYAPUNOV_METHODS)
        check_choice("kick_angle", self.kick_angle, KICK_ANGLES)
        put("sigma", check_real("sigma", self.sigma, low=0.0))
        put("systems", _subset("systems", self.systems, SYSTEMS))
        put("diagnostics", _subset("diagnostics", self.diagnostics, DIAGNOSTICS))
        put("block_size", check_int("block_size", self.block_size, low=1))
        if self.holes is None or (hasattr(self.holes, "__len__") and len(self.holes) == 0):
            put("holes", ())
        else:
            from kicktimes.billiard.checks import check_holes

            put("holes", tuple(tuple(row) for row in check_holes(self.holes).tolist()))
            if "lyapunov" in self.diagnostics and self.lyapunov_method != "tangent":
                raise ValueError("holes: the FTLE up to an escape needs lyapunov_method="
                                 f"'tangent', got {self.lyapunov_method!r}")
        if not isinstance(self.description, str):
            raise TypeError(f"description: expected a string, got {self.description!r}")
        self._check_partner(put)
        self._check_log_events()
        self._check_table(put)

    def _check_table(self, put):
        """``table``: the billiard table as text (`kicktimes.tables.parse_table`: ``"circle"``,
        ``"stadium a=1"``, ``"ellipse a=1.5 b=1"``; a table value is written as its text).
        Beyond the circle the ICs are the invariant measure's and the circle's own
        constructions are refused: the paper's ICs, the kinetic-rate systems (tabulated on
        the circle's angular momentum), holes (arcs of the circle) and unequal disks."""
        from kicktimes.billiard.tables import check_table, parse_table, table_spec

        value = self.table
        table = parse_table(value) if isinstance(value, str) else check_table(value)
        put("table", table_spec(table))
        if self.table == "circle":
            return
        for r in self.radii:
            try:
                table.check_radius(r)
            except ValueError as exc:
                raise ValueError(f"radii: {exc}") from None
        kinetic = [s for s in KINETIC_SYSTEMS if s in self.systems]
        problems = [
            (self.ic_method != "uniform",
             f"ic_method must be 'uniform' (the paper's ICs are the circle's), got "
             f"{self.ic_method!r}"),
            (bool(kinetic), f"systems: {kinetic} tabulate the circle's kinetic rate; leave "
                            f"them out"),
            (bool(self.holes), "holes (arcs of the circle's wall) are not allowed"),
            (self.partner_ratio != 1.0 or self.partner_mass != 1.0,
             "partner_ratio and partner_mass must be 1 (equal disks)"),
        ]
        for bad, text in problems:
            if bad:
                raise ValueError(f"table={self.table!r}: {text}")

    @property
    def table_value(self):
        """The table as a value (`kicktimes.tables.Circle`, `Stadium`, `Ellipse`)."""
        from kicktimes.billiard.tables import parse_table

        return parse_table(self.table)

    def _check_log_events(self):
        """``log_events = false``: an FTLE-only sweep (tangent method, uniform sampling, no
        holes, systems of `LOG_FREE_SYSTEMS`) whose runs keep no event log."""
        if not isinstance(self.log_events, bool):
            raise TypeError(f"log_events: expected true or false, got {self.log_events!r}")
        if self.log_events:
            return
        wrong = [s for s in self.systems if s not in LOG_FREE_SYSTEMS]
        problems = [
            (tuple(self.diagnostics) != ("lyapunov",),
             f"diagnostics must be ['lyapunov'], got {list(self.diagnostics)}"),
            (self.lyapunov_method != "tangent",
             f"lyapunov_method must be 'tangent', got {self.lyapunov_method!r}"),
            (self.sampling != "uniform", f"sampling must be 'uniform', got {self.sampling!r}"),
            (bool(self.holes), "holes are not allowed"),
            (bool(wrong), f"systems must be among {list(LOG_FREE_SYSTEMS)}, got {wrong}"),
        ]
        for bad, text in problems:
            if bad:
                raise ValueError(f"log_events=false (an FTLE-only sweep without event logs): "
                                 f"{text}")

    def _check_partner(self, put):
        """Validate ``partner_ratio`` and ``partner_mass`` against the radii, rule and ICs."""
        ratio = check_real("partner_ratio", self.partner_ratio, low=0.0)
        mass = check_real("partner_mass", self.partner_mass, low=0.0)
        put("partner_ratio", ratio)
        put("partner_mass", mass)
        if mass != 1.0 and self.rule != "elastic":
            raise ValueError(f"partner_mass: masses apply to rule='elastic' (the mirror rule "
                             f"keeps each disk's speed), got partner_mass={mass!r} with "
                             f"rule={self.rule!r}")
        kinetic = [s for s in KINETIC_SYSTEMS if s in self.systems]
        if mass != 1.0 and kinetic:
            raise ValueError(f"partner_mass={mass!r}: the {kinetic[0]!r} system tabulates the "
                             "kinetic rate of equal masses on the energy shell |v0|^2 + "
                             "|v1|^2 = 2 (KineticRate); leave it out of systems or use "
                             "partner_mass = 1")
        if mass != 1.0 and self.ic_method != "uniform":
            raise ValueError(f"partner_mass: the paper's ICs have unit speeds; masses need "
                             f"ic_method='uniform', got partner_mass={mass!r} with "
                             f"ic_method={self.ic_method!r}")
        if ratio == 1.0:
            return
        r1 = ratio * self.r_max
        limit = 1.0 / 3.0 if self.ic_method == "uniform" else 0.5 - 1e-9
        if not r1 <= limit:
            raise ValueError(
                f"partner_ratio: disk 1 at the largest radius has radius {ratio!r} * "
                f"{self.r_max!r} = {r1!r}; partner_ratio * max(radii) must be at most "
                f"{limit:.6g} (ic_method={self.ic_method!r}), i.e. partner_ratio <= "
                f"{limit / self.r_max:.6g}"
            )
        if self.ic_method == "uniform" and self.r_max > limit:
            raise ValueError(f"partner_ratio: unequal disks' invariant ICs need every radius "
                             f"at most 1/3, got max(radii) = {self.r_max!r}")
        if kinetic:
            raise ValueError(f"partner_ratio={ratio!r}: the {kinetic[0]!r} system tabulates "
                             "the kinetic rate of equal disks (KineticRate); leave it out of "
                             "systems or use partner_ratio = 1")

    # ------------------------------------------------------------------ derived
    @property
    def r_max(self) -> float:
        """The largest radius: the ICs are drawn (and valid) at it."""
        return self.radii[-1]

    def radius_pair(self, r: float):
        """The two-disk ``r`` argument at sweep radius ``r``: ``r`` itself for equal disks,
        ``(r, partner_ratio * r)`` otherwise."""
        return r if self.partner_ratio == 1.0 else (r, self.partner_ratio * r)

    @property
    def masses(self):
        """The two-disk ``masses`` argument: ``None`` (equal) or ``(1.0, partner_mass)``."""
        return None if self.partner_mass == 1.0 else (1.0, self.partner_mass)

    @property
    def ic_radius(self):
        """The ``r_max`` the ICs are drawn at, valid for the pair at every radius.

        Equal disks: ``r_max``. Unequal disks, paper ICs: the larger disk at ``r_max``,
        ``max(1, partner_ratio) * r_max`` (both disks drawn that large fit at every
        radius); invariant ICs: the pair ``(r_max, partner_ratio * r_max)``, whose
        configurations stay valid for every smaller pair of the same ratio.
        """
        if self.partner_ratio == 1.0:
            return self.r_max
        if self.ic_method == "paper":
            return max(1.0, self.partner_ratio) * self.r_max
        return (self.r_max, self.partner_ratio * self.r_max)

    def ic_radius_label(self) -> str:
        """`ic_radius` as text: ``0.02``, or ``(0.02, 0.04)`` for a pair."""
        r = self.ic_radius
        return f"({r[0]:g}, {r[1]:g})" if isinstance(r, tuple) else f"{r:g}"

    def kinetic_rate(self, radius):
        """The pair's kinetic collision rate at sweep radius (or radii) ``radius``
        (`kicktimes.stats.kinetic_rate` of ``radius_pair``, ``rule`` and ``masses``)."""
        import numpy as np

        from kicktimes.stats import kinetic_rate

        if self.table != "circle":
            return kinetic_rate(radius, rule=self.rule, table=self.table_value)
        if self.partner_ratio == 1.0 and self.masses is None:
            return kinetic_rate(radius, rule=self.rule)
        rates = [kinetic_rate(self.radius_pair(float(r)), rule=self.rule, masses=self.masses)
                 for r in np.ravel(radius)]
        return np.reshape(rates, np.shape(radius)) if np.ndim(radius) else rates[0]

    @property
    def horizon(self) -> float:
        """``n_steps * tau``: the duration of a uniform run, an upper bound for a paper run."""
        return self.n_steps * self.tau

    def tasks(self):
        """All tasks of the sweep (radius-major, then IC block); see `kicktimes.experiment.Task`."""
        from kicktimes.experiment.plan import make_tasks

        return make_tasks(self)

    # -------------------------------------------------------------- conversions
    def to_dict(self) -> dict:
        """JSON/TOML-ready dict of every field (tuples become lists)."""
        out = asdict(self)
        for key in ("radii", "eps", "systems", "diagnostics"):
            out[key] = list(out[key])
        out["holes"] = [list(row) for row in out["holes"]]
        return out

    @classmethod
    def from_dict(cls, d) -> Experiment:
        """Experiment from `to_dict` output (or a parsed TOML file); unknown keys are refused."""
        if not isinstance(d, dict):
            raise TypeError(f"expected a dict of experiment fields, got {type(d).__name__}")
        known = [f.name for f in fields(cls)]
        unknown = sorted(set(d) - set(known))
        if unknown:
            raise ValueError(
                f"unknown experiment key(s) {unknown}; valid keys are {', '.join(known)}"
            )
        missing = [k for k in _REQUIRED if k not in d]
        if missing:
            raise ValueError(f"missing required experiment key(s) {missing}")
        return cls(**d)

    @classmethod
    def from_record(cls, d) -> Experiment:
        """Experiment from a store's record: fields the record predates get their legacy value.

        A store written before a field existed (``_LATER_FIELDS``) was computed with the
        value that reproduces the earlier results (e.g. ``lyapunov_method = "twin"``), not
        with today's default; a TOML file, by contrast, gets the defaults (`from_dict`).
        """
        if not isinstance(d, dict):
            raise TypeError(f"expected a dict of experiment fields, got {type(d).__name__}")
        return cls.from_dict({**{k: v for k, v in _LATER_FIELDS.items() if k not in d}, **d})

    def hash(self) -> str:
        """Stable identity: the first 16 hex digits of SHA-256 of the canonical JSON.

        The canonical form is `to_dict` except that fields added later are left out while
        they keep the value that reproduces the earlier results, and a single ``eps`` is
        written as a float: stores written before those fields existed keep their hash.
        """
        record = self.to_dict()
        for key, legacy in _LATER_FIELDS.items():
            if record[key] == legacy:
                del record[key]
        if len(record["eps"]) == 1:
            record["eps"] = record["eps"][0]
        text = json.dumps(record, sort_keys=True, separators=(",", ":"), allow_nan=False)
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def to_toml(self) -> str:
        """The experiment as TOML text (flat keys, in field order); `from_toml_string` reads it."""
        lines = []
        for key, value in self.to_dict().items():
            lines.append(f"{key} = {_toml_value(value)}")
        return "\n".join(lines) + "\n"

    def write_toml(self, path: str | os.PathLike) -> None:
        """Write `to_toml` to ``path``."""
        with open(path, "w", encoding="utf-8") as fh:
            fh.write(self.to_toml())

    @classmethod
    def from_toml_string(cls, text: str) -> Experiment:
        """Experiment from TOML text."""
        try:
            data = _tomllib().loads(text)
        except _tomllib().TOMLDecodeError as exc:
            raise ValueError(f"invalid TOML: {exc}") from None
        return cls.from_dict(data)

    @classmethod
    def from_toml(cls, path: str | os.PathLike) -> Experiment:
        """Read an experiment TOML file; errors name the file."""
        path = os.fspath(path)
        try:
            with open(path, encoding="utf-8") as fh:
                text = fh.read()
        except OSError as exc:
            raise ValueError(f"path: cannot read experiment file {path!r}: {exc}") from None
        try:
            return cls.from_toml_string(text)
        except (ValueError, TypeError) as exc:
            raise type(exc)(f"{path}: {exc}") from None

    def summary(self) -> str:
        """A few lines describing the sweep."""
        n_tasks = len(self.tasks())
        radii = ", ".join(f"{r:g}" for r in self.radii)
        return (
            f"Experiment {self.name!r} (hash {self.hash()})\n"
            f"  radii ({len(self.radii)}): {radii}\n"
            f"  {self.n_ics} ICs ({self.ic_method}, seed {self.seed}, drawn at r_max = "
            f"{self.ic_radius_label()}); {self.n_steps} steps of tau = {self.tau:g} "
            f"({self.sampling} sampling); rule {self.rule}\n"
            f"  systems: {', '.join(self.systems)}; diagnostics: {', '.join(self.diagnostics)}"
            f" (eps = {', '.join(f'{e:g}' for e in self.eps)} on {self.rr_sampling} samples, "
            f"lag = {self.lag}, ACF to lag {self.acf_max_lag}; Lyapunov {self.lyapunov_method}"
            f"{f' d0 = {self.d0:g}' if self.lyapunov_method == 'twin' else ''}, variant "
            f"{self.lyapunov_variant}; kicks {self.kick_angle})\n"
            f"  {n_tasks} tasks of up to {self.block_size} ICs"
            + (f"\n  {self.partner_line()}" if self.partner_line() else "")
            + (f"\n  table: {self.table}" if self.table != "circle" else "")
        )

    def partner_line(self) -> str:
        """One line on disk 1 when it differs from disk 0 (empty for equal disks)."""
        if self.partner_ratio == 1.0 and self.partner_mass == 1.0:
            return ""
        mass = f", mass {self.partner_mass:g} m0" if self.partner_mass != 1.0 else ""
        return (f"unequal disks: disk 1 has radius {self.partner_ratio:g} r{mass}; disk 0 "
                f"(radius r) is the disk kicked alone")


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)  # shortest round-trip form; valid TOML for finite floats
    if isinstance(value, str):
        # JSON string escapes are valid TOML basic-string escapes
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {value!r} as TOML")


def _tomllib():
    import tomllib

    return tomllib

"""The ``disks`` experiment: a tagged disk's collision times in a gas of N disks, over N.

A `DisksExperiment` sweeps the number of disks ``n_disks`` at a fixed packing (or a fixed
radius) under one collision rule. For each N it simulates independent runs of the N-disk
engine (`kicktimes.simulate_disks`) from `kicktimes.initial_state`, and records the
collision times of a few *tagged* disks per run, each up to at least ``collisions + 1``
collisions (the Poisson battery is read at a fixed number of collisions per tagged disk,
docs/disks_gas.md). Under the elastic rule it also records the speed each tagged disk
flew each interval at (`kicktimes.experiment.disks_tasks`), for the speed-conditioned
(Cox) rescaling of Visco, van Wijland & Trizac, Phys. Rev. E 77, 041117 (2008).

It is stored, resumed and run on a local pool or a Dask cluster exactly like an
`Experiment` (`run_experiment`, `load_store`): a task is one N times one block of runs,
and run ``k`` at N draws every random number from ``SeedSequence(seed, spawn_key=(N, k))``,
so the results depend neither on the executor nor on the block size.

Examples
--------
>>> exp = DisksExperiment(name="gas", n_disks=[10, 2], packing=0.1, n_tagged=20)
>>> exp.n_disks, exp.tagged_per_run(2), exp.tagged_per_run(10), exp.n_runs(10)
((2, 10), 1, 10, 8)
>>> DisksExperiment.from_record(exp.to_dict()) == exp
True
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import math
from dataclasses import asdict, dataclass, field, fields

from kicktimes.validation import (
    check_choice,
    check_distinct,
    check_file_name,
    check_int,
    check_real,
)

__all__ = ["DISKS_CONTROLS", "DISKS_PRESETS", "DISKS_REFERENCES", "DisksExperiment", "DisksTask",
           "KICKED_SYSTEMS", "disks_control", "disks_preset"]

RULES = ("mirror", "elastic")
#: the number of disks a packing preset sweeps (issue 42)
N_SWEEP = (2, 3, 4, 6, 10, 30, 100, 300, 1000)
#: the largest packing `kicktimes.initial_state` builds
PACKING_MAX = 0.7
#: fields added after the first stores, with the value that leaves those stores' hash: the
#: kicked comparison's (left out of the hash while it is off) and later ones (left out of the
#: hash whenever they are at this value)
_LATER_FIELDS = {"kicked_runs": 0, "kicked_time": 60.0}
_LATER_OPTIONAL = {"kicked_systems": ("poisson", "actual")}
#: the gas's FTLE in the kicked comparison: ``"tangent"`` (tangent vectors in the engine,
#: the default since they exist) or ``"twin"`` (a Benettin twin, what the stores written
#: before carry: a record without the field is read as ``"twin"`` and keeps its hash)
GAS_FTLE_METHODS = ("tangent", "twin")
#: where the disks are (`DisksExperiment.boundary`)
BOUNDARIES = ("circle", "box")
#: the kicks' rate in the kicked comparison (and its lambda / nu): ``"gas"`` the whole
#: gas's collision frequency per disk, ``2 n_pp / (N T)`` (the default since issue 50, the
#: rate disks.csv reads), or ``"disk"`` the followed disk's own ``n / T`` (about 200
#: collisions: what the stores written before carry; a record without the field is read as
#: ``"disk"`` and keeps its hash)
KICKED_RATES = ("gas", "disk")
#: the kicked single disk's systems: uniform new directions at Poisson times of the gas
#: disk's rate (poisson) or at its collision times (actual); scattering kicks off a virtual
#: partner from the collision kernel at Poisson times of that rate (scatter)
KICKED_SYSTEMS = ("poisson", "actual", "scatter")


@dataclass(frozen=True)
class DisksTask:
    """One unit of work: ``n_disks`` (the ``n_index``-th of the sweep), runs ``ic_start ..
    ic_stop - 1``. ``radius`` is the disks' radius at that N; ``radius_index`` is
    ``n_index`` (the store's manifest records both)."""

    n_index: int
    n_disks: int
    radius: float
    ic_start: int
    ic_stop: int

    @property
    def radius_index(self) -> int:
        return self.n_index

    @property
    def id(self) -> str:
        """Stable name, e.g. ``"n0030-ic000008-000016"`` (used for part files)."""
        return f"n{self.n_disks:04d}-ic{self.ic_start:06d}-{self.ic_stop:06d}"

    @property
    def n_ics(self) -> int:
        return self.ic_stop - self.ic_start


@dataclass(frozen=True)
class DisksExperiment:
    """A sweep over the number of disks N of the tagged-disk collision-time process.

    Parameters
    ----------
    name : str
        The store's and the page's name: letters, digits and ``_ . -``.
    n_disks : sequence of int
        Numbers of disks ``>= 2``, distinct (stored sorted increasingly).
    packing : float, optional
        Area fraction ``N r^2`` in ``(0, 0.7]``, the same for every N (``r = sqrt(packing /
        N)``). Give exactly one of ``packing`` and ``r``.
    r : float, optional
        One disk radius for every N (``N r^2 <= 0.7`` at the largest N).
    rule : {"mirror", "elastic"}
        Disk-disk collision rule. Elastic runs start on the energy shell ``sum |v|^2 = N``
        (``kT = 1/2``) and record the tagged disks' speeds.
    n_tagged : int
        Tagged disks per N (``>= 1``), summed over runs: each run tags
        `tagged_per_run` disks and N gets `n_runs` runs.
    collisions : int
        The fixed number of collisions per tagged disk the tests read (``>= 5``; the
        issue's 30).
    max_tagged_per_run : int
        At most this many tagged disks per run (``>= 1``): more runs, less correlation
        between the tagged sequences, fewer position samples in memory.
    min_runs : int
        At least this many runs per N (``>= 2``): the confidence intervals are bootstraps
        clustered on runs.
    t_factor : float
        Each run lasts ``t_factor (collisions + 1) / nu`` (``>= 1``), ``nu`` the Enskog
        frequency (`kicktimes.stats.enskog_frequency`), or the two-disk kinetic rate when it
        is lower (few disks); a tagged disk with fewer than ``collisions + 1`` collisions by
        then is recorded and counted, not tested.
    samples_per_collision : int
        Elastic rule: position samples per mean free time (``>= 2``), from which each
        interval's speed is read (`kicktimes.experiment.disks_tasks.interval_speeds`).
    seed : int
        Root seed (``>= 0``).
    block_sequences : int
        Tagged sequences per task, about (``>= 1``): a task is one N times
        ``max(1, block_sequences // tagged_per_run(N))`` runs.
    description : str
        Free text for the page.
    kicked_runs : int
        The first ``min(kicked_runs, n_runs(N))`` runs of each N (``>= 0``,
        `kicked_states`) also compare
        the gas with a kicked single disk (the paper's question for a gas,
        `kicktimes.experiment.disks_tasks.kicked_rows`): another state of the same N is
        run for ``kicked_time`` mean free times (``> 0``), and the first disk's FTLE,
        boundary-angle autocorrelation and recurrence rate are compared with those of one
        disk from its state kicked at its own collision rate (Poisson) and at its
        collision times (actual). Mirror rule only.
    kicked_systems : tuple of str
        The kicked systems of that comparison, from `KICKED_SYSTEMS` (default ``("poisson",
        "actual")``; ``"scatter"``: kicks at Poisson times of the disk's rate, each a
        collision with a virtual partner drawn from the collision kernel,
        `kicktimes.billiard.scatter`).
    gas_ftle : {"tangent", "twin"}
        How that comparison measures the gas's largest Lyapunov exponent
        (`kicktimes.diagnostics.gas_lyapunov.disks_lyapunov`'s ``method``): tangent vectors
        carried by the engine (default) or a Benettin twin. Stores written before the field
        existed used the twin and are read so.
    kicked_rate : {"gas", "disk"}
        The rate of that comparison's Poisson and scatter kicks and of its ``lambda / nu``:
        the whole gas's collision frequency per disk, ``2 n_pp / (N T)`` (default, the
        rate of the density tables), or the followed disk's own ``n / T`` (about 200
        collisions, a few per cent of noise). Stores written before the field existed
        used the disk's own rate and are read so.
    boundary : {"circle", "box"}
        The unit circular table (default), or the periodic square box of the same area
        (side `box_side` ``= sqrt(pi)``: the same radius gives the same packing ``N r^2``
        and the same Enskog rate; no wall). The box needs at least 3 cells of width 2 r
        per side (``N >= 3`` at packing 0.2) and no kicked comparison.
    """

    name: str
    n_disks: tuple
    packing: float | None = None
    r: float | None = None
    rule: str = "mirror"
    n_tagged: int = 1000
    collisions: int = 30
    max_tagged_per_run: int = 250
    min_runs: int = 8
    t_factor: float = 3.0
    samples_per_collision: int = 40
    seed: int = 0
    block_sequences: int = 250
    description: str = field(default="")
    kicked_runs: int = 0
    kicked_time: float = 60.0
    kicked_systems: tuple = ("poisson", "actual")
    gas_ftle: str = "tangent"
    kicked_rate: str = "gas"
    boundary: str = "circle"

    #: what a store's record says this is (`Experiment` records have no ``kind``)
    kind = "disks"

    def __post_init__(self):
        put = functools.partial(object.__setattr__, self)  # (the dataclass is frozen)
        check_file_name("name", self.name)
        put("n_disks", check_distinct("n_disks", self.n_disks, what="disk numbers",
                                      check_item=lambda n, v: check_int(n, v, low=2, high=100_000)))
        if (self.packing is None) == (self.r is None):
            raise ValueError(f"packing, r: give exactly one of them, got packing={self.packing!r}"
                             f", r={self.r!r}")
        if self.packing is not None:
            put("packing", check_real("packing", self.packing, low=0.0, high=PACKING_MAX,
                                      high_open=False))
        else:
            r = check_real("r", self.r, low=0.0, high=0.5)
            n_max = self.n_disks[-1]
            phi = n_max * r * r
            if phi > PACKING_MAX:
                raise ValueError(f"r: {n_max} disks of radius {r!r} have packing "
                                 f"{phi:.6g}; N r^2 must be at most {PACKING_MAX} at the "
                                 f"largest N, i.e. r <= {math.sqrt(PACKING_MAX / n_max):.6g}")
            put("r", r)
        check_choice("rule", self.rule, RULES)
        put("n_tagged", check_int("n_tagged", self.n_tagged, low=1))
        put("collisions", check_int("collisions", self.collisions, low=5))
        put("max_tagged_per_run", check_int("max_tagged_per_run", self.max_tagged_per_run,
                                            low=1))
        put("min_runs", check_int("min_runs", self.min_runs, low=2))
        put("t_factor", check_real("t_factor", self.t_factor, low=1.0, low_open=False,
                                   high=100.0, high_open=False))
        put("samples_per_collision", check_int("samples_per_collision",
                                               self.samples_per_collision, low=2))
        put("seed", check_int("seed", self.seed, low=0))
        put("block_sequences", check_int("block_sequences", self.block_sequences, low=1))
        if not isinstance(self.description, str):
            raise TypeError(f"description: expected a string, got {self.description!r}")
        put("kicked_runs", check_int("kicked_runs", self.kicked_runs, low=0))
        put("kicked_time", check_real("kicked_time", self.kicked_time, low=0.0))
        systems = self.kicked_systems
        if isinstance(systems, (str, bytes)) or not hasattr(systems, "__iter__"):
            raise TypeError(f"kicked_systems: expected a list of systems, got {systems!r}")
        systems = tuple(systems)
        for s in systems:
            check_choice("kicked_systems", s, KICKED_SYSTEMS)
        if not systems or len(set(systems)) != len(systems):
            raise ValueError(f"kicked_systems: give distinct systems of {KICKED_SYSTEMS}, got "
                             f"{list(systems)}")
        put("kicked_systems", systems)
        check_choice("gas_ftle", self.gas_ftle, GAS_FTLE_METHODS)
        check_choice("kicked_rate", self.kicked_rate, KICKED_RATES)
        check_choice("boundary", self.boundary, BOUNDARIES)
        if self.boundary == "box" and self.kicked_runs:
            raise ValueError("kicked_runs: the kicked comparison is in the circle; give "
                             "kicked_runs=0 with boundary='box'")
        if self.kicked_runs and self.rule != "mirror":
            raise ValueError(f"kicked_runs: the kicked disk keeps its speed, so the comparison "
                             f"needs rule='mirror', got rule={self.rule!r}")

    # ------------------------------------------------------------------ derived
    def radius(self, n_disks: int) -> float:
        """The disks' radius at ``n_disks``: ``sqrt(packing / N)`` or the fixed ``r``."""
        return math.sqrt(self.packing / n_disks) if self.packing is not None else self.r

    def packing_at(self, n_disks: int) -> float:
        """The area fraction ``N r^2`` at ``n_disks``."""
        return n_disks * self.radius(n_disks) ** 2

    def tagged_per_run(self, n_disks: int) -> int:
        """Tagged disks per run: one for two disks (their sequences are the same), else
        ``min(N, max_tagged_per_run, n_tagged)``."""
        return 1 if n_disks == 2 else min(n_disks, self.max_tagged_per_run, self.n_tagged)

    def n_runs(self, n_disks: int) -> int:
        """Runs at ``n_disks``: enough for ``n_tagged`` sequences, at least ``min_runs``."""
        return max(self.min_runs, -(-self.n_tagged // self.tagged_per_run(n_disks)))

    @property
    def box_side(self) -> float | None:
        """The periodic box's side ``sqrt(pi)`` (the unit circle's area), or ``None`` in the
        circle."""
        return math.sqrt(math.pi) if self.boundary == "box" else None

    def kicked_states(self, n_disks: int) -> int:
        """States of the kicked comparison at ``n_disks``: its first ``min(kicked_runs,
        n_runs(N))`` runs. A design that gives few disks many runs (``n_tagged`` large)
        gives them many kicked states too, where a state's collision rate varies most
        (about 18 % from state to state at N = 2, 0.3 % at N = 1000, packing 0.02)."""
        return min(self.kicked_runs, self.n_runs(n_disks))

    def reference_frequency(self, n_disks: int) -> float:
        """The collision frequency a run's length is set by: Enskog's
        (`kicktimes.stats.enskog_frequency`, ``kT = 1/2``), or the two-disk kinetic rate
        (`kicktimes.stats.kinetic_rate`) of the same radius when lower."""
        from kicktimes.stats import enskog_frequency, kinetic_rate

        r = self.radius(n_disks)
        nu = enskog_frequency(r, n_disks, rule=self.rule)
        if r < 1.0 / 3.0:
            # two disks of radius r collide at the rate Gamma(r); a few disks nearly so
            nu = min(nu, float(kinetic_rate(r, rule=self.rule)) * (n_disks - 1))
        return nu

    def t_max(self, n_disks: int) -> float:
        """Duration of each run at ``n_disks``: ``t_factor (collisions + 1) / nu``."""
        return self.t_factor * (self.collisions + 1) / self.reference_frequency(n_disks)

    def tasks(self) -> list[DisksTask]:
        """All tasks of the sweep (N-major, then blocks of runs)."""
        out = []
        for k, n in enumerate(self.n_disks):
            runs = self.n_runs(n)
            block = max(1, self.block_sequences // self.tagged_per_run(n))
            for start in range(0, runs, block):
                out.append(DisksTask(k, n, self.radius(n), start, min(start + block, runs)))
        return out

    @property
    def geometry_label(self) -> str:
        """``packing 0.02`` or ``r = 0.0045``."""
        return f"packing {self.packing:g}" if self.packing is not None else f"r = {self.r:g}"

    # -------------------------------------------------------------- conversions
    def to_dict(self) -> dict:
        """JSON-ready dict of every field, with ``kind = "disks"``."""
        out = asdict(self)
        out["n_disks"] = list(out["n_disks"])
        out["kicked_systems"] = list(out["kicked_systems"])
        out["kind"] = self.kind
        return out

    @classmethod
    def from_record(cls, d) -> DisksExperiment:
        """The experiment of `to_dict` output (a store's record); unknown keys are refused."""
        if not isinstance(d, dict):
            raise TypeError(f"expected a dict of experiment fields, got {type(d).__name__}")
        d = dict(d)
        d.setdefault("gas_ftle", "twin")  # a record from before the field: a twin's FTLE
        d.setdefault("kicked_rate", "disk")  # before the field: the followed disk's rate
        if d.pop("kind", cls.kind) != cls.kind:
            raise ValueError(f"kind: a disks experiment's record has kind {cls.kind!r}")
        known = [f.name for f in fields(cls)]
        unknown = sorted(set(d) - set(known))
        if unknown:
            raise ValueError(f"unknown experiment key(s) {unknown}; valid keys are "
                             f"{', '.join(known)}")
        return cls(**d)

    from_dict = from_record

    def hash(self) -> str:
        """Stable identity: the first 16 hex digits of SHA-256 of the canonical JSON (the
        kicked comparison's fields left out while it is off, later fields while they have
        their first value, as before they existed)."""
        record = self.to_dict()
        if not self.kicked_runs:
            for key, default in _LATER_FIELDS.items():
                if record[key] == default:
                    del record[key]
        for key, default in _LATER_OPTIONAL.items():
            if tuple(record[key]) == default:
                del record[key]
        if not self.kicked_runs or self.gas_ftle == "twin":
            # the field is unused without the kicked comparison, and "twin" is what the
            # records written before it existed mean
            del record["gas_ftle"]
        if not self.kicked_runs or self.kicked_rate == "disk":
            del record["kicked_rate"]
        if self.boundary == "circle":
            del record["boundary"]  # as before the field existed
        text = json.dumps(record, sort_keys=True, separators=(",", ":"), allow_nan=False)
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def partner_line(self) -> str:
        """Empty: the disks are equal (`Store.summary` asks every experiment)."""
        return ""

    def summary(self) -> str:
        """A few lines describing the sweep."""
        ns = ", ".join(str(n) for n in self.n_disks)
        runs = sum(self.n_runs(n) for n in self.n_disks)
        return (f"Disks experiment {self.name!r} (hash {self.hash()})\n"
                f"  N ({len(self.n_disks)}): {ns}; {self.geometry_label}; rule {self.rule}\n"
                f"  about {self.n_tagged} tagged disks per N ({runs} runs in all), "
                f"{self.collisions} collisions each; seed {self.seed}\n"
                f"  {len(self.tasks())} tasks")


def _preset(name, rule, description, **geometry):
    return DisksExperiment(name=name, n_disks=N_SWEEP, rule=rule, seed=42, n_tagged=4000,
                           description=description, **geometry)


#: the issue's sweep: N = 2 .. 1000 at packings 0.02 and 0.2 and at the radius of packing
#: 0.02 at N = 1000, under both rules; about 4000 tagged disks per N, 30 collisions each
DISKS_PRESETS = {
    f"disks-{geo}-{rule}": _preset(
        f"disks-{geo}-{rule}", rule,
        f"The tagged disk among N = 2 .. 1000 disks at {text}, {rule} rule.", **kw)
    for geo, text, kw in (
        ("phi0.02", "packing 0.02", {"packing": 0.02}),
        ("phi0.2", "packing 0.2", {"packing": 0.2}),
        ("r0.0045", "the fixed radius 0.0045 (packing 0.02 at N = 1000)", {"r": 0.0045}),
    )
    for rule in RULES
}


#: the kicked single disk against the tagged disk of the gas (packing 0.02, mirror rule):
#: states of 200 mean free times each, 2000 tagged sequences per N so that few disks get
#: many states (1000 at N = 2, 667 at N = 3, ..., 16 from N = 300): a state's collision
#: rate varies by 18 % at N = 2 and 0.3 % at N = 1000, and the comparison's rate must
#: match the density table's (disks.csv) to within 2 % at every N
DISKS_PRESETS["disks-kicked-phi0.02-mirror"] = DisksExperiment(
    name="disks-kicked-phi0.02-mirror", n_disks=N_SWEEP, packing=0.02, rule="mirror", seed=43,
    n_tagged=2000, min_runs=16, kicked_runs=1000, kicked_time=200.0, kicked_systems=KICKED_SYSTEMS,
    description="The kicked single disk (uniform kicks at Poisson and at the actual times, "
                "scattering kicks from the collision kernel at Poisson times) against the "
                "tagged disk of N = 2 .. 1000 disks at packing 0.02, mirror rule: FTLE, "
                "boundary-angle ACF, recurrence.")

#: the controls of every sweep, named ``<sweep>-<control>``: an independent replicate
#: (``seed``: another root seed, the same design), another number of collisions per tagged
#: disk (``k60``: K = 60, another seed too; the tests' power grows with K) and the periodic
#: box of the same area (``box``: no wall, N >= 3, another seed), which says what the wall
#: makes of each finding
_CONTROL_FIELDS = {"seed": {"seed": 1042}, "k60": {"collisions": 60, "seed": 2042},
                   "box": {"boundary": "box", "seed": 3042}}


def _control_n(exp, control):
    """The numbers of disks of a control: the box leaves out N = 2 (two disks on a torus
    of side sqrt(pi) have fewer than 3 cells of width 2 r at packing 0.2)."""
    return tuple(n for n in exp.n_disks if n >= 3) if control == "box" else exp.n_disks


DISKS_CONTROLS = {
    f"{name}-{control}": dataclasses.replace(
        exp, name=f"{name}-{control}", n_disks=_control_n(exp, control), **change,
        description=f"{exp.description} Control {control!r} of {name}: "
                    + ", ".join(f"{k} = {v}" for k, v in change.items()) + ".")
    for name, exp in DISKS_PRESETS.items() if not exp.kicked_runs
    for control, change in _CONTROL_FIELDS.items()
}

#: the elastic N = 2 validation with the power its 10 % margin needs (issue 42): 30000
#: two-disk runs of the engine (one tagged disk each) against as many of the two-disk
#: simulator (`DISKS_REFERENCES`); the sample size from the share's binomial variance
DISKS_N2_RUNS = 30000
DISKS_PRESETS["disks-n2-phi0.02-elastic"] = DisksExperiment(
    name="disks-n2-phi0.02-elastic", n_disks=(2,), packing=0.02, rule="elastic", seed=45,
    n_tagged=DISKS_N2_RUNS, block_sequences=2500,
    description="Two disks in the N-disk engine at packing 0.02 (r = 0.1), elastic rule, "
                f"{DISKS_N2_RUNS} runs: the powered validation against the two-disk "
                "simulator.")


def _two_disk_reference(rule, *, name=None, n_ics=None, seed=44):
    from kicktimes.experiment.config import Experiment

    base = DISKS_PRESETS[f"disks-phi0.02-{rule}"]
    r = base.radius(2)
    horizon = base.t_max(2)
    return Experiment(
        name=name or f"disks-two-phi0.02-{rule}", radii=[r], n_ics=n_ics or base.n_tagged,
        n_steps=int(math.ceil(horizon / 0.5)), tau=0.5, ic_method="uniform", seed=seed,
        rule=rule, systems=("two_particle",), diagnostics=("autocorrelation",),
        block_size=500 if n_ics is None else 2500,
        description=f"The two-disk simulator at the radius of N = 2 at packing 0.02 "
                    f"(r = {r:g}), invariant-measure ICs, {rule} rule, as long as the "
                    f"disks sweep's N = 2 runs: the reference of its N = 2 row.")


#: the two-disk simulator's own sweep at the N = 2 radius of packing 0.02 (an `Experiment`
#: of one radius, invariant-measure ICs, as many ICs as tagged disks): the N = 2 row of the
#: disks sweep against the two-disk results
DISKS_REFERENCES = {f"disks-two-phi0.02-{rule}": _two_disk_reference(rule) for rule in RULES}
DISKS_REFERENCES["disks-two-n2-phi0.02-elastic"] = _two_disk_reference(
    "elastic", name="disks-two-n2-phi0.02-elastic", n_ics=DISKS_N2_RUNS, seed=46)


def disks_control(name: str):
    """``(sweep, control)`` of a control preset's name (`DISKS_CONTROLS`), else ``None``.

    >>> disks_control("disks-phi0.2-elastic-k60"), disks_control("disks-phi0.2-elastic")
    (('disks-phi0.2-elastic', 'k60'), None)
    """
    head, _, control = name.rpartition("-")
    return (head, control) if control in _CONTROL_FIELDS and head else None


def disks_preset(name: str) -> DisksExperiment:
    """The built-in disks experiment ``name``: one of `DISKS_PRESETS`, of their controls
    `DISKS_CONTROLS`, or of the two-disk references `DISKS_REFERENCES` (`Experiment`
    objects)."""
    check_choice("name", name, sorted(DISKS_PRESETS) + sorted(DISKS_CONTROLS)
                 + sorted(DISKS_REFERENCES))
    return DISKS_PRESETS.get(name) or DISKS_CONTROLS.get(name) or DISKS_REFERENCES[name]

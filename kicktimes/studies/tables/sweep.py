r"""The sweeps of the tables study: the paper's comparison in the circle, the ellipse and the
stadium, one store per (table, collision rule).

Each table's experiment is the paper's family A design (`kicktimes.experiment.presets`:
25000 collision-truncated steps of 0.2, recurrence at eps = 1e-3 and 1e-2 on the paper's
samples and at uniform times, the autocorrelation of the boundary angles, the paper's
tangent-space FTLE variant) at three radii (0.01, 0.02, 0.03), with invariant-measure ICs
(the paper's construction is the circle's) and the systems the question needs: the two
disks, the disk kicked at Poisson times of the IC's own rate, at the two disks' actual
collision times, and by scattering kicks at Poisson times. The mirror rule's store is the
primary (``tables_<table>``); the elastic rule's (``tables_<table>-elastic``) is its
collision-rule control, which `kicktimes.report.controls.merge_control_families` folds in
by its name.

The sweep report (`kicktimes.report.build_report`) computes every store's findings with
the estimators and verdict rules of the circle's pages; `kicktimes.studies.tables.compare`
reads them.
"""

from __future__ import annotations

from kicktimes.experiment import Experiment
from kicktimes.studies.cache import study_store
from kicktimes.tables import Circle, Ellipse, Stadium, table_spec

__all__ = ["RADII", "RULES", "SEED", "SYSTEMS", "TABLES", "family_name", "run_stores",
           "tables_experiment"]

#: the tables, by their short name: the integrable circle; an ellipse of the circle's area
#: (semi-axes 1.25 and 0.8, eccentricity 0.6), integrable for a point particle with
#: another invariant; Bunimovich's stadium with a = 1, chaotic for a single disk
TABLES = {"circle": Circle(), "ellipse": Ellipse(1.25, 0.8), "stadium": Stadium(1.0)}
RADII = (0.01, 0.02, 0.03)
RULES = ("mirror", "elastic")
SYSTEMS = ("two_particle", "poisson", "actual", "poisson_scatter")
SEED = 63


def family_name(table: str, rule: str) -> str:
    """The store's experiment name: ``tables_<table>`` for the mirror rule, and
    ``tables_<table>-elastic``, its collision-rule control (the ``<family>-<control>``
    form of `kicktimes.report.controls.merge_control_families`).

    >>> family_name("stadium", "mirror"), family_name("stadium", "elastic")
    ('tables_stadium', 'tables_stadium-elastic')
    """
    if table not in TABLES:
        raise ValueError(f"table must be one of {sorted(TABLES)}, got {table!r}")
    if rule not in RULES:
        raise ValueError(f"rule must be one of {list(RULES)}, got {rule!r}")
    return f"tables_{table}" + ("" if rule == "mirror" else f"-{rule}")


def tables_experiment(table: str, rule: str, *, n_ics: int, n_steps: int = 25000,
                      tau: float = 0.2, radii=RADII, seed: int = SEED,
                      block_size: int = 25) -> Experiment:
    """The experiment of one (table, rule) (module docstring).

    >>> exp = tables_experiment("ellipse", "mirror", n_ics=200)
    >>> exp.name, exp.table, exp.radii, exp.ic_method, exp.n_steps, exp.tau
    ('tables_ellipse', 'ellipse a=1.25 b=0.8', (0.01, 0.02, 0.03), 'uniform', 25000, 0.2)
    """
    return Experiment(
        name=family_name(table, rule), radii=radii, n_ics=n_ics, n_steps=n_steps, tau=tau,
        ic_method="uniform", seed=seed, sampling="paper", rule=rule, eps=(1e-3, 1e-2),
        rr_sampling="run+uniform", lyapunov_variant="paper", lyapunov_method="tangent",
        systems=SYSTEMS, block_size=block_size, table=table_spec(TABLES[table]),
        description=f"the paper's comparison in the {table} ({table_spec(TABLES[table])}) "
                    f"under the {rule} rule, invariant-measure ICs")


def run_stores(out, experiments, *, workers=1, scheduler=None, say=print) -> dict:
    """Run (or resume) each experiment's store ``out/store-<name>``
    (`kicktimes.studies.cache.study_store`): ``{name: Store}``."""
    return {exp.name: study_store(exp, out, workers=workers, scheduler=scheduler, say=say)[0]
            for exp in experiments}

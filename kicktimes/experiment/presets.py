"""The paper's two experiment families and their quick versions, built in.

The same experiments are the files ``analysis/<name>.toml`` of the repository (a test
checks that they agree); they are also built in so that ``kicktimes reproduce`` works
from an installed package without the repository.

Why ``sampling = "paper"``: the paper's "time steps" end early at every collision
(Section 2), its ``n`` counts those truncated steps, and its recurrence rates and
Lyapunov exponents are computed on the samples taken at the step ends. Uniform samples
at ``k tau`` would change the number of samples per time and where they fall (the
paper's samples cluster at collisions), hence the recurrence rate, so the reproduction
uses the paper's steps. ``lyapunov_variant = "paper"`` (``max(lambda_x, lambda_y)``) and
``d0 = 1/5000`` are likewise the paper's choices.
"""

from __future__ import annotations

from kicktimes.experiment.config import Experiment

__all__ = ["PRESETS", "preset"]


def _radii(start_mm: int, stop_mm: int) -> list[float]:
    # radii in steps of 0.002 written from integers, so 0.010 is exactly the float 0.01
    return [k / 1000 for k in range(start_mm, stop_mm + 1, 2)]


_PAPER = {
    "ic_method": "paper",
    "sampling": "paper",
    "rule": "mirror",
    "eps": (1e-3, 1e-2),
    "rr_sampling": "run",
    "lag": 1,
    "acf_max_lag": 20,
    "d0": 1.0 / 5000.0,
    "lyapunov_method": "tangent",
    "lyapunov_variant": "paper",
    "kick_angle": "uniform",
    "sigma": 1.0,
    # the paper's three systems and, beyond the paper, the scatter-kicked disk
    # (docs/scatter.md) with Poisson and with actual kick times
    "systems": ("two_particle", "poisson", "actual", "poisson_scatter", "actual_scatter"),
}

PRESETS = {
    "family_a": Experiment(
        name="family_a",
        radii=_radii(8, 30),
        n_ics=200,
        n_steps=25000,
        tau=0.2,
        seed=1,
        block_size=25,
        description=(
            "The paper's family A (Figs. 6-8, top): radii 0.008-0.030, 200 ICs drawn at "
            "r = 0.030, 25000 collision-truncated steps of tau = 0.2."
        ),
        **_PAPER,
    ),
    "family_b": Experiment(
        name="family_b",
        radii=_radii(8, 26),
        n_ics=1000,
        n_steps=15000,
        tau=0.3,
        seed=2,
        block_size=50,
        description=(
            "The paper's family B (Figs. 6 and 8, bottom): radii 0.008-0.026, 1000 ICs drawn "
            "at r = 0.026, 15000 collision-truncated steps of tau = 0.3."
        ),
        **_PAPER,
    ),
    "quick_a": Experiment(
        name="quick_a",
        radii=[0.008, 0.014, 0.02, 0.03],
        n_ics=20,
        n_steps=2000,
        tau=0.2,
        seed=1,
        block_size=10,
        description="A small version of family A for smoke tests (4 radii, 20 ICs, 2000 steps).",
        **_PAPER,
    ),
    "quick_b": Experiment(
        name="quick_b",
        radii=[0.008, 0.014, 0.02, 0.026],
        n_ics=20,
        n_steps=2000,
        tau=0.3,
        seed=2,
        block_size=10,
        description="A small version of family B for smoke tests (4 radii, 20 ICs, 2000 steps).",
        **_PAPER,
    ),
}

#: The experiments ``kicktimes reproduce --scale`` runs.
SCALES = {"paper": ("family_a", "family_b"), "quick": ("quick_a", "quick_b")}


def preset(name: str) -> Experiment:
    """One of the built-in experiments: ``family_a``, ``family_b``, ``quick_a``, ``quick_b``."""
    if name not in PRESETS:
        raise ValueError(f"name: unknown preset {name!r}; choose one of {sorted(PRESETS)}")
    return PRESETS[name]

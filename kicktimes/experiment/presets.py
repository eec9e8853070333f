"""The paper's two experiment families and their quick versions, built in.

They are the one definition of these experiments: ``kicktimes run NAME`` runs one,
``kicktimes presets NAME`` prints it as TOML (the file to copy and edit for a sweep of
one's own), and ``kicktimes reproduce`` runs them from an installed package.

Why ``sampling = "paper"``: the paper's "time steps" end early at every collision
(Section 2), its ``n`` counts those truncated steps, and its recurrence rates and
Lyapunov exponents are computed on the samples taken at the step ends. Uniform samples
at ``k tau`` would change the number of samples per time and where they fall (the
paper's samples cluster at collisions), hence the recurrence rate, so the reproduction
uses the paper's steps. ``lyapunov_variant = "paper"`` (``max(lambda_x, lambda_y)``) and
``d0 = 1/5000`` are likewise the paper's choices.
"""

from __future__ import annotations

import dataclasses

from kicktimes.experiment.config import Experiment

__all__ = ["CONTENTS", "CONTROL_ICS_B", "CONTROL_PRESETS", "PAPER_CONTENT", "PRESETS", "preset",
           "preset_names"]


def _radii(start_mm: int, stop_mm: int) -> list[float]:
    # radii in steps of 0.002 written from integers, so 0.010 is exactly the float 0.01
    return [k / 1000 for k in range(start_mm, stop_mm + 1, 2)]


_PAPER = {
    "ic_method": "paper",
    "sampling": "paper",
    "rule": "mirror",
    "eps": (1e-3, 1e-2),
    # the recurrence rows on the paper's samples and, as the control of the recurrence
    # findings, on uniform-time samples of the same trajectories (uniform_* rows)
    "rr_sampling": "run+uniform",
    "lag": 1,
    "acf_max_lag": 20,
    "d0": 1.0 / 5000.0,
    "lyapunov_method": "tangent",
    "lyapunov_variant": "paper",
    "kick_angle": "uniform",
    "sigma": 1.0,
    # the paper's three systems and, beyond the paper, the scatter-kicked disk
    # (docs/scatter.md) with Poisson, actual and kinetic-rate kick times (docs/mechanism.md)
    # and uniform kicks at that kinetic rate (the fourth cell of the deflection x timing
    # factorial, kicktimes.report.decomposition)
    "systems": ("two_particle", "poisson", "actual", "poisson_scatter", "actual_scatter",
                "poisson_kinetic", "uniform_kinetic"),
}

PRESETS = {
    "family_a": Experiment(
        name="family_a", radii=_radii(8, 30), n_ics=200, n_steps=25000, tau=0.2, seed=1,
        block_size=25, description=(
            "The paper's family A (Figs. 6-8, top): radii 0.008-0.030, 200 ICs drawn at "
            "r = 0.030, 25000 collision-truncated steps of tau = 0.2."), **_PAPER),
    "family_b": Experiment(
        name="family_b", radii=_radii(8, 26), n_ics=1000, n_steps=15000, tau=0.3, seed=2,
        block_size=50, description=(
            "The paper's family B (Figs. 6 and 8, bottom): radii 0.008-0.026, 1000 ICs drawn "
            "at r = 0.026, 15000 collision-truncated steps of tau = 0.3."), **_PAPER),
    **{name: Experiment(
        name=name, radii=radii, n_ics=20, n_steps=2000, tau=tau, seed=seed, block_size=10,
        description=f"A small version of family {family} for smoke tests (4 radii, 20 ICs, "
        "2000 steps).", **_PAPER)
       for name, family, radii, tau, seed in (
           ("quick_a", "A", [0.008, 0.014, 0.02, 0.03], 0.2, 1),
           ("quick_b", "B", [0.008, 0.014, 0.02, 0.026], 0.3, 2))},
}



def _control(base: Experiment, control: str, label: str, what: str, **changes) -> Experiment:
    """``base`` again with ``changes``, named ``"<base>-<control>"``: a control of its
    findings (`kicktimes.report.controls.merge_control_families` folds its ratios into
    ``base``'s findings table under ``control``)."""
    return dataclasses.replace(base, name=f"{base.name}-{control}",
                               description=f"Control of {label}: the same experiment {what}.",
                               **changes)


#: ICs of each of family B's control experiments: a stated subset (the first 300 of the
#: control's own draw) keeps the added cost of the controls bounded; their intervals come
#: from these ICs alone
CONTROL_ICS_B = 300

#: The controls of a family's findings that other experiments provide: the 2 x 2 design
#: collision rule (mirror, elastic) x IC measure (the paper's procedure, the invariant
#: measure). (control name, what changes, the settings)
_DESIGN = (
    ("invariant_ics",
     "with initial conditions drawn from the invariant measure (positions uniform on the "
     "non-overlapping pairs, uniform directions) instead of the paper's procedure",
     {"ic_method": "uniform"}),
    ("elastic",
     "under the elastic collision rule (energy exchanged between the disks), from the "
     "paper's initial conditions (unit speeds at the start)",
     {"rule": "elastic"}),
    ("elastic+invariant_ics",
     "under the elastic collision rule, with initial conditions drawn from the invariant "
     "measure (positions as for invariant_ics, velocities uniform on the energy shell)",
     {"rule": "elastic", "ic_method": "uniform"}),
)
_KEYS = {"invariant_ics": "invariant", "elastic": "elastic",
         "elastic+invariant_ics": "elastic_invariant"}
for _family, _label, _extra in (("family_a", "family A", {}),
                                ("family_b", "family B", {"n_ics": CONTROL_ICS_B})):
    for _name, _what, _changes in _DESIGN:
        _subset = (f" (the first {CONTROL_ICS_B} ICs of its own draw)" if _extra else "")
        PRESETS[f"{_family}_{_KEYS[_name]}"] = _control(
            PRESETS[_family], _name, _label, _what + _subset, **_changes, **_extra)

#: Presets that are controls of another family's findings (named "<family>-<control>").
CONTROL_PRESETS = tuple(f"{family}_{key}" for family in ("family_a", "family_b")
                        for key in _KEYS.values())
#: What ``content="paper"`` keeps of a preset: the paper's own systems and diagnostics.
PAPER_CONTENT = {
    # the two-disk billiard and the disk kicked at Poisson and at actual times (no
    # scatter-kicked systems)
    "systems": ("two_particle", "poisson", "actual"),
    # the recurrence rate at the paper's eps = 1e-3 only (no RQA at a second threshold)
    "eps": (1e-3,),
    # the lag-1 autocorrelation R_1 only (no ACF curve)
    "acf_max_lag": 1,
    # the recurrence rate on the paper's samples only (no uniform-sampling control)
    "rr_sampling": "run",
}
#: The contents a preset comes in (``preset(name, content=...)``).
CONTENTS = ("full", "paper")


def preset(name: str, content: str = "full") -> Experiment:
    """One of the built-in experiments: ``family_a``, ``family_b``, ``quick_a``, ``quick_b``.

    Parameters
    ----------
    name : str
        The preset.
    content : {"full", "paper"}, default "full"
        ``"full"``: kicktimes' presets, the paper's systems and diagnostics plus the
        scatter-kicked systems, the RQA at eps = 1e-3 and 1e-2 and the ACF curve to lag 20.
        ``"paper"``: the paper's own content only (`PAPER_CONTENT`: three systems, the
        recurrence rate at eps = 1e-3, ``R_1``), about half the sweep's work; the rest of
        the experiment (radii, ICs, steps, seed, FTLE) is the same, so the rows both
        contents have are bitwise the same, except ``decorrelation_lag`` and ``tau_int``,
        which are read off the ACF curve and depend on its length.

    Examples
    --------
    >>> from kicktimes.experiment import preset
    >>> preset("family_b").systems[:3], len(preset("family_b").systems)
    (('two_particle', 'poisson', 'actual'), 7)
    >>> exp = preset("family_b", content="paper")
    >>> exp.systems, exp.eps, exp.acf_max_lag
    (('two_particle', 'poisson', 'actual'), (0.001,), 1)
    """
    for arg, value, choices in (("name", name, sorted(PRESETS)), ("content", content, CONTENTS)):
        if not isinstance(value, str):
            raise TypeError(f"{arg}: expected a str, one of {list(choices)}, got {value!r}")
    if name not in PRESETS:
        raise ValueError(f"name: unknown preset {name!r}; choose one of {sorted(PRESETS)}")
    if content not in CONTENTS:
        raise ValueError(f"content: expected one of {list(CONTENTS)}, got {content!r}")
    exp = PRESETS[name]
    if content == "paper":
        exp = dataclasses.replace(
            exp,
            **PAPER_CONTENT,
            description=exp.description + " The paper's own content: its three systems, the "
            "recurrence rate at eps = 0.001, the lag-1 autocorrelation.",
        )
    return exp


def preset_names() -> tuple[list[str], list[str]]:
    """The names of the built-in experiments: the two-disk presets (`PRESETS`, with the
    controls), and the disks presets with their controls and two-disk references
    (`kicktimes.experiment.disks_preset`), each list in its registry's order.

    >>> two, disks = preset_names()
    >>> two[:4]
    ['family_a', 'family_b', 'quick_a', 'quick_b']
    """
    from kicktimes.experiment.disks import DISKS_CONTROLS, DISKS_PRESETS, DISKS_REFERENCES

    return list(PRESETS), [*DISKS_PRESETS, *DISKS_CONTROLS, *DISKS_REFERENCES]

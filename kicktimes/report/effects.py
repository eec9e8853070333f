r"""Effect sizes with 95 % confidence intervals and the verdict rules of the Findings.

Every comparison of the report is a ratio (a kicked system over the two-particle system,
or an observed rate over the kinetic rate) with a 95 % confidence interval, and every
verdict follows one printed rule (:func:`ratio_rule`, :data:`SHARE_RULE`), so no verdict
is typed by hand. The record and the rules are those of every page kicktimes writes
(:mod:`kicktimes.stats.findings`; ``kicktimes analyze`` states its findings with them):
an :class:`Effect` is a :class:`kicktimes.stats.Finding` with the compared system.

The bootstrap resamples initial conditions: the same IC index is the same initial
condition in every system and at every radius (the paper's design), so one resample of IC
indices is applied to all systems and radii at once (a paired, clustered bootstrap).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from kicktimes.stats import paired_ratio
from kicktimes.stats.findings import (
    Finding,
    effect_statement,
    ratio_rule,
    ratio_verdict,
)

__all__ = ["BUILT_IN", "Effect", "store_ratio"]

#: appended to a verdict whose agreement is guaranteed by how the kicked system is built
BUILT_IN = "built in"


@dataclass(frozen=True)
class Effect(Finding):
    """A finding of the report (:class:`kicktimes.stats.Finding`): an effect size, its
    95 % CI, how the CI was computed and the verdict, for one kicked ``system`` against
    the two-particle one (or for the store, ``system=""``).

    Attributes
    ----------
    question : str
        The question answered (e.g. ``"FTLE"``).
    system : str
        The kicked system compared with the two-particle one, or ``""``.
    quantity : str
        What ``estimate`` is (e.g. ``"ratio of means, kicked / two-particle"``).
    estimate, ci_low, ci_high : float
        The effect and its 95 % confidence interval.
    verdict : str
        From the printed rule; ``"… (built in)"`` when the agreement holds by construction.
    rule : str
        The rule that turned the interval into the verdict.
    method : str
        How the interval was computed.
    detail : str
        The supporting numbers (per radius, medians, predictions).
    statement : str
        One sentence, derived from the rest: question, effect, CI and verdict.
    """

    statement: str = field(init=False, default="")
    system: str = ""

    def __post_init__(self):
        from kicktimes.render.figures import system_label

        who = f", {system_label(self.system)} vs two-particle" if self.system else ""
        text = effect_statement(self.question + who, self.quantity, self.estimate, self.ci_low,
                                self.ci_high, self.method, self.verdict)
        object.__setattr__(self, "statement", text)

    @classmethod
    def of_ratio(cls, question, system, quantity, overall, *, tolerance, detail="", method=None,
                 verdict=None):
        """The Effect of a ratio and its bootstrap CI, ``overall`` as :func:`paired_ratio`
        returns it: the verdict of :func:`ratio_verdict` (unless ``verdict`` is given) under
        the printed :func:`ratio_rule`, the method "paired bootstrap over N ICs" (unless
        ``method`` is given)."""
        low, high = overall["ci_low"], overall["ci_high"]
        return cls(
            question=question,
            system=system,
            quantity=quantity,
            estimate=overall["ratio"],
            ci_low=low,
            ci_high=high,
            verdict=verdict or ratio_verdict(low, high, tolerance=tolerance),
            rule=ratio_rule(tolerance=tolerance),
            method=method or f"paired bootstrap over {overall['n_ics']} ICs",
            detail=detail,
        )


def store_ratio(ctx, numerator, denominator):
    """:func:`paired_ratio` under the store's bootstrap: the Findings' stream
    (``ctx.boot_rng()``), ``ctx.n_boot`` resamples, shared by every ratio of the store
    (``ctx.resamples``)."""
    return paired_ratio(numerator, denominator, rng=ctx.boot_rng(), n_boot=ctx.n_boot,
                        resamples=ctx.resamples)

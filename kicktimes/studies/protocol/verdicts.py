"""The protocol study's verdict rules beyond a ratio's: closeness, the balloon, "reproduces?".

Each rule is a `kicktimes.stats` rule read for one kind of claim of the paper, with its
margin stated here, before any data:

* `closer_verdict`: which kicks give the FTLE closer to the two-disk value, from the 95 %
  CI of ``d = |ln R_poisson| - |ln R_actual|`` against `CLOSER_MARGIN`
  (`kicktimes.stats.null_verdict`: an equivalence test around 0), with the sign of a
  difference inside the margin kept (`kicktimes.stats.share_verdict` against 0);
* `residual_verdict`: a least-squares line's RMS relative residual against `MARGIN` (the
  fit is good when the CI of the residual lies below it), read as a residual, not as a
  ratio;
* `balloon_verdict`: the sign of a kicked/two-disk RR ratio against 1 (the paper's balloon
  is a two-disk RR above the kicked ones, a ratio below 1);
* `reproduces`: the table's "reproduces?" column, from a claim's kind and its verdict
  (`REPRODUCES_RULE` prints it).

Examples
--------
>>> closer_verdict(-0.0807, -0.0679), closer_verdict(-0.00327, -0.00103)
('Poisson closer', 'Poisson closer, inside the margin')
>>> reproduces("poisson_better", "Poisson closer, inside the margin")
'in sign only'
>>> balloon_verdict(1.02, 1.04), reproduces("balloon", balloon_verdict(1.02, 1.04))
('no balloon (ratio > 1)', 'no, opposite sign')
"""

from __future__ import annotations

from kicktimes.stats import MARGIN, null_verdict, share_verdict

__all__ = ["CLOSER_MARGIN", "CLOSER_RULE", "KINDS", "REPRODUCES_RULE", "balloon_verdict",
           "closer_verdict", "reproduces", "residual_verdict"]

#: the margin of "equally close" on d = |ln R_poisson| - |ln R_actual|: a tenth of the
#: agreement band `kicktimes.stats.MARGIN`, i.e. the Poisson- and actual-kicked FTLEs 1 %
#: apart on the same side of the two-disk value. A smaller difference moves no ratio
#: across the band's edge by more than 1 % of it, so it cannot make one kick law a
#: "better" approximation in the sense of the 10 % verdicts; the renormalised reading's
#: difference (about 0.07) is 7 margins, the printed eq. (4)'s (about 0.002) a fifth of one
CLOSER_MARGIN = MARGIN / 10

CLOSER_RULE = (
    f"d = |ln R_poisson| − |ln R_actual| (negative: Poisson closer to the two-disk value) "
    f"against the margin m = {CLOSER_MARGIN:g}, a tenth of the 10 % band, stated in "
    f"advance: *equally close* when the CI of d lies in [−m, m] and contains 0; *… closer, "
    f"inside the margin* when it lies in [−m, m] but excludes 0 (real but negligible); "
    f"*… closer* when it lies beyond ±m; else *inconclusive* (`kicktimes.stats.null_verdict`)")


def closer_verdict(low: float, high: float, margin: float = CLOSER_MARGIN) -> str:
    """The verdict on the 95 % CI ``[low, high]`` of ``d = |ln R_P| - |ln R_A|``
    (`CLOSER_RULE`): ``"Poisson closer"``, ``"actual closer"``, ``"Poisson closer, inside
    the margin"``, ``"actual closer, inside the margin"``, ``"equally close"`` or
    ``"inconclusive"`` (also for a non-finite endpoint).

    Examples
    --------
    >>> closer_verdict(-0.004, 0.003), closer_verdict(0.02, 0.05), closer_verdict(-0.02, 0.0)
    ('equally close', 'actual closer', 'inconclusive')
    """
    if not margin > 0:
        raise ValueError(f"margin must be > 0, got {margin!r}")
    verdict = null_verdict(low, high, margin=margin)
    if verdict == "below its null":
        return "Poisson closer"
    if verdict == "above its null":
        return "actual closer"
    if verdict == "at its null":
        side = share_verdict(low, high, level=0.0)
        return {"below": "Poisson closer, inside the margin",
                "above": "actual closer, inside the margin"}.get(side, "equally close")
    return "inconclusive"


def balloon_verdict(low: float, high: float) -> str:
    """The sign of a kicked/two-disk RR ratio's 95 % CI against 1: ``"balloon (ratio <
    1)"`` when it lies entirely below 1 (the two-disk RR above the kicked one, the paper's
    balloon), ``"no balloon (ratio > 1)"`` when entirely above, else ``"inconclusive"``
    (`kicktimes.stats.share_verdict` against 1).

    Examples
    --------
    >>> balloon_verdict(0.8, 0.95), balloon_verdict(0.98, 1.01)
    ('balloon (ratio < 1)', 'inconclusive')
    """
    return {"below": "balloon (ratio < 1)", "above": "no balloon (ratio > 1)"}.get(
        share_verdict(low, high, level=1.0), "inconclusive")


def residual_verdict(low: float, high: float, margin: float = MARGIN) -> str:
    """The verdict on the 95 % CI ``[low, high]`` of an RMS relative residual about a
    least-squares line: ``"residual below 10 %"`` when the CI lies below ``margin`` (the
    points within ``margin`` of their line in RMS), ``"residual above 10 %"`` when it lies
    above, else ``"inconclusive"`` (also for a non-finite endpoint). A residual is >= 0 and
    0 for a perfect line, so it is read against the margin, never against 1.

    Examples
    --------
    >>> residual_verdict(0.0144, 0.086), residual_verdict(0.12, 0.2), residual_verdict(0.05, 0.3)
    ('residual below 10 %', 'residual above 10 %', 'inconclusive')
    """
    if not margin > 0:
        raise ValueError(f"margin must be > 0, got {margin!r}")
    label = f"{100 * margin:g} %"
    if high < margin:
        return f"residual below {label}"
    if low > margin:
        return f"residual above {label}"
    return "inconclusive"


#: each kind of claim: {verdict: answer}; a verdict not listed is "undecided"
KINDS = {
    "agreement": {f"within {100 * MARGIN:g} %": "yes", "higher": "no", "lower": "no"},
    "line_fit": {f"residual below {100 * MARGIN:g} %": "yes",
                 f"residual above {100 * MARGIN:g} %": "no"},
    "balloon": {"balloon (ratio < 1)": "yes", "no balloon (ratio > 1)": "no, opposite sign"},
    "poisson_better": {"Poisson closer": "yes",
                       "Poisson closer, inside the margin": "in sign only",
                       "equally close": "no", "actual closer": "no, opposite sign",
                       "actual closer, inside the margin": "no, opposite sign"},
    "not_tested": {},
    "not_in_paper": {},
}

REPRODUCES_RULE = (
    "*reproduces?* follows from the verdict by the paper's protocol: an agreement is *yes* "
    "within 10 %, *no* when higher or lower; a line fit *yes* when its residual lies below "
    "10 %, *no* above; the balloon *yes* below 1, *no, opposite sign* "
    "above; \"Poisson sometimes better\" *yes* when Poisson is closer beyond the margin, "
    "*in sign only* inside it, *no* when equally close; *undecided* when inconclusive; *not "
    "tested* where it was not run; *not in the paper* for a panel the figure does not show "
    "(`verdicts.reproduces`)")


def reproduces(kind: str, verdict) -> str:
    """The "reproduces?" answer of a claim of ``kind`` (`KINDS`) with ``verdict`` by the
    paper's protocol (`REPRODUCES_RULE`).

    Examples
    --------
    >>> reproduces("agreement", "within 10 %"), reproduces("agreement", "inconclusive")
    ('yes', 'undecided')
    >>> reproduces("not_tested", None), reproduces("not_in_paper", "within 10 %")
    ('not tested', 'not in the paper')
    """
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {sorted(KINDS)}, got {kind!r}")
    if kind == "not_tested":
        return "not tested"
    if kind == "not_in_paper":
        return "not in the paper"
    return KINDS[kind].get(verdict, "undecided")

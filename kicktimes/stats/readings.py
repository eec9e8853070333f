"""How every results page reads a verdict that is "inconclusive".

An inconclusive equivalence verdict has a 95 % interval that straddles an edge of the
margin. Two cases differ, and the pages say which:

- the interval excludes the null value (1 for a ratio, 0 for a difference from a null
  stream): a real departure whose size the margin does not resolve (the interval
  reaches both inside the margin and beyond it, possibly far beyond); it reads "below 1,
  size unresolved" (or "above its null, size unresolved") beside its interval, which
  gives the size, and names no sample size;
- the interval contains the null value: "not resolved at this size", with the size that
  would resolve it (`kicktimes.stats.equivalence_sample_size`).
"""

from __future__ import annotations

import math

from kicktimes.validation import keyword_only_after

from .findings import MARGIN, null_verdict, ratio_verdict

__all__ = ["null_reading", "ratio_reading", "ratio_words", "side_of"]


@keyword_only_after(2, since="0.2.0")
def side_of(low, high, *, null=1.0):
    """``"above"`` / ``"below"`` when the interval ``[low, high]`` lies entirely above /
    below ``null``, else ``None`` (also for a non-finite end).

    >>> side_of(1.06, 1.15), side_of(0.815, 0.942), side_of(0.913, 1.15)
    ('above', 'below', None)
    """
    if not (math.isfinite(low) and math.isfinite(high)):
        return None
    if low > high:
        raise ValueError(f"low must not exceed high, got [{low!r}, {high!r}]")
    return "above" if low > null else "below" if high < null else None


@keyword_only_after(2, since="0.2.0")
def ratio_reading(low, high, *, tolerance=MARGIN):
    """`kicktimes.stats.ratio_verdict` of a ratio's 95 % CI, except that an inconclusive
    interval lying entirely on one side of 1 reads ``"below 1, size unresolved"`` (or
    above): a departure from 1 whose size against the margin is not resolved (its interval
    gives the size), not an unresolved departure.

    >>> ratio_reading(0.815, 0.942), ratio_reading(0.3, 0.4), ratio_reading(0.913, 1.15)
    ('below 1, size unresolved', 'lower', 'inconclusive')
    """
    verdict = ratio_verdict(low, high, tolerance=tolerance)
    side = side_of(low, high, null=1.0) if verdict == "inconclusive" else None
    if side:
        return f"{side} 1, size unresolved"
    return verdict


@keyword_only_after(2, since="0.2.0")
def ratio_words(low, high, *, tolerance=MARGIN):
    """`ratio_reading` in a page's words: a verdict *within* the margin whose interval
    excludes 1 says on which side (a real difference smaller than the margin), so that
    "within 10 %" never hides an interval that excludes the null.

    >>> ratio_words(1.046, 1.099), ratio_words(0.95, 1.02), ratio_words(0.815, 0.942)
    ('within 10 %, above 1', 'within 10 %', 'below 1, size unresolved')
    """
    verdict = ratio_reading(low, high, tolerance=tolerance)
    side = side_of(low, high, null=1.0) if verdict.startswith("within") else None
    return f"{verdict}, {side} 1" if side else verdict


@keyword_only_after(2, since="0.2.0")
def null_reading(low, high, *, margin):
    """`kicktimes.stats.null_verdict` of the 95 % CI of *statistic − its null value*,
    except that an inconclusive interval lying entirely on one side of 0 reads ``"above
    its null, size unresolved"`` (or below).

    >>> null_reading(0.005, 0.077, margin=0.07), null_reading(-0.03, 0.09, margin=0.07)
    ('above its null, size unresolved', 'inconclusive')
    """
    verdict = null_verdict(low, high, margin=margin)
    side = side_of(low, high, null=0.0) if verdict == "inconclusive" else None
    if side:
        return f"{side} its null, size unresolved"
    return verdict

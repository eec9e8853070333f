"""The margins of kicktimes' equivalence tests, each fixed in advance and stated once.

A margin is half the smallest effect the comparison means to resolve
(docs/definitions.md, "Margins and nulls"); a verdict reads a 95 % interval against it
(`kicktimes.stats.ratio_verdict`, `kicktimes.stats.null_verdict`).
"""

from __future__ import annotations

__all__ = ["COUNTS_MARGIN", "DIAGNOSTIC_MARGINS", "D_MARGIN", "EOS_MARGIN", "FINE_MARGIN",
           "MARGIN", "RR_MARGIN", "margin_of"]

#: The equivalence margin of every ratio kicktimes reads, fixed in advance: "within 10 %"
#: when the whole CI of the ratio lies in [1 - MARGIN, 1 + MARGIN] (`ratio_verdict`).
MARGIN = 0.1


#: the margin of the scatter-kick and unequal-disk FTLE ratios, stated in advance: half
#: the smallest effect those comparisons mean to detect, the exponent the partner's
#: tangent memory carries (zeroing it costs the two disks 10.6 % of their FTLE,
#: docs/results/scatter.md); `MARGIN` (10 %) equals that effect and cannot resolve it
FINE_MARGIN = 0.05

#: the margin of the off-diagonal recurrence rate ratio: half the two-disk RR's excess
#: over a uniform filling of the table, eps^2 / (1 - r)^2, which any process that fills it
#: gives (6.4 % in family A and 8.1 % in family B at eps = 1e-2 on uniform-time samples,
#: 11-13 % at 1e-3; the recurrence figures' dotted guide); at 10 % a kicked disk that did
#: no more than fill the table would read "within"
RR_MARGIN = 0.03

#: each paper diagnostic's margin where it is not `MARGIN`, fixed in advance: half the
#: smallest effect the comparison means to resolve (docs/definitions.md, "Margins and
#: nulls"): the FTLE at `FINE_MARGIN` (the scatter kick's deficit, the partner's tangent
#: memory, is about 10 %), the off-diagonal RR at `RR_MARGIN`, the counts at `COUNTS_MARGIN`
#: the margin of the collision counts over kinetic theory, Gamma(r) T: half the shift that
#: the sticky runs (about 0.5 % of the runs) give the ensemble ratio, 5 %
COUNTS_MARGIN = 0.025

#: the margin of the N-disk engine's equation of state, Z over a reference, and of its
#: collision frequency over Enskog's with the same Z's contact value: 0.1 %, which tells
#: Henderson's approximation from the exact Z from packing 0.4 on (0.14 % there); a
#: reference's own stated error is added to it (`kicktimes.studies.eos`)
EOS_MARGIN = 0.001

DIAGNOSTIC_MARGINS = {"ftle": FINE_MARGIN, "rr_offdiag": RR_MARGIN, "counts": COUNTS_MARGIN}


def margin_of(diagnostic, *, default=MARGIN):
    """The equivalence margin of a findings table's ``diagnostic`` (``"ftle"``,
    ``"rr_offdiag@0.01"``, ``"det@0.001"``, ...): `DIAGNOSTIC_MARGINS` by the name before
    the ``@``, else ``default``.

    >>> margin_of("ftle"), margin_of("rr_offdiag@0.01"), margin_of("det@0.01")
    (0.05, 0.03, 0.1)
    >>> margin_of("one_minus_r1", default=0.2)
    0.2
    """
    if not isinstance(diagnostic, str):
        raise TypeError(f"diagnostic must be a str, got {type(diagnostic).__name__}")
    return DIAGNOSTIC_MARGINS.get(diagnostic.split("@")[0], default)

#: the margin of a dispersion index D read against its null stream's D (`null_verdict`):
#: half the smallest effect the gas pages mean to detect, the elastic linear-Boltzmann
#: excess D_inf - 1 = 0.14 of a dilute tagged disk (docs/definitions.md, "Margins")
D_MARGIN = 0.07

r"""Exact Shapley values of a cooperative game with a handful of players.

For players :math:`N = \{0, \dots, n-1\}` and a value :math:`v(S)` of every coalition
:math:`S \subseteq N`, player :math:`i`'s Shapley value (Shapley 1953) is its marginal
contribution averaged over the orders in which the players join,

.. math:: \phi_i = \sum_{S \subseteq N \setminus \{i\}}
          \frac{|S|!\,(n - |S| - 1)!}{n!}\,\bigl(v(S \cup \{i\}) - v(S)\bigr),

and :math:`\sum_i \phi_i = v(N) - v(\varnothing)` (efficiency). kicktimes splits a
kicked-versus-two-disk gap between the ingredients of the kicks this way: the report's
gap decomposition (two ingredients, :math:`v(S) = -|\log \rho_S|`) and the protocol
study's choices of the paper's eq. (4) (three).

Examples
--------
>>> v = {frozenset(): 0.0, frozenset({0}): 1.0, frozenset({1}): 2.0, frozenset({0, 1}): 5.0}
>>> shapley_values(v, 2)   # the synergy of 2 is split evenly
[2.0, 3.0]
"""

from __future__ import annotations

import itertools
import math

__all__ = ["shapley_values"]


def shapley_values(values, n: int) -> list:
    """The exact Shapley value of each of ``n`` players.

    Parameters
    ----------
    values : mapping
        ``values[frozenset(S)]`` for every coalition ``S`` of ``range(n)``: numbers, or
        numpy arrays of one shape (one game per element, e.g. per bootstrap resample).
    n : int
        The players, at least 1 (the sum has :math:`2^{n-1}` terms per player).

    Returns
    -------
    list
        ``[phi_0, ..., phi_{n-1}]``, each of the values' type.
    """
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ValueError(f"n must be an integer >= 1, got {n!r}")
    missing = [set(s) for k in range(n + 1) for s in itertools.combinations(range(n), k)
               if frozenset(s) not in values]
    if missing:
        raise ValueError(f"values: no value for the coalition {missing[0] or '{}'}")
    phi = []
    for i in range(n):
        total = 0.0
        others = [j for j in range(n) if j != i]
        for k in range(n):
            for s in itertools.combinations(others, k):
                w = math.factorial(k) * math.factorial(n - k - 1) / math.factorial(n)
                total = total + w * (values[frozenset(s) | {i}] - values[frozenset(s)])
        phi.append(total)
    return phi

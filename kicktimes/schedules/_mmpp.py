r"""Markov-modulated Poisson kicks (`MMPP`): a hidden Markov chain switches the kick rate.

The schedule counterpart of ``kicktimes.stats.fit_mmpp``: kicks clustered in time as the
disk-disk collisions are, "fit, then simulate from the fit" (`MMPP.from_fit`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from kicktimes.schedules._base import Schedule, _register, _renewal_times
from kicktimes.schedules._validate import (
    _FIRST_CHUNK,
    _MAX_CHUNK,
    DEFAULT_MAX_KICKS,
    _check_bool,
    _check_max_kicks,
    _check_t_max,
    _float_array,
)
from kicktimes.validation import check_rng, keyword_only_after

__all__ = ["MMPP"]

#: relative tolerance of a rate matrix's zero row sums (a fit's diagonal is minus the sum
#: of its row, exact to a few rounding errors)
_ROW_SUM_RTOL = 1e-9
#: the same for initial probabilities summing to 1
_PROB_ATOL = 1e-9


# ---------------------------------------------------------------------------- checks
def _check_rates(rates):
    arr = _float_array(rates, "rates", lower="non-negative", sorted_=False)
    if arr.size == 0:
        raise ValueError("rates must hold one kick rate per hidden state, got none")
    return arr


def _check_generator(generator, n):
    """A read-only float64 copy of an ``n x n`` rate matrix (the CTMC's generator ``Q``)."""
    q = np.asarray(generator)
    if q.dtype == object or q.dtype.kind not in "iuf":
        raise TypeError(f"generator must be a matrix of real numbers, got dtype {q.dtype}")
    if q.shape != (n, n):
        raise ValueError(
            f"generator must be a square matrix of shape ({n}, {n}), one row per rate, "
            f"got shape {q.shape}"
        )
    q = q.astype(np.float64) + 0.0  # a copy, and -0.0 -> 0.0 (hash by bytes)
    bad = np.argwhere(~np.isfinite(q))
    if bad.size:
        i, j = bad[0]
        raise ValueError(f"generator must be finite, got {float(q[i, j])!r} at [{i}, {j}]")
    off = q - np.diag(np.diag(q))
    bad = np.argwhere(off < 0)
    if bad.size:
        i, j = bad[0]
        raise ValueError(
            f"generator[{i}, {j}] must be >= 0 (the rate of switching from state {i} to {j}), "
            f"got {float(q[i, j])!r}"
        )
    exits = off.sum(axis=1)
    for i in range(n):
        if abs(q[i, i] + exits[i]) > _ROW_SUM_RTOL * max(exits[i], abs(q[i, i])):
            raise ValueError(
                f"generator rows must sum to 0 (a rate matrix: each diagonal entry is minus "
                f"its row's switching rates), row {i} sums to {float(q[i].sum())!r}"
            )
    q.flags.writeable = False
    return q


def _recurrent_classes(off):
    """The closed communicating classes of the chain with switching rates ``off``."""
    n = off.shape[0]
    reach = (off > 0) | np.eye(n, dtype=bool)
    for k in range(n):  # transitive closure (Warshall); n is a handful of states
        reach |= reach[:, [k]] & reach[[k], :]
    classes = []
    for i in range(n):
        if all(reach[j, i] for j in np.flatnonzero(reach[i])):  # i is recurrent
            members = tuple(int(j) for j in np.flatnonzero(reach[i]))
            if members not in classes:
                classes.append(members)
    return classes


def _stationary(q):
    r"""The unique ``pi`` with ``pi Q = 0``, ``sum(pi) = 1``, or None if it is not unique."""
    off = q - np.diag(np.diag(q))
    if len(_recurrent_classes(off)) != 1:
        return None
    n = q.shape[0]
    a = np.vstack([q.T, np.ones(n)])
    b = np.zeros(n + 1)
    b[-1] = 1.0
    pi = np.linalg.lstsq(a, b, rcond=None)[0]
    pi = np.clip(pi, 0.0, None)  # rounding below 0 in transient states
    return pi / pi.sum()


def _check_initial(initial, n):
    if isinstance(initial, str):
        if initial != "stationary":
            raise ValueError(
                f"initial must be 'stationary' or an array of {n} state probabilities, "
                f"got {initial!r}"
            )
        return initial
    p = _float_array(initial, "initial", lower="non-negative", sorted_=False)
    if p.size != n:
        raise ValueError(f"initial must hold {n} state probabilities (one per rate), got {p.size}")
    if abs(p.sum() - 1.0) > _PROB_ATOL:
        raise ValueError(f"initial probabilities must sum to 1, got {float(p.sum())!r}")
    return p


# -------------------------------------------------------------------------- sampling
def _chain_path(off, start, t_max, rng):
    """Sojourns ``(states, starts, ends)`` of the hidden chain from state ``start`` until one
    ends at or after ``t_max`` (an absorbing state's sojourn ends at inf).

    Holding times (and, with more than two states, the uniforms of the jumps) are drawn in
    chunks of fixed sizes, not from t_max: the path of a shorter horizon is a prefix of a
    longer one's, for the same stream.
    """
    n = off.shape[0]
    exits = off.sum(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        jump_cdf = np.cumsum(off / exits[:, None], axis=1)  # rows of absorbing states unused
    states, ends = [], []
    state, elapsed, m = start, 0.0, _FIRST_CHUNK
    while True:
        hold = rng.standard_exponential(m)
        u = rng.random(m) if n > 2 else None
        chunk = np.empty(m, dtype=np.int64)
        if n == 2 and exits.all():
            chunk[0::2], chunk[1::2] = state, 1 - state  # two states alternate
            state = int(1 - chunk[-1])
        else:
            for k in range(m):
                chunk[k] = state
                if exits[state] == 0.0:  # absorbing: the chain stays for ever
                    chunk = chunk[: k + 1]
                    break
                if n == 2:
                    state = 1 - state
                else:
                    state = min(int(np.searchsorted(jump_cdf[state], u[k], side="right")), n - 1)
        with np.errstate(divide="ignore", over="ignore"):
            total = elapsed + np.cumsum(hold[: chunk.size] / exits[chunk])  # exit rate 0: inf
        states.append(chunk)
        ends.append(total)
        if chunk.size < m or total[-1] >= t_max:
            break
        elapsed = float(total[-1])
        m = min(m + m // 4, _MAX_CHUNK)
    states, ends = np.concatenate(states), np.concatenate(ends)
    keep = int(np.searchsorted(ends, t_max, side="left")) + 1  # sojourns starting before t_max
    states, ends = states[:keep], ends[:keep]
    return states, np.concatenate([[0.0], ends[:-1]]), ends


# -------------------------------------------------------------------------- schedule
@dataclass(frozen=True, eq=False, repr=False)
class MMPP(Schedule):
    r"""Markov-modulated Poisson kicks: a hidden Markov chain switches the kick rate.

    A continuous-time Markov chain :math:`J(t)` on ``n`` states with generator ``Q``
    jumps from state ``i`` to ``j`` at rate :math:`Q_{ij}`; while it is in state ``i``
    kicks come as a Poisson process of rate :math:`\lambda_i` (``rates[i]``). Kicks
    cluster in time when the rates differ and the chain switches slowly.

    Parameters
    ----------
    rates : array_like, shape (n,)
        Kick rate of each hidden state, finite and ``>= 0``.
    generator : array_like, shape (n, n)
        The rate matrix ``Q``: off-diagonal switching rates ``Q[i, j] >= 0``, each row
        summing to 0 (``Q[i, i] = -sum_{j != i} Q[i, j]``, to a relative 1e-9).
    initial : "stationary" or array_like, shape (n,), keyword-only
        Law of the state at ``t = 0``. ``"stationary"`` (default): the chain's stationary
        law ``pi`` (``pi Q = 0``, which must be unique: one closed class of states), so
        the kicks are stationary from ``t = 0`` with mean rate ``pi . rates``. An array:
        these probabilities (``>= 0``, summing to 1).

    Notes
    -----
    Sampling. The chain's sojourns are drawn from one child stream of ``rng`` (holding
    times :math:`E/q_i`, :math:`q_i = -Q_{ii}`, the next state ``j`` with probability
    :math:`Q_{ij}/q_i`). The kicks of state ``i`` are a Poisson process of rate
    :math:`\lambda_i` on the chain's *occupation time* of ``i``, drawn from a child stream
    of their own and mapped back to the sojourns in ``i``: Poisson processes on disjoint
    intervals are independent, so this is the MMPP. Every stream is drawn in chunks of
    fixed sizes, so horizons are nested (the package's convention). An absorbing state
    (``q_i = 0``) keeps kicking at :math:`\lambda_i` for ever.

    The mean number of kicks in ``(0, t]`` from the stationary start is
    :math:`t\,\pi\cdot\lambda` (`stationary_rate`); the counts are over-dispersed
    (index of dispersion above 1) when the rates differ.

    Examples
    --------
    >>> kicks = MMPP([0.5, 4.0], [[-0.1, 0.1], [0.4, -0.4]])
    >>> kicks
    MMPP(rates=[0.5, 4.0], generator=[[-0.1, 0.1], [0.4, -0.4]], initial='stationary')
    >>> round(kicks.stationary_rate, 6)  # pi = (0.8, 0.2)
    1.2
    >>> times = kicks.sample(1000.0, rng=1)
    """

    _law = "Markov-modulated Poisson kicks (a Poisson rate switched by a hidden Markov chain)"

    rates: np.ndarray
    generator: np.ndarray
    initial: object = field(default="stationary", kw_only=True)
    _type = "mmpp"

    def __post_init__(self):
        rates = _check_rates(self.rates)
        q = _check_generator(self.generator, rates.size)
        initial = _check_initial(self.initial, rates.size)
        pi = _stationary(q)
        if isinstance(initial, str) and pi is None:
            closed = _recurrent_classes(q - np.diag(np.diag(q)))
            raise ValueError(
                "initial='stationary' needs a generator with a unique stationary law, but the "
                f"chain has {len(closed)} closed classes of states {closed}; give the initial "
                "state probabilities instead"
            )
        object.__setattr__(self, "rates", rates)
        object.__setattr__(self, "generator", q)
        object.__setattr__(self, "initial", initial)
        self.__dict__["_cache"] = {"pi": pi}

    # ---------------------------------------------------------------- constructors
    @classmethod
    def from_fit(cls, fit, *, stationary=True):
        """Schedule from a ``kicktimes.stats.fit_mmpp`` result (its rates and generator).

        ``stationary=True`` (default) starts the chain in its stationary law; ``False`` in
        the fit's initial law (``fit.initial``), the state distribution the fit estimated
        for the start of its windows.
        """
        if not (hasattr(fit, "rates") and hasattr(fit, "generator")):
            raise TypeError(
                "fit must have rates and generator (a kicktimes.stats.fit_mmpp result), got "
                f"{type(fit).__name__}"
            )
        stationary = _check_bool(stationary, "stationary")
        if stationary:
            initial = "stationary"
        else:
            initial = getattr(fit, "initial", None)
            if initial is None:
                raise ValueError(
                    f"stationary=False needs the fit's initial law (fit.initial); "
                    f"{type(fit).__name__} has none"
                )
        return cls(fit.rates, fit.generator, initial=initial)

    # ------------------------------------------------------------------ properties
    @property
    def n_states(self) -> int:
        """Number of hidden states."""
        return int(self.rates.size)

    @property
    def stationary(self):
        """The stationary law ``pi`` of the chain (``pi Q = 0``), or None if not unique."""
        pi = self._cached("pi", lambda: _stationary(self.generator))
        return None if pi is None else pi.copy()

    @property
    def stationary_rate(self) -> float:
        r"""Mean kick rate of the stationary process, :math:`\pi\cdot\lambda` (nan if
        ``pi`` is not unique)."""
        pi = self.stationary
        return math.nan if pi is None else float(pi @ self.rates)

    @property
    def mean_interval(self) -> float:
        """``1 / stationary_rate`` (inf for rate 0)."""
        rate = self.stationary_rate
        return math.inf if rate == 0 else 1.0 / rate

    @property
    def switching_rates(self) -> np.ndarray:
        """``-diag(Q)``: the rate of leaving each state (mean sojourn ``1 / q_i``)."""
        return -np.diag(self.generator)

    # -------------------------------------------------------------------- sampling
    @keyword_only_after(1, since="0.2.0", names=('rng',))
    def sample(self, t_max, *, rng=None, max_kicks=DEFAULT_MAX_KICKS):
        """Kick times of the MMPP on ``(0, t_max]``, sorted float64 (see Notes)."""
        t_max = _check_t_max(t_max)
        max_kicks = _check_max_kicks(max_kicks)
        rng = check_rng(rng)
        bound = t_max * float(self.rates.max())  # mean kicks from any start <= this
        mean = t_max * self.stationary_rate if isinstance(self.initial, str) else bound
        if mean > max_kicks:
            raise ValueError(
                f"t_max={t_max!r} with mean kick rate {mean / t_max:.6g} means about "
                f"{mean:.3g} kicks, more than max_kicks={max_kicks}; shorten t_max or raise "
                "max_kicks"
            )
        chain, *streams = rng.spawn(1 + self.n_states)
        p0 = self.stationary if isinstance(self.initial, str) else self.initial
        cdf = np.cumsum(p0)
        start = min(int(np.searchsorted(cdf, chain.random() * cdf[-1], side="right")),
                    self.n_states - 1)
        off = self.generator - np.diag(np.diag(self.generator))
        states, starts, ends = _chain_path(off, start, t_max, chain)
        pieces, count = [], 0
        for i, stream in enumerate(streams):
            mine = states == i
            rate = float(self.rates[i])
            if rate == 0.0 or not mine.any():
                continue
            a, b = starts[mine], ends[mine]
            lengths = np.minimum(b, t_max) - a  # the last sojourn clipped at t_max
            local_end = np.cumsum(lengths)
            # occupation time of state i before each sojourn (not local_end - lengths: the
            # same bits whether the sojourn is clipped at this horizon or not)
            offset = np.concatenate([[0.0], local_end[:-1]])
            # a little beyond the clipped occupation time: every kick whose global time is
            # <= t_max is drawn whatever the rounding, so horizons stay nested
            horizon = float(local_end[-1]) * (1.0 + 1e-12) + 1e-300

            def draw(m, stream=stream, rate=rate):
                with np.errstate(over="ignore"):
                    return stream.standard_exponential(m) / rate

            local = _renewal_times(draw, horizon, mean=1.0 / rate, max_kicks=max_kicks)
            k = np.minimum(np.searchsorted(local_end, local, side="left"), lengths.size - 1)
            times = a[k] + (local - offset[k])
            times = times[times <= t_max]
            count += times.size
            if count > max_kicks:
                raise ValueError(
                    f"more than max_kicks={max_kicks} kicks in (0, {t_max!r}]; shorten t_max "
                    "or raise max_kicks"
                )
            pieces.append(times)
        out = np.sort(np.concatenate(pieces)) if pieces else np.empty(0)
        out[out <= 0.0] = np.nextafter(0.0, 1.0)  # "0+": kicks stay in (0, t_max]
        return out

    # ------------------------------------------------------------------ values
    def _params(self):
        initial = self.initial if isinstance(self.initial, str) else self.initial.tolist()
        return {"rates": self.rates.tolist(), "generator": self.generator.tolist(),
                "initial": initial}

    def _key(self):
        initial = self.initial if isinstance(self.initial, str) else self.initial.tobytes()
        return (self.rates.tobytes(), self.generator.tobytes(), initial)

    def __eq__(self, other):
        if type(other) is not type(self):
            return NotImplemented
        return self._key() == other._key()

    def __hash__(self):
        return hash((self._type, *self._key()))

    def __repr__(self):
        def vec(x):
            return "[" + ", ".join(repr(float(v)) for v in x) + "]"

        if self.n_states <= 4:
            q = "[" + ", ".join(vec(row) for row in self.generator) + "]"
        else:
            q = f"<{self.n_states}x{self.n_states} rate matrix>"
        initial = repr(self.initial) if isinstance(self.initial, str) else vec(self.initial)
        rates = vec(self.rates) if self.n_states <= 6 else (
            f"<{self.n_states} rates in [{self.rates.min():.6g}, {self.rates.max():.6g}]>")
        return f"MMPP(rates={rates}, generator={q}, initial={initial})"


_register(MMPP)

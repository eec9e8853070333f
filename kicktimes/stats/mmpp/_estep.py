r"""The E-step of the Markov-modulated Poisson process: the data layout, the
decomposition of ``D = Q - diag(rates)`` and the forward-backward pass.

Parameters are ``rates`` (the Poisson rate in each state, shape ``(n,)``), the generator
``Q`` (``n x n``, rows summing to 0) and ``alpha``, the state distribution at each
window's start. Everything here runs in the fit's time unit, in which the mean event
rate is 1 (see :class:`Windows`).

* :func:`spectral` decomposes ``D`` for the kernels: a reversible ``Q`` (every 2-state
  chain) makes ``D`` similar to a symmetric matrix, whose orthogonal eigenvectors are
  perfectly conditioned; otherwise the general (complex) decomposition, and for an
  ill-conditioned one (a nearly defective ``D``) the block-matrix reference
  :func:`estep_reference` instead.
* :func:`estep` runs the compiled forward-backward pass and returns the expected
  complete-data statistics: time in each state, transitions, events per state, the
  state at each window's start, and the exact log-likelihood.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit
from scipy import linalg

from ._kernels import forward_backward

#: Floors and caps of the generator's off-diagonal entries and of the rates, in the fit's
#: unit (mean event rate 1): they keep the chain irreducible and every state reachable,
#: so that the stationary law, the eigendecomposition and the logarithms stay defined.
Q_FLOOR, Q_CAP, RATE_FLOOR = 1e-10, 1e6, 1e-12
#: Above this condition number of the eigenvectors of a non-reversible ``D`` the E-step
#: uses the block-matrix exponentials instead (about 1e-16 * cond of accuracy is lost).
_COND_MAX = 1e8


@dataclass
class Windows:
    """Intervals of every window in the fit's unit (``x``, ``start``: the kernels'
    layout), the events per window and ``unit``, the data's time per fit time unit
    (total time / total events). Work space of the kernels is kept per dtype."""

    x: np.ndarray
    start: np.ndarray
    n_events: np.ndarray
    unit: float
    _work: dict = field(default_factory=dict, repr=False)

    @classmethod
    def of(cls, times, t_max, unit=None):
        """From validated per-window event times and window lengths (data units)."""
        n_events = np.array([t.size for t in times], dtype=np.int64)
        if unit is None:
            unit = float(np.sum(t_max)) / max(int(n_events.sum()), 1)
        parts = [np.diff(np.concatenate(([0.0], t, [w])))
                 for t, w in zip(times, t_max, strict=True)]
        start = np.zeros(len(parts) + 1, dtype=np.int64)
        start[1:] = np.cumsum(n_events + 1)
        x = np.concatenate(parts) / unit if parts else np.empty(0)
        return cls(np.maximum(x, 0.0), start, n_events, float(unit))

    @property
    def n_windows(self) -> int:
        return self.n_events.size

    @property
    def total_time(self) -> float:
        return float(self.x.sum())

    def subset(self, idx):
        """The windows ``idx`` (same unit)."""
        pieces = [self.x[self.start[w]:self.start[w + 1]] for w in idx]
        n_events = self.n_events[idx]
        start = np.zeros(len(idx) + 1, dtype=np.int64)
        start[1:] = np.cumsum(n_events + 1)
        return Windows(np.concatenate(pieces), start, n_events, self.unit)

    def first_events(self):
        """The first interval of each window with events, ended by its event (for the
        likelihood of the first event alone)."""
        has = self.n_events > 0
        x = np.zeros(2 * int(has.sum()))
        x[0::2] = self.x[self.start[:-1][has]]
        start = np.arange(0, x.size + 1, 2, dtype=np.int64)
        return Windows(x, start, np.ones(int(has.sum()), dtype=np.int64), self.unit)

    def work(self, dtype, n):
        key = (np.dtype(dtype).str, n)
        if key not in self._work:
            self._work[key] = (np.empty((self.x.size, n), dtype=dtype),
                               np.empty((self.x.size, n), dtype=dtype),
                               np.empty((self.x.size, n)))
        return self._work[key]


@dataclass
class EStats:
    """Expected complete-data statistics of one E-step and the log-likelihood."""

    loglik: float
    ll_windows: np.ndarray
    ll_first: np.ndarray
    time: np.ndarray         # expected time in each state
    transitions: np.ndarray  # expected number of i -> j jumps (zero diagonal)
    events: np.ndarray       # expected number of events in each state
    init: np.ndarray         # expected number of windows starting in each state
    log_surv: np.ndarray | None = None


@njit(cache=True)
def stationary_law(Q):
    """The stationary distribution ``pi Q = 0``, ``sum pi = 1`` of an irreducible ``Q``."""
    n = Q.shape[0]
    A = np.ascontiguousarray(Q.T)
    A[n - 1, :] = 1.0
    rhs = np.zeros(n)
    rhs[n - 1] = 1.0
    pi = np.linalg.solve(A, rhs)
    for i in range(n):
        pi[i] = max(pi[i], 0.0)
    return pi / pi.sum()


def spectral(Q, rates):
    """``(U, Uinv, mu)`` with ``Q - diag(rates) = U diag(mu) Uinv``, or None when only
    an ill-conditioned decomposition exists."""
    D = Q - np.diag(rates)
    n = rates.size
    pi = stationary_law(Q)
    flux = pi[:, None] * Q
    scale = np.abs(flux).max() + 1e-300
    if n <= 2 or (np.abs(flux - flux.T).max() <= 1e-12 * scale and pi.min() > 1e-150):
        # detailed balance: S D S^-1 is symmetric for S = diag(sqrt(pi))
        s = np.sqrt(pi)
        sym = D * s[:, None] / s[None, :]
        mu, V = np.linalg.eigh(0.5 * (sym + sym.T))
        return V / s[:, None], V.T * s[None, :], mu
    mu, U = np.linalg.eig(D)
    Uinv = np.linalg.inv(U)
    if np.linalg.norm(U, 1) * np.linalg.norm(Uinv, 1) > _COND_MAX:
        return None
    if np.all(mu.imag == 0.0):
        return np.ascontiguousarray(U.real), np.ascontiguousarray(Uinv.real), mu.real.copy()
    return U.astype(complex), Uinv.astype(complex), mu.astype(complex)


def estep(rates, Q, alpha, data: Windows, *, log_surv=False) -> EStats:
    """One forward-backward pass over all windows (compiled; see ``_kernels``)."""
    n = rates.size
    dec = spectral(Q, rates)
    if dec is None:
        return estep_reference(rates, Q, alpha, data, log_surv=log_surv)
    U, Uinv, mu = dec
    bt, e, r = data.work(U.dtype, n)
    ll = np.empty(data.n_windows)
    ll_first = np.empty(data.n_windows)
    G = np.zeros((n, n), dtype=U.dtype)
    events = np.zeros(n)
    init = np.zeros(n)
    surv = np.empty(data.x.size if log_surv else 0)
    forward_backward(data.x, data.start, U, Uinv, mu, np.ascontiguousarray(rates, float),
                     np.ascontiguousarray(alpha, float), bt, e, r, ll, ll_first, G, events,
                     init, surv)
    W = (Uinv.T @ G @ U.T).real
    return _stats(W, Q, ll, ll_first, events, init, surv if log_surv else None)


def _stats(W, Q, ll, ll_first, events, init, log_surv):
    trans = np.where(np.eye(Q.shape[0], dtype=bool), 0.0, np.maximum(W, 0.0) * Q)
    return EStats(float(ll.sum()), ll, ll_first, np.maximum(np.diag(W).copy(), 0.0), trans,
                  events, init, log_surv)


def estep_reference(rates, Q, alpha, data: Windows, *, log_surv=False) -> EStats:
    r"""The same E-step, written plainly: ``scipy.linalg.expm`` of the Van Loan block
    matrix :math:`\begin{pmatrix} D & r a \\ 0 & D \end{pmatrix} x` per interval, whose
    upper-right block is :math:`\int_0^x e^{D(x-s)} r a e^{Ds} ds`. Slow (one 2n x 2n
    exponential per interval); the reference of the tests and benchmarks, and the
    fallback for a nearly defective ``D``."""
    n = rates.size
    D = Q - np.diag(rates)
    ll = np.empty(data.n_windows)
    ll_first = np.zeros(data.n_windows)
    W = np.zeros((n, n))
    events, init = np.zeros(n), np.zeros(n)
    surv = np.empty(data.x.size) if log_surv else None
    block = np.zeros((2 * n, 2 * n))
    for w in range(data.n_windows):
        xs = data.x[data.start[w]:data.start[w + 1]]
        last = xs.size - 1
        right = [None] * xs.size
        b = np.ones(n)
        for k in range(last, -1, -1):
            right[k] = b if k == last else rates * b
            b = linalg.expm(D * xs[k]) @ right[k]
            b = b / b.sum()
        init += alpha * b / (alpha @ b)
        a = np.asarray(alpha, float).copy()
        total = 0.0
        for k in range(xs.size):
            block[:n, :n] = block[n:, n:] = D * xs[k]
            block[:n, n:] = np.outer(right[k], a) * xs[k]
            big = linalg.expm(block)
            p = a @ big[:n, :n]
            z = p @ right[k]
            W += big[:n, n:].T / z
            if surv is not None:
                surv[data.start[w] + k] = math.log(p.sum())
            if k < last:
                events += p * right[k] / z
                a = p * rates
                term = math.log(a.sum())
                a = a / a.sum()
                ll_first[w] = term if k == 0 else ll_first[w]
                total += term
            else:
                total += math.log(p.sum())
        ll[w] = total
    return _stats(W, Q, ll, ll_first, events, init, surv)

r"""The EM of the Markov-modulated Poisson process (Rydén 1996): M-step, score,
the accelerated iterations, starting points and the observed information.

The E-step and the data layout are in :mod:`._estep` (names re-exported here).

* :func:`mstep` maximises the expected complete-data log-likelihood: rates ``N_i/T_i``;
  the generator in closed form ``M_ij / T_i`` for a free start, and by Newton's method
  (:func:`._em_kernels.generator_step`, compiled) when the start is the stationary law of ``Q``,
  whose ``sum_k s_k log pi_k(Q)`` term has no closed form.
* :func:`score` is the exact gradient of the observed log-likelihood by Fisher's
  identity (the gradient of the expected complete-data log-likelihood at the E-step's
  parameters).
* :func:`run_em` iterates E- and M-steps with SQUAREM (for two states one compiled loop,
  :mod:`._em_kernels`); :func:`starting_points` and
  :func:`information` serve the fit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._em_kernels import em_run_reversible, estep_reversible, generator_step, hopeless, value_grad
from ._em_kernels import generator_of as _generator_of
from ._em_kernels import objective as _objective
from ._estep import (  # noqa: F401 - the E-step's names, used as em.<name>
    Q_CAP,
    Q_FLOOR,
    RATE_FLOOR,
    EStats,
    Windows,
    estep_reference,
    spectral,
    stationary_law,
)
from ._estep import estep as _estep_any


def estep(rates, Q, alpha, data: Windows, *, log_surv=False) -> EStats:
    """:func:`._estep.estep`; for two states (a reversible chain) without ``log_surv``
    the compiled :func:`._em_kernels.estep_reversible`, the same kernel without the
    Python work around it."""
    if rates.size != 2 or log_surv:
        return _estep_any(rates, Q, alpha, data, log_surv=log_surv)
    bt, e, r = data.work(np.float64, 2)
    out = estep_reversible(np.ascontiguousarray(rates, dtype=float),
                           np.ascontiguousarray(Q, dtype=float),
                           np.ascontiguousarray(alpha, dtype=float), data.x, data.start,
                           bt, e, r)
    return EStats(float(out[0]), out[5], out[6], out[1], out[2], out[3], out[4])


# --------------------------------------------------------------------------- M-step

def mstep(st: EStats, rates, Q, alpha, initial):
    """Maximiser of the expected complete-data log-likelihood: ``(rates, Q, alpha)``."""
    n = rates.size
    new_rates = np.clip(st.events / np.maximum(st.time, 1e-300), RATE_FLOOR, None)
    off = ~np.eye(n, dtype=bool)
    lo, hi = math.log(Q_FLOOR), math.log(Q_CAP)
    closed = np.log(np.clip(st.transitions / np.maximum(st.time, 1e-300)[:, None],
                            Q_FLOOR, Q_CAP))[off]
    if initial == "free":
        u = closed
        new_alpha = st.init / st.init.sum()
    else:
        M, T, s = st.transitions, st.time, st.init
        old = np.log(np.clip(Q[off], Q_FLOOR, Q_CAP))
        # start Newton from the better of the old point (which guarantees an ascent)
        # and the closed form that ignores the stationary start
        u0 = max((closed, old), key=lambda v: value_grad(v, M, T, s, n)[0])
        u = generator_step(u0, M, T, s, n, lo, hi)
        new_alpha = None
    new_Q = _generator_of(np.ascontiguousarray(u, dtype=float), n)
    if new_alpha is None:
        new_alpha = stationary_law(new_Q)
    return new_rates, new_Q, new_alpha


def score(st: EStats, rates, Q, initial):
    r"""Gradient of the observed log-likelihood in ``(log rates, log q_ij)`` (Fisher's
    identity): :math:`N_i - \lambda_i T_i` and :math:`M_{ij} - q_{ij} T_i` plus, for the
    stationary start, the derivative of :math:`\sum_k s_k \log \pi_k(Q)`."""
    n = rates.size
    off = ~np.eye(n, dtype=bool)
    g_rates = st.events - rates * st.time
    u = np.log(Q[off])
    s = np.zeros(n) if initial == "free" else st.init
    g_q = _objective(np.ascontiguousarray(u), st.transitions, st.time, s, n)[1]
    return np.concatenate([g_rates, g_q])


# ------------------------------------------------------------------ the EM and its starts

@dataclass
class EMRun:
    """One EM run: the parameters at the last E-step, its statistics and bookkeeping."""

    rates: np.ndarray
    Q: np.ndarray
    alpha: np.ndarray
    stats: EStats
    n_iter: int
    converged: bool

    @property
    def loglik(self) -> float:
        return self.stats.loglik


def _pack(rates, Q, alpha, initial):
    off = ~np.eye(rates.size, dtype=bool)
    parts = [np.log(rates), np.log(Q[off])]
    if initial == "free":
        parts.append(np.log(np.maximum(alpha, 1e-300)))
    return np.concatenate(parts)


def _unpack(phi, n, initial):
    rates = np.exp(np.clip(phi[:n], math.log(RATE_FLOOR), 700.0))
    u = np.clip(phi[n:n * n], math.log(Q_FLOOR), math.log(Q_CAP))
    Q = _generator_of(np.ascontiguousarray(u), n)
    if initial == "free":
        w = np.exp(phi[n * n:] - phi[n * n:].max())
        return rates, Q, w / w.sum()
    return rates, Q, stationary_law(Q)


def run_em(rates, Q, data: Windows, *, initial, max_iter, tol, alpha=None,
           compiled=True, floor=-math.inf) -> EMRun:
    r"""Baum-Welch iterations from ``(rates, Q)``, accelerated by SQUAREM, until an EM
    step changes the log-likelihood by at most ``tol * |loglik|`` or ``max_iter``
    E-steps were made; the result holds the last E-step's parameters with their exact
    log-likelihood.

    SQUAREM (Varadhan & Roland 2008, scheme S3) extrapolates two EM steps
    :math:`r = F(\theta) - \theta`, :math:`v = F(F(\theta)) - 2F(\theta) + \theta` in the
    log-parameters to :math:`\theta - 2 s r + s^2 v`, with
    :math:`s = -\lVert r\rVert / \lVert v\rVert`, at most ``step_max`` in size (from 1,
    four-fold up after each step that reached it, down after a failure). The
    extrapolated point is kept only if its likelihood beats the second EM step's (one
    retry halfway back), so the iterations stay monotone. EM crawls where the
    likelihood is flat (states nearly alike, a rate or switching rate running to 0);
    SQUAREM cuts those runs several-fold and leaves quick ones as they were.

    With a ``floor`` (the best log-likelihood of other starts) a run stops early, not
    converged, when it is :func:`._em_kernels.hopeless`: below the floor by more than ten
    times its last gain per E-step for all the E-steps left.

    Two states (a reversible chain) run as one compiled loop
    (:func:`._em_kernels.em_run_reversible`, the same steps); ``compiled=False`` runs this
    Python loop instead (the reference of the tests).
    """
    n = rates.size
    if alpha is None:
        alpha = stationary_law(Q)
    if n == 2 and compiled:
        # every two-state chain is reversible: the whole run in one compiled loop
        out = em_run_reversible(np.array(rates, dtype=float), np.array(Q, dtype=float),
                                np.array(alpha, dtype=float), data.x, data.start,
                                initial == "free", int(max_iter), float(tol), float(floor))
        stats = EStats(float(out[3]), out[8], out[9], out[4], out[5], out[6], out[7])
        return EMRun(out[0], out[1], out[2], stats, int(out[10]), bool(out[11]))
    theta = (rates, Q, alpha)
    st = estep(*theta, data)
    used = 1
    step_max = 1.0  # bound of |step|, raised 4-fold after each accepted step at the bound

    def em_step(theta, st):
        new = mstep(st, *theta, initial)
        return new, estep(*new, data)

    def done(old, new):
        return abs(new.loglik - old.loglik) <= tol * abs(new.loglik)

    while used < max_iter:
        cycle_loglik, cycle_used = st.loglik, used
        theta1, st1 = em_step(theta, st)
        used += 1
        if done(st, st1) or used >= max_iter:
            return EMRun(*theta1, st1, used, done(st, st1))
        theta2, st2 = em_step(theta1, st1)
        used += 1
        if done(st1, st2) or used >= max_iter:
            return EMRun(*theta2, st2, used, done(st1, st2))
        phi0, phi1, phi2 = (_pack(*t, initial) for t in (theta, theta1, theta2))
        r, v = phi1 - phi0, phi2 - 2 * phi1 + phi0
        free = -np.linalg.norm(r) / max(np.linalg.norm(v), 1e-300)
        step = max(free, -step_max)
        theta, st = theta2, st2
        if step >= -1.0:
            if free < -1.0:  # EM's own point was the bounded step: allow longer ones
                step_max *= 4.0
            if hopeless(st.loglik, floor, (st.loglik - cycle_loglik) / (used - cycle_used),
                        used, max_iter):
                break
            continue
        for _ in range(2):  # the extrapolation, then once halfway back towards EM's point
            if used >= max_iter:
                break
            trial = _unpack(phi0 - 2 * step * r + step * step * v, n, initial)
            st_trial = estep(*trial, data)
            used += 1
            if np.isfinite(st_trial.loglik) and st_trial.loglik > st2.loglik:
                theta, st = trial, st_trial
                if step <= -step_max:
                    step_max *= 4.0
                break
            step_max = max(1.0, step_max / 4.0)
            step = 0.5 * (step - 1.0)
        if hopeless(st.loglik, floor, (st.loglik - cycle_loglik) / (used - cycle_used), used,
                    max_iter):
            break
    return EMRun(*theta, st, used, False)


def starting_points(data: Windows, n, n_starts, rng):
    """``n_starts`` pairs ``(rates, Q)``: two from quantiles of local event rates (blocks
    of up to 8 consecutive intervals within a window), with slow switching (every 20 and
    every 100 events), then random perturbations of them."""
    local = []
    for w in range(data.n_windows):
        xs = data.x[data.start[w]:data.start[w + 1] - 1]
        m = min(8, xs.size)
        if m:
            blocks = xs[: xs.size // m * m].reshape(-1, m).sum(axis=1)
            local.append(m / np.maximum(blocks, 1e-300))
    local = np.concatenate(local) if local else np.ones(1)
    mean_rate = float(data.n_events.sum()) / max(data.total_time, 1e-300)
    if local.size < 2 * n or np.ptp(local) == 0:
        local = mean_rate * np.linspace(0.5, 1.5, 2 * n)
    base = [np.quantile(local, (np.arange(n) + 0.5) / n),
            np.quantile(local, (np.arange(n) + 1.0) / (n + 1))]
    points = []
    for k in range(n_starts):
        if k < 2:
            rates = base[k].copy()
            q = (0.05 if k == 0 else 0.01) * mean_rate / max(n - 1, 1)
            Q = np.full((n, n), q)
        else:
            rates = base[k % 2] * np.exp(0.7 * rng.standard_normal(n))
            Q = mean_rate * 10.0 ** rng.uniform(-3.0, 0.0, (n, n)) / max(n - 1, 1)
        rates = np.sort(np.clip(rates, 1e-3 * mean_rate, None))
        np.fill_diagonal(Q, 0.0)
        np.fill_diagonal(Q, -Q.sum(axis=1))
        points.append((rates, Q))
    return points


def information(rates, Q, alpha, data: Windows, initial, h=1e-4):
    """Observed information in ``(log rates, log q_ij)``: central differences of the
    exact score (:func:`score`), symmetrised; ``2 p`` E-steps. A free start is held at
    ``alpha`` (the information is conditional on it)."""
    n = rates.size
    off = ~np.eye(n, dtype=bool)
    theta = np.concatenate([np.log(rates), np.log(Q[off])])
    p = theta.size

    def grad(th):
        r = np.exp(th[:n])
        q = _generator_of(np.ascontiguousarray(th[n:]), n)
        start = stationary_law(q) if initial == "stationary" else alpha
        return score(estep(r, q, start, data), r, q, initial)

    H = np.empty((p, p))
    for j in range(p):
        step = np.zeros(p)
        step[j] = h
        H[:, j] = (grad(theta + step) - grad(theta - step)) / (2 * h)
    return -0.5 * (H + H.T)

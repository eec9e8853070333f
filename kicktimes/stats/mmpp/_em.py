r"""The EM of the Markov-modulated Poisson process (Rydén 1996): M-step, score,
the accelerated iterations, starting points and the observed information.

The E-step and the data layout are in :mod:`._estep` (names re-exported here).

* :func:`mstep` maximises the expected complete-data log-likelihood: rates ``N_i/T_i``;
  the generator in closed form ``M_ij / T_i`` for a free start, and by Newton's method
  (:func:`_generator_step`, compiled) when the start is the stationary law of ``Q``,
  whose ``sum_k s_k log pi_k(Q)`` term has no closed form.
* :func:`score` is the exact gradient of the observed log-likelihood by Fisher's
  identity (the gradient of the expected complete-data log-likelihood at the E-step's
  parameters).
* :func:`run_em` iterates E- and M-steps with SQUAREM; :func:`starting_points` and
  :func:`information` serve the fit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from ._estep import (  # noqa: F401 - the E-step's names, used as em.<name>
    Q_CAP,
    Q_FLOOR,
    RATE_FLOOR,
    EStats,
    Windows,
    estep,
    estep_reference,
    spectral,
    stationary_law,
)

# --------------------------------------------------------------------------- M-step

@njit(cache=True)
def _generator_of(u, n):
    Q = np.zeros((n, n))
    k = 0
    for i in range(n):
        for j in range(n):
            if i != j:
                Q[i, j] = math.exp(u[k])
                Q[i, i] -= Q[i, j]
                k += 1
    return Q


@njit(cache=True)
def _objective(u, M, T, s, n):
    r"""The generator's part of the expected complete-data log-likelihood,
    :math:`\sum_{i \ne j} (M_{ij} \log q_{ij} - T_i q_{ij}) + \sum_k s_k \log\pi_k(Q)`,
    and its gradient in ``u = log q``: with :math:`Z = (Q - 1\pi)^{-1}` and
    :math:`v = Z (s / \pi)`,
    :math:`\partial_{q_{ij}} \sum_k s_k \log \pi_k = -\pi_i (v_j - v_i)`."""
    Q = _generator_of(u, n)
    pi = stationary_law(Q)
    value = 0.0
    for k in range(n):
        if s[k] > 0.0:
            value += s[k] * math.log(max(pi[k], 1e-300))
    A = Q.copy()
    for i in range(n):
        for j in range(n):
            A[i, j] -= pi[j]
    Z = np.linalg.inv(A)
    v = Z @ (s / np.maximum(pi, 1e-300))
    grad = np.empty(u.size)
    k = 0
    for i in range(n):
        for j in range(n):
            if i != j:
                q = Q[i, j]
                value += M[i, j] * u[k] - T[i] * q
                grad[k] = M[i, j] - T[i] * q - q * pi[i] * (v[j] - v[i])
                k += 1
    return value, grad


@njit(cache=True)
def _generator_step(u, M, T, s, n, lo, hi, max_iter=50):
    """Maximise :func:`_objective` from ``u`` by damped Newton (Hessian by differences of
    the gradient, Levenberg shift, Armijo backtracking) inside ``[lo, hi]``; never
    returns a point worse than ``u``."""
    f, g = _objective(u, M, T, s, n)
    p = u.size
    for _ in range(max_iter):
        scale = 1.0 + np.abs(M).max() + np.abs(s).max()
        if np.abs(g).max() <= 1e-10 * scale:
            break
        H = np.empty((p, p))
        for j in range(p):
            h = 1e-6 * max(1.0, abs(u[j]))
            v = u.copy()
            v[j] += h
            H[:, j] = (_objective(v, M, T, s, n)[1] - g) / h
        H = 0.5 * (H + H.T)
        # Levenberg: shift -H until it is safely positive definite
        low = np.linalg.eigvalsh(-H)[0]
        shift = max(0.0, 1e-8 * (1.0 + np.abs(H).max()) - low)
        step = np.linalg.solve(-H + shift * np.eye(p), g)
        t = 1.0
        improved = False
        for _b in range(40):
            v = np.minimum(np.maximum(u + t * step, lo), hi)
            fv, gv = _objective(v, M, T, s, n)
            if np.isfinite(fv) and fv >= f + 1e-4 * t * (g @ step) - 1e-12 * abs(f):
                improved = fv > f
                u, f, g = v, fv, gv
                break
            t *= 0.5
        if not improved:
            break
    return u


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
        u0 = max((closed, old), key=lambda v: _objective(v, M, T, s, n)[0])
        u = _generator_step(u0, M, T, s, n, lo, hi)
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


def run_em(rates, Q, data: Windows, *, initial, max_iter, tol, alpha=None) -> EMRun:
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
    """
    n = rates.size
    if alpha is None:
        alpha = stationary_law(Q)
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

r"""Compiled EM of the Markov-modulated Poisson process: the M-step's generator update
and, for two states, the whole accelerated EM run.

* :func:`generator_of`, :func:`objective`, :func:`generator_step`: the generator's part of
  the M-step (the stationary start's ``sum_k s_k log pi_k(Q)`` has no closed form: damped
  Newton in ``u = log q``).
* :func:`em_run_reversible`: :func:`kicktimes.stats.mmpp._em.run_em` (Baum-Welch with
  SQUAREM) as one compiled loop, for a reversible chain (every two-state chain), whose
  decomposition ``D = U diag(mu) U^-1`` is that of a symmetric matrix. The same
  arithmetic as the Python loop; what it saves is the Python work around each E-step
  (about 0.4 ms, against a few microseconds of kernel for a window of 100 events), which
  dominated the fits of single collision sequences.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._estep import Q_CAP, Q_FLOOR, RATE_FLOOR, stationary_law
from ._kernels import forward_backward

# ---------------------------------------------------------- the M-step's generator

@njit(cache=True)
def generator_of(u, n):
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
def objective(u, M, T, s, n):
    r"""The generator's part of the expected complete-data log-likelihood,
    :math:`\sum_{i \ne j} (M_{ij} \log q_{ij} - T_i q_{ij}) + \sum_k s_k \log\pi_k(Q)`,
    and its gradient in ``u = log q``: with :math:`Z = (Q - 1\pi)^{-1}` and
    :math:`v = Z (s / \pi)`,
    :math:`\partial_{q_{ij}} \sum_k s_k \log \pi_k = -\pi_i (v_j - v_i)`."""
    Q = generator_of(u, n)
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
def objective_two(u, M, T, s):
    r""":func:`objective` of a two-state chain in closed form, with its Hessian: with
    :math:`a = q_{01}, b = q_{10}`, :math:`\pi = (b, a) / (a + b)`, so
    :math:`f = (M_{01} + s_1) u_0 - T_0 a + (M_{10} + s_0) u_1 - T_1 b - S \log(a + b)`,
    :math:`S = s_0 + s_1`: a concave function of ``u = log(a, b)`` (log-sum-exp is
    convex), whose maximum Newton's method finds in a few steps."""
    a, b = math.exp(u[0]), math.exp(u[1])
    S = s[0] + s[1]
    ab = a + b
    value = (M[0, 1] * u[0] - T[0] * a + M[1, 0] * u[1] - T[1] * b
             + S * (-math.log(ab)))
    if s[0] > 0.0:
        value += s[0] * u[1]
    if s[1] > 0.0:
        value += s[1] * u[0]
    grad = np.empty(2)
    grad[0] = M[0, 1] + s[1] - T[0] * a - S * a / ab
    grad[1] = M[1, 0] + s[0] - T[1] * b - S * b / ab
    c = S * a * b / (ab * ab)
    H = np.empty((2, 2))
    H[0, 0] = -T[0] * a - c
    H[1, 1] = -T[1] * b - c
    H[0, 1] = c
    H[1, 0] = c
    return value, grad, H


@njit(cache=True)
def value_grad(u, M, T, s, n):
    if n == 2:
        f, g, _ = objective_two(u, M, T, s)
        return f, g
    return objective(u, M, T, s, n)


@njit(cache=True)
def generator_step(u, M, T, s, n, lo, hi, max_iter=50):
    """Maximise :func:`objective` from ``u`` by damped Newton (Hessian in closed form for
    two states, :func:`objective_two`, else by differences of the gradient; Levenberg
    shift, Armijo backtracking) inside ``[lo, hi]``; never returns a point worse than
    ``u``."""
    f, g = value_grad(u, M, T, s, n)
    p = u.size
    for _ in range(max_iter):
        scale = 1.0 + np.abs(M).max() + np.abs(s).max()
        if np.abs(g).max() <= 1e-10 * scale:
            break
        if n == 2:
            H = objective_two(u, M, T, s)[2]
        else:
            H = np.empty((p, p))
            for j in range(p):
                h = 1e-6 * max(1.0, abs(u[j]))
                v = u.copy()
                v[j] += h
                H[:, j] = (objective(v, M, T, s, n)[1] - g) / h
            H = 0.5 * (H + H.T)
        # Levenberg: shift -H until it is safely positive definite
        low = np.linalg.eigvalsh(-H)[0]
        shift = max(0.0, 1e-8 * (1.0 + np.abs(H).max()) - low)
        step = np.linalg.solve(-H + shift * np.eye(p), g)
        t = 1.0
        improved = False
        for _b in range(40):
            v = np.minimum(np.maximum(u + t * step, lo), hi)
            fv, gv = value_grad(v, M, T, s, n)
            if np.isfinite(fv) and fv >= f + 1e-4 * t * (g @ step) - 1e-12 * abs(f):
                improved = fv > f
                u, f, g = v, fv, gv
                break
            t *= 0.5
        if not improved:
            break
    return u




# ----------------------------------------------------- the whole EM, reversible chains

@njit(cache=True)
def _decompose_reversible(Q, rates):
    """``(U, Uinv, mu)`` of ``D = Q - diag(rates)`` for a reversible ``Q`` (as
    ``_estep.spectral``): ``diag(sqrt(pi)) D diag(sqrt(pi))^-1`` is symmetric."""
    n = rates.size
    pi = stationary_law(Q)
    s = np.sqrt(pi)
    sym = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            d = Q[i, j] - (rates[i] if i == j else 0.0)
            sym[i, j] = d * s[i] / s[j]
    mu, V = np.linalg.eigh(0.5 * (sym + sym.T))
    U = np.empty((n, n))
    Uinv = np.empty((n, n))
    for i in range(n):
        for l in range(n):
            U[i, l] = V[i, l] / s[i]
            Uinv[l, i] = V[i, l] * s[i]
    return U, Uinv, mu


@njit(cache=True)
def estep_reversible(rates, Q, alpha, x, start, bt, e, r):
    """One E-step (``_estep.estep`` for a reversible ``Q``): ``(loglik, time, transitions,
    events, init, ll, ll_first)``."""
    n = rates.size
    n_windows = start.size - 1
    U, Uinv, mu = _decompose_reversible(Q, rates)
    ll = np.empty(n_windows)
    ll_first = np.empty(n_windows)
    G = np.zeros((n, n))
    events = np.zeros(n)
    init = np.zeros(n)
    forward_backward(x, start, U, Uinv, mu, rates, alpha, bt, e, r, ll, ll_first, G, events,
                     init, np.empty(0))
    # W = Uinv.T @ G @ U.T
    W = np.zeros((n, n))
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for l in range(n):
                for m in range(n):
                    acc += Uinv[l, i] * G[l, m] * U[j, m]
            W[i, j] = acc
    time = np.empty(n)
    trans = np.zeros((n, n))
    for i in range(n):
        time[i] = max(W[i, i], 0.0)
        for j in range(n):
            if i != j:
                trans[i, j] = max(W[i, j], 0.0) * Q[i, j]
    return ll.sum(), time, trans, events, init, ll, ll_first


@njit(cache=True)
def _mstep(rates, Q, time, trans, events, init, free):
    """``_em.mstep``: rates ``N_i / T_i``; the generator in closed form (free start) or by
    Newton from the better of the old one and the closed form (stationary start)."""
    n = rates.size
    lo, hi = math.log(Q_FLOOR), math.log(Q_CAP)
    new_rates = np.empty(n)
    for i in range(n):
        new_rates[i] = max(events[i] / max(time[i], 1e-300), RATE_FLOOR)
    closed = np.empty(n * (n - 1))
    old = np.empty(n * (n - 1))
    k = 0
    for i in range(n):
        for j in range(n):
            if i != j:
                closed[k] = math.log(min(max(trans[i, j] / max(time[i], 1e-300), Q_FLOOR),
                                         Q_CAP))
                old[k] = math.log(min(max(Q[i, j], Q_FLOOR), Q_CAP))
                k += 1
    if free:
        new_Q = generator_of(closed, n)
        return new_rates, new_Q, init / init.sum()
    u0 = closed
    if value_grad(old, trans, time, init, n)[0] > value_grad(closed, trans, time, init, n)[0]:
        u0 = old
    u = generator_step(u0, trans, time, init, n, lo, hi)
    new_Q = generator_of(u, n)
    return new_rates, new_Q, stationary_law(new_Q)


@njit(cache=True)
def _pack(rates, Q, alpha, free):
    n = rates.size
    phi = np.empty(n * n + (n if free else 0))
    for i in range(n):
        phi[i] = math.log(rates[i])
    k = n
    for i in range(n):
        for j in range(n):
            if i != j:
                phi[k] = math.log(Q[i, j])
                k += 1
    if free:
        for i in range(n):
            phi[n * n + i] = math.log(max(alpha[i], 1e-300))
    return phi


@njit(cache=True)
def _unpack(phi, n, free):
    rates = np.exp(np.minimum(np.maximum(phi[:n], math.log(RATE_FLOOR)), 700.0))
    u = np.minimum(np.maximum(phi[n:n * n], math.log(Q_FLOOR)), math.log(Q_CAP))
    Q = generator_of(u, n)
    if free:
        w = np.exp(phi[n * n:] - phi[n * n:].max())
        return rates, Q, w / w.sum()
    return rates, Q, stationary_law(Q)


@njit(cache=True)
def hopeless(loglik, floor, gain, used, max_iter):
    """Whether a run at ``loglik``, gaining ``gain`` per E-step over its last cycle, stays
    below ``floor`` (the best log-likelihood of the starts before it) even if it kept
    ten times that gain for all its remaining E-steps: EM's gains shrink as it converges,
    so it cannot end above the best. Checked after ``ABANDON_AFTER`` E-steps (a start
    near a saddle gains little at first)."""
    return used >= ABANDON_AFTER and floor - loglik > 10.0 * max(gain, 0.0) * (max_iter - used)


#: the fewest E-steps of a start before :func:`hopeless` may stop it
ABANDON_AFTER = 30


@njit(cache=True, inline="always")
def _em_step(rates, Q, st, free, x, start, bt, e, r, tol):
    """One Baum-Welch step from the E-step statistics ``st`` at ``(rates, Q)``: the M-step,
    the E-step at its parameters, and whether the log-likelihood moved by at most
    ``tol * |loglik|``; returns ``(rates, Q, alpha, st, done)``."""
    rates1, Q1, alpha1 = _mstep(rates, Q, st[1], st[2], st[3], st[4], free)
    st1 = estep_reversible(rates1, Q1, alpha1, x, start, bt, e, r)
    return rates1, Q1, alpha1, st1, abs(st1[0] - st[0]) <= tol * abs(st1[0])


@njit(cache=True)
def em_run_reversible(rates, Q, alpha, x, start, free, max_iter, tol, floor=-np.inf):
    """``_em.run_em`` compiled, for a reversible chain: Baum-Welch iterations with SQUAREM
    (scheme S3, the same steps, bounds and acceptance rule) until an EM step changes the
    log-likelihood by at most ``tol * |loglik|``, ``max_iter`` E-steps were made, or the
    run is :func:`hopeless` against ``floor``.

    Returns ``(rates, Q, alpha, loglik, time, transitions, events, init, ll, ll_first,
    n_iter, converged)``, the statistics of the last E-step at the returned parameters.
    """
    n = rates.size
    bt = np.empty((x.size, n))
    e = np.empty((x.size, n))
    r = np.empty((x.size, n))
    st = estep_reversible(rates, Q, alpha, x, start, bt, e, r)
    used = 1
    step_max = 1.0
    while used < max_iter:
        cycle_loglik, cycle_used = st[0], used
        rates1, Q1, alpha1, st1, done = _em_step(rates, Q, st, free, x, start, bt, e, r, tol)
        used += 1
        if done or used >= max_iter:
            return (rates1, Q1, alpha1) + st1 + (used, done)
        rates2, Q2, alpha2, st2, done = _em_step(rates1, Q1, st1, free, x, start, bt, e, r, tol)
        used += 1
        if done or used >= max_iter:
            return (rates2, Q2, alpha2) + st2 + (used, done)
        phi0 = _pack(rates, Q, alpha, free)
        phi1 = _pack(rates1, Q1, alpha1, free)
        phi2 = _pack(rates2, Q2, alpha2, free)
        rr = phi1 - phi0
        v = phi2 - 2 * phi1 + phi0
        step_free = -np.linalg.norm(rr) / max(np.linalg.norm(v), 1e-300)
        step = max(step_free, -step_max)
        rates, Q, alpha, st = rates2, Q2, alpha2, st2
        if step >= -1.0:
            if step_free < -1.0:  # EM's own point was the bounded step: allow longer ones
                step_max *= 4.0
            if hopeless(st[0], floor, (st[0] - cycle_loglik) / (used - cycle_used), used,
                        max_iter):
                break
            continue
        for _ in range(2):  # the extrapolation, then once halfway back towards EM's point
            if used >= max_iter:
                break
            tr_rates, tr_Q, tr_alpha = _unpack(phi0 - 2 * step * rr + step * step * v, n, free)
            st_trial = estep_reversible(tr_rates, tr_Q, tr_alpha, x, start, bt, e, r)
            used += 1
            if np.isfinite(st_trial[0]) and st_trial[0] > st2[0]:
                rates, Q, alpha, st = tr_rates, tr_Q, tr_alpha, st_trial
                if step <= -step_max:
                    step_max *= 4.0
                break
            step_max = max(1.0, step_max / 4.0)
            step = 0.5 * (step - 1.0)
        if hopeless(st[0], floor, (st[0] - cycle_loglik) / (used - cycle_used), used,
                    max_iter):
            break
    return (rates, Q, alpha) + st + (used, False)

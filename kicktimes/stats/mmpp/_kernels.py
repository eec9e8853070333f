r"""Compiled kernels of the Markov-modulated Poisson process (MMPP): the scaled
forward-backward pass of the EM, the filter's compensator, and simulation.

Conventions. ``x`` holds the intervals of every window in turn, window ``w`` owning
``x[start[w]:start[w + 1]]``: the ``N_w`` intervals that end with an event (the first
from the window's start at 0) and, last, the censored interval from the last event to the
window's end (0 if an event falls on it). ``D = Q - diag(rates)`` is given by its
eigendecomposition ``D = U diag(mu) Uinv`` (float64 or complex128 arrays: every kernel
compiles for both), so that

.. math::

    a\, e^{Dx} = (a U)\, \mathrm{diag}(e^{\mu x})\, U^{-1}, \qquad
    \int_0^x [a e^{Ds}]_i\, [e^{D(x-s)} b]_j\, ds
    = \sum_{l,m} U^{-1}_{li}\, U_{jm}\, (aU)_l\, (U^{-1} b)_m\, \Phi_{lm}(x),

with :math:`\Phi_{lm}(x) = \int_0^x e^{\mu_l s + \mu_m (x - s)} ds`. The dominant
eigenvalue ``mu0`` (real: ``D`` is a Metzler matrix) is factored out of every
exponential, so nothing overflows and long intervals underflow only in the fast modes;
``mu0 x`` is added to the log-likelihood instead. The expected-time and transition
integrals are summed over all intervals in the eigenbasis (``G``) and mapped back once by
the caller: ``W = Uinv.T @ G @ U.T``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# 1/1!, 1/2!, ..., 1/10!
_INV_FACTORIAL = tuple(1.0 / math.factorial(k) for k in range(1, 11))


@njit(cache=True)
def _phi1_series(z):
    """``(e^z - 1) / z`` for ``|z| < 0.1`` (real or complex), to rounding: the terms
    beyond ``z^9 / 10!`` are below 1e-16."""
    s = _INV_FACTORIAL[9] * z + _INV_FACTORIAL[8]
    for k in range(7, -1, -1):
        s = s * z + _INV_FACTORIAL[k]
    return s


@njit(cache=True)
def forward_backward(x, start, U, Uinv, mu, rates, alpha, bt_buf, e_buf, r_buf,
                     ll, ll_first, G, events, init, log_surv):
    """One E-step over every window (see the module notes for the conventions).

    Writes, per window, the log-likelihood ``ll[w]`` and that of its first interval with
    its event, ``ll_first[w]`` (``log`` of the first event's density; 0 for an empty
    window); over all windows, adds the eigenbasis integrals of the posterior (each
    interval divided by its likelihood) to ``G``, the posterior numbers of events in each
    state to ``events`` and the posterior state at each window's start to ``init``. With
    ``log_surv.size == x.size``, ``log_surv[k]`` is the log-survival of interval ``k``
    given the history before it (minus the compensator's increment). ``bt_buf``,
    ``e_buf`` (the dtype of ``U``) and ``r_buf`` (float64), ``x.size`` rows of ``n``,
    are work space.
    """
    n = rates.size
    k0 = 0
    for l in range(1, n):
        if mu[l].real > mu[k0].real:
            k0 = l
    mu0 = mu[k0].real
    dmu = mu - mu0
    b = np.empty(n)
    a = np.empty(n)
    at = np.empty(n, dtype=U.dtype)
    p = np.empty(n)
    surv_out = log_surv.size == x.size
    for w in range(start.size - 1):
        i0, last = start[w], start[w + 1] - 1
        # backward: r is the vector at an interval's end (Lambda b after an event, ones
        # after the censored end), b = e^{Dx} r the one at its start, renormalised
        for i in range(n):
            b[i] = 1.0
        for k in range(last, i0 - 1, -1):
            for i in range(n):
                r_buf[k, i] = b[i] if k == last else rates[i] * b[i]
            for l in range(n):
                s = 0.0 * U[0, 0]
                for i in range(n):
                    s += Uinv[l, i] * r_buf[k, i]
                e_buf[k, l] = np.exp(dmu[l] * x[k])
                bt_buf[k, l] = s
            total = 0.0
            for i in range(n):
                s = 0.0 * U[0, 0]
                for l in range(n):
                    s += U[i, l] * (e_buf[k, l] * bt_buf[k, l])
                b[i] = max(s.real, 0.0)
                total += b[i]
            for i in range(n):
                b[i] /= total
        total = 0.0
        for i in range(n):
            total += alpha[i] * b[i]
        for i in range(n):
            init[i] += alpha[i] * b[i] / total
        # forward: a is the filtered state distribution at an interval's start
        for i in range(n):
            a[i] = alpha[i]
        loglik = 0.0
        ll_first[w] = 0.0
        for k in range(i0, last + 1):
            xk = x[k]
            for l in range(n):
                s = 0.0 * U[0, 0]
                for i in range(n):
                    s += a[i] * U[i, l]
                at[l] = s
            z = 0.0
            surv = 0.0
            for i in range(n):
                s = 0.0 * U[0, 0]
                for l in range(n):
                    s += at[l] * e_buf[k, l] * Uinv[l, i]
                p[i] = max(s.real, 0.0)
                z += p[i] * r_buf[k, i]
                surv += p[i]
            if surv_out:
                log_surv[k] = math.log(surv) + mu0 * xk
            if z > 0.0:
                for l in range(n):
                    for m in range(n):
                        if l == m:
                            phi = xk * e_buf[k, l]
                        else:
                            d = dmu[l] - dmu[m]
                            if abs(d * xk) >= 0.1:
                                phi = (e_buf[k, l] - e_buf[k, m]) / d
                            else:
                                phi = e_buf[k, m] * xk * _phi1_series(d * xk)
                        G[l, m] += at[l] * bt_buf[k, m] * phi / z
            if k < last:
                c = 0.0
                for i in range(n):
                    if z > 0.0:
                        events[i] += p[i] * r_buf[k, i] / z
                    a[i] = p[i] * rates[i]
                    c += a[i]
                for i in range(n):
                    a[i] /= c
                term = math.log(c) + mu0 * xk
                if k == i0:
                    ll_first[w] = term
                loglik += term
            else:
                loglik += math.log(surv) + mu0 * xk
        ll[w] = loglik


@njit(cache=True)
def simulate_window(rates, Q, state, t, t_max, u, pos, buf, n_buf):
    """Advance one window of an MMPP from time ``t`` in ``state`` by competing
    exponentials, two uniforms of ``u`` per jump from ``u[pos]`` on: the first gives the
    holding time, the second chooses an event (probability ``rates[s] / R_s``) or the
    next state. Event times go to ``buf`` from ``n_buf`` on. Stops at ``t_max``, when
    ``buf`` is full or when ``u`` runs out; returns ``(n_buf, pos, state, t, done)``."""
    n = rates.size
    while pos + 2 <= u.size and n_buf < buf.size:
        total = rates[state] - Q[state, state]
        if total <= 0.0:
            return n_buf, pos, state, t, True
        step = -math.log1p(-u[pos]) / total
        if t + step > t_max:
            return n_buf, pos + 2, state, t_max, True
        t += step
        v = u[pos + 1] * total
        pos += 2
        if v < rates[state]:
            buf[n_buf] = t
            n_buf += 1
            continue
        v -= rates[state]
        nxt = state
        for j in range(n):
            if j != state:
                nxt = j
                if v < Q[state, j]:
                    break
                v -= Q[state, j]
        state = nxt
    return n_buf, pos, state, t, False

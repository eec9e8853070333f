"""The two-disk system as the scatter model sees it: the tangent FTLE of disk 0 with the
partner disk's deviation set to zero just before every disk-disk collision."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from kicktimes.billiard.kernels import two
from kicktimes.billiard.kernels.tangent import pair_tangent, renormalise, wall_tangent

__all__ = ["fresh_lam", "fresh_partner_tangent"]


@njit(cache=True)
def fresh_partner_tangent(st, rho, sigma, n_steps, tau, U):
    """`tangent_two_kernel` (paper sampling, mirror rule) with disk 1's deviation zeroed
    before each disk-disk collision. Returns ``(log_scale, t_end)``."""
    m = U.shape[0]
    ev = np.empty(3)
    two.init_events(st, ev, (rho, rho, 1.0, 1.0), sigma)
    log_scale = np.zeros(m)
    t_prev = 0.0
    for _ in range(n_steps):
        tk = min(t_prev + tau, st[0] + min(ev[0], min(ev[1], ev[2])))
        while True:
            ke, dt = two.next_event(two.load(st, ev))
            if not st[0] + dt <= tk:
                break
            for j in range(m):
                U[j, 0] += U[j, 2] * dt
                U[j, 1] += U[j, 3] * dt
                U[j, 4] += U[j, 6] * dt
                U[j, 5] += U[j, 7] * dt
            v0x, v0y, v1x, v1y = st[3], st[4], st[7], st[8]
            two.process_event(st, ev, ke, (rho, rho, 1.0, 1.0), sigma, 0)
            if ke == 2:
                for j in range(m):
                    for i in range(4, 8):
                        U[j, i] = 0.0
                    (U[j, 0], U[j, 1], U[j, 2], U[j, 3], U[j, 4], U[j, 5], U[j, 6],
                     U[j, 7]) = pair_tangent(U[j, 0], U[j, 1], U[j, 2], U[j, 3], U[j, 4],
                                             U[j, 5], U[j, 6], U[j, 7], st[1], st[2], st[5],
                                             st[6], v0x, v0y, v1x, v1y, st[3], st[4], st[7],
                                             st[8], 0)
                    renormalise(U, log_scale, j)
            else:
                o = 1 + 4 * ke
                vx = v0x if ke == 0 else v1x
                vy = v0y if ke == 0 else v1y
                if vx != st[o + 2] or vy != st[o + 3]:
                    for j in range(m):
                        (U[j, o - 1], U[j, o], U[j, o + 1], U[j, o + 2]) = wall_tangent(
                            U[j, o - 1], U[j, o], U[j, o + 1], U[j, o + 2], st[o], st[o + 1],
                            vx, vy, st[o + 2], st[o + 3], rho)
                        renormalise(U, log_scale, j)
        t_prev = tk
    dt = t_prev - st[0]
    for j in range(m):
        U[j, 0] += U[j, 2] * dt
        U[j, 1] += U[j, 3] * dt
    return log_scale, t_prev


def fresh_lam(ic, r, n_steps, tau):
    """The paper's ``max(lambda_x, lambda_y)`` of disk 0 in the two-disk run of ``ic``
    (equal radii ``r``, paper sampling) with the partner's deviation zeroed before every
    disk-disk collision (`fresh_partner_tangent`)."""
    st = np.zeros(11)
    st[1:9] = ic.ravel()
    st[10] = (ic[:, 2:] ** 2).sum()
    U = np.zeros((2, 8))
    U[0, 0] = 1.0
    U[1, 1] = 1.0
    log_scale, t_end = fresh_partner_tangent(st, 1.0 - r, 2.0 * r, n_steps, tau, U)
    return max((log_scale[0] + math.log(abs(U[0, 0]))) / t_end,
               (log_scale[1] + math.log(abs(U[1, 1]))) / t_end)

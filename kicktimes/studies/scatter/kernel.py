"""The two-disk system as the scatter model sees it: the tangent FTLE of disk 0 with the
partner disk's deviation set to zero just before every disk-disk collision, through the
two-disk driver's event loop
(`kicktimes.billiard.kernels.drive_two.fresh_partner_tangent_two_kernel`)."""

from __future__ import annotations

import math

import numpy as np

from kicktimes.billiard.kernels import two
from kicktimes.billiard.kernels.drive_two import fresh_partner_tangent_two_kernel
from kicktimes.diagnostics.lyapunov import EVENTS_PER_TIME

__all__ = ["fresh_lam"]

def fresh_lam(ic, r, n_steps, tau):
    """The paper's ``max(lambda_x, lambda_y)`` of disk 0 in the two-disk run of ``ic``
    (equal radii ``r``, paper sampling, mirror rule) with the partner's deviation zeroed
    before every disk-disk collision."""
    st = np.zeros(11)
    st[1:9] = np.asarray(ic, float).ravel()
    st[10] = (np.asarray(ic, float)[:, 2:] ** 2).sum()
    U = np.zeros((2, 8))
    U[0, 0] = 1.0
    U[1, 1] = 1.0
    # the event budget of the sweep's FTLE (`kicktimes.diagnostics.lyapunov`)
    max_events = int(EVENTS_PER_TIME * n_steps * tau) + 10**6
    log_scale, _, _, t_end, status = fresh_partner_tangent_two_kernel(
        st, two.table(1.0 - r, 1.0 - r), 2.0 * r, np.int64(n_steps), float(tau), U,
        np.int64(max_events))
    if status != 0:
        raise RuntimeError(f"fresh_lam: the tangent loop stopped with status {status} "
                           f"(1 budget, 2 stuck at one instant, 3 non-finite time) at r = {r}")
    return max((log_scale[0] + math.log(abs(U[0, 0]))) / t_end,
               (log_scale[1] + math.log(abs(U[1, 1]))) / t_end)

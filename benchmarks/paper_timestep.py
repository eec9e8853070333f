"""The paper's own two-disk algorithm in plain NumPy: a reference for benchmarks only.

Ranković & Porter (Sec. 2): "After each discrete time step (of fixed duration tau), we
calculate the positions and velocities of both particles. For each time step, we check if
a collision occurs ... If no collisions occur, we determine the new particle positions
based on their free movement after a time tau. Otherwise, the particles evolve freely for
the (shorter) time step tau' < tau until the next collision, and we then calculate their
new positions and velocities immediately after that collision."

Every step is a Python iteration with small NumPy operations, as a direct transcription
would be. Not part of the library.
"""

import numpy as np


def paper_timestep(ic, r, n_steps, tau):
    """Return (pp_times, n_boundary, samples) after ``n_steps`` collision-truncated steps."""
    pos = np.array(ic[:, :2], dtype=float)
    vel = np.array(ic[:, 2:], dtype=float)
    rho, sigma = 1.0 - r, 2.0 * r
    t = 0.0
    pp_times = []
    n_boundary = 0
    samples = np.empty((n_steps + 1, 2))
    samples[0] = pos[0]
    for k in range(1, n_steps + 1):
        # time to the boundary for each disk
        b = np.sum(pos * vel, axis=1)
        c = rho**2 - np.sum(pos * pos, axis=1)
        vv = np.sum(vel * vel, axis=1)
        tb = (-b + np.sqrt(np.maximum(b * b + vv * c, 0.0))) / vv
        # time to contact of the pair
        d = pos[0] - pos[1]
        w = vel[0] - vel[1]
        dw = d @ w
        cc = d @ d - sigma**2
        disc = dw * dw - (w @ w) * cc
        tp = cc / (-dw + np.sqrt(disc)) if (dw < 0 and disc > 0) else np.inf
        times = np.array([tb[0], tb[1], tp])
        i = int(np.argmin(times))
        step = min(tau, times[i])
        pos += vel * step
        t += step
        if step < tau:
            if i < 2:
                n = pos[i] / np.linalg.norm(pos[i])
                vel[i] -= 2 * (vel[i] @ n) * n
                n_boundary += 1
            else:
                n = d + w * step
                n /= np.linalg.norm(n)
                vel[0] -= 2 * (vel[0] @ n) * n
                vel[1] -= 2 * (vel[1] @ n) * n
                pp_times.append(t)
        samples[k] = pos[0]
    return np.array(pp_times), n_boundary, samples

"""Simulation of Markov-modulated Poisson processes (see :mod:`kicktimes.stats.mmpp`)."""

from __future__ import annotations

import numpy as np

from .._checks import check_choice, check_int, check_real, check_rng
from ._em import stationary_law
from ._kernels import simulate_window

# uniforms are drawn in blocks of this size, whatever the horizon, so that with one seed
# a shorter window's events are a prefix of a longer one's
_CHUNK = 4096


def simulate_mmpp(rates, generator, t_max, *, n_windows=1, initial="stationary", rng=None):
    r"""Event times of a Markov-modulated Poisson process in windows ``[0, t_max]``.

    Parameters
    ----------
    rates : array_like, shape (n,)
        Event rate in each state (>= 0, not all 0).
    generator : array_like, shape (n, n)
        Generator of the hidden chain: off-diagonal entries >= 0, rows summing to 0.
    t_max : float or sequence of float
        Window length, or one length per window (then ``n_windows`` is their number).
    n_windows : int, optional
        Number of windows of the common length.
    initial : "stationary", array_like or int, optional
        State law at each window's start: the stationary law of ``generator``, a
        distribution over the states, or one state.
    rng : Generator or int, optional

    Returns
    -------
    ndarray or list of ndarray
        The times of one window (``t_max`` a number and ``n_windows == 1``), else a list.

    Notes
    -----
    Competing exponentials: in state ``s`` the next jump comes after an
    :math:`\text{Exp}(\lambda_s - q_{ss})` time and is an event with probability
    :math:`\lambda_s / (\lambda_s - q_{ss})`, else a switch to ``j`` with probability
    proportional to :math:`q_{sj}`. Uniforms are drawn in fixed blocks, so with one seed
    the events of a shorter window are a prefix of a longer one's.

    Examples
    --------
    >>> from kicktimes import stats
    >>> t = stats.simulate_mmpp([0.5, 5.0], [[-0.1, 0.1], [0.3, -0.3]], 100.0, rng=0)
    >>> bool(t.size > 0 and t[-1] <= 100.0)
    True
    """
    rates = np.array(rates, dtype=float, ndmin=1)
    Q = np.array(generator, dtype=float, ndmin=2)
    n = rates.size
    if rates.ndim != 1 or not np.all(np.isfinite(rates)) or np.any(rates < 0) or rates.max() <= 0:
        raise ValueError(f"rates must be a 1-D array of finite rates >= 0, not all 0, "
                         f"got {rates!r}")
    off = ~np.eye(n, dtype=bool)
    if (Q.shape != (n, n) or not np.all(np.isfinite(Q)) or np.any(Q[off] < 0)
            or np.abs(Q.sum(axis=1)).max() > 1e-9 * max(1.0, np.abs(Q).max())):
        raise ValueError(f"generator must be an {n} x {n} matrix with off-diagonal entries "
                         f">= 0 and rows summing to 0, got {Q!r}")
    if np.ndim(t_max) == 0:
        count = check_int("n_windows", n_windows, low=1)
        lengths = np.full(count, check_real("t_max", t_max, low=0.0))
    else:
        lengths = np.array([check_real(f"t_max[{i}]", v, low=0.0) for i, v in enumerate(t_max)])
    if isinstance(initial, str):
        check_choice("initial", initial, ("stationary",))
        law = stationary_law(Q) if n > 1 else np.ones(1)
    elif np.ndim(initial) == 0:
        law = np.eye(n)[check_int("initial", initial, low=0, high=n - 1)]
    else:
        law = np.asarray(initial, dtype=float)
        if law.shape != (n,) or np.any(law < 0) or not np.isclose(law.sum(), 1.0):
            raise ValueError(f"initial must be 'stationary', a state in [0, {n - 1}] or a "
                             f"distribution over the {n} states, got {initial!r}")
    rng = check_rng(rng)
    cdf = np.cumsum(law)
    u, pos = rng.random(_CHUNK), 0
    out = []
    for length in lengths:
        if pos >= u.size:
            u, pos = rng.random(_CHUNK), 0
        state = min(int(np.searchsorted(cdf, u[pos] * cdf[-1], side="right")), n - 1)
        pos += 1
        buf, count, t = np.empty(64), 0, 0.0
        while True:
            count, pos, state, t, done = simulate_window(rates, Q, state, t, length, u, pos,
                                                         buf, count)
            if done:
                break
            if pos + 2 > u.size:
                u, pos = rng.random(_CHUNK), 0
            if count == buf.size:
                buf = np.concatenate([buf, np.empty(buf.size)])
        out.append(buf[:count].copy())
    return out[0] if np.ndim(t_max) == 0 and lengths.size == 1 else out

r"""Markov-modulated Poisson processes (MMPP): maximum-likelihood fit by EM over many
censored windows, the fitted model, and simulation.

A hidden continuous-time Markov chain on ``n`` states with generator ``Q`` switches the
rate of a Poisson process between ``rates[0] < ... < rates[n-1]``. Observed are event
times ``0 < t_1 < ... < t_N <= T`` in each window ``[0, T]``; each window starts from the
stationary law ``pi`` of ``Q`` (``initial="stationary"``, default) or from one
distribution common to all windows, estimated (``initial="free"``). With
``D = Q - diag(rates)``, ``x_k = t_k - t_{k-1}`` (``t_0 = 0``) the exact likelihood of a
window, the right end censored, is

.. math::

    L = \alpha\, e^{D x_1} \Lambda\, e^{D x_2} \Lambda \cdots e^{D x_N} \Lambda\,
        e^{D (T - t_N)} \mathbf 1, \qquad \Lambda = \mathrm{diag}(\text{rates}),

the last factor being the probability of no event from the last event to the window's
end. The model, the likelihood, the EM and its checks: ``docs/mmpp.md``.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from kicktimes._results import nan_reason
from kicktimes.validation import keyword_only_after

from .._checks import as_1d_float, check_choice, check_int, check_real, check_rng, check_times
from .._information import inverse_information
from ..poisson import _is_ensemble
from ..renewal import FitWarning
from . import _em as em
from ._starts import starting_points
from .simulation import simulate_mmpp

INITIAL = ("stationary", "free")
MAX_STATES = 4
#: the fewest events of one sequence fitted by an MMPP-2 alone (4 parameters: two rates,
#: two switching rates): about 12 events per parameter. Fewer, and kicktimes does not fit
#: it on its own: the sweep's ``mmpp`` system falls back to Poisson times, the report and
#: ``kicktimes analyze --mmpp`` leave the sequence out, the MMPP study's per-run fits skip
#: the run
MMPP_MIN_EVENTS = 50
#: Data over _SEARCH_INTERVALS intervals (in 4 windows or more) are searched on a random
#: subset of whole windows of about that size: every start runs to convergence there, and
#: the _FINALISTS best distinct optima continue on all the data
_SEARCH_INTERVALS, _FINALISTS = 20_000, 2
#: E-steps of every start in the search's first pass (see _search)
_FIRST_PASS = 100
#: a start "reached the best" log-likelihood when it ended within this much of it,
#: relative (the EM stops at a relative change of ``tol = 1e-9`` per iteration, which
#: leaves converged starts up to about 1e-7 relative apart)
BEST_RTOL = 1e-6


def check_windows(times, t_max):
    """Validated ``(list of event-time arrays, array of window lengths)``: one window (a
    1-D array) or a list of windows, ``t_max`` one length or one per window."""
    if isinstance(times, np.ndarray) and times.dtype != object and times.ndim != 1:
        raise TypeError(f"times must be a 1-D array (one window) or a list of 1-D arrays "
                        f"(one per window), got an array of shape {times.shape}")
    several = _is_ensemble(times)
    seqs = list(times) if several else [times]
    if np.ndim(t_max) == 0:
        lengths = np.full(len(seqs), check_real("t_max", t_max, low=0.0))
    else:
        lengths = np.array([check_real(f"t_max[{i}]", v, low=0.0) for i, v in enumerate(t_max)])
        if lengths.size != len(seqs):
            raise ValueError(f"t_max must be a number or hold one length per window "
                             f"({len(seqs)}), got {lengths.size}")
    out = []
    for i, (seq, length) in enumerate(zip(seqs, lengths, strict=True)):
        name = f"times[{i}]" if several else "times"
        t = as_1d_float(name, seq)
        outside = (t < 0) | (t > length)
        if outside.any():
            j = int(np.flatnonzero(outside)[0])
            raise ValueError(f"{name} must lie in [0, t_max] = [0, {float(length)!r}], got "
                             f"{name}[{j}] = {float(t[j])!r}")
        out.append(check_times(name, t, float(length)))
    return out, lengths


@dataclass(frozen=True, repr=False)
class MMPPFit:
    r"""A fitted Markov-modulated Poisson process (result of :func:`fit_mmpp`).

    Attributes
    ----------
    rates : ndarray, shape (n,)
        Event rate in each state, ascending (per unit of time of the data).
    generator : ndarray, shape (n, n)
        The hidden chain's generator ``Q``: ``Q[i, j]`` (``i != j``) is the switching
        rate from state ``i`` to ``j``; rows sum to 0.
    stationary : ndarray, shape (n,)
        The stationary law ``pi`` of ``Q``.
    initial : ndarray, shape (n,)
        The state law at each window's start (``stationary`` unless
        ``initial_method == "free"``).
    loglik : float
        Exact log-likelihood of all windows (censored ends included).
    rates_se, generator_se : ndarray
        Standard errors from the observed information (central differences of the exact
        score, Fisher's identity), by the delta method; the diagonal of
        ``generator_se`` is that of ``-sum_j q_ij``. NaN when the information is
        singular. A free start is held fixed in them.
    covariance : ndarray
        Covariance of ``(rates, off-diagonal q_ij in row order)``.
    converged, n_iter, n_starts, warnings :
        EM health: the kept run converged within ``max_iter`` E-steps (``n_iter``), the
        best of ``n_starts`` starts each run to convergence; ``warnings`` lists
        degenerate fits (a state without events, states not distinguished, a switching
        rate at its floor or cap) and numerical trouble.
    n_best, start_logliks :
        The convergence report: how many of the starts ended at the best
        log-likelihood (within ``BEST_RTOL = 1e-6`` relative), and the log-likelihood
        each start ended at (in the order of the starts; -inf for a failed one). A
        best reached by one start only is fragile: more starts may find a better one.
    """

    rates: np.ndarray
    generator: np.ndarray
    stationary: np.ndarray
    initial: np.ndarray
    initial_method: str
    loglik: float
    n_windows: int
    n_events: int
    total_time: float
    converged: bool
    n_iter: int
    n_starts: int
    rates_se: np.ndarray
    generator_se: np.ndarray
    covariance: np.ndarray
    warnings: tuple = ()
    n_best: int = 1
    start_logliks: tuple = ()

    @property
    def n_states(self) -> int:
        return int(self.rates.size)

    @property
    def n_params(self) -> int:
        """Free parameters: ``n`` rates, ``n (n - 1)`` switching rates, and ``n - 1``
        for a free start."""
        n = self.n_states
        return n * n + (n - 1 if self.initial_method == "free" else 0)

    @property
    def reason(self) -> str | None:
        """Why a rate, a switching rate or a standard error is NaN (the fit's `warnings`),
        None when all are finite."""
        return nan_reason(np.concatenate([np.ravel(a) for a in (
            self.rates, self.generator, self.rates_se, self.generator_se)]), self.warnings)

    @property
    def aic(self) -> float:
        """``2 k - 2 loglik``."""
        return 2 * self.n_params - 2 * self.loglik

    @property
    def bic(self) -> float:
        """``k log(n_events) - 2 loglik``."""
        return self.n_params * math.log(max(self.n_events, 1)) - 2 * self.loglik

    @property
    def stationary_rate(self) -> float:
        """Mean event rate of the stationary process, ``stationary @ rates``."""
        return float(self.stationary @ self.rates)

    @property
    def mean_sojourns(self) -> np.ndarray:
        """Mean time the chain stays in each state, ``-1 / Q[i, i]``."""
        with np.errstate(divide="ignore"):
            return -1.0 / np.diag(self.generator)

    @property
    def params(self) -> dict:
        """``{"rate[i]": ..., "q[i,j]": ...}`` (the free parameters)."""
        return _keyed(self.rates, self.generator)

    @property
    def stderr(self) -> dict:
        """Standard errors keyed as :attr:`params`."""
        return _keyed(self.rates_se, self.generator_se)

    def __repr__(self) -> str:
        flag = "" if self.converged else ", converged=False"
        rates = np.array2string(self.rates, precision=4)
        best = f", best_of_starts={self.n_best}/{self.n_starts}" if self.n_states > 1 else ""
        return (f"MMPPFit(n_states={self.n_states}, rates={rates}, loglik={self.loglik:.6g}, "
                f"aic={self.aic:.6g}, n_windows={self.n_windows}, "
                f"n_events={self.n_events}{best}{flag})")

    def summary(self) -> str:
        """A readable table of the fit."""
        n = self.n_states
        start = ("stationary start" if self.initial_method == "stationary"
                 else "free start, " + ", ".join(f"{v:.3g}" for v in self.initial))
        lines = [f"MMPP fit: {n} state{'s' if n > 1 else ''} (exact censored likelihood, "
                 f"EM; {start})",
                 f"  windows: {self.n_windows}, events: {self.n_events}, total time "
                 f"{self.total_time:.6g}; each window's right end censored",
                 f"  log-likelihood {self.loglik:.6g}   AIC {self.aic:.6g}   BIC {self.bic:.6g}"
                 f"   (k = {self.n_params})",
                 f"  {'parameter':<10} {'estimate':>14} {'std. err.':>14}"]
        se = self.stderr
        lines += [f"  {k:<10} {v:>14.6g} {se[k]:>14.6g}" for k, v in self.params.items()]
        lines.append("  stationary law " + ", ".join(f"{v:.4g}" for v in self.stationary)
                     + f"   stationary rate {self.stationary_rate:.6g}")
        if n > 1:
            lines.append("  mean sojourns " + ", ".join(f"{v:.4g}" for v in self.mean_sojourns))
            lines.append(f"  EM: {self.n_starts} starts run to convergence; {self.n_best} "
                         f"reached the best log-likelihood (within {BEST_RTOL:g} relative)"
                         f"{' - a fragile optimum' if self.n_best < 2 else ''}; the kept "
                         f"run took {self.n_iter} iterations")
        if not self.converged:
            lines.append("  NOT CONVERGED: the numbers above are not a maximum-likelihood fit")
        lines.extend(f"  warning: {w}" for w in self.warnings)
        return "\n".join(lines)

    @keyword_only_after(1, since="0.2.0", names=('rng',))
    def simulate(self, t_max, *, rng=None, n_windows=1, stationary=True):
        """Event times of the fitted process: see :func:`simulate_mmpp`. Each window
        starts from :attr:`stationary` (``stationary=True``) or from :attr:`initial`."""
        return simulate_mmpp(self.rates, self.generator, t_max, n_windows=n_windows,
                             initial=self.stationary if stationary else self.initial, rng=rng)

    def loglik_of(self, times, t_max) -> float:
        """Exact log-likelihood of other windows (e.g. held-out data) under the fit."""
        seqs, lengths = check_windows(times, t_max)
        data = em.Windows.of(seqs, lengths)
        st = em.estep(self.rates * data.unit, self.generator * data.unit, self.initial, data)
        return st.loglik - data.n_events.sum() * math.log(data.unit)


def _keyed(rates, generator) -> dict:
    n = rates.size
    out = {f"rate[{i}]": float(v) for i, v in enumerate(rates)}
    out.update({f"q[{i},{j}]": float(generator[i, j])
                for i in range(n) for j in range(n) if i != j})
    return out


def fit_mmpp(times, t_max, *, n_states=2, n_starts=12, rng=None, max_iter=1000, tol=1e-9,
             initial="stationary"):
    r"""Fit a Markov-modulated Poisson process to event times in censored windows.

    Parameters
    ----------
    times : array_like or list of array_like
        Event times of one window (a 1-D array) or of several (a list of 1-D arrays),
        strictly increasing, in ``[0, t_max]`` of their window.
    t_max : float or sequence of float
        Window lengths (> 0): one for all, or one per window. Every window starts at 0;
        its right end is censored (the likelihood includes the probability of no event
        from the last event to ``t_max``).
    n_states : int, optional
        Number of hidden states, 1 to 4 (1 is the homogeneous Poisson process).
    n_starts : int, optional
        EM starts (>= 1), each run to convergence; the best log-likelihood is kept.
        The structured starts built from the data come first (bursts from the shortest
        gaps, quiet spells from the longest, local event
        rates, the fast- and slow-switching limits), then ``n_starts // 6`` random ones
        (see Notes).
    rng : Generator or int, optional
        Randomness of the random starts.
    max_iter : int, optional
        Most E-steps of each start's run (>= 1).
    tol : float, optional
        Stop when the log-likelihood changes by at most ``tol * |loglik|`` in an
        iteration, in (0, 1).
    initial : {"stationary", "free"}, optional
        Each window starts from the stationary law of the chain (default: windows cut
        from a stationary process) or from one estimated distribution.

    Returns
    -------
    MMPPFit

    Raises
    ------
    ValueError, TypeError
        Bad input, naming the argument and its valid range; fewer events than
        parameters.

    Warns
    -----
    FitWarning
        EM did not converge, a degenerate fit (a state without events, two states with
        nearly equal rates, a chain that switches less than once in all the data, a
        switching rate at its floor or cap: the likelihood has no interior maximum and
        a smaller model fits as well), or standard errors unavailable; the result is
        defined and ``warnings`` says which.

    Notes
    -----
    EM for MMPPs (Rydén 1996): the E-step runs scaled forward and backward recursions
    over the intervals of every window and, from the eigendecomposition of
    :math:`D = Q - \Lambda`, integrates exactly the expected time in each state
    :math:`T_i` and transitions :math:`M_{ij}` within each interval, the expected events
    in each state :math:`N_i` and the state at each window's start :math:`s_i`. The
    M-step sets :math:`\lambda_i = N_i / T_i`, and :math:`q_{ij} = M_{ij} / T_i` for a
    free start; with the stationary start it maximises
    :math:`\sum_{i \ne j} (M_{ij}\log q_{ij} - T_i q_{ij}) + \sum_k s_k \log \pi_k(Q)` by
    Newton's method. SQUAREM (Varadhan & Roland 2008) accelerates the iterations,
    keeping them monotone. The likelihood has several local maxima; on clustered event
    times the global one often has a burst state (a rate far above the mean, entered a
    few times) or a quiet one, which starts near the local event rates never reach. So
    the starts are built for every regime (``kicktimes.stats.mmpp._starts``) and all are
    run to convergence; ``n_best`` counts those that reached the best, and a fit is
    never below the Poisson fit it nests (equal rates). Standard errors: the observed
    information, by central
    differences of the exact score (Fisher's identity: the gradient of the expected
    complete-data log-likelihood at the fit). Computations run in a time unit in which
    the mean event rate is 1. Details: ``docs/mmpp.md``.

    References
    ----------
    T. Rydén, "An EM algorithm for estimation in Markov-modulated Poisson processes",
    Comput. Stat. Data Anal. 21 (1996) 431-447.

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes import stats
    >>> Q = np.array([[-0.1, 0.1], [0.3, -0.3]])
    >>> times = stats.simulate_mmpp([0.5, 5.0], Q, 60.0, n_windows=300, rng=1)
    >>> fit = stats.fit_mmpp(times, 60.0, rng=2)
    >>> np.round(fit.rates, 1)
    array([0.5, 5. ])
    """
    n = check_int("n_states", n_states, low=1, high=MAX_STATES)
    n_starts = check_int("n_starts", n_starts, low=1)
    max_iter = check_int("max_iter", max_iter, low=1)
    tol = check_real("tol", tol, low=0.0, high=1.0)
    check_choice("initial", initial, INITIAL)
    rng = check_rng(rng)
    seqs, lengths = check_windows(times, t_max)
    data = em.Windows.of(seqs, lengths)
    fit = _fit(data, n, n_starts=n_starts, rng=rng, max_iter=max_iter, tol=tol,
               initial=initial)
    if fit.warnings:
        status = "" if fit.converged else "did not converge: "
        warnings.warn(f"fit_mmpp(n_states={n}): {status}{'; '.join(fit.warnings)}",
                      FitWarning, stacklevel=2)
    return fit


def _fit(data, n, *, n_starts=12, rng=None, max_iter=1000, tol=1e-9, initial="stationary",
         covariance=True):
    """fit_mmpp on a validated :class:`~._em.Windows`; no warning is issued."""
    rng = check_rng(rng)
    k = n * n + (n - 1 if initial == "free" else 0)
    n_events = int(data.n_events.sum())
    if n_events < max(k, 1):
        raise ValueError(f"times: a {n}-state MMPP has {k} parameters and needs at least as "
                         f"many events, got {n_events}")
    if n == 1:
        return _poisson(data, covariance)
    points = starting_points(data, n, n_starts, rng)
    search = data
    if data.x.size > _SEARCH_INTERVALS and data.n_windows >= 4:
        size = max(2, math.ceil(data.n_windows * _SEARCH_INTERVALS / data.x.size))
        search = data.subset(np.sort(rng.choice(data.n_windows, size=size, replace=False)))
    runs = _search(points, search, initial=initial, max_iter=max_iter, tol=tol)
    lls = np.array([run.loglik if np.isfinite(run.loglik) else -np.inf for run in runs])
    top = lls.max()
    n_best = int(np.sum(lls >= top - BEST_RTOL * abs(top)))
    shift = search.n_events.sum() * math.log(search.unit)
    start_logliks = tuple(float(v - shift) for v in lls)
    if search is data:
        best = runs[int(np.argmax(lls))]
    else:
        finals, seen = [], []
        for i in np.argsort(-lls, kind="stable"):
            if len(finals) == _FINALISTS or not np.isfinite(lls[i]):
                break
            if any(abs(lls[i] - v) <= BEST_RTOL * abs(v) for v in seen):
                continue  # the same optimum as a finalist
            seen.append(lls[i])
            run = runs[i]
            final = em.run_em(run.rates, run.Q, data, initial=initial, max_iter=max_iter,
                              tol=tol, alpha=run.alpha if initial == "free" else None)
            final.n_iter += run.n_iter
            finals.append(final)
        best = max(finals, key=lambda run: run.loglik if np.isfinite(run.loglik) else -np.inf)
    # the Poisson fit is nested (equal rates): no MMPP fit may end below it
    rate = n_events / data.total_time
    loglik_poisson = n_events * math.log(rate) - rate * data.total_time
    if not best.loglik >= loglik_poisson - 1e-12 * abs(loglik_poisson):
        rates = np.full(n, rate)
        Q = np.full((n, n), rate / max(n - 1, 1)) - np.eye(n) * rate * n / max(n - 1, 1)
        alpha = em.stationary_law(Q)
        best = em.EMRun(rates, Q, alpha, em.estep(rates, Q, alpha, data), 1, True)
    return _result(best, data, initial, n_starts=len(points), covariance=covariance,
                   n_best=n_best, start_logliks=start_logliks)


def _search(points, data, *, initial, max_iter, tol):
    """Run every start to convergence, in two passes: each start first for up to
    ``_FIRST_PASS`` E-steps, then those not converged from where they stopped, the best
    first. A start that cannot catch up with the best so far stops early
    (:func:`._em.run_em`'s ``floor``), and the first pass gives the floor early, so that
    the starts crawling along a flat ridge below the best are stopped before they took
    ``max_iter`` E-steps."""
    runs, floor = [], -math.inf
    for r, q, _ in points:
        run = em.run_em(r, q, data, initial=initial, max_iter=min(_FIRST_PASS, max_iter),
                        tol=tol, floor=floor)
        runs.append(run)
        if run.converged and np.isfinite(run.loglik):
            floor = max(floor, run.loglik)
    pending = [i for i, run in enumerate(runs) if not run.converged and run.n_iter < max_iter
               and np.isfinite(run.loglik)]
    for i in sorted(pending, key=lambda i: -runs[i].loglik):
        run = runs[i]
        more = em.run_em(run.rates, run.Q, data, initial=initial, tol=tol, floor=floor,
                         max_iter=max_iter - run.n_iter,
                         alpha=run.alpha if initial == "free" else None)
        more.n_iter += run.n_iter
        runs[i] = more
        if np.isfinite(more.loglik):
            floor = max(floor, more.loglik)
    return runs


def _poisson(data, covariance):
    n_events = int(data.n_events.sum())
    time = data.total_time * data.unit
    rate = n_events / time
    loglik = n_events * math.log(rate) - rate * time
    se = rate / math.sqrt(n_events) if covariance else math.nan
    return MMPPFit(np.array([rate]), np.zeros((1, 1)), np.ones(1), np.ones(1), "stationary",
                   float(loglik), data.n_windows, n_events, time, True, 0, 1, np.array([se]),
                   np.zeros((1, 1)), np.array([[se * se]]))


def _result(run, data, initial, *, n_starts, covariance, n_best=1, start_logliks=()):
    n = run.rates.size
    order = np.argsort(run.rates, kind="stable")
    rates, Q = run.rates[order], run.Q[np.ix_(order, order)]
    alpha = run.alpha[order]
    st = run.stats
    events, pi = st.events[order], em.stationary_law(Q)
    problems = [] if run.converged else [f"EM stopped after max_iter = {run.n_iter} E-steps"]
    off = ~np.eye(n, dtype=bool)
    for i in range(n):
        if events[i] < 1.0 or pi[i] < 1e-6:
            problems.append(f"state {i} holds {events[i]:.3g} expected events and stationary "
                            f"probability {pi[i]:.3g}: a state with (almost) no events")
    close = np.flatnonzero(np.diff(rates) <= 0.01 * rates[1:])
    # the best of all starts: no start found distinct rates with a higher likelihood
    problems += [f"states {i} and {i + 1} have rates within 1 % ({rates[i]:.4g}, "
                 f"{rates[i + 1]:.4g}) and no start found distinct rates with a higher "
                 f"log-likelihood: the states are not distinguished" for i in close]
    switches = float(st.transitions.sum())
    if switches < 1.0:
        problems.append(f"the hidden chain switches {switches:.3g} times (expected) in all the "
                        "windows: the fit is a mixture of Poisson windows, not a switching "
                        "process, and the switching rates are not identified")
    if np.any(Q[off] <= 1.01 * em.Q_FLOOR) or np.any(Q[off] >= 0.99 * em.Q_CAP):
        problems.append("a switching rate ran to its floor or cap (in units of the mean event "
                        "rate: 1e-10, 1e6): the chain hardly switches, or switches much "
                        "faster than events occur")
    k = n + n * (n - 1)
    cov = np.full((k, k), np.nan)
    if covariance:
        info = em.information(rates, Q, alpha, data, initial)
        # identifiability decided on the unit-diagonal information (not by whether a BLAS
        # kernel's inverse of a near-singular matrix happens to come out finite)
        cov_log, ok = inverse_information(info)
        if ok:
            theta = np.concatenate([rates, Q[off]])
            cov = cov_log * np.outer(theta, theta)
        else:
            problems.append("standard errors unavailable: the observed information is "
                            "singular or not positive definite (an estimate at a boundary, "
                            "or parameters not identified)")
    u = data.unit
    cov = cov / u**2
    se = np.sqrt(np.where(np.diag(cov) >= 0, np.diag(cov), np.nan))
    q_se = np.zeros((n, n))
    q_se[off] = se[n:]
    for i in range(n):
        # q_ii = -sum_j q_ij: the variance of the sum over row i's entries
        row = n + i * (n - 1) + np.arange(n - 1)
        q_se[i, i] = math.sqrt(cov[np.ix_(row, row)].sum()) if np.isfinite(se[row]).all() \
            else math.nan
    return MMPPFit(rates / u, Q / u, pi, alpha, initial,
                   float(st.loglik - data.n_events.sum() * math.log(u)), data.n_windows,
                   int(data.n_events.sum()), data.total_time * u, bool(run.converged),
                   int(run.n_iter), n_starts, se[:n], q_se, cov, tuple(problems),
                   n_best=n_best, start_logliks=start_logliks)

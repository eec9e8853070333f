r"""The state-dependent rate and the twin processes of the Poisson battery.

Between collisions each disk's angular momentum is conserved, so the pair collides at
the rate :math:`\Gamma(r; L_0, L_1)` of `kicktimes.stats.conditional_kinetic_rate`, reset
at every collision (`rate`). The twins are point processes with the runs' rates, put
through the same Poisson battery (`battery`) as the runs: a Poisson process at the pooled
rate, a mixed Poisson process at each IC's predicted rate, Cox processes whose rate is
redrawn at every event (independently from the group's post-collision states, or the
run's own sequence), and an out-of-sample Markov chain of the rate fitted on the other
half of the ICs (`fit_rate_chain`, `draw_rate_chains`).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from kicktimes import stats

__all__ = ["BATTERY", "CHAIN_STATES", "TWINS", "battery", "dispersion", "draw_rate_chains",
           "fit_rate_chain", "rate", "twin_batteries"]

BATTERY = ("uniformity_ks", "exponential_ks", "exponential_ad", "dispersion")
TWINS = ("poisson", "mixed_poisson", "cox_iid", "cox_sequence", "cox_markov_oos")
#: states drawn per out-of-sample twin (its path is recycled if a run needs more)
CHAIN_STATES = 600


def rate(r, L0, L1, speed0=None, speed1=None):
    """Gamma(r; L0, L1), vectorised (`kicktimes.stats.conditional_kinetic_rate`); with the
    speeds, the elastic rule's rate conditioned on them as well."""
    L0, L1 = np.asarray(L0, float), np.asarray(L1, float)
    if speed0 is None:
        return np.asarray(stats.conditional_kinetic_rate(r, L0, L1), float)
    return np.asarray(stats.conditional_kinetic_rate(
        r, L0, L1, rule="elastic", speed1=np.asarray(speed0, float),
        speed2=np.asarray(speed1, float)), float)


def fit_rate_chain(first, post_by_run, n_bins=10):
    """A first-order Markov chain of the post-collision rate, fitted on training runs.

    The pairs (rate of the state before, rate of the state after) of consecutive
    collisions of each run (the first "before" is the IC's predicted rate) are binned by
    the rate before at its deciles; the chain's step from a rate in bin k draws the next
    rate uniformly from the training pairs' "after" values in bin k. Returns
    ``(edges, pool, counts)``.
    """
    prev = np.concatenate([np.r_[g, p[:-1]] for g, p in zip(first, post_by_run, strict=True)
                           if p.size])
    nxt = np.concatenate([p for p in post_by_run if p.size])
    edges = np.unique(np.quantile(prev, np.linspace(0, 1, n_bins + 1)[1:-1]))
    b = np.digitize(prev, edges)
    counts = np.bincount(b, minlength=edges.size + 1)
    pool = np.full((edges.size + 1, max(int(counts.max()), 1)), np.nan)
    for k in range(edges.size + 1):
        pool[k, :counts[k]] = nxt[b == k] if counts[k] else np.nan
        if not counts[k]:                      # an empty bin steps like the whole sample
            pool[k, :min(nxt.size, pool.shape[1])] = nxt[:pool.shape[1]]
            counts[k] = min(nxt.size, pool.shape[1])
    return edges, pool, counts


def draw_rate_chains(chain, start, n_states, rng):
    """Paths (len(start), n_states + 1) of the chain, each from its start rate."""
    edges, pool, counts = chain
    out = np.empty((len(start), n_states + 1))
    out[:, 0] = cur = np.asarray(start, float)
    for k in range(n_states):
        b = np.digitize(cur, edges)
        cur = pool[b, (rng.random(cur.size) * counts[b]).astype(int)]
        out[:, k + 1] = cur
    return out


def dispersion(counts):
    """Index of dispersion var / mean of ``counts`` (NaN for a zero mean)."""
    counts = np.asarray(counts, float)
    return counts.var(ddof=1) / counts.mean() if counts.mean() > 0 else math.nan


def battery(seqs, t_max, rng):
    """The Poisson battery of `kicktimes.stats.poisson_group` on sequences over
    ``[0, t_max]``: per sequence whether each test of `BATTERY` rejects at 0.05, the
    counts and the index of dispersion."""
    res = stats.poisson_group(seqs, t_max, n_mc=199, rng=rng)
    per = res.ensemble.per_sequence
    reject = pd.DataFrame({t: (per[f"p_{t}"] < 0.05).to_numpy() for t in BATTERY})
    counts = per["n_events"].to_numpy()
    return {"reject": reject, "counts": counts,
            "dispersion_index": res.homogeneity["dispersion_index"]}


def twin_batteries(runs, tab, pred, post, t_max, n_twins, rng):
    """The battery on n_twins ensembles of each twin model, paired with the runs."""
    by_run = [post[tab["run"].to_numpy() == i] for i in range(len(runs))]
    pooled = np.array([run.n_pp for run in runs]).sum() / (len(runs) * t_max)
    out = {name: [] for name in TWINS}
    # out of sample: each half of the ICs gets the chain fitted on the other half
    half = np.arange(len(runs)) % 2
    chains = {h: fit_rate_chain(pred[half != h], [by_run[i] for i in np.flatnonzero(half != h)])
              for h in (0, 1)}
    for _ in range(n_twins):
        paths = np.empty((len(runs), CHAIN_STATES + 1))
        for h in (0, 1):
            paths[half == h] = draw_rate_chains(chains[h], pred[half == h], CHAIN_STATES, rng)
        draws = {
            "poisson": [stats.simulate_cox_times([pooled], t_max, rng=rng) for _ in runs],
            "mixed_poisson": [stats.simulate_cox_times([g], t_max, rng=rng) for g in pred],
            "cox_iid": [stats.simulate_cox_times(post, t_max, order="iid", rng=rng)
                        for _ in runs],
            "cox_sequence": [stats.simulate_cox_times(np.concatenate([[g], p]), t_max, rng=rng)
                             for g, p in zip(pred, by_run, strict=True)],
            "cox_markov_oos": [stats.simulate_cox_times(path, t_max, rng=rng) for path in paths],
        }
        for name, seqs in draws.items():
            out[name].append(battery(seqs, t_max, rng))
    return out

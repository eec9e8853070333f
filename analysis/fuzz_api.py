"""Fuzz the public API: N random calls, each in a worker process with a time and memory limit.

Every call is drawn from ``(seed, i)`` alone (valid-looking and pathological arguments
to the billiard, schedule, diagnostics and statistics functions), so two versions of the
package fuzzed with the same seed make exactly the same calls. Numba kernels cannot be
interrupted by signals, so each call runs in a persistent worker subprocess that is
killed and replaced when it overruns ``--timeout``; its address space is capped at
``--mem-gb``. Each call ends in one outcome:

=================  ===========================================================
ok                 returned; every number in the result is finite and runs
                   satisfy their invariants (inside the table, times in order)
clear-error        ValueError/TypeError whose message names an argument (or a
                   MemoryError whose message starts with the argument's name)
unclear-error      ValueError/TypeError that names no argument (or shows
                   ``np.float64(...)``)
other-exception    any other exception
explained-nan      returned NaN/inf with a stated reason (a warning, or the result's
                   ``reason``/``undefined``/``warnings``/``note``): a defined result
non-finite         returned NaN/inf somewhere in the result, silently
invalid            returned a run that breaks an invariant
timeout            still running after ``--timeout`` seconds (worker killed)
memory             MemoryError, or the worker died (address-space limit)
=================  ===========================================================

Run (before/after on the same seed)::

    PYTHONPATH=/work/main python analysis/fuzz_api.py --n 500 --seed 1
    PYTHONPATH=$PWD python analysis/fuzz_api.py --n 500 --seed 1 --show other-exception
"""

from __future__ import annotations

import argparse
import collections
import json
import math
import os
import select
import subprocess
import sys
import time

import numpy as np

OUTCOMES = ("ok", "clear-error", "unclear-error", "other-exception", "explained-nan",
            "non-finite", "invalid",
            "timeout", "memory")
NAN, INF = math.nan, math.inf


# ------------------------------------------------------------------ argument pools
def _time_options(rng, kw, modes, *, simulator):
    """The run's length into ``kw``: ``t_max`` (a simulator only), steps of ``tau``, the
    paper's steps, or (``"mixed"``, a simulator) steps and a ``t_max`` together; valid or
    not."""
    mode = _pick(rng, modes)
    if mode == "t_max" and simulator:
        kw["t_max"] = _maybe(rng, TIMES, BAD_TIMES)
        return
    kw["n_steps"] = _maybe(rng, STEPS, BAD_STEPS, 0.25)
    kw["tau"] = _maybe(rng, TAUS, BAD_TAUS, 0.25)
    if mode == "paper":
        kw["sampling"] = "paper"
    if mode == "mixed" and simulator:
        kw["t_max"] = _maybe(rng, TIMES, BAD_TIMES)


def _pick(rng, pool):
    return pool[int(rng.integers(len(pool)))]


def _maybe(rng, valid, bad, p_bad=0.2):
    """A valid-looking value most of the time, a pathological one otherwise."""
    return _pick(rng, bad) if rng.uniform() < p_bad else _pick(rng, valid)


RADII = [0.01, 0.02, 0.03, 0.05, 0.1, 0.2]
BAD_RADII = [0.0, -0.1, 0.5, 0.45, 0.49, 0.4999, 0.34, 0.4, 1.0, NAN, INF, 1e-300, "0.1", None,
             True, np.float64(-2.0), [0.1]]
TIMES = [1.0, 10.0, 50.0, 200.0]
BAD_TIMES = [0.0, -1.0, NAN, INF, 1e300, 1e-300, 1e9, "10", np.float64(-2.0), 1e15]
STEPS = [10, 100, 1000]
BAD_STEPS = [0, -5, 10**12, 2.5, True, np.int64(10**10), "100"]
TAUS = [0.1, 0.3, 1.0]
BAD_TAUS = [0.0, -0.3, NAN, INF, 1e-300, 1e300, 1e-12, "0.3"]


def _two_ic(rng):
    kind = _pick(rng, ["valid"] * 5 + ["tangent", "tangent2", "overlap", "outside", "nan",
                                       "fast", "slow", "zero", "shape", "strings", "touch",
                                       "onwall_out", "elastic"])
    if kind == "valid":
        return ("ic", int(rng.integers(1000)))
    return {
        "tangent": [[0.95, 0.0, 0.0, 1.0], [0.0, 0.5, 0.0, 1.0]],
        "tangent2": [[0.0, -0.95, 1.0, 0.0], [0.95, 0.0, 0.0, -1.0]],
        "overlap": [[0.0, 0.0, 1.0, 0.0], [0.01, 0.0, 0.0, 1.0]],
        "outside": [[1.2, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]],
        "nan": [[NAN, 0.0, 1.0, 0.0], [0.0, 0.5, 0.0, 1.0]],
        "fast": [[0.1, 0.0, 1e156, 0.0], [0.0, 0.5, 0.0, 1e156]],
        "slow": [[0.1, 0.0, 1e-300, 0.0], [0.0, 0.5, 0.0, 1e-300]],
        "zero": [[0.1, 0.0, 0.0, 0.0], [0.0, 0.5, 0.0, 0.0]],
        "shape": [[0.1, 0.0, 1.0, 0.0]],
        "strings": [["a", "b", "c", "d"], ["e", "f", "g", "h"]],
        "touch": [[-0.05, 0.0, 1.0, 0.0], [0.05, 0.0, -1.0, 0.0]],
        "onwall_out": [[0.95, 0.0, 1.0, 0.0], [-0.95, 0.0, -1.0, 0.0]],
        "elastic": [[0.1, 0.0, 3.0, 4.0], [0.0, 0.5, 0.0, 0.0]],
    }[kind]


def _one_state(rng):
    kind = _pick(rng, ["valid"] * 5 + ["tangent", "outward", "fast", "slow", "nan", "zero",
                                       "shape", "outside", "corner"])
    if kind == "valid":
        a = rng.uniform(0, 2 * np.pi)
        return [float(rng.uniform(-0.5, 0.5)), float(rng.uniform(-0.5, 0.5)), math.cos(a),
                math.sin(a)]
    return {
        "tangent": [0.95, 0.0, 0.0, 1.0],
        "outward": [0.95, 0.0, -1.0, 0.0],
        "fast": [0.1, 0.0, 1e156, 0.0],
        "slow": [0.1, 0.0, 1e-300, 0.0],
        "nan": [0.1, NAN, 1.0, 0.0],
        "zero": [0.1, 0.0, 0.0, 0.0],
        "shape": [0.1, 0.0, 1.0],
        "outside": [0.99, 0.0, 1.0, 0.0],
        "corner": [0.95 * math.cos(1.0), 0.95 * math.sin(1.0), -math.sin(1.0), math.cos(1.0)],
    }[kind]


def _kicks(rng, t_max):
    t = t_max if isinstance(t_max, float) and math.isfinite(t_max) and 0 < t_max < 1e6 else 10.0
    kind = _pick(rng, ["none", "array", "array", "poisson", "renewal", "zero", "unsorted",
                       "negative", "nan", "string", "series", "beyond", "huge_rate", "tangent",
                       "dup", "object", "bootstrap"])
    if kind == "none":
        return None
    if kind == "array":
        return ("sorted", int(rng.integers(1, 50)), t)
    return {
        "poisson": ("schedule", "Poisson", 0.5),
        "renewal": ("schedule", "Renewal", 1.0),
        "bootstrap": ("schedule", "Bootstrap", 0.3),
        "huge_rate": ("schedule", "Poisson", 1e9),
        "zero": [0.0],
        "unsorted": [2.0, 1.0],
        "negative": [-1.0],
        "nan": [NAN],
        "string": "poisson",
        "series": ("series", [0.5, 1.5]),
        "beyond": [t * 2 + 1.0],
        "tangent": [0.0],
        "dup": [1.0] * 500,
        "object": object(),
    }[kind]


def _materialise(value):
    """Turn the pools' recipes (tuples) into objects; done inside the worker."""
    import pandas as pd
    import scipy.stats as st

    import kicktimes as kt
    from kicktimes import schedules

    if isinstance(value, tuple) and value:
        tag = value[0]
        if tag == "ic":
            return kt.initial_conditions(1, 0.1, rng=value[1])[0]
        if tag == "sorted":
            g = np.random.default_rng(value[1])
            return np.sort(g.uniform(0.0, value[2], size=value[1]))
        if tag == "series":
            return pd.Series(value[1])
        if tag == "schedule":
            name, p = value[1], value[2]
            if name == "Poisson":
                return schedules.Poisson(p)
            if name == "Renewal":
                return schedules.Renewal(st.gamma(0.5, scale=p))
            return schedules.Bootstrap(np.array([p, 2 * p, 0.1]))
    return value


# ------------------------------------------------------------------------- targets
def _call_spec(seed: int, i: int):
    """``(target name, args, kwargs)`` of call ``i``: plain recipes, no package objects."""
    rng = np.random.default_rng([seed, i])
    target = _pick(rng, ["initial_conditions"] * 3 + ["simulate_two_particle"] * 6
                   + ["simulate_one_particle"] * 6 + ["schedule_sample"] * 3
                   + ["lyapunov_two", "lyapunov_one", "recurrence_rate", "autocorrelation",
                      "intervals_from_times", "test_poisson", "fit_renewal", "kinetic_rate",
                      "run_theta", "kick_file"])
    kw = {}
    if target == "initial_conditions":
        args = (_maybe(rng, [1, 3, 10], [0, -1, 2.5, 10**9, "3"]),
                _maybe(rng, RADII, BAD_RADII, 0.5))
        kw["seed"] = _maybe(rng, [0, 1, 7], [-1, 1.5, None])
        kw["method"] = _maybe(rng, ["paper", "uniform"], ["PAPER", 1], 0.1)
        kw["rule"] = _maybe(rng, ["mirror", "elastic"], ["x"], 0.1)
    elif target in ("simulate_two_particle", "lyapunov_two"):
        ic = _two_ic(rng)
        r = 0.05 if isinstance(ic, list) and rng.uniform() < 0.7 else _maybe(rng, RADII, BAD_RADII)
        args = (ic, r)
        _time_options(rng, kw, ["t_max", "steps", "paper", "mixed"],
                      simulator=target == "simulate_two_particle")
        kw["rule"] = _maybe(rng, ["mirror", "elastic"], ["bounce", None], 0.1)
        if rng.uniform() < 0.2:
            kw["track"] = _pick(rng, [0, 1, 2, -1, 0.5])
    elif target in ("simulate_one_particle", "lyapunov_one"):
        state = _one_state(rng)
        r = 0.05 if rng.uniform() < 0.5 else _maybe(rng, RADII + [0.5, 0.9],
                                                     BAD_RADII + [0.99999999])
        args = (state, r)
        _time_options(rng, kw, ["t_max", "steps", "paper"],
                      simulator=target == "simulate_one_particle")
        horizon = kw.get("t_max", 10.0)
        kicks = _kicks(rng, horizon)
        if kicks is not None:
            kw["kicks"] = kicks
            kw["rng"] = _maybe(rng, [0, 1, 2], [-1, "seed", 1.5], 0.2)
            if kicks == [0.0] and rng.uniform() < 0.7:
                kw["kick_angles"] = [math.pi / 2]
            elif rng.uniform() < 0.2:
                kw["kick_angles"] = _pick(rng, [[0.1], [NAN], "x", [1.0, 2.0]])
        if rng.uniform() < 0.2:
            kw["kick_angle"] = _pick(rng, ["gaussian", "uniform", "cauchy"])
            kw["sigma"] = _maybe(rng, [0.1, 1.0], [0.0, -1.0, NAN, 1e300])
    elif target == "schedule_sample":
        kind = _pick(rng, ["Poisson", "Renewal", "Bootstrap", "Replay"])
        param = _maybe(rng, [0.1, 1.0, 3.0], [0.0, -1.0, NAN, INF, 1e12, 1e-300, "1"])
        args = (kind, param, _maybe(rng, TIMES, BAD_TIMES), _maybe(rng, [0, 1], [-1, "x"], 0.2))
    elif target == "recurrence_rate":
        n = _pick(rng, [0, 1, 2, 50, 500])
        pts = rng.uniform(-1, 1, size=(n, 2)).tolist()
        if n and rng.uniform() < 0.3:
            pts[0][0] = _pick(rng, [NAN, INF, 1e308])
        args = (pts,)
        kw["eps"] = _maybe(rng, [1e-3, 0.1], [0.0, -1.0, NAN, INF, 1e300, "x"])
        if rng.uniform() < 0.3:
            kw["theiler"] = _pick(rng, [0, 5, -1, 10**9, 1.5])
    elif target == "autocorrelation":
        n = _pick(rng, [0, 1, 3, 100])
        series = rng.normal(size=n).tolist()
        if n and rng.uniform() < 0.3:
            series = [_pick(rng, [1.0, NAN, INF])] * n
        args = (series,)
        kw["lag"] = _maybe(rng, [1, 2], [0, -1, 10**9, 1.5])
    elif target in ("intervals_from_times", "test_poisson"):
        n = _pick(rng, [0, 1, 5, 200])
        times = np.sort(rng.uniform(0, 100, size=n)).tolist()
        if n and rng.uniform() < 0.3:
            times[-1] = _pick(rng, [NAN, INF, -1.0, 1e300])
        args = (times, _maybe(rng, [100.0, 150.0], [0.0, -1.0, NAN, 50.0, 1e300]))
        if target == "test_poisson":
            kw["n_mc"] = _maybe(rng, [19, 49], [0, -1, 10**9, 2.5], 0.2)
            kw["rng"] = 0
    elif target == "fit_renewal":
        n = _pick(rng, [0, 2, 20, 200])
        iv = rng.exponential(1.0, size=n).tolist()
        if n and rng.uniform() < 0.3:
            iv[0] = _pick(rng, [0.0, -1.0, NAN, INF, 1e300])
        args = (iv, _maybe(rng, ["exponential", "weibull", "gamma", "lognormal"],
                           ["nonsense", 3, None], 0.2))
    elif target == "kinetic_rate":
        args = (_maybe(rng, RADII, BAD_RADII, 0.5),)
        kw["rule"] = _maybe(rng, ["mirror", "elastic"], ["x", None], 0.2)
    elif target == "run_theta":
        args = (_two_ic(rng), 0.05, _maybe(rng, [0, 1, None], [2, -1, "a"], 0.3))
    else:  # kick_file
        n = _pick(rng, [0, 3, 100])
        times = np.sort(rng.uniform(0, 10, size=n)).tolist()
        if n and rng.uniform() < 0.3:
            times[0] = _pick(rng, [NAN, -1.0, 0.0])
        args = (times, _pick(rng, [".csv", ".csv", ".parquet", ".txt"]),
                _maybe(rng, [10.0, None], [-1.0, NAN, 1.0]))
    return target, args, kw


def _run_call(target, args, kw):
    """Execute one call (inside a worker); returns the result object."""
    import tempfile

    import kicktimes as kt
    from kicktimes import diagnostics, schedules, stats

    args = tuple(_materialise(a) for a in args)
    kw = {k: _materialise(v) for k, v in kw.items()}
    if target in ("simulate_one_particle", "lyapunov_one"):
        # the kick law's fields (the spec keeps the flat names) as one KickLaw, built here
        # so that its checks are exercised by the call
        law = {new: kw.pop(old) for old, new in (("kick_angle", "angle"),
                                                 ("kick_angles", "angles"), ("sigma", "sigma"))
               if old in kw}
        if law:
            kw["kicks"] = kt.billiard.KickLaw(kw.pop("kicks", None), **law)
    if target == "initial_conditions":
        return kt.initial_conditions(*args, **kw)
    if target == "simulate_two_particle":
        return kt.simulate_two_particle(*args, **kw)
    if target == "simulate_one_particle":
        return kt.simulate_one_particle(*args, **kw)
    if target == "lyapunov_two":
        kw.pop("t_max", None)
        return diagnostics.lyapunov(*args, **kw)
    if target == "lyapunov_one":
        kw.pop("t_max", None)
        return diagnostics.lyapunov(*args, **kw)
    if target == "schedule_sample":
        kind, param, t_max, seed = args
        if kind == "Poisson":
            sched = schedules.Poisson(param)
        elif kind == "Renewal":
            import scipy.stats as st

            sched = schedules.Renewal(st.gamma(2.0, scale=param))
        elif kind == "Bootstrap":
            sched = schedules.Bootstrap([param, 1.0, 2.0])
        else:
            sched = schedules.Replay([param, 1.0, 2.0], window=param + 5.0)
        return sched.sample(t_max, rng=seed)
    if target == "recurrence_rate":
        return diagnostics.recurrence_rate(*args, **kw)
    if target == "autocorrelation":
        return diagnostics.autocorrelation(*args, **kw)
    if target == "intervals_from_times":
        return stats.intervals_from_times(*args, **kw)
    if target == "test_poisson":
        return stats.test_poisson(*args, **kw)
    if target == "fit_renewal":
        return stats.fit_renewal(*args, **kw)
    if target == "kinetic_rate":
        return stats.kinetic_rate(*args, **kw)
    if target == "run_theta":
        ic, r, particle = args
        return kt.simulate_two_particle(ic, r, t_max=20.0).theta(particle)
    times, suffix, t_max = args
    with tempfile.TemporaryDirectory() as folder:
        path = schedules.write_kick_times(times, os.path.join(folder, "k" + suffix), t_max=t_max)
        return schedules.read_kick_times(path)


# ------------------------------------------------------------------ result checks
def _numbers(obj, depth=0):
    """Every float array or float reachable in a result (dataclasses, tuples, frames)."""
    if depth > 4 or obj is None or isinstance(obj, str | bytes | bool):
        return
    if isinstance(obj, float | int | np.number):
        yield np.asarray(obj, dtype=float)
        return
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind in "fiu":
            yield obj
        return
    if hasattr(obj, "to_numpy") and hasattr(obj, "dtypes"):  # DataFrame
        for col in obj.columns:
            yield from _numbers(obj[col].to_numpy(), depth + 1)
        return
    if isinstance(obj, list | tuple):
        for x in obj:
            yield from _numbers(x, depth + 1)
        return
    if isinstance(obj, dict):
        for x in obj.values():
            yield from _numbers(x, depth + 1)
        return
    fields = getattr(obj, "__dataclass_fields__", None)
    if fields:
        documented = _DOCUMENTED_NAN.get(type(obj).__name__, lambda _: ())(obj)
        for name in fields:
            if name not in documented:
                yield from _numbers(getattr(obj, name, None), depth + 1)


#: fields documented as NaN where they do not apply (not a silent NaN): the paper
#: variant's parts of a 2-norm FTLE, the stretching per perturbation of a run without any
_DOCUMENTED_NAN = {
    "LyapunovResult": lambda res: (("lam_x", "lam_y") if res.variant == "norm" else ())
    + (("lam_per_perturbation",) if res.n_perturbations == 0 else ()),
}


def _run_invariants(run):
    """A message if a billiard run breaks an invariant, else None."""
    rho = 1.0 - run.r
    pos = [np.atleast_2d(run.final_state)[:, :2], np.asarray(run.samples).reshape(-1, 2)]
    for p in pos:
        if p.size and np.hypot(p[:, 0], p[:, 1]).max() > rho + 1e-9:
            return "a centre outside the table"
    t = run.boundary_log.time
    if t.size and (np.diff(t) < 0).any():
        return "boundary times out of order"
    if t.size and (t[0] < 0 or t[-1] > run.t_max * (1 + 1e-12)):
        return "boundary times outside [0, t_max]"
    if not math.isfinite(run.t_max) or run.t_max <= 0:
        return f"t_max = {run.t_max}"
    if hasattr(run, "pp_times"):
        fs = run.final_state
        if math.hypot(fs[0, 0] - fs[1, 0], fs[0, 1] - fs[1, 1]) < 2 * run.r - 1e-9:
            return "disks overlap"
    return None


def classify(target, args, kw):
    """``(outcome, detail)`` of one call."""
    import warnings

    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            result = _run_call(target, args, kw)
    except MemoryError as exc:
        # a MemoryError that names the argument asking for too much is a clear answer
        if str(exc).split(":")[0] in set(kw) | {"n", "n_mc", "t_max", "n_steps"}:
            return "clear-error", f"MemoryError: {exc}"[:300]
        return "memory", f"MemoryError: {exc}"[:300]
    except (ValueError, TypeError) as exc:
        msg = str(exc)
        names = set(kw) | {"ic", "r", "state", "r_max", "n", "system", "points", "series",
                           "times", "t_window", "intervals", "model", "rate", "t_max", "rng",
                           "particle", "path", "dist", "window", "seed", "eps", "lag", "rule",
                           "kicks", "max_events", "mean", "scale"}
        named = any(name in msg for name in names)
        if named and "np.float64(" not in msg and "np.int64(" not in msg:
            return "clear-error", f"{type(exc).__name__}: {msg}"[:300]
        return "unclear-error", f"{type(exc).__name__}: {msg}"[:300]
    except Exception as exc:  # noqa: BLE001 - counting every kind is the point
        return "other-exception", f"{type(exc).__name__}: {exc}"[:300]
    for arr in _numbers(result):
        if arr.dtype.kind == "f" and not np.isfinite(arr).all():
            reason = _stated_reason(result, caught)
            if reason:
                return "explained-nan", f"{type(result).__name__} holds NaN/inf: {reason}"[:300]
            return "non-finite", f"{type(result).__name__} holds NaN/inf"
    if hasattr(result, "boundary_log"):
        bad = _run_invariants(result)
        if bad:
            return "invalid", bad
    return "ok", type(result).__name__


def _stated_reason(result, caught):
    """Why a result holds NaN/inf, if the library said so: a warning it issued, or a
    reason carried by the result (``reason``, ``undefined``, ``warnings``, a ``note``
    column); empty when the NaN is silent."""
    if caught:
        return f"{caught[0].category.__name__}: {caught[0].message}"
    for name in ("reason", "undefined", "warnings"):
        value = getattr(result, name, None)
        if value:
            return f"{name}: {value}"
    note = getattr(result, "get", lambda *_: None)("note")
    if note is not None and note.astype(str).str.len().gt(0).any():
        return "note column"
    return ""


# ------------------------------------------------------------------------- workers
def worker_main(seed, mem_gb):
    import resource

    limit = int(mem_gb * 2**30)
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    out = os.fdopen(os.dup(1), "w", buffering=1)
    sys.stdout = sys.stderr  # the library must not write into the protocol
    import kicktimes as kt
    from kicktimes import diagnostics, schedules, stats  # noqa: F401 - import cost up front

    kt.simulate_two_particle(kt.initial_conditions(1, 0.05, rng=0)[0], 0.05, t_max=1.0)
    out.write("ready\n")
    for line in sys.stdin:
        i = int(line)
        outcome, detail = classify(*_call_spec(seed, i))
        out.write(json.dumps({"i": i, "outcome": outcome, "detail": detail}) + "\n")


class Worker:
    def __init__(self, seed, mem_gb):
        self.proc = subprocess.Popen(
            [sys.executable, os.path.abspath(__file__), "--worker", "--seed", str(seed),
             "--mem-gb", str(mem_gb)],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
            bufsize=1,
        )
        line = self.proc.stdout.readline()
        if line.strip() != "ready":
            raise RuntimeError("fuzz worker failed to start")
        self.i = None
        self.t0 = 0.0

    def submit(self, i):
        self.i = i
        self.t0 = time.monotonic()
        self.proc.stdin.write(f"{i}\n")
        self.proc.stdin.flush()

    def kill(self):
        self.proc.kill()
        self.proc.wait()


def fuzz(n, seed, timeout, workers, mem_gb, progress=True):
    results = {}
    pool = [Worker(seed, mem_gb) for _ in range(workers)]
    todo = list(range(n))[::-1]
    for w in pool:
        if todo:
            w.submit(todo.pop())
    busy = [w for w in pool if w.i is not None]
    while busy:
        ready, _, _ = select.select([w.proc.stdout for w in busy], [], [], 0.2)
        now = time.monotonic()
        for w in list(busy):
            done = False
            if w.proc.stdout in ready:
                line = w.proc.stdout.readline()
                if line:
                    rec = json.loads(line)
                    results[rec["i"]] = (rec["outcome"], rec["detail"])
                else:  # the worker died: out of address space, or killed by the kernel
                    results[w.i] = ("memory", f"worker died (exit {w.proc.wait()})")
                    w.kill()
                    pool[pool.index(w)] = w = Worker(seed, mem_gb)
                done = True
            elif now - w.t0 > timeout:
                results[w.i] = ("timeout", f"> {timeout:g} s")
                w.kill()
                pool[pool.index(w)] = w = Worker(seed, mem_gb)
                done = True
            if done:
                w.i = None
                if todo:
                    w.submit(todo.pop())
                busy = [b for b in pool if b.i is not None]
                if progress:
                    print(f"\r{len(results)}/{n}", end="", file=sys.stderr)
    for w in pool:
        w.kill()
    if progress:
        print(file=sys.stderr)
    return results


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=500)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=10.0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--mem-gb", type=float, default=4.0)
    ap.add_argument("--show", action="append", default=[],
                    help="print the calls with this outcome (repeatable)")
    ap.add_argument("--json", help="write {i: [target, outcome, detail]} here")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        worker_main(args.seed, args.mem_gb)
        return
    t0 = time.monotonic()
    results = fuzz(args.n, args.seed, args.timeout, args.workers, args.mem_gb)
    import kicktimes

    targets = {i: _call_spec(args.seed, i)[0] for i in results}
    counts = collections.Counter(outcome for outcome, _ in results.values())
    print(f"kicktimes from {os.path.dirname(kicktimes.__file__)}; {args.n} calls, seed "
          f"{args.seed}, timeout {args.timeout:g} s, {time.monotonic() - t0:.0f} s wall")
    for outcome in OUTCOMES:
        print(f"  {outcome:16s} {counts.get(outcome, 0):5d}")
    by_target = collections.defaultdict(collections.Counter)
    for i, (outcome, _) in results.items():
        by_target[targets[i]][outcome] += 1
    print("  bad outcomes by target:")
    for target in sorted(by_target):
        bad = {k: v for k, v in by_target[target].items() if k not in ("ok", "clear-error")}
        if bad:
            print(f"    {target:24s} {dict(sorted(bad.items()))}")
    for i in sorted(results):
        outcome, detail = results[i]
        if outcome in args.show:
            target, a, kw = _call_spec(args.seed, i)
            print(f"[{i}] {outcome} {target}{tuple(a)!r:.200} {kw!r:.200}\n      {detail}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({i: [targets[i], *results[i]] for i in sorted(results)}, fh, indent=1)


if __name__ == "__main__":
    main()

"""Golden outputs of the billiard simulators: case list, dump and bit-for-bit comparison.

The kernels are optimised without changing a single bit of their output; this script
records the outputs of ~50 varied runs (both rules, all samplings, radii 0.005-0.3,
uniform/gaussian/scatter kicks) and compares later code against them.

Usage (from the repository root, with ``PYTHONPATH=$PWD``)::

    python tests/data/kernel_cases.py dump /tmp/kern_ref.npz          # record
    python tests/data/kernel_cases.py check /tmp/kern_ref.npz         # compare (exit 1 if not)
    python tests/data/kernel_cases.py dump tests/data/kernels_golden.npz --small

``--lyapunov`` adds the FTLE kernels (tangent, twin, one pass with its continuation,
spectrum) on the same kinds of runs: a same-machine reference for a change to the event
loops (not stored: their chaotic outputs are bitwise only on one machine).
"""

from __future__ import annotations

import sys

import numpy as np

from kicktimes.billiard import KickLaw
from kicktimes.diagnostics import Tangent, Twin


def _two_cases(small: bool):
    from kicktimes import initial_conditions

    n = 60 if small else 1500
    cases = []
    for i, r in enumerate((0.005, 0.01, 0.03, 0.1, 0.2, 0.3)):
        for rule in ("mirror", "elastic"):
            method = "paper" if rule == "mirror" and i % 2 == 0 else "uniform"
            ic = initial_conditions(1, r, rng=100 + i, method=method, rule=rule)[0]
            track = i % 2
            cases.append((f"two_{rule}_{r}_uniform", ic, r,
                          dict(rule=rule, n_steps=n, tau=0.3, track=track)))
            cases.append((f"two_{rule}_{r}_paper", ic, r,
                          dict(rule=rule, n_steps=n, tau=0.3, sampling="paper", track=1 - track)))
            if i % 2 == 0:
                cases.append((f"two_{rule}_{r}_none_log", ic, r,
                              dict(rule=rule, t_max=0.2 * n, log_collisions=True)))
    return cases


def _one_cases(small: bool):
    from kicktimes import initial_conditions, schedules

    n = 60 if small else 1500
    cases = []
    for i, r in enumerate((0.005, 0.02, 0.1, 0.3)):
        state = initial_conditions(1, r, rng=200 + i)[0, 0]
        for law, extra in (("uniform", {}), ("gaussian", {"sigma": 0.3}),
                           ("scatter", {"rule": "mirror"}), ("scatter", {"rule": "elastic"})):
            for sampling in ("uniform", "paper"):
                kw = dict(kicks=KickLaw(schedules.Poisson(0.5), angle=law, **extra),
                          rng=10 * i + len(cases), n_steps=n, tau=0.3, sampling=sampling)
                cases.append((f"one_{r}_{law}_{extra.get('rule', '')}_{sampling}", state, r, kw))
        cases.append((f"one_{r}_free", state, r, dict(t_max=0.2 * n)))
    return cases


def outputs(small: bool = False) -> dict[str, np.ndarray]:
    """Every array a run returns, keyed ``case/field``."""
    from kicktimes import simulate_one_particle, simulate_two_particle

    out = {}
    for name, ic, r, kw in _two_cases(small):
        run = simulate_two_particle(ic, r, **kw)
        out.update(_fields(name, run, ("pp_times", "pp_log")))
    for name, state, r, kw in _one_cases(small):
        run = simulate_one_particle(state, r, **kw)
        out.update(_fields(name, run, ("kick_times", "kick_angles", "kick_log_array")))
    return out


def lyapunov_outputs(small: bool = False) -> dict[str, np.ndarray]:
    """Every number the FTLE kernels return, keyed ``case/field``."""
    from kicktimes import initial_conditions, schedules
    from kicktimes.diagnostics import lyapunov, lyapunov_spectrum
    from kicktimes.diagnostics.lyapunov import lyapunov_pass

    n = 60 if small else 1500
    out = {}

    def put(name, res):
        for key, val in res.__dict__.items():
            if isinstance(val, int | float | np.ndarray) and not isinstance(val, bool):
                out[f"{name}/{key}"] = np.asarray(val)

    for name, ic, r, kw in _two_cases(small):
        if "t_max" in kw:
            continue
        kw = {k: v for k, v in kw.items() if k != "log_collisions"}
        for method, variant in (("tangent", "norm"), ("tangent", "paper"), ("twin", "paper")):
            how = Twin(d0=1e-8, variant=variant) if method == "twin" else Tangent(variant=variant)
            put(f"{name}/{method}_{variant}", lyapunov(ic, r, method=how, **kw))
        if kw.get("sampling") == "paper":
            res, run, pp = lyapunov_pass(ic, r, t_continue=0.5 * n, **kw)
            put(f"{name}/pass", res)
            out.update(_fields(f"{name}/pass_run", run, ("pp_times",)))
            out[f"{name}/pass_pp"] = np.asarray(pp)
    for name, state, r, kw in _one_cases(small):
        if "t_max" in kw:
            continue
        for method in ("tangent", "twin"):
            how = Twin(d0=1e-8) if method == "twin" else "tangent"
            put(f"{name}/{method}", lyapunov(state, r, method=how, **kw))
        res, run = lyapunov(state, r, method=Tangent(return_run=True), **kw)
        put(f"{name}/pass", res)
        out.update(_fields(f"{name}/pass_run", run, ("kick_times", "kick_log_array")))
    for i, rule in enumerate(("mirror", "elastic")):
        r = 0.05
        ic = initial_conditions(1, r, rng=300 + i, method="uniform", rule=rule)[0]
        put(f"spectrum_{rule}", lyapunov_spectrum(ic, r, t_max=0.1 * n, rule=rule))
    del schedules
    return out


def _fields(name, run, extra):
    d = {f"{name}/{k}": np.asarray(v) for k, v in run.boundary_log._asdict().items()}
    d[f"{name}/sample_times"] = run.sample_times
    d[f"{name}/samples"] = run.samples
    d[f"{name}/final_state"] = run.final_state
    d[f"{name}/t_max"] = np.array(run.t_max)
    for k in extra:
        d[f"{name}/{k}"] = np.asarray(getattr(run, k))
    return d


def differences(ref: dict[str, np.ndarray], new: dict[str, np.ndarray]) -> list[str]:
    """Keys whose arrays differ in shape, dtype or any bit (NaN equal to NaN)."""
    bad = sorted(set(ref) ^ set(new))
    for key in sorted(set(ref) & set(new)):
        a, b = ref[key], new[key]
        if a.shape != b.shape or a.dtype != b.dtype or a.tobytes() != b.tobytes():
            bad.append(key)
    return bad


def save(path, arrays: dict[str, np.ndarray]) -> None:
    """Write ``arrays`` as one packed float64 blob (a zip member per array would cost
    ~300 bytes each, more than the data of the small cases)."""
    keys = sorted(arrays)
    flat = [np.asarray(arrays[k]) for k in keys]
    np.savez_compressed(
        path,
        keys=np.array(keys),
        dtypes=np.array([a.dtype.str for a in flat]),
        shapes=np.array([",".join(map(str, a.shape)) for a in flat]),
        data=np.concatenate([a.astype(np.float64).ravel() for a in flat]),
    )


def load(path) -> dict[str, np.ndarray]:
    """The arrays written by `save` (the int8 particle column round-trips exactly)."""
    with np.load(path) as f:
        keys, dtypes, shapes, data = f["keys"], f["dtypes"], f["shapes"], f["data"]
    out, pos = {}, 0
    for key, dt, sh in zip(keys, dtypes, shapes, strict=True):
        shape = tuple(int(s) for s in str(sh).split(",") if s)
        n = int(np.prod(shape))
        out[str(key)] = data[pos:pos + n].astype(np.dtype(str(dt))).reshape(shape)
        pos += n
    return out


def main(argv):
    action, path = argv[0], argv[1]
    small = "--small" in argv

    def everything(small):
        out = outputs(small)
        if "--lyapunov" in argv:
            out.update(lyapunov_outputs(small))
        return out

    if action == "dump":
        out = everything(small)
        save(path, out)
        print(f"{len(out)} arrays written to {path}")
        return 0
    ref = load(path)
    small = small or "golden" in path
    bad = differences(ref, everything(small))
    print(f"{len(ref)} arrays compared: {len(bad)} differ" + (": " + ", ".join(bad[:20])
                                                               if bad else ""))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

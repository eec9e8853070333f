"""Every event-loop driver of the kernel layer, timed against a previous commit in one process.

One workload per driver, on the issue-13 setting (r = 0.01, tau = 0.3, 15 000 steps, paper
ICs): the two-disk simulation (mirror/uniform, elastic/paper, with the collision log), the
kicked disk (Poisson kicks with uniform angles, scattering kicks), the tangent FTLE of both
systems (uniform and paper steps), the twin FTLE of both, the one pass (simulation + FTLE:
two-disk with its continuation, kicked disk with uniform angles and with scattering kicks)
and the Lyapunov spectrum.

``--baseline REV`` (default ``HEAD``) extracts the package at commit ``REV`` with ``git
archive``, renamed ``kt_baseline`` so that both import side by side, and times each driver
on the working tree and on the baseline *interleaved in this process*: the ratio is immune
to the load of a shared machine drifting between runs. Each figure is CPU seconds
(``time.process_time``), the minimum over ``--repeat`` rounds.

Run: python benchmarks/bench_kernels.py [--baseline HEAD~3] [--n-ics 20] [--repeat 30]
     python benchmarks/bench_kernels.py --only "pass one scatter" "ftle two twin"
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
import time
from importlib import import_module
from pathlib import Path


def workloads(pkg: str, n_ics: int):
    """``{name: callable}`` for the package ``pkg``: one call runs a driver on every IC."""
    kt = import_module(pkg)
    kicks = import_module(pkg + ".schedules").Poisson(0.1)
    diag = import_module(pkg + ".diagnostics")
    lyapunov_pass = import_module(pkg + ".diagnostics.lyapunov").lyapunov_pass
    sim2, sim1, lyap = kt.simulate_two_particle, kt.simulate_one_particle, diag.lyapunov
    r, tau, n = 0.01, 0.3, 15000
    ics = kt.initial_conditions(n_ics, r, rng=2026, method="paper")
    el = kt.initial_conditions(n_ics, r, rng=2026, method="uniform", rule="elastic")
    few = ics[: max(1, n_ics // 4)]
    one = {"n_steps": n, "tau": tau, "kicks": kicks}
    billiard = import_module(pkg + ".billiard")
    if hasattr(billiard, "KickLaw"):  # kicktimes >= 0.2: the kick law and the method as values
        scatter = {**one, "kicks": billiard.KickLaw(kicks, angle="scatter"), "sampling": "paper"}
        twin_paper, with_run = {"method": diag.Twin(variant="paper")}, {
            "method": diag.Tangent(return_run=True)}
    else:  # a baseline before 0.2.0: the flat keywords
        scatter = {**one, "kick_angle": "scatter", "sampling": "paper"}
        twin_paper, with_run = {"method": "twin", "variant": "paper"}, {"return_run": True}

    def each(fn, items):
        return lambda: [fn(i, x) for i, x in enumerate(items)]

    return {
        "two mirror uniform": each(lambda i, ic: sim2(ic, r, n_steps=n, tau=tau), ics),
        "two elastic paper": each(lambda i, ic: sim2(ic, r, n_steps=n, tau=tau, rule="elastic",
                                                     sampling="paper"), el),
        "two collision log": each(lambda i, ic: sim2(ic, r, t_max=n * tau,
                                                     log_collisions=True), ics),
        "one poisson uniform": each(lambda i, ic: sim1(ic[0], r, rng=i, **one), ics),
        "one scatter paper": each(lambda i, ic: sim1(ic[0], r, rng=i, **scatter), ics),
        "ftle two tangent": each(lambda i, ic: lyap(ic, r, n_steps=n, tau=tau), ics),
        "ftle two paper": each(lambda i, ic: lyap(ic, r, n_steps=n, tau=tau, sampling="paper"),
                               ics),
        "ftle one tangent": each(lambda i, ic: lyap(ic[0], r, rng=i, **one), ics),
        "ftle two twin": each(lambda i, ic: lyap(ic, r, n_steps=n, tau=tau, **twin_paper), few),
        "ftle one twin": each(lambda i, ic: lyap(ic[0], r, rng=i, method="twin", **one), few),
        "pass two paper": each(lambda i, ic: lyapunov_pass(
            ic, r, n_steps=n, tau=tau, sampling="paper", t_continue=1.2 * n * tau), ics),
        "pass one uniform": each(lambda i, ic: lyap(ic[0], r, rng=i, **with_run, **one), ics),
        "pass one scatter": each(lambda i, ic: lyap(ic[0], r, rng=i, **with_run, **scatter),
                                 ics),
        "spectrum two": each(lambda i, ic: diag.lyapunov_spectrum(ic, r, t_max=n * tau / 4),
                             few),
    }


def baseline_package(rev: str) -> str:
    """Extract ``kicktimes`` at commit ``rev`` as the package ``kt_baseline`` in a temporary
    folder put on ``sys.path``; returns its name."""
    root = Path(tempfile.mkdtemp(prefix="kt_baseline_"))
    repo = Path(__file__).resolve().parent.parent
    tar = subprocess.run(["git", "-C", str(repo), "archive", rev, "kicktimes"], check=True,
                         capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(root)], input=tar, check=True)
    (root / "kicktimes").rename(root / "kt_baseline")
    for path in (root / "kt_baseline").rglob("*.py"):
        text = path.read_text()
        path.write_text(re.sub(r"\bkicktimes\b", "kt_baseline", text))
    sys.path.insert(0, str(root))
    return "kt_baseline"


def compare(rev: str, n_ics: int, repeat: int, only=None) -> None:
    new = workloads("kicktimes", n_ics)
    old = workloads(baseline_package(rev), n_ics)
    if only:
        new = {name: fn for name, fn in new.items() if name in only}
    print(f"{n_ics} ICs, r = 0.01, tau = 0.3, 15 000 steps; CPU ms, min of {repeat} rounds, "
          f"baseline {rev} and working tree interleaved in one process")
    print(f"{'driver':22s} {'baseline':>9s} {'now':>9s} {'now / base':>10s}")
    for name in new:
        old[name]()  # compile, or load from the numba cache
        new[name]()
        best = [float("inf"), float("inf")]
        for _ in range(repeat):
            for i, fn in enumerate((old[name], new[name])):
                t0 = time.process_time()
                fn()
                best[i] = min(best[i], time.process_time() - t0)
        print(f"{name:22s} {best[0] * 1e3:9.3f} {best[1] * 1e3:9.3f} {best[1] / best[0]:10.3f}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--baseline", default="HEAD", help="the commit to compare against")
    ap.add_argument("--n-ics", type=int, default=20)
    ap.add_argument("--repeat", type=int, default=30)
    ap.add_argument("--only", nargs="+", metavar="DRIVER", help="time only these drivers")
    args = ap.parse_args()
    compare(args.baseline, args.n_ics, args.repeat, args.only)


if __name__ == "__main__":
    main()

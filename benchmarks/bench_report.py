"""Speed of the report (kicktimes.report): its exact KS kernel and the whole build.

Run: ``python benchmarks/bench_report.py [--stores A B] [--skip-renewal] [--sequences 2000]
[--load-only]``

1. Exact two-sided KS p-values of the Poisson tests' uniformity test on an ensemble of
   sequences of 5..140 events (the range where scipy's law runs the Pomeranz recursion in
   Python); reference: ``scipy.stats.ks_1samp(..., method="exact")`` on the same rows,
   same run (what the report called before).
2. ``build_report`` of the given stores (default: a small two-family sweep built here),
   ``force=True``, with ``workers=1`` (the reference: everything in one process) and
   ``workers=2``, same run: wall and CPU seconds (this process and its children), and the
   report's stage table of the parallel build. ``--skip-renewal`` leaves out the renewal
   model fits (their own benchmark is ``bench_stats.py``).
3. Figure rendering: the same builds (``workers=1``) with ``savefig`` (two draws per
   figure: a layout pass, then the real one) and with the report's one Agg draw,
   alternating, rendering seconds summed per build; the PNG bytes are compared.
4. Pools inside the parts against the report's rule, alternating.
5. Reading a store as the report does, ``load_report_store`` (``system``/``diagnostic``
   read as Parquet dictionaries, no ``note``), against the former
   ``report_store(load_store(path))`` (Arrow strings, converted afterwards), alternating,
   the frames checked equal first. ``--load-only`` runs this section only.

Wall times depend on what else runs on the machine: the load average is printed, and the
CPU seconds are the figure to compare between runs on a busy machine.
"""

from __future__ import annotations

import argparse
import os
import resource
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy.stats


def cpu_seconds():
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def bench_ks(n_sequences, rng):
    from kicktimes.stats.poisson import pomeranz_cdf, uniformity_ks

    pomeranz_cdf(10, 0.3)  # load the compiled kernel outside the timing
    counts = rng.integers(5, 141, n_sequences)
    rows = {
        n: np.sort(rng.uniform(size=(int((counts == n).sum()), n)), axis=1) for n in set(counts)
    }
    start = time.perf_counter()
    ref = [
        scipy.stats.ks_1samp(u, scipy.stats.uniform.cdf, axis=-1, method="exact")
        for u in rows.values()
    ]
    t_ref = time.perf_counter() - start
    start = time.perf_counter()
    new = [uniformity_ks(u) for u in rows.values()]
    t_new = time.perf_counter() - start
    err = max(float(np.max(np.abs(r.pvalue - p))) for r, (_, p) in zip(ref, new, strict=True))
    print(f"exact KS p-values: {n_sequences} sequences of 5..140 events ({len(rows)} distinct n)")
    print(f"  reference scipy ks_1samp(method='exact')  {t_ref:8.3f} s")
    print(
        f"  kicktimes uniformity_ks (compiled)        {t_new:8.3f} s   ratio {t_ref / t_new:6.1f}x"
    )
    print(f"  largest |p - p_scipy|                     {err:8.1e}")


def small_stores(root):
    from kicktimes.experiment import Experiment, run_experiment

    paths = []
    for name, n_ics in (("bench_a", 8), ("bench_b", 16)):
        exp = Experiment(
            name=name,
            radii=[0.01, 0.015, 0.02, 0.025],
            n_ics=n_ics,
            n_steps=3000,
            tau=0.3,
            diagnostics=["lyapunov", "recurrence_rate", "autocorrelation"],
        )
        path = root / f"store-{name}"
        run_experiment(exp, path, workers=2, progress=False)
        paths.append(path)
    return paths


def bench_build(paths, out_root, skip_renewal):
    import pandas as pd

    from kicktimes.report import build_report, renewal

    if skip_renewal:  # forked workers inherit the stub
        renewal.sections = lambda ctx: []
        renewal.effects = lambda ctx: []
    result = {}
    for workers in (1, 2):
        out = out_root / f"report-w{workers}"
        c0, t0 = cpu_seconds(), time.perf_counter()
        build_report(paths, out, workers=workers, force=True, progress=False)
        result[workers] = (time.perf_counter() - t0, cpu_seconds() - c0, out)
    print(
        f"build_report of {len(paths)} stores (force=True; renewal fits "
        f"{'skipped' if skip_renewal else 'included'}), load average {os.getloadavg()[0]:.1f}"
    )
    print(f"  {'':32}{'wall (s)':>10}{'CPU (s)':>10}")
    for workers, (wall, cpu, _) in result.items():
        label = "workers=1 (reference)" if workers == 1 else f"workers={workers}"
        print(f"  {label:32}{wall:>10.1f}{cpu:>10.1f}")
    print(f"  parallel speed-up (wall)        {result[1][0] / result[2][0]:>10.2f}x")
    same = all(
        (result[1][2] / f.name).read_bytes() == f.read_bytes()
        for f in result[2][2].glob("*.csv")
        if "timings" not in f.name
    )
    print(f"  CSV tables identical for workers=1 and 2: {same}")
    table = pd.read_csv(result[2][2] / "report_timings.csv").fillna({"experiment": "-"})
    print("  stage seconds of the workers=2 build (parts run at the same time):")
    print(
        table.pivot_table(
            index="stage", columns="experiment", values="seconds", aggfunc="sum", sort=False
        )
        .round(2)
        .to_string()
    )


def bench_render(paths, out_root, rounds=2):
    """The report's figures drawn by ``savefig`` (two draws: a layout pass, then the real
    one) against one Agg draw (`kicktimes.render.html._png`): builds of the same stores
    with ``workers=1``, alternating, summing each build's rendering time; the PNG bytes
    of the two methods are compared."""
    import io

    from kicktimes.render import html
    from kicktimes.report import build_report

    one_draw = html._png

    def savefig(fig, dpi):
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=dpi)
        return buf.getvalue()

    seconds = {"savefig": [], "one draw": []}
    pngs = {}
    try:
        for k in range(rounds):
            for name, fun in (("savefig", savefig), ("one draw", one_draw)):
                spent, out = [0.0], []

                def timed(fig, dpi, fun=fun, spent=spent, out=out):
                    t0 = time.perf_counter()
                    png = fun(fig, dpi)
                    spent[0] += time.perf_counter() - t0
                    out.append(png)
                    return png

                html._png = timed
                build_report(paths, out_root / f"render-{k}", force=True, workers=1)
                seconds[name].append(spent[0])
                pngs[name] = out
    finally:
        html._png = one_draw
    n = len(pngs["one draw"])
    same = pngs["savefig"] == pngs["one draw"]
    print()
    print(f"figure rendering: {n} figures, builds with workers=1, {rounds} alternating rounds")
    for name, values in seconds.items():
        print(f"  {name:<10} " + "  ".join(f"{v:6.2f} s" for v in values))
    best = {name: min(values) for name, values in seconds.items()}
    print(f"  savefig / one draw (best of each): {best['savefig'] / best['one draw']:.2f}x;"
          f" PNG bytes identical: {same}")


def bench_inner(paths, out_root, rounds=3):
    """Nested pools (each part's own pools as wide as the machine) against
    `pipeline._inner_workers`, ``workers=2``, alternating."""
    from kicktimes.report import build_report, pipeline

    rule = pipeline._inner_workers
    chosen = rule(2, [pipeline._read_manifest(p) for p in paths])
    runs = {"inner pools": [], "rule": []}
    try:
        for k in range(rounds):
            for name in runs:
                pipeline._inner_workers = (lambda w, m: w) if name == "inner pools" else rule
                c0, t0 = cpu_seconds(), time.perf_counter()
                build_report(paths, out_root / f"inner-{k}", force=True, workers=2,
                             progress=False)
                runs[name].append((time.perf_counter() - t0, cpu_seconds() - c0))
    finally:
        pipeline._inner_workers = rule
    print()
    print(f"pools inside the parts, workers=2, {rounds} alternating rounds "
          f"(the rule gives inner = {chosen} for these stores)")
    for name, values in runs.items():
        print(f"  {name:<12} wall " + "  ".join(f"{w:6.2f}" for w, _ in values)
              + "   CPU " + "  ".join(f"{c:6.2f}" for _, c in values))


def bench_load(paths, rounds=7):
    """`load_report_store` against ``report_store(load_store(path))``, alternating."""
    import pandas as pd

    from kicktimes.experiment import load_store
    from kicktimes.report.store import load_report_store, report_store

    def former(path):
        return report_store(load_store(path))

    print()
    print(f"reading a store as the report does, {rounds} alternating rounds (min / median, s)")
    for path in paths:
        a, b = former(path), load_report_store(path)  # also warms the imports
        pd.testing.assert_frame_equal(a.results, b.results, check_exact=True)
        pd.testing.assert_frame_equal(a.collisions, b.collisions, check_exact=True)
        times = {"former": [], "load_report_store": []}
        for _ in range(rounds):
            for name, fn in (("former", former), ("load_report_store", load_report_store)):
                t0 = time.perf_counter()
                fn(path)
                times[name].append(time.perf_counter() - t0)
        old, new = (np.array(times[k]) for k in times)
        print(f"  {Path(path).name:<24} {len(b.results):>9} rows: former "
              f"{old.min():6.3f} / {np.median(old):6.3f}, load_report_store "
              f"{new.min():6.3f} / {np.median(new):6.3f}  ({old.min() / new.min():.2f}x)")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stores", nargs="+", type=Path, default=None, help="stores to report")
    parser.add_argument("--skip-renewal", action="store_true", help="leave out renewal fits")
    parser.add_argument("--sequences", type=int, default=2000, help="KS benchmark sequences")
    parser.add_argument("--load-only", action="store_true", help="only section 5 (store loading)")
    args = parser.parse_args()
    if args.load_only:
        with tempfile.TemporaryDirectory() as tmp:
            bench_load(args.stores if args.stores else small_stores(Path(tmp)))
        return
    bench_ks(args.sequences, np.random.default_rng(2024))
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        paths = args.stores if args.stores else small_stores(tmp)
        bench_build(paths, tmp, args.skip_renewal)
        bench_render(paths, tmp)
        bench_inner(paths, tmp)
        bench_load(paths)


if __name__ == "__main__":
    main()

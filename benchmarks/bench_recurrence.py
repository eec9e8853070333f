"""Benchmark: recurrence rate (cell list, numba) against cKDTree and brute force; RQA cost.

Run as ``python benchmarks/bench_recurrence.py [--quick] [--max-n N] [--rqa-only]``.

Point sets: a billiard-like trajectory (a point particle in the unit disk, straight
chords sampled every tau = 0.2, direction redrawn at every wall hit, so the chords fill
the disk as a kicked trajectory does) and points uniform in the unit disk; eps = 1e-3.

References, measured in the same run:
* ``scipy.spatial.cKDTree(points).count_neighbors(tree, eps)`` (build + count; the count
  of ordered pairs including the diagonal, i.e. N^2 RR) and the count alone;
* brute force with numpy (row blocks of the distance matrix) at a smaller N, scaled by
  (N / n_small)^2.
Then the scaling of our code to N = 10^6 and 10^7 with its extra peak memory (growth
of the peak resident set during the call, each N in a fresh process), and the same for
``rqa`` with its defaults (laminarity included) at N = 10^5 and 10^6.

RQA (``rqa``: the recurrent pairs kept as sorted rows, then the line statistics) against
``recurrence_rate`` of the same points in the same run, N = 25 000, eps = 1e-3 and 1e-2,
for both point sets and for a paper-sampled billiard run (the sweep's input); the sweep's
call on its dense grid against the sorted occupied cells; and its line kernels against
the former ones (a loop per point over its recurrent pairs, every line walked; copied
here as the reference).
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time

import numpy as np
from numba import njit
from scipy.spatial import cKDTree

from kicktimes.diagnostics import recurrence_rate, rqa
from kicktimes.diagnostics._recurrence_kernels import _add_line, _cell_keys, _recurrent


@njit(cache=True)
def kicked_chords(n, tau, seed):
    """Centre of a point particle in the unit disk sampled at k * tau, k = 0..n-1."""
    # numba's own generator: the legacy API is the one it supports inside njit code
    np.random.seed(seed)  # noqa: NPY002
    x, y = 0.3, -0.2
    a = np.random.uniform(0.0, 2.0 * np.pi)  # noqa: NPY002
    vx, vy = np.cos(a), np.sin(a)
    pts = np.empty((n, 2))
    t = 0.0
    k = 0
    while k < n:
        b = x * vx + y * vy
        dt = -b + np.sqrt(b * b - (x * x + y * y) + 1.0)
        while k < n and k * tau <= t + dt:
            s = k * tau - t
            pts[k, 0] = x + s * vx
            pts[k, 1] = y + s * vy
            k += 1
        x += dt * vx
        y += dt * vy
        t += dt
        # new inward direction, uniform within the half-plane facing the centre
        a = np.arctan2(y, x) + np.pi + np.random.uniform(-0.5 * np.pi, 0.5 * np.pi)  # noqa: NPY002
        vx, vy = np.cos(a), np.sin(a)
    return pts


def uniform_disk(n, seed):
    rng = np.random.default_rng(seed)
    r = np.sqrt(rng.uniform(size=n))
    a = rng.uniform(0.0, 2.0 * np.pi, n)
    return np.column_stack([r * np.cos(a), r * np.sin(a)])


def timeit(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), statistics.median(times), out


def brute_count(pts, eps, block=1024):
    eps2 = eps * eps
    total = 0
    for lo in range(0, len(pts), block):
        p = pts[lo : lo + block]
        dx = p[:, None, 0] - pts[None, :, 0]
        dy = p[:, None, 1] - pts[None, :, 1]
        total += int(np.count_nonzero(dx * dx + dy * dy <= eps2))
    return total


def scaling_row(size, eps, flag="--child"):
    """Time and extra peak memory of one N, measured in a fresh process (``flag``:
    ``--child`` for `recurrence_rate`, ``--child-rqa`` for `rqa`)."""
    out = subprocess.run(
        [sys.executable, __file__, flag, str(size), "--eps", repr(eps)],
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def first_call(fn):
    """``(result, seconds, extra peak bytes)`` of ``fn()``: the kernel's peak-RSS mark
    (VmHWM) is reset to the current RSS just before the call (``/proc/self/clear_refs``),
    so its growth is the extra peak memory of the call."""
    with open("/proc/self/clear_refs", "w") as fh:
        fh.write("5")
    before = _status_kb("VmRSS")
    t0 = time.perf_counter()
    out = fn()
    dt = time.perf_counter() - t0
    return out, dt, (_status_kb("VmHWM") - before) * 1024


def child_rqa(size, eps):
    """`rqa(points, eps)` with its defaults (laminarity included) on the chords: the time
    (min of a first call and 2 more) and the peak RSS the first call added."""
    rqa(uniform_disk(300, 0), eps=eps)  # load the kernels of this grid outside the timing
    pts = kicked_chords(size, 0.2, 3)
    res, dt, extra = first_call(lambda: rqa(pts, eps=eps))
    dt = min(dt, timeit(lambda: rqa(pts, eps=eps), 2)[0])
    print(json.dumps({"n": size, "pairs": res.n_recurrent // 2, "lam": res.lam,
                      "time": dt, "extra_bytes": extra}))


def rqa_scaling(sizes):
    """rqa() with laminarity at large N, each N and eps in a fresh process."""
    print()
    print("rqa(points, eps) with its defaults (laminarity included), chords, each N in a fresh")
    print("process: time (min of 3) and peak RSS added by the call")
    header = (
        f"{'N':>10} {'eps':>6} {'pairs':>11} {'LAM':>7} {'time [s]':>9} {'mem [MB]':>9} "
        f"{'B/point':>8}"
    )
    print(header)
    print("-" * len(header))
    for size in sizes:
        for eps in (1e-3, 1e-2):
            row = scaling_row(size, eps, "--child-rqa")
            mem = row["extra_bytes"]
            print(f"{size:>10} {eps:6g} {row['pairs']:>11} {row['lam']:7.4f} {row['time']:9.3f} "
                  f"{mem / 2**20:9.1f} {mem / size:8.1f}")


def _status_kb(field):
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    raise RuntimeError(f"{field} not in /proc/self/status")


def child(size, eps):
    """Generate the points, then report RR, its time, and the peak RSS it added
    (`first_call`)."""
    recurrence_rate(uniform_disk(100, 0), eps=eps)
    pts = kicked_chords(size, 0.2, 3)
    rr, dt, extra = first_call(lambda: recurrence_rate(pts, eps=eps))
    row = {"n": size, "rr": rr, "time": dt, "extra_bytes": extra}
    if size <= 10**6:
        row["time"] = min(dt, timeit(lambda: recurrence_rate(pts, eps=eps), 5)[0])
        k_dt, _, count = timeit(lambda: (lambda tr: tr.count_neighbors(tr, eps))(cKDTree(pts)), 1)
        assert count == round(rr * size * size)
        row["kdtree_time"] = k_dt
    print(json.dumps(row))


def paper_run_samples(n_steps):
    """Disk 0's samples of a paper-sampled two-disk run (family A: r = 0.02, tau = 0.2)."""
    from kicktimes import initial_conditions, simulate_two_particle

    ic = initial_conditions(1, 0.03, rng=1)[0]
    return simulate_two_particle(ic, 0.02, sampling="paper", n_steps=n_steps, tau=0.2).samples


def rqa_table(rep):
    """rqa (Theiler 1) against recurrence_rate of the same points, same run."""
    n = 25_000
    sets = [
        ("trajectory", kicked_chords(n, 0.2, 1)),
        ("uniform", uniform_disk(n, 2)),
        ("paper run", paper_run_samples(n - 1)),
    ]
    rqa(uniform_disk(100, 0), eps=1e-3)  # compile / load the cache outside timings
    print(f"RQA against the recurrence rate, N = {n}  (min / median of {rep} runs)")
    header = (
        f"{'point set':<11} {'eps':>6} {'RR offdiag':>11} {'DET':>6} {'Lmax':>5} "
        f"{'RR [ms]':>15} {'RQA [ms]':>15} {'RQA / RR':>9} {'+LAM [ms]':>10} {'ratio':>6}"
    )
    print(header)
    print("-" * len(header))
    for name, pts in sets:
        for eps in (1e-3, 1e-2):
            r_min, r_med, _ = timeit(lambda p=pts, e=eps: recurrence_rate(p, eps=e), rep)
            q_min, q_med, res = timeit(lambda p=pts, e=eps: rqa(p, eps=e, laminarity=False), rep)
            lam_min, _, _ = timeit(lambda p=pts, e=eps: rqa(p, eps=e), rep)
            assert res.rr == recurrence_rate(pts, eps=eps, theiler=1)
            print(
                f"{name:<11} {eps:6g} {res.rr:11.3e} {res.det:6.3f} {res.l_max:5d} "
                f"{r_min * 1e3:7.3f} / {r_med * 1e3:5.3f} {q_min * 1e3:7.3f} / "
                f"{q_med * 1e3:5.3f} {q_min / r_min:9.1f} {lam_min * 1e3:10.3f} "
                f"{lam_min / r_min:6.1f}"
            )
    print("RQA = rqa(laminarity=False), as in the sweep; +LAM = rqa() with laminarity")
    grid_table(sets, rep)
    batch_table(sets, rep)


def grid_table(sets, rep):
    """The sweep's call, rqa(points, [1e-3, 1e-2]), on the dense grid it takes against the
    radix-sorted occupied cells (the former path, forced), same points, same run."""
    from kicktimes.diagnostics import recurrence

    print()
    print(f"The sweep's rqa(points, [1e-3, 1e-2]): dense grid against sorted occupied cells "
          f"(min / median of {rep} runs)")
    header = f"{'point set':<11} {'sorted cells [ms]':>18} {'dense grid [ms]':>16} {'speed-up':>9}"
    print(header)
    print("-" * len(header))
    saved = recurrence._DENSE_CELLS_PER_POINT, recurrence._DENSE_CELLS_MIN
    for name, pts in sets:
        def call(p=pts):
            return rqa(p, eps=[1e-3, 1e-2], laminarity=False)

        d_min, d_med, dense = timeit(call, rep)
        recurrence._DENSE_CELLS_PER_POINT, recurrence._DENSE_CELLS_MIN = 0, 0
        try:
            s_min, s_med, sparse = timeit(call, rep)
        finally:
            recurrence._DENSE_CELLS_PER_POINT, recurrence._DENSE_CELLS_MIN = saved
        assert dense == sparse
        print(f"{name:<11} {s_min * 1e3:8.3f} / {s_med * 1e3:7.3f} {d_min * 1e3:7.3f} / "
              f"{d_med * 1e3:6.3f} {s_min / d_min:9.2f}")


# ----------------------------------------------------------------- the former line sweep
# The reference of `batch_table`: the dense-grid build and line sweep as they were before
# the recurrent pairs were accounted in batches (commit 356782d): a copy of the grid
# (``fill``), and a loop per point over its recurrent candidates with a walk of every line.


@njit(cache=True)
def _former_dense_cells_lines(points, xmin, ymin, inv_h, ncx, n_cells):
    n = points.shape[0]
    keys = _cell_keys(points, xmin, ymin, inv_h, ncx)
    start = np.zeros(n_cells + 1, np.int64)
    for a in range(n):
        start[keys[a] + 1] += 1
    for c in range(n_cells):
        start[c + 1] += start[c]
    fill = start[:n_cells].copy()
    g = np.empty((n, 6))
    perm = np.empty(n, np.int64)
    skey = np.empty(n, np.int64)
    for i in range(n):
        k = keys[i]
        a = fill[k]
        fill[k] = a + 1
        perm[a] = i
        skey[a] = k
        g[a, 0] = points[i, 0]
        g[a, 1] = points[i, 1]
        if i > 0:
            g[a, 2] = points[i - 1, 0]
            g[a, 3] = points[i - 1, 1]
        else:
            g[a, 2] = g[a, 3] = np.nan
        if i + 1 < n:
            g[a, 4] = points[i + 1, 0]
            g[a, 5] = points[i + 1, 1]
        else:
            g[a, 4] = g[a, 5] = np.nan
    return g, perm, skey, start


@njit(cache=True)
def _former_sweep_lines_dense(g, perm, skey, start, ncx, w, pts, eps2s, count, diag):
    n = g.shape[0]
    eps2 = eps2s[0]
    cand = np.empty(n, np.int64)
    dist2 = np.empty(n)
    for a in range(n):
        key = skey[a]
        xa = g[a, 0]
        ya = g[a, 1]
        m = 0
        for b in range(a + 1, start[key + 2]):
            dx = xa - g[b, 0]
            dy = ya - g[b, 1]
            d2 = dx * dx + dy * dy
            cand[m] = b
            dist2[m] = d2
            m += d2 <= eps2
        for b in range(start[key + ncx - 1], start[key + ncx + 2]):
            dx = xa - g[b, 0]
            dy = ya - g[b, 1]
            d2 = dx * dx + dy * dy
            cand[m] = b
            dist2[m] = d2
            m += d2 <= eps2
        ia = perm[a]
        for t in range(m):
            b = cand[t]
            ib = perm[b]
            if w > 1 and abs(ia - ib) < w:
                continue
            px = g[a, 2] - g[b, 2]
            py = g[a, 3] - g[b, 3]
            p2 = px * px + py * py
            sx = g[a, 4] - g[b, 4]
            sy = g[a, 5] - g[b, 5]
            s2 = sx * sx + sy * sy
            d2 = dist2[t]
            for k in range(eps2s.shape[0]):
                e2 = eps2s[k]
                if not (d2 <= e2):
                    break
                count[k] += 1
                if not (p2 <= e2):
                    length = 1
                    if s2 <= e2:
                        i = min(ia, ib)
                        j = max(ia, ib)
                        length = 2
                        while j + length < n and _recurrent(pts, i + length, j + length, e2):
                            length += 1
                    _add_line(diag, k, length)


def _line_kernels(pts, build, sweep, *extra):
    """The sweep's call at [1e-2, 1e-3] (Theiler 1, l_min 2, no laminarity) through the
    given kernels (``extra``: the current sweep's Theiler window and empty laminarity
    sums)."""
    from kicktimes.diagnostics import recurrence

    xmin, ymin, inv_h, ncx, ncy, _ = recurrence._grid(pts, 1e-2)
    eps2s = np.array([1e-2 * 1e-2, 1e-3 * 1e-3])
    count = np.zeros(2, np.int64)
    diag = np.zeros((2, 4), np.int64)
    diag[:, 0] = 2
    g, perm, skey, start = build(pts, xmin, ymin, inv_h, ncx, ncx * ncy)
    sweep(g, perm, skey, start, ncx, 1, pts, eps2s, count, diag, *extra)
    return count, diag


def batch_table(sets, rep):
    """The sweep's dense-grid kernels (build + line sweep at [1e-2, 1e-3]) against the
    former ones (per-point accounting, every line walked), same points, same run,
    alternating; the counts must be equal."""

    from kicktimes.diagnostics import _recurrence_kernels as kernels

    no_lam = np.zeros((0, 4), np.int64)
    new = (kernels._dense_cells_lines, kernels._sweep_lines_dense, 1, no_lam)
    old = (_former_dense_cells_lines, _former_sweep_lines_dense)
    print()
    print(f"The sweep's line kernels at [1e-2, 1e-3] (build + sweep): batched accounting "
          f"against the former per-point loop (min / median of {rep} alternating runs)")
    header = f"{'point set':<11} {'former [ms]':>16} {'batched [ms]':>16} {'speed-up':>9}"
    print(header)
    print("-" * len(header))
    for name, pts in sets:
        a = _line_kernels(pts, *new)
        b = _line_kernels(pts, *old)
        assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True)), name
        t_new, t_old = [], []
        for _ in range(rep):
            t_old.append(timeit(lambda p=pts: _line_kernels(p, *old), 1)[0])
            t_new.append(timeit(lambda p=pts: _line_kernels(p, *new), 1)[0])
        o_min, n_min = min(t_old), min(t_new)
        print(f"{name:<11} {o_min * 1e3:7.3f} / {statistics.median(t_old) * 1e3:6.3f} "
              f"{n_min * 1e3:7.3f} / {statistics.median(t_new) * 1e3:6.3f} "
              f"{o_min / n_min:9.2f}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats, N <= 10^6")
    parser.add_argument("--rqa-only", action="store_true", help="only the RQA table")
    parser.add_argument("--max-n", type=float, default=1e7, help="largest N of the scaling")
    parser.add_argument("--child", type=int, default=0, help=argparse.SUPPRESS)
    parser.add_argument("--child-rqa", type=int, default=0, help=argparse.SUPPRESS)
    parser.add_argument("--eps", type=float, default=1e-3, help="recurrence threshold")
    args = parser.parse_args()
    eps = args.eps
    if args.child:
        child(args.child, eps)
        return
    if args.child_rqa:
        child_rqa(args.child_rqa, eps)
        return
    n = 25_000
    n_brute = 5_000
    rep = 5 if args.quick else 30
    if args.rqa_only:
        rqa_table(rep)
        rqa_scaling([10**5, 10**6])
        return

    recurrence_rate(uniform_disk(100, 0), eps=eps)  # compile / load the cache outside timings
    kicked_chords(10, 0.2, 0)

    print(f"Recurrence rate, eps = {eps:g}, N = {n}  (times: min / median of {rep} runs)")
    header = (
        f"{'point set':<12} {'RR':>11} {'ours [ms]':>15} {'cKDTree [ms]':>17} "
        f"{'KDT count [ms]':>15} {'brute* [ms]':>12} {'KDT/ours':>9} {'brute/ours':>11}"
    )
    print(header)
    print("-" * len(header))
    for name, pts in [("trajectory", kicked_chords(n, 0.2, 1)), ("uniform", uniform_disk(n, 2))]:
        t_min, t_med, rr = timeit(lambda p=pts: recurrence_rate(p, eps=eps), rep)
        tree = cKDTree(pts)
        k_min, k_med, count = timeit(
            lambda p=pts: (lambda tr: tr.count_neighbors(tr, eps))(cKDTree(p)), rep
        )
        c_min, _, _ = timeit(lambda tr=tree: tr.count_neighbors(tr, eps), rep)
        assert count == round(rr * n * n), (count, rr * n * n)
        small = pts[:n_brute]
        b_min, _, bcount = timeit(lambda s=small: brute_count(s, eps), 3)
        assert bcount == round(recurrence_rate(small, eps=eps) * n_brute**2)
        b_scaled = b_min * (n / n_brute) ** 2
        print(
            f"{name:<12} {rr:11.4e} {t_min * 1e3:7.3f} / {t_med * 1e3:5.3f} "
            f"{k_min * 1e3:8.2f} / {k_med * 1e3:6.2f} {c_min * 1e3:15.2f} "
            f"{b_scaled * 1e3:12.0f} {k_min / t_min:9.1f} {b_scaled / t_min:11.0f}"
        )
    print(
        f"* brute force with numpy at N = {n_brute}, scaled by (N / {n_brute})^2; "
        "cKDTree = build + count_neighbors, KDT count = count_neighbors on a built tree"
    )

    print()
    rqa_table(rep)

    print()
    print(f"Scaling (trajectory, eps = {eps:g}), each N in a fresh process; memory = peak RSS")
    print("added by the call (input points, 16 B/point, not included)")
    header = (
        f"{'N':>10} {'RR':>11} {'ours [s]':>9} {'ns/point':>9} {'mem [MB]':>9} "
        f"{'B/point':>8} {'cKDTree [s]':>12} {'KDT/ours':>9}"
    )
    print(header)
    print("-" * len(header))
    sizes = [25_000, 10**5, 10**6] + ([10**7] if not args.quick else [])
    for size in [s for s in sizes if s <= args.max_n]:
        row = scaling_row(size, eps)
        dt, mem = row["time"], row["extra_bytes"]
        if "kdtree_time" in row:
            kdt = f"{row['kdtree_time']:12.3f} {row['kdtree_time'] / dt:9.1f}"
        else:
            kdt = f"{'-':>12} {'-':>9}"
        print(
            f"{size:>10} {row['rr']:11.4e} {dt:9.4f} {dt / size * 1e9:9.1f} "
            f"{mem / 2**20:9.1f} {mem / size:8.1f} {kdt}"
        )
    rqa_scaling([10**5, 10**6])


if __name__ == "__main__":
    main()

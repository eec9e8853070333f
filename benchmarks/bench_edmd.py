"""Same-machine speed against Smallenburg's EDMD `Single` (issue 51): collisions per CPU second.

EDMD (F. Smallenburg, Eur. Phys. J. E 45, 22 (2022); github.com/FSmallenburg/EDMD) is an
event-driven C code for hard spheres in a cubic periodic box, with neighbour lists and a
calendar that schedules one event per particle. Its `Single` program takes every parameter
from global variables at the top of ``mdSingle.c`` and reads its start from ``init.sph`` in
the working directory. This script does not build it: it runs a binary built beforehand with
EDMD's own Makefile, from ``mdSingle.c`` with two globals changed (``maxtime = 1e9``, so the
script decides when to stop; ``usethermostat = 0``, the velocity kicks off as its README
describes the default; the source ships with them on). The binary is looked for at
``EDIR/Single/md_bench`` (``--edmd EDIR``) or given by ``--binary``; ``--thermo-binary``
adds a second one (thermostat on) to the rounds, ``--cell-binary`` EDMD's `Cell` program
(cell lists only, ``maxtime = 1e9``; its thermostat is off as shipped).

Workload, per number of bodies N and packing fraction eta:

* EDMD: N spheres of diameter 1 at volume fraction ``eta`` in a periodic cube, started from
  a simple-cubic lattice with N sites filled at random and jittered (written here), velocities
  its own (Maxwellian, kT = 1). Its counter of collisions is printed once per unit of time;
  the script reads the child's CPU time (``/proc/PID/schedstat``) as each line arrives and
  measures from the first line with at least ``--warm`` collisions per particle (start-up
  and equilibration excluded) to the first with ``--collisions`` more, then kills it. Its
  pressure over the measured window is checked against Carnahan-Starling's.
* kicktimes: `kicktimes.simulate_disks` (elastic rule, the physics of EDMD's spheres; the
  collision log on, as a user calls it; wall hits run but are not counted) on N disks in the
  unit circle at area fraction ``phi``, from `kicktimes.initial_state` run ``--warm``
  collisions per disk further (not timed); CPU seconds (``time.process_time``) of one call
  giving about ``--collisions`` disk-disk collisions. ``--geometry box`` uses the periodic
  square box of the same area (side sqrt(pi): the same radius at the same packing) instead,
  ``--geometry both`` runs the two in the same rounds.

Two matchings of a 2-D area fraction to a 3-D volume fraction:

* ``phi = eta`` (the same fraction of space filled);
* the same mean free path in diameters (the same collisions per particle in the time a
  particle needs to travel one diameter), from Enskog's frequency: ``sigma / lambda =
  6 sqrt(2) eta g_CS(eta)`` in 3-D (Carnahan-Starling's contact value) and ``8 sqrt(2) phi
  g_H(phi) / pi`` in 2-D (Henderson's, `kicktimes.stats.contact_value`). This sets how many
  events that are not collisions (cell crossings, neighbour-list rebuilds, wall hits) each
  collision costs, so it is the closer match of the work per collision.

Each round runs every cell's programs one after the other (EDMD first in odd rounds, last in
even ones); per cell the medians over rounds and the ratio kicktimes / EDMD of each round
(median and range) are printed. The machine is shared: run it under ``nice -n 10``.

Run: nice -n 10 python benchmarks/bench_edmd.py --edmd /work/edmd [--rounds 5]
[--sizes 1000 10000] [--packings 0.1 0.3 0.4] [--collisions 3e6] [--csv runs.csv]
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import re
import shutil
import subprocess
import tempfile
import time

import numpy as np
from scipy.optimize import brentq

import kicktimes as kt
from kicktimes.stats import contact_value, enskog_frequency

LINE = re.compile(r"Simtime: ([0-9.eE+-]+), Collisions: (\d+), Press: ([0-9.eE+-]+)")


def cs_contact(eta):
    """Carnahan-Starling's contact value of hard spheres, ``(1 - eta/2) / (1 - eta)^3``."""
    return (1.0 - 0.5 * eta) / (1.0 - eta) ** 3


def cs_pressure(eta):
    """Carnahan-Starling's reduced pressure ``beta P sigma^3`` at kT = 1, diameter 1."""
    rho = 6.0 * eta / math.pi
    return rho * (1.0 + eta + eta * eta - eta ** 3) / (1.0 - eta) ** 3


def free_path_match(eta):
    """The 2-D area fraction whose Enskog mean free path in diameters equals that of hard
    spheres at volume fraction ``eta``: ``phi g_H(phi) = (3 pi / 4) eta g_CS(eta)``."""
    target = 0.75 * math.pi * eta * cs_contact(eta)
    return brentq(lambda p: p * float(contact_value(p)) - target, 1e-9, 0.7)


def sphere_lattice(n, eta, seed=1):
    """``(box length, positions)`` of ``n`` spheres of diameter 1 at volume fraction ``eta``:
    a simple-cubic lattice of ``ceil(n^(1/3))^3`` sites, ``n`` of them filled at random, each
    sphere jittered inside its own site's free room (no overlaps)."""
    if not 0.0 < eta < math.pi / 6.0:
        raise ValueError(f"packings: a lattice start needs 0 < eta < pi/6, got {eta!r}")
    box = (n * math.pi / (6.0 * eta)) ** (1.0 / 3.0)
    m = math.ceil(round(n ** (1.0 / 3.0), 9))
    a = box / m
    if a <= 1.0:
        raise ValueError(f"packings: eta={eta!r} with n={n} leaves lattice spacing {a:.4g} "
                         f"< 1 diameter; use a smaller packing")
    rng = np.random.default_rng(seed)
    sites = rng.choice(m ** 3, n, replace=False)
    ijk = np.stack(np.unravel_index(sites, (m, m, m)), axis=1)
    pos = (ijk + 0.5) * a + rng.uniform(-1.0, 1.0, (n, 3)) * 0.499 * (a - 1.0)
    return box, pos


def write_sph(path, box, pos):
    """EDMD's ``.sph`` snapshot: N, the box lengths, then ``a x y z radius`` per sphere."""
    with open(path, "w") as f:
        f.write(f"{len(pos)}\n{box:.12f} {box:.12f} {box:.12f}\n")
        for x, y, z in pos:
            f.write(f"a {x:.12f} {y:.12f} {z:.12f} 0.5\n")


def cpu_ns(pid):
    """CPU nanoseconds used so far by process ``pid`` (``/proc/PID/schedstat``)."""
    with open(f"/proc/{pid}/schedstat") as f:
        return int(f.read().split()[0])


def edmd_rate(binary, workdir, n, warm, collisions, timeout=900.0):
    """One EDMD run in ``workdir`` (holding ``init.sph``): a dict with the collisions and
    the CPU and wall seconds of the measured window and its mean pressure."""
    proc = subprocess.Popen(["stdbuf", "-oL", binary], cwd=workdir, stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL, text=True)
    start = None
    press = []
    t_out = time.perf_counter() + timeout
    try:
        for line in proc.stdout:
            hit = LINE.search(line)
            if hit is None:
                continue
            cpu, wall = cpu_ns(proc.pid), time.perf_counter()
            t, c, p = float(hit[1]), int(hit[2]), float(hit[3])
            if start is None:
                if c >= warm * n:
                    start = (t, c, cpu, wall)
            else:
                press.append(p)
                if c - start[1] >= collisions:
                    break
            if wall > t_out:
                raise RuntimeError(f"EDMD at n={n} passed {timeout} s without "
                                   f"{collisions:.3g} collisions")
        else:
            raise RuntimeError(f"EDMD stopped early (exit {proc.wait()}); see {workdir}")
    finally:
        proc.kill()
        proc.wait()
    return {"collisions": c - start[1], "cpu_s": (cpu - start[2]) * 1e-9,
            "wall_s": wall - start[3], "sim_time": t - start[0],
            "pressure": float(np.mean(press))}


def disks_state(n, phi, warm, box=None):
    """An equilibrated elastic state of ``n`` disks at area fraction ``phi``: the initial
    state run ``warm`` collisions per disk further (not timed; compiles the engine)."""
    extra = {} if box is None else {"box": box}
    r = math.sqrt(phi / n)
    state = kt.initial_state(n, r, rng=1, rule="elastic", **extra)
    nu = enskog_frequency(r, n, rule="elastic")
    state = kt.simulate_disks(state, r, t_max=warm / nu, rule="elastic", **extra).final_state
    return state, r, nu


def disks_rate(state, r, nu, collisions, box=None):
    """One `simulate_disks` call of about ``collisions`` disk-disk collisions: a dict."""
    extra = {} if box is None else {"box": box}
    n = len(state)
    t_max = collisions / (0.5 * n * nu)
    w0, c0 = time.perf_counter(), time.process_time()
    run = kt.simulate_disks(state, r, t_max=t_max, rule="elastic", **extra)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    return {"collisions": int(run.n_pp), "cpu_s": cpu, "wall_s": wall, "sim_time": t_max,
            "pressure": float("nan")}


def spread(values):
    v = np.asarray(values, dtype=float)
    return float(np.median(v)), float(v.min()), float(v.max())


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--edmd", default="/work/edmd", help="EDMD's folder (a snapshot)")
    ap.add_argument("--binary", help="EDMD Single binary (default EDIR/Single/md_bench)")
    ap.add_argument("--thermo-binary", help="also run this EDMD Single binary (thermostat on)")
    ap.add_argument("--cell-binary", help="also run this EDMD Cell binary (cell list, no "
                    "neighbour list; built like md_bench, from mdCell.c)")
    ap.add_argument("--no-kicktimes", action="store_true", help="EDMD's binaries only")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--sizes", type=int, nargs="+", default=[1000, 10000])
    ap.add_argument("--packings", type=float, nargs="+", default=[0.1, 0.3, 0.4])
    ap.add_argument("--collisions", type=float, default=3e6,
                    help="collisions per measured run")
    ap.add_argument("--warm", type=float, default=10.0,
                    help="collisions per particle before the measured window")
    ap.add_argument("--no-free-path", action="store_true",
                    help="skip the kicktimes runs at the free-path-matched packing")
    ap.add_argument("--geometry", choices=["circle", "box", "both"], default="circle",
                    help="kicktimes in the unit circle, in the periodic box of the same area "
                         "(simulate_disks(box=sqrt(pi))), or both in the same rounds")
    ap.add_argument("--csv", help="also write every run here")
    args = ap.parse_args(argv)
    if args.rounds < 1:
        raise SystemExit(f"--rounds must be >= 1, got {args.rounds}")
    binary = args.binary or os.path.join(args.edmd, "Single", "md_bench")
    if not os.access(binary, os.X_OK):
        raise SystemExit(
            f"no EDMD binary at {binary}: build Single with EDMD's own Makefile from "
            f"mdSingle.c with maxtime = 1e9 and usethermostat = 0 (this script builds nothing)")
    edmds = [("EDMD", binary)]
    if args.thermo_binary:
        edmds.append(("EDMD+thermostat", args.thermo_binary))
    if args.cell_binary:
        edmds.append(("EDMD Cell", args.cell_binary))
    collisions = int(args.collisions)
    stamp = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    print(f"kicktimes {kt.__version__} from {os.path.dirname(kt.__file__)}, EDMD {binary}")
    print(f"{stamp}, load {os.getloadavg()[0]:.2f}, "
          f"{args.rounds} rounds, ~{collisions:.2g} collisions per run, CPU seconds")
    tmp = tempfile.mkdtemp(prefix="bench_edmd_")
    try:
        _run(args, edmds, collisions, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _run(args, edmds, collisions, tmp):
    """The rounds, the table and the CSV of `main`, EDMD's start files in ``tmp``."""
    cells = []
    for n in args.sizes:
        for eta in args.packings:
            d = os.path.join(tmp, f"n{n}_eta{eta}")
            os.makedirs(d)
            write_sph(os.path.join(d, "init.sph"), *sphere_lattice(n, eta))
            packs = [] if args.no_kicktimes else [("kicktimes phi=eta", eta)]
            if not (args.no_free_path or args.no_kicktimes):
                packs.append(("kicktimes free path", free_path_match(eta)))
            # the box has the circle's area pi: the same radius at the same packing
            boxes = {"circle": [None], "box": [math.sqrt(math.pi)],
                     "both": [None, math.sqrt(math.pi)]}[args.geometry]
            kts = [(lab + ("" if box is None else " box"), phi, box)
                   for lab, phi in packs for box in boxes]
            prepared = []
            for label, phi, box in kts:
                t0 = time.perf_counter()
                prepared.append((label, phi, box, disks_state(n, phi, args.warm, box=box)))
                print(f"  prepared {label} n={n} phi={phi:.3f} in "
                      f"{time.perf_counter() - t0:.0f} s", flush=True)
            cells.append((n, eta, d, prepared))
    rows = []
    for rnd in range(args.rounds):
        for n, eta, d, prepared in cells:
            jobs = [(lab, "3-D periodic", eta,
                     lambda b=b, d=d, n=n: edmd_rate(b, d, n, args.warm, collisions))
                    for lab, b in edmds]
            jobs += [(lab, "2-D circle" if box is None else "2-D periodic", phi,
                      lambda s=s, box=box: disks_rate(*s, collisions, box=box))
                     for lab, phi, box, s in prepared]
            if rnd % 2:
                jobs.reverse()
            for label, geom, pack, job in jobs:
                out = job()
                out.update(round=rnd, program=label, geometry=geom, n=n, eta=eta,
                           packing=pack, rate_cpu=out["collisions"] / out["cpu_s"],
                           rate_wall=out["collisions"] / out["wall_s"])
                rows.append(out)
                print(f"round {rnd} n={n:>6} eta={eta} {label:>24} packing {pack:.3f}: "
                      f"{out['rate_cpu']:.3g} coll/CPU-s ({out['rate_wall']:.3g}/wall-s, "
                      f"{out['collisions']:.3g} in {out['cpu_s']:.2f} CPU-s)", flush=True)
    print(f"\nmedians over {args.rounds} rounds (range), collisions per CPU second; the ratio "
          f"kicktimes / EDMD of each round")
    print(f"{'program':>24} {'geometry':>13} {'N':>6} {'packing':>7} {'coll/s':>9} "
          f"{'range':>17} {'ratio':>6} {'ratio range':>12}")
    for n, eta, _d, prepared in cells:
        mine = [r for r in rows if r["n"] == n and r["eta"] == eta]
        ref = {r["round"]: r["rate_cpu"] for r in mine if r["program"] == "EDMD"}
        for label in [lab for lab, _ in edmds] + [lab for lab, _p, _b, _s in prepared]:
            got = [r for r in mine if r["program"] == label]
            med, lo, hi = spread([r["rate_cpu"] for r in got])
            ratio = spread([r["rate_cpu"] / ref[r["round"]] for r in got])
            print(f"{label:>24} {got[0]['geometry']:>13} {n:>6} {got[0]['packing']:>7.3f} "
                  f"{med:>9.3g} {lo:>8.3g}-{hi:<8.3g} {ratio[0]:>6.2f} "
                  f"{ratio[1]:>5.2f}-{ratio[2]:<5.2f}")
        p = [r["pressure"] for r in mine if r["program"] == "EDMD"]
        print(f"{'':>24} EDMD pressure {np.mean(p):.4g}, Carnahan-Starling "
              f"{cs_pressure(eta):.4g}")
    if args.csv:
        keys = ["round", "program", "geometry", "n", "eta", "packing", "collisions", "cpu_s",
                "wall_s", "sim_time", "rate_cpu", "rate_wall", "pressure"]
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
            w.writeheader()
            w.writerows(rows)
        print(f"runs written to {args.csv}")


if __name__ == "__main__":
    main()

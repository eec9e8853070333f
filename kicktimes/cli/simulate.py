"""``kicktimes simulate``: two-disk runs of an ensemble, their collision times to Parquet;
with ``--disks N``, one run of N disks (`kicktimes.simulate_disks`) and its collision log."""

from __future__ import annotations

import dataclasses

import click

from kicktimes import __version__
from kicktimes.cli._group import _cli_errors, _Real, option
from kicktimes.compilation import compile_first


# --- simulate command -------------------------------------------------------------------
@click.command("simulate")
@option("--radius", "-r", "radii", type=_Real(0.0, 0.5), multiple=True, default=(0.01, 0.02),
        help="Disk radius (repeat for several), 0 < r < 0.5.")
@option("--n-ics", type=click.IntRange(min=1), default=100,
        help="Number of initial conditions (drawn once, at the largest radius).")
@option("--t-max", type=_Real(0.0), default=1000.0, help="Run time per IC.")
@option("--seed", type=click.IntRange(min=0), default=0, help="Ensemble seed.")
@option("--rule", type=click.Choice(["mirror", "elastic"]), default="mirror",
        help="Disk-disk collision rule.")
@option("--ic-method", type=click.Choice(["paper", "uniform"]), default=None,
        help="'paper' procedure or the invariant measure (default: 'paper' in the circle, "
             "'uniform' in another table, the only one there).")
@click.option("--out", "out", type=click.Path(file_okay=False), required=True,
              help="Output folder (created).")
@click.option("--save-runs", is_flag=True, help="Also write every run (boundary log) to OUT/runs/.")
@option("--disks", "n_disks", type=click.IntRange(min=1, max=10**7), default=None,
        help="Simulate this many disks together in one table instead (with --packing).")
@option("--packing", type=_Real(0.0), default=None,
        help="Area fraction of the --disks (sum r^2), 0 < packing <= 0.7.")
@option("--box", "box", type=_Real(0.0), default=None,
        help="With --disks: a periodic square box of this side instead of the table (area "
             "fraction N pi r^2 / box^2).")
@option("--table", "table_kind", type=click.Choice(["circle", "stadium", "ellipse"]),
        default="circle", help="The table: the unit circle, Bunimovich's stadium (--a) or an "
                               "ellipse (--a, --b).")
@option("--a", "table_a", type=_Real(0.0), default=None,
        help="The stadium's half-length of its straight sides (radius 1), or the ellipse's "
             "semi-axis along x.")
@option("--b", "table_b", type=_Real(0.0), default=None,
        help="The ellipse's semi-axis along y.")
def simulate_command(radii, n_ics, t_max, seed, rule, ic_method, out, save_runs, n_disks,
                     packing, box, table_kind, table_a, table_b):
    """Simulate two-disk billiards and log every disk-disk collision.

    Writes OUT/collisions.parquet (one row per radius and IC: radius, ic, t_window, n_pp,
    pp_times) with the parameters in its metadata, and prints, per radius, the mean
    number of disk-disk collisions per IC beside the kinetic-theory expectation
    (exact for --ic-method uniform).

    With --disks N --packing PHI: N disks of radius sqrt(PHI / N) together, from an
    initial state of `kicktimes.initial_state` (--seed, --rule); writes the collision
    log OUT/disks.parquet (time, i, j) and prints the collision frequency per disk beside
    Enskog's with Henderson's contact value, and the compressibility factor Z = PA/(NkT)
    from the wall, the virial and the central region beside Henderson's equation of
    state. With --box L: in the periodic square box [0, L)^2, r = L sqrt(PHI / (pi N)).

    With --table stadium --a A or --table ellipse --a A --b B, in that table
    (`kicktimes.tables`; docs/tables.md): the kinetic rate is the table's, the ICs are the
    invariant measure, and the N disks' radius is sqrt(PHI |table| / (pi N)).
    """
    table = _table(table_kind, table_a, table_b)
    if ic_method is None:
        ic_method = "paper" if table is None else "uniform"
    if n_disks is not None or packing is not None or box is not None:
        _simulate_disks(n_disks, packing, t_max, seed, rule, out, box, table)
        return
    import json
    import os

    import numpy as np
    import pandas as pd
    import pyarrow as pa
    import pyarrow.parquet as pq
    from tqdm.auto import tqdm

    from kicktimes import initial_conditions, simulate_two_particle
    from kicktimes.fileio import atomic_write
    from kicktimes.stats import kinetic_rate

    # the options are range-checked by click; this maps anything the library still
    # refuses back to the option that caused it
    options = {"r_max": "--radius", "r": "--radius", "n": "--n-ics", "t_max": "--t-max",
               "seed": "--seed", "rng": "--seed", "rule": "--rule", "method": "--ic-method",
               "table": "--table"}
    from kicktimes.compilation import SIMULATE_KERNELS

    compile_first(None, SIMULATE_KERNELS)
    with _cli_errors(options):
        ics = initial_conditions(n_ics, max(radii), rng=seed, method=ic_method, rule=rule,
                                 table=table)
        for r in radii:
            # validates r, t_max
            simulate_two_particle(ics[0], r, t_max=t_max, rule=rule, table=table)
        os.makedirs(out, exist_ok=True)
    rows = []
    quiet = bool(os.environ.get("CI")) or not os.isatty(2)
    with _cli_errors(options), tqdm(total=len(radii) * n_ics, disable=quiet,
                                    desc="simulate") as bar:
        for r in radii:
            for i, ic in enumerate(ics):
                # the run file records the IC seed
                run = dataclasses.replace(
                    simulate_two_particle(ic, r, t_max=t_max, rule=rule, table=table), seed=seed)
                rows.append((r, i, run.t_max, run.n_pp, run.pp_times))
                if save_runs:
                    run.to_parquet(os.path.join(out, "runs", f"r{r:.4f}-ic{i:05d}.parquet"))
                bar.update()
    frame = pa.table(
        {
            "radius": pa.array([row[0] for row in rows], pa.float64()),
            "ic": pa.array([row[1] for row in rows], pa.int64()),
            "t_window": pa.array([row[2] for row in rows], pa.float64()),
            "n_pp": pa.array([row[3] for row in rows], pa.int64()),
            "pp_times": pa.array([row[4] for row in rows], pa.list_(pa.float64())),
        }
    )
    meta = {"radii": list(radii), "n_ics": n_ics, "t_max": t_max, "seed": seed, "rule": rule,
            "ic_method": ic_method, "table": _spec(table), "version": __version__}
    frame = frame.replace_schema_metadata({b"kicktimes": json.dumps(meta).encode()})
    path = os.path.join(out, "collisions.parquet")
    with _cli_errors():
        atomic_write(path, lambda tmp: pq.write_table(frame, tmp))
    df = pd.DataFrame({"radius": frame["radius"].to_numpy(), "n_pp": frame["n_pp"].to_numpy()})
    summary = df.groupby("radius", observed=True).n_pp.agg(["mean", "std", "count"])
    summary["sem"] = summary["std"] / np.sqrt(summary["count"])
    summary["kinetic"] = [kinetic_rate(r, rule=rule, table=table) * t_max
                          for r in summary.index]
    click.echo(f"{n_ics} ICs ({ic_method}), rule={rule}, t_max={t_max:g}, seed={seed}"
               + ("" if table is None else f", table={table!r}"))
    click.echo(f"{'radius':>8} {'mean n_pp':>10} {'± sem':>8} {'kinetic':>9}")
    for r, row in summary.iterrows():
        click.echo(f"{r:8.4f} {row['mean']:10.2f} {row['sem']:8.2f} {row['kinetic']:9.2f}")
    note = ("exact at the largest radius, where the ICs are invariant-measure draws"
            if ic_method == "uniform" else "the invariant-measure value; 'paper' ICs differ")
    click.echo(f"kinetic = Gamma(r) * t_max ({note})")
    click.echo(f"wrote {path}")


def _table(kind, a, b):
    """The table of ``--table``, ``--a``, ``--b`` (``None`` for the circle, the default)."""
    from kicktimes.tables import Ellipse, Stadium

    given = {"--a": a, "--b": b}
    need = {"circle": (), "stadium": ("--a",), "ellipse": ("--a", "--b")}[kind]
    extra = [k for k, v in given.items() if v is not None and k not in need]
    if extra:
        raise click.UsageError(f"{' and '.join(extra)} do not apply to --table {kind}")
    missing = [k for k in need if given[k] is None]
    if missing:
        raise click.UsageError(f"--table {kind} needs {' and '.join(missing)}")
    with _cli_errors({"a": "--a", "b": "--b"}):
        return None if kind == "circle" else Stadium(a) if kind == "stadium" else Ellipse(a, b)


def _spec(table) -> str:
    from kicktimes.tables import table_spec

    return "circle" if table is None else table_spec(table)


def _simulate_disks(n_disks, packing, t_max, seed, rule, out, box=None, table=None):
    """``kicktimes simulate --disks N --packing PHI [--box L | --table ...]``: one N-disk
    run, its log to Parquet, its collision frequency and pressure beside Enskog's and
    Henderson's."""
    import math
    import os

    from kicktimes import initial_state, simulate_disks
    from kicktimes.compilation import DISKS_KERNELS
    from kicktimes.stats import enskog_frequency

    if n_disks is None or packing is None:
        raise click.UsageError("--disks and --packing go together: give both")
    compile_first(None, DISKS_KERNELS)
    options = {"n_disks": "--disks", "packing": "--packing", "r": "--packing",
               "t_max": "--t-max", "seed": "--seed", "rng": "--seed", "rule": "--rule",
               "state": "--packing",
               "box": "--box", "table": "--table"}
    if box is not None and table is not None:
        raise click.UsageError("--box and --table are two containers: give one")
    if table is not None:
        area = table.area(0.0)
    else:
        area = math.pi if box is None else box * box
    with _cli_errors(options):
        if box is not None and packing > 0.7:
            raise ValueError(f"packing must lie in (0.0, 0.7], got {packing!r}")
        r = math.sqrt(packing * area / (math.pi * n_disks))
        if box is not None and 6.0 * r > box:
            raise ValueError(f"box must be at least 3 cells of one diameter wide, box >= 6 r = "
                             f"{6.0 * r:.6g} for {n_disks} disks at packing {packing:g}, got "
                             f"{box:g}")
        state = initial_state(n_disks, r, rng=seed, rule=rule, box=box, table=table)
        os.makedirs(out, exist_ok=True)
        run = simulate_disks(state, r, t_max=t_max, rule=rule, box=box, table=table)
    path = os.path.join(out, "disks.parquet")
    with _cli_errors():
        run.to_parquet(path)
    nu = run.collision_frequency
    kT = run.kT if rule == "elastic" else 0.5
    enskog = enskog_frequency(r, n_disks, rule=rule, area=area, kT=kT)
    where = "the whole table, its wall layer included" if box is None else "the periodic box"
    click.echo(f"{n_disks} disks, r={r:.6g}, packing={packing:g}, rule={rule}, t_max={t_max:g}, "
               f"seed={seed}" + ("" if box is None else f", box={box:g}")
               + ("" if table is None else f", table={table!r}"))
    click.echo(f"{run.n_pp} disk-disk collisions, {run.n_wall} wall collisions")
    click.echo(f"collision frequency per disk {nu:.6g}, Enskog-Henderson {enskog:.6g} "
               f"(ratio {nu / enskog:.4f}; {where})")
    click.echo(_pressure_lines(run))
    click.echo(f"wrote {path}")


def _pressure_lines(run) -> str:
    """The run's compressibility factors beside Henderson's (`DisksRun.pressure`)."""
    rows = 0 if run.pressure_log is None else run.pressure_log.shape[0]
    if rows < 3:
        return "Z = PA/(NkT): the run is too short for block errors (fewer than 2 blocks)"
    try:
        p = run.pressure(blocks=min(10, rows - 1))
    except ValueError as exc:
        return f"Z = PA/(NkT): not computed ({exc})"
    table = getattr(run, "table", None)
    if run.box is not None:
        area = "box^2"
    elif table is None or type(table).__name__ == "Circle":
        area = "pi (1 - r)^2, the centres' room"
    else:
        area = f"the centres' room in {table!r}"
    out = [f"Z = PA/(NkT) (A = {area}), +- one standard error over {p.blocks} blocks:"]
    if run.box is None:
        out.append(f"  wall   {p.z_wall:.4f} +- {p.se_wall:.4f}")
        out.append(f"  virial {p.z_virial:.4f} +- {p.se_virial:.4f}")
        out.append(f"  bulk   {p.z_bulk:.4f} +- {p.se_bulk:.4f} (centres within "
                   f"{run.bulk_radius:g} of the centre, their packing {p.bulk_packing:.4f}); "
                   f"Henderson {p.henderson:.4f} at that packing")
    else:
        out.append(f"  virial {p.z_virial:.4f} +- {p.se_virial:.4f}; Henderson "
                   f"{p.henderson:.4f} at the packing {p.packing:.4f}")
    return "\n".join(out)


# --- end simulate command ---------------------------------------------------------------

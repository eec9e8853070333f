"""``kicktimes schedule``: a kick schedule drawn to a file."""

from __future__ import annotations

import click

from kicktimes.cli._group import _os_message, _plain, _Real


# --- schedule command (kick-schedule generator) -----------------------------------
def _parse_schedule_params(params):
    parsed = {}
    for item in params:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise click.BadParameter(f"expected NAME=VALUE, got {item!r}", param_hint="--param")
        try:
            parsed[name.strip()] = float(value)
        except ValueError:
            raise click.BadParameter(
                f"{name.strip()} must be a number, got {value!r}", param_hint="--param"
            ) from None
    return parsed


def _fitted_mmpp(input_path, params, stationary, window):
    """A two-state MMPP fitted to the times of ``input_path`` on ``(0, window]`` (the file's
    ``t_max`` metadata by default), started in its stationary law."""
    from kicktimes import schedules
    from kicktimes.stats import fit_mmpp

    if params or stationary:
        raise click.UsageError("mmpp with --input is fitted to the times: it takes no --param "
                               "and starts stationary (no --stationary)")
    times, meta = schedules.read_kick_times(input_path, with_metadata=True)
    window = window if window is not None else meta.get("t_max")
    if window is None:
        raise click.UsageError("mmpp with --input needs --window, the observation window of "
                               "the input times (the file has no t_max metadata)")
    return schedules.MMPP.from_fit(fit_mmpp(times, float(window), n_states=2, rng=0))


_SCHEDULE_OPTIONS = {"t_max": "--t-max", "seed": "--seed", "rng": "--seed", "window": "--window",
                     "times": "--input", "dist": "--dist", "path": "--output"}


@click.command("schedule")
@click.argument(
    "model",
    type=click.Choice(["poisson", "renewal", "bootstrap", "replay", "mmpp", "json"], False),
)
@click.option(
    "--param",
    "-p",
    "params",
    multiple=True,
    metavar="NAME=VALUE",
    help="Model parameter, repeatable: rate=R (poisson); shape names, loc, scale (renewal); "
    "rate0, rate1, ... (kick rate of each hidden state), q01, q10, ... (switching rate from "
    "state i to j) and optionally p0, p1, ... (initial probabilities) (mmpp).",
)
@click.option("--dist", help="Interval distribution for renewal: a scipy.stats name, e.g. gamma.")
@click.option(
    "--stationary/--no-stationary",
    default=False,
    help="Renewal/bootstrap: first interval from the equilibrium law (stationary from t=0). "
    "mmpp starts in the stationary law unless p0, p1, ... are given.",
)
@click.option("--input", "input_path", type=click.Path(exists=True, dir_okay=False),
              help="bootstrap/replay: CSV/Parquet file of event times; mmpp: event times to "
              "fit a two-state MMPP to (then sampled from the fit); json: a schedule JSON file.")
@click.option("--window", type=_Real(0.0), default=None,
              help="replay, mmpp with --input: observation window of the input times "
              "(default: the file's t_max metadata; replay: sampling beyond it is an error).")
@click.option("--t-max", "t_max", type=_Real(0.0), required=True, help="Horizon: kicks in (0, T].")
@click.option(
    "--seed",
    type=click.IntRange(min=0),
    default=None,
    help="Integer seed (default: fresh entropy, printed and stored so the run can be redone).",
)
@click.option("--output", "-o", type=click.Path(dir_okay=False), required=True,
              help="Output file, .csv or .parquet (one column kick_time, metadata inside).")
@click.option("--print-json", is_flag=True, help="Also print the schedule's JSON.")
def schedule_command(
    model, params, dist, stationary, input_path, window, t_max, seed, output, print_json
):
    """Generate kick times from a schedule MODEL and write them to a file.

    \b
    Examples:
      kicktimes schedule poisson -p rate=0.5 --t-max 1000 --seed 1 -o kicks.parquet
      kicktimes schedule renewal --dist gamma -p a=2 -p scale=0.5 --stationary \\
          --t-max 1000 --seed 1 -o kicks.csv
      kicktimes schedule bootstrap --input pp_times.csv --t-max 1000 --seed 2 -o boot.csv
      kicktimes schedule mmpp -p rate0=0.5 -p rate1=4 -p q01=0.1 -p q10=0.4 \\
          --t-max 1000 --seed 4 -o clustered.csv
      kicktimes schedule mmpp --input pp_times.csv --window 5000 --t-max 1000 -o fitted.csv
      kicktimes schedule json --input schedule.json --t-max 1000 --seed 3 -o kicks.csv

    mmpp with --input fits a two-state Markov-modulated Poisson process to the input
    times (maximum likelihood, kicktimes.stats.fit_mmpp, fit seed 0) and samples kicks
    from the fit, started in its stationary law; --print-json shows the fitted rates and
    generator.
    """
    import numpy as np

    from kicktimes import schedules

    try:
        if model == "json":
            if input_path is None or params or dist or stationary or window is not None:
                raise click.UsageError("model json takes only --input SCHEDULE.json")
            with open(input_path) as fh:
                schedule = schedules.from_json(fh.read())
        elif model == "mmpp" and input_path is not None:
            schedule = _fitted_mmpp(input_path, params, stationary, window)
        else:
            schedule = schedules.from_spec(
                model,
                _parse_schedule_params(params),
                dist=dist,
                stationary=stationary,
                times=input_path,
                window=window,
            )
        if seed is None:
            seed = int(np.random.SeedSequence().entropy)
        times = schedule.sample(t_max, rng=seed)
        path = schedules.write_kick_times(times, output, t_max=t_max, schedule=schedule, seed=seed)
    except (ValueError, TypeError) as exc:
        raise click.UsageError(_plain(str(exc), _SCHEDULE_OPTIONS)) from None
    except OSError as exc:
        raise click.ClickException(_plain(_os_message(exc))) from None
    mean = f"{np.diff(times).mean():.6g}" if times.size > 1 else "n/a"
    click.echo(
        f"{schedule!r}: {times.size} kicks in (0, {t_max:g}], mean interval {mean}, "
        f"seed {seed} -> {path}"
    )
    if print_json:
        click.echo(schedule.to_json())


# --- end schedule command ------------------------------------------------------------

"""``kicktimes analyze``: the statistics of collision times from any source (a CLI command).

Registered on the ``kicktimes`` group by :mod:`kicktimes.cli`.
"""

from __future__ import annotations

import re

import click

from kicktimes.cli._group import _plain, option

#: library argument names as the command's options, at the start of a message
_OPTIONS = {
    "windows": "--windows",
    "window": "--window",
    "group": "--group",
    "reference": "--reference",
    "covariates": "--covariate",
    "labels": "--group",
    "alpha": "--alpha",
    "n_mc": "--n-mc",
    "max_fits_per_group": "--max-fits-per-group",
}
#: phrases of the library's messages that name its arguments, as the command's options
_PHRASES = (
    (r"window=\(t_start, t_end\)", "--window T_START T_END"),
    (r"a windows table", "a --windows table"),
    (r"as a table \(windows\) or as window", "as --windows or as --window"),
    (r"covariates: no table", "--covariate: no table"),
)
#: the option that chooses each column, for a missing column
_COLUMN_OPTIONS = (
    ("time", "--time-col"),
    ("sequence", "--sequence-col"),
    ("t_start", "--start-col"),
    ("t_end", "--end-col"),
)


def _cli_message(message: str, columns: dict) -> str:
    """A library message in the command's words: options instead of argument names, and
    for a missing column the option that names it."""
    message = _plain(message, _OPTIONS)
    for pattern, replacement in _PHRASES:
        message = re.sub(pattern, replacement, message)
    missing = re.search(r"no column '([^']*)'", message)
    if missing:
        for key, opt in _COLUMN_OPTIONS:
            if columns[key] == missing.group(1):
                message += f" (name the column with {opt})"
                break
    return message


@click.command("analyze")
@click.argument("files", nargs=-1, required=True, type=click.Path(exists=True, dir_okay=False))
@click.option("--out", "out", type=click.Path(file_okay=False), required=True,
              help="Output folder: report.html, findings.md, figures (PNG/PDF), tables (CSV).")
@click.option("--windows", type=click.Path(exists=True, dir_okay=False), default=None,
              help="CSV/Parquet table with one row per sequence: id, start, end (and covariates).")
@click.option("--window", type=(float, float), default=None, metavar="T_START T_END",
              help="One observation window for every sequence.")
@click.option("--sequence-col", default="sequence", show_default=True, help="Sequence-id column.")
@click.option("--time-col", default="time", show_default=True, help="Event-time column.")
@click.option("--start-col", default="t_start", show_default=True, help="Window-start column.")
@click.option("--end-col", default="t_end", show_default=True, help="Window-end column.")
@click.option(
    "--covariate",
    "covariates",
    multiple=True,
    help="Per-sequence numeric column to regress the counts on (repeat; default: every "
    "further column of the windows table and constant columns of the event table).",
)
@click.option("--group", default=None, help="Covariate whose values group the sequences.")
@click.option("--reference", default=None,
              help="Covariate holding each sequence's expected rate (e.g. a kinetic-theory rate).")
@click.option("--alpha", type=float, default=0.05, show_default=True, help="Test and FDR level.")
@option("--n-mc", type=click.IntRange(min=19), default=199,
        help="Monte Carlo samples of the conditional nulls.")
@option("--max-fits-per-group", type=click.IntRange(min=0), default=12,
        help="Sequences per group with their own renewal-model comparison.")
@click.option("--mmpp", "mmpp", is_flag=True, default=False,
              help="Also fit a two-state Markov-modulated Poisson process (clustered events) "
              "to every sequence with 50+ events (up to --max-fits-per-group per group): a "
              "bootstrap likelihood-ratio test against Poisson and its AIC against the renewal "
              "models. Slow: about 3-5 s per sequence at --mmpp-boot 99.")
@option("--mmpp-boot", type=click.IntRange(min=1), default=99,
        help="Bootstrap samples of each MMPP likelihood-ratio test (with --mmpp).")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True, help="Seed.")
@click.option("--dpi", type=click.IntRange(min=30), default=150, show_default=True)
def analyze_command(
    files,
    out,
    windows,
    window,
    sequence_col,
    time_col,
    start_col,
    end_col,
    covariates,
    group,
    reference,
    alpha,
    n_mc,
    max_fits_per_group,
    mmpp,
    mmpp_boot,
    seed,
    dpi,
):
    """Analyse event (collision) times from FILES (CSV or Parquet) into --out.

    FILES hold one row per event: a sequence id and a time. Each sequence's window
    comes from --start-col/--end-col columns, a --windows table, or --window.

    With --mmpp, every sequence with 50 or more events (up to --max-fits-per-group per
    group) also gets a two-state Markov-modulated Poisson process: a hidden Markov chain
    switching the event rate, the model of clustered events. A parametric-bootstrap
    likelihood-ratio test says whether it is needed against Poisson (p-values
    Fisher-combined per group: the finding "Clustered (MMPP-2)?"), and its AIC on the
    renewal fits' likelihood whether it beats the renewal models; the page shows the
    fitted rates and the mean time in each state (mmpp_per_sequence.csv).

    \b
    Examples:
      kicktimes analyze events.csv --window 0 1000 --out report
      kicktimes analyze events.csv --windows sequences.csv --group density \\
          --reference kinetic_rate --out report
      kicktimes analyze events.csv --window 0 1000 --mmpp --out report
    """
    from kicktimes.report.analyze_page import write_analysis
    from kicktimes.stats import analyze

    try:
        res = analyze(
            list(files),
            windows=windows,
            window=window,
            columns={"sequence": sequence_col, "time": time_col, "start": start_col,
                     "end": end_col},
            covariates=list(covariates) or None,
            group=group,
            reference=reference,
            alpha=alpha,
            n_mc=n_mc,
            max_fits_per_group=max_fits_per_group,
            rng=seed,
        )
        table = None
        if mmpp:
            from kicktimes.report.mmpp_analysis import analyze_mmpp

            table = analyze_mmpp(res, n_boot=mmpp_boot, max_fits_per_group=max_fits_per_group,
                                 rng=seed)
        path = write_analysis(res, out, dpi=dpi, sources=list(files), windows=windows,
                              mmpp=table)
    except (ValueError, TypeError) as exc:
        # bad input is bad usage: exit status 2 with the usage line, as every command
        columns = {"time": time_col, "sequence": sequence_col, "t_start": start_col,
                   "t_end": end_col}
        raise click.UsageError(_cli_message(str(exc), columns)) from None
    except OSError as exc:
        raise click.ClickException(f"{exc.strerror or exc}: {exc.filename or out}") from None
    click.echo(res.summary())
    if table is not None:
        from kicktimes.report.mmpp_analysis import mmpp_finding

        f = mmpp_finding(res, table)
        click.echo(f"- {f.question} {f.verdict}.\n  {f.statement}")
    click.echo(f"report written to {path}")

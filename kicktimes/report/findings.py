r"""The Findings: one computed statement per question, with its effect size, 95 % CI and
verdict, opening the report (and ``docs/results/``).

Questions, in order: are the collision times Poisson; which renewal model; which model
with a Markov-modulated Poisson process (clustered collisions); do the counts
follow kinetic theory; and, for every kicked system against the two-particle system, the
FTLE, the off-diagonal recurrence rate and DET at each ε, and the lag-1 autocorrelation
(whose agreement is built in). Each section module provides its own ``effects(ctx)``;
this module only gathers them, states the rules and the scale.
"""

from __future__ import annotations

import pandas as pd

from kicktimes.report import (
    autocorrelation,
    counts,
    lyapunov,
    mmpp,
    poisson,
    recurrence,
    renewal,
)
from kicktimes.report.answers import answers, overview_table, poisson_share, ratio_curves_figure
from kicktimes.report.context import Section
from kicktimes.report.controls import compute_controls
from kicktimes.report.counts import experiment_kinetic
from kicktimes.report.decomposition import gap_decomposition, gap_figure
from kicktimes.report.effects import BUILT_IN
from kicktimes.report.store import PAPER_SCALE, is_paper_scale
from kicktimes.stats import SHARE_RULE, ratio_rule
from kicktimes.stats.findings import findings_table

__all__ = ["collect", "scale_statement", "section", "EFFECT_MODULES", "STATEMENT_COLUMNS"]

#: the modules whose ``effects(ctx)`` make the Findings, in the order of the questions
EFFECT_MODULES = (poisson, renewal, mmpp, counts, lyapunov, recurrence, autocorrelation)
#: the columns of ``findings_statements.csv``: one row per `Effect`
STATEMENT_COLUMNS = ("question", "system", "quantity", "estimate", "ci_low", "ci_high",
                     "verdict", "method", "rule", "detail")


def collect(ctx):
    """Every module's effects, in question order."""
    out = []
    for module in EFFECT_MODULES:
        out += module.effects(ctx)
    return out


def scale_statement(store):
    """``(is_paper_scale, sentence)`` describing the store's size."""
    exp = store.experiment
    coll = store.collisions
    per_ic = coll.groupby("radius", observed=True)["n_pp"].mean()
    r0 = float(per_ic.index.min())
    text = (
        f"{exp.name}: {exp.n_ics} ICs × {len(exp.radii)} radii, {exp.n_steps} steps of "
        f"τ = {exp.tau:g}; {per_ic.loc[r0]:.3g} disk-disk collisions per IC at r = {r0:g} "
        f"({per_ic.max():.3g} at most)"
    )
    return is_paper_scale(exp), text


def rules_text(ctx):
    return (
        "Verdict rules. Ratios (kicked / two-particle, observed / kinetic): "
        + ratio_rule(tolerance=ctx.tolerance)
        + ". Shares (of rejections against α, of fitted ICs against 1/2): "
        + SHARE_RULE.format(level=0.5).replace("0.5", "the level")
        + ". Ratios average the per-radius ratios of ensemble means; their CIs come from "
        f"{ctx.n_boot} bootstrap resamples of the IC indices (seeded from the experiment's "
        "seed; the same resamples for every ratio, each applied to all systems and radii). "
        f"'{BUILT_IN}' marks agreement the kicked system has by construction (kick rate = "
        "collision rate): it is not a confirmation."
    )


def section(ctx):
    """The Findings section of one store, and its effects as a table."""
    effects = collect(ctx)
    paper, scale = scale_statement(ctx.store)
    sec = Section("findings", f"Findings: {ctx.exp.name}", answers_first=True)
    if not paper:
        sec.banner(
            f"A pipeline check, not an answer: {scale}, below the paper's scale "
            f"({PAPER_SCALE['n_ics']} ICs, {PAPER_SCALE['n_steps']}+ steps). The tables and "
            "figures below show that every stage runs; their verdicts are too noisy to read. "
            "The answers at the paper's scale are in docs/results/README.md of the kicktimes "
            "repository, and `kicktimes reproduce --scale paper` computes them (about 13 "
            "minutes on 2 cores: 788 s measured on 2026-11-28, docs/benchmarks.md)."
        )
    else:
        sec.text(f"Scale: {scale}.")
    computed = compute_controls(
        ctx.results, ctx.store.collisions, family=ctx.exp.name, eps=ctx.exp.eps,
        rule=ctx.exp.rule, rng=ctx.boot_rng(), n_boot=ctx.n_boot, resamples=ctx.resamples,
        kinetic=experiment_kinetic(ctx.exp),
    )
    if ctx.found.rejections is not None and not ctx.found.rejections.empty:
        # the Poisson question joins the findings table, under the same controls
        from kicktimes.report.controls import COLUMNS, Controls, poisson_rows, with_robustness

        extra = pd.DataFrame(poisson_rows(ctx.exp.name, ctx.found.rejections,
                                          ctx.found.poisson_per_ic, alpha=ctx.alpha,
                                          rng=ctx.boot_rng(), n_boot=ctx.n_boot,
                                          null=ctx.found.null_calibration,
                                          cis=ctx.found.poisson_cis,
                                          referenced=ctx.found.null_referenced),
                             columns=list(COLUMNS))
        computed = Controls(with_robustness(pd.concat([computed.table, extra],
                                                      ignore_index=True)), computed.curves)
    controls = computed.table
    ctx.found.controls = computed
    if paper:  # below paper scale the verdicts answer nothing (the banner says so)
        for sentence in answers(controls, {ctx.exp.name: poisson_share(effects)}):
            sec.text(sentence.replace("**", ""))
    sec.table("findings", controls, "Findings under their controls (ratio to the two-disk "
              "value, 95 % CI, verdict, robust to every control)", show=False)
    sec.table("findings_overview", overview_table(controls), "Overview: ✓ robust to every "
              "control; ✗ depends on the named control")
    sec.table("findings_by_radius", computed.curves, "Every ratio per radius, under every "
              "control (95 % CI, bootstrap clustered on ICs)", show=False)
    sec.figure(
        "fig00_ratios_vs_radius",
        ratio_curves_figure(computed.curves),
        "The ratio of each kicked system to the two-disk value against r, per diagnostic, with "
        "95 % CIs (bootstrap clustered on ICs) and the ±10 % band; the recurrence panels on "
        "uniform-time samples (on the paper's samples the kicked systems' ratios are inflated "
        "by where the samples fall: see the table).",
    )
    gaps = gap_decomposition(
        ctx.results, ctx.store.collisions, family=ctx.exp.name, eps=ctx.exp.eps,
        rule=ctx.exp.rule, rng=ctx.boot_rng(), n_boot=min(ctx.n_boot, 1000),
        kinetic=experiment_kinetic(ctx.exp),
    )
    ctx.found.gaps = gaps
    if not gaps.empty:
        sec.table("gap_decomposition", gaps, "How much of the paper's kicked-versus-two-disk "
                  "gap |log ratio| each ingredient closes: the scatter kick (deflection law), "
                  "then the kinetic rate (state-dependent timing), and what is left (partner "
                  "memory, re-collisions); ratios and shares under every control, 95 % CI",
                  show=False)
        sec.figure(
            "fig00b_gap_decomposition", gap_figure(gaps),
            "Each ingredient of the kicks against the two-disk value: the paper's kick "
            "(uniform direction, Poisson times), a collision with a virtual partner, and the "
            "same collisions at the kinetic rate of the disk's own angular momentum (95 % CI, "
            "bootstrap clustered on ICs; recurrence on uniform-time samples).",
        )
    sec.fold()
    sec.text("All statements, under the primary setting:")
    sec.bullets(e.sentence() for e in effects)
    sec.text(rules_text(ctx))
    table = findings_table(effects, columns=STATEMENT_COLUMNS)
    sec.table("findings_statements", table, "Findings (effect, 95 % CI, verdict)", show=False)
    ctx.found.effects = effects
    return sec

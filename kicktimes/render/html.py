"""Writing the pages: figures (PNG, optionally PDF), tables (CSV), the HTML of the
sections and the page around them (:func:`write_page`: the sweep report of
:func:`kicktimes.report.build_report` and the page of ``kicktimes analyze``,
:func:`kicktimes.report.analyze_page.write_analysis`); every file atomically
(:func:`kicktimes.fileio.atomic_write_bytes`)."""

from __future__ import annotations

import base64
import datetime as _dt
import html
import io
import re
from pathlib import Path

from kicktimes import __version__
from kicktimes.fileio import atomic_write_bytes
from kicktimes.memory import keep_freed_memory

__all__ = [
    "write_page",
    "toc_item",
    "write_outputs",
    "embed_figures",
    "save_figure",
    "render_figures",
    "write_table",
    "write_text",
    "table_html",
    "CSS",
]

#: 4 significant figures in every HTML table (the CSV files keep full precision)
_FLOAT = "{:.4g}".format

CSS = """
body{font-family:sans-serif;max-width:70em;margin:2em auto;padding:0 1em;color:#222}
h1{font-size:1.6em}h2{font-size:1.25em;border-bottom:1px solid #ccc;margin-top:2em}
table.dataframe{border-collapse:collapse;font-size:.8em;margin:.5em 0 1em}
table.dataframe td,table.dataframe th{border:1px solid #ccc;padding:2px 6px;text-align:right}
figure{margin:1em 0}figure img{max-width:100%}figcaption{font-size:.9em;color:#444}
.meta td{padding:1px 8px;vertical-align:top}.note{background:#fff6dd;padding:.5em}
.banner{background:#ffe3e3;border:1px solid #d66;padding:.6em;font-weight:bold}
.table-wrap{overflow-x:auto;max-width:100%;max-height:32em;overflow-y:auto}
ul.findings li{margin:.3em 0}
details.contents{margin:1.5em 0;border:1px solid #ccc;padding:.3em .8em}
details.contents summary{cursor:pointer;font-weight:bold}
p.built{font-size:.85em;color:#555}
"""


def table_html(df):
    """A table with 4 significant figures in a scrollable container (wide tables scroll
    instead of stretching the page)."""
    inner = df.to_html(index=False, float_format=_FLOAT, na_rep="NaN", border=0)
    return f'<div class="table-wrap">{inner}</div>'


def _png(fig, dpi):
    """PNG bytes of ``fig`` at ``dpi``: the bytes of ``fig.savefig(format="png", dpi=dpi)``
    from one draw instead of two.

    With a layout engine, ``savefig`` draws the figure twice (a draw with rendering
    disabled that runs the constrained layout, then the real one); an Agg canvas draw runs
    the layout and renders in one pass, and `matplotlib.image.imsave` encodes the buffer
    exactly as ``savefig`` does (same metadata and compression), so the files are
    byte-identical (tested) in less time (benchmarks/bench_report.py; docs/benchmarks.md).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.image import imsave

    old_dpi = fig.dpi
    fig.set_dpi(dpi)
    try:
        canvas = FigureCanvasAgg(fig)
        canvas.draw()
        buf = io.BytesIO()
        imsave(buf, canvas.buffer_rgba(), format="png", origin="upper", dpi=dpi)
    finally:
        fig.set_dpi(old_dpi)
    return buf.getvalue()


def _render(fig, dpi, pdf):
    """``(png bytes, pdf bytes or None)`` of one figure."""
    png, pdf_bytes = _png(fig, dpi), None
    if pdf:
        buf = io.BytesIO()
        # no creation date: the same figure gives the same bytes (and cache entry)
        fig.savefig(buf, format="pdf", metadata={"CreationDate": None})
        pdf_bytes = buf.getvalue()
    return png, pdf_bytes


#: the figures a forked renderer process reads: inherited with the process, never pickled
_PENDING: list = []


def _render_pending(job):
    k, dpi, pdf = job
    return _render(_PENDING[k], dpi, pdf)


def render_figures(figs, dpi, *, pdf=False, workers=1):
    """PNG (and PDF) bytes of each figure, ``[(png, pdf or None), ...]`` in order.

    Rendering (layout, drawing, compression) is ~0.3-1 s a figure and a report has ~30:
    with ``workers > 1`` they are rendered on that many processes forked from this one,
    which inherit the Figure objects (nothing is pickled) and return the bytes. A figure
    renders to the same bytes in a forked child as here (each is rendered once, from the
    same state), so the files do not depend on ``workers``. Without ``fork`` (not Linux),
    or with fewer than two figures, everything renders here.
    """
    global _PENDING
    import multiprocessing as mp

    figs = list(figs)
    if workers < 2 or len(figs) < 2 or "fork" not in mp.get_all_start_methods():
        return [_render(fig, dpi, pdf) for fig in figs]
    from concurrent.futures import ProcessPoolExecutor

    _PENDING = figs
    try:
        with ProcessPoolExecutor(
            max_workers=min(workers, len(figs)), mp_context=mp.get_context("fork"),
            initializer=keep_freed_memory,
        ) as ex:
            return list(ex.map(_render_pending, [(k, dpi, pdf) for k in range(len(figs))]))
    finally:
        _PENDING = []


def _store_rendered(out, name, rendered, files):
    png, pdf_bytes = rendered
    files[f"{name}.png"] = atomic_write_bytes(out / f"{name}.png", png)
    if pdf_bytes is not None:
        files[f"{name}.pdf"] = atomic_write_bytes(out / f"{name}.pdf", pdf_bytes)
    return png


def save_figure(fig, out, name, dpi, files, *, pdf=False):
    """Write ``fig`` as ``name.png`` (and ``name.pdf``), atomically; record their SHA-256
    in ``files``; return the PNG's bytes."""
    return _store_rendered(out, name, _render(fig, dpi, pdf), files)


def write_table(out, name, df, files):
    """``df`` as ``name.csv`` (no index), atomically, its SHA-256 recorded in ``files``."""
    files[f"{name}.csv"] = atomic_write_bytes(out / f"{name}.csv", df.to_csv(index=False).encode())


def write_text(out, filename, text, files):
    """``text`` as ``filename`` (UTF-8), atomically, its SHA-256 recorded in ``files``."""
    files[filename] = atomic_write_bytes(out / filename, text.encode("utf-8"))


#: the page embeds each figure's PNG; the cached HTML fragments name the file instead
#: (``src="kt-png:NAME.png"``) and :func:`embed_figures` inlines it when the page is written
_PNG_REF = re.compile(r'src="kt-png:([^"/\\]+\.png)"')


def embed_figures(fragment, out):
    """``fragment`` with every ``kt-png:`` reference replaced by the file's base64 data."""

    def inline(match):
        data = base64.b64encode((out / match.group(1)).read_bytes()).decode("ascii")
        return f'src="data:image/png;base64,{data}"'

    return _PNG_REF.sub(inline, fragment)


def _block_html(kind, block):
    if kind == "fold":
        return ""
    if kind == "banner":
        return f'<p class="banner">{html.escape(block)}</p>'
    if kind == "ul":
        items = "".join(f"<li>{html.escape(item)}</li>" for item in block)
        return f'<ul class="findings">{items}</ul>'
    return f"<p>{html.escape(block)}</p>"


def write_outputs(
    sections, out, dpi, prefix="", *, pdf=True, files=None, embed=True, workers=1
):
    """Save figures (PNG, and PDF if ``pdf``) and tables (CSV), atomically, recording each
    file's SHA-256 in ``files``; return the HTML of the sections, with the PNGs embedded
    (``embed``) or referenced for :func:`embed_figures` (the report's cached fragments).
    The figures render on ``workers`` processes (:func:`render_figures`)."""
    files = {} if files is None else files
    rendered = iter(
        render_figures(
            [fig for sec in sections for _, fig, _ in sec.figures], dpi, pdf=pdf, workers=workers
        )
    )
    body = []
    for sec in sections:
        body.append(f'<h3 id="{prefix}{sec.key}">{html.escape(sec.title)}</h3>')
        figures = []
        for name, _fig, caption in sec.figures:
            name = prefix + name
            _store_rendered(out, name, next(rendered), files)
            links = f'<a href="{name}.png">PNG</a>' + (
                f', <a href="{name}.pdf">PDF</a>' if pdf else ""
            )
            figures.append(
                f'<figure><img alt="{html.escape(name)}" src="kt-png:{name}.png">'
                f"<figcaption>{html.escape(caption)} Files: {links}.</figcaption></figure>"
            )
        blocks = [_block_html(kind, block) for kind, block in sec.blocks]
        shown, listed = [], []
        for name, df, title, show in sec.tables:
            name = prefix + name
            write_table(out, name, df, files)
            link = f'<a href="{name}.csv">{name}.csv</a>'
            if show:
                shown.append(f"<h4>{html.escape(title)} ({link})</h4>{table_html(df)}")
            else:
                listed.append(f"<p>{html.escape(title)}: {link} ({len(df)} rows).</p>")
        if sec.answers_first:
            kinds = [kind for kind, _ in sec.blocks]
            fold = next((k for k, kind in enumerate(kinds) if kind in ("fold", "ul")),
                        len(kinds))
            body += blocks[:fold] + shown + figures + blocks[fold:] + listed
        else:
            body += figures + blocks + shown + listed
        sec.figures.clear()  # drop the Figure objects: nothing stays alive
    text = "\n".join(body)
    return embed_figures(text, out) if embed else text


def toc_item(anchor, title, children=()):
    """One entry of a page's contents: a link to ``#anchor`` titled ``title``, with the
    entries ``children`` (HTML ``<li>`` items) nested below it."""
    nested = f"<ul>{''.join(children)}</ul>" if children else ""
    return f'<li><a href="#{anchor}">{html.escape(title)}</a>{nested}</li>'


def write_page(out, title, *, sources, toc, body, lead="", appendix="", files=None) -> Path:
    """Write the self-contained page ``out/report.html``, atomically.

    The page opens with its answers: the title, one line saying what it was built from,
    then ``lead`` (the findings), then the contents, collapsed, then the rest.

    Parameters
    ----------
    out : pathlib.Path
        The output folder.
    title : str
        The page's title and heading.
    sources : str
        HTML (escaped by the caller) completing "Built <time> with kicktimes <version>
        from ...": what the page was computed from (paths relative to ``out``, short).
    toc : sequence of str
        The contents, ``<li>`` items (:func:`toc_item`).
    body : str
        The sections' HTML (:func:`write_outputs`), figures embedded.
    lead : str, optional
        HTML shown before the contents: the answers.
    appendix : str, optional
        HTML after the sections (the report's timings).
    files : dict, optional
        Records the page's SHA-256 (as :func:`write_table`).

    Returns
    -------
    pathlib.Path
        ``out / "report.html"``.
    """
    built = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
    n_items = sum(item.count("<li>") for item in toc)
    text = (
        '<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">'
        f"<title>{html.escape(title)}</title><style>{CSS}</style></head><body>"
        f"<h1>{html.escape(title)}</h1><p class=\"built\">Built {built} with kicktimes "
        f"{html.escape(__version__)} from {sources}.</p>{lead}"
        f'<details class="contents"><summary>Contents ({n_items} sections)</summary>'
        f"<ul>{''.join(toc)}</ul></details>"
        f"{body}{appendix}</body></html>"
    )
    write_text(out, "report.html", text, {} if files is None else files)
    return out / "report.html"

r"""What every generated page shares: the rendering, not the statistics.

- :mod:`kicktimes.render.pages`: the Markdown pages of ``docs/results/`` (the title and
  "Generated … from …" line, tables, the phrases beside a verdict of
  :mod:`kicktimes.stats`, the number formats, the shared null-calibration file);
- :mod:`kicktimes.render.html`: the HTML pages (the sweep report of
  :func:`kicktimes.report.build_report` and the page of ``kicktimes analyze``): figures as
  PNG (and PDF), tables as CSV, sections and the page around them, each file written
  atomically;
- :mod:`kicktimes.render.figures`: the figure style (systems' labels and colours, axes,
  the input checks of every figure function);
- :mod:`kicktimes.render.provenance`: the closing table of every results page, from a
  CSV's columns to the function that computed them.

Nothing here computes a number that a page states: the numbers come from
:mod:`kicktimes.stats` and the studies; this layer only writes them.
"""

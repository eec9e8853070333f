"""Sphinx configuration of the kicktimes documentation (API reference from the docstrings,
the guides in docs/*.md, the notebooks rendered as they are committed).

Build: ``python -m pip install -e '.[docs]' && sphinx-build -W -b html docs docs/_build/html``
"""

import os
import sys

sys.path.insert(0, os.path.abspath(".."))

project = "kicktimes"
author = "kicktimes developers"
from kicktimes import __version__ as release  # noqa: E402

version = release
extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_nb",
]
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
root_doc = "index"
exclude_patterns = ["_build", "results/*.csv", "**/.ipynb_checkpoints"]
autosummary_generate = True
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
nb_execution_mode = "off"  # the notebooks are committed executed (docs/notebooks.md)
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]
html_theme = "alabaster"

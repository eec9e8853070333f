"""Shared by the compile-time tests: run code in a fresh process with an empty numba cache
and report what numba compiled."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

_FOOTER = """
sigs = {}
for _, ev in rec.buffer:
    if ev.is_start:
        f = ev.data["dispatcher"].py_func
        sigs.setdefault(f"{f.__module__}.{f.__qualname__}", []).append(str(ev.data["args"]))
print(json.dumps(sigs))
"""


def compiled_signatures(setup: str, calls: str, cache_dir) -> dict[str, list[str]]:
    """``{qualified function name: [argument types of each compilation]}`` of everything
    numba compiles while ``calls`` runs (after ``setup``) in a new interpreter whose numba
    cache is the empty ``cache_dir``."""
    script = (
        "import json\nfrom numba.core import event\n" + textwrap.dedent(setup)
        + '\nwith event.install_recorder("numba:compile") as rec:\n'
        + textwrap.indent(textwrap.dedent(calls), "    ") + _FOOTER
    )
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache_dir))
    out = subprocess.run([sys.executable, "-c", script], env=env, check=True,
                         capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def string_formatting(sigs: dict) -> list[str]:
    """The compiled functions that belong to numba's string formatting (error messages of
    slice assignments or of ``raise`` with formatted text: seconds of compilation)."""
    return [name for name in sigs if "unicode" in name or "raise_with_shape" in name
            or "ol_str_generic" in name]

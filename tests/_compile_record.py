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


#: the drivers, compiled once per set of observers (simulation alone, with tangent
#: vectors, tangent vectors alone; the twins once per system): an argument passed as None
#: is compiled out, so up to 3 signatures each
DRIVERS = ({f"kicktimes.billiard.kernels.{m}.{f}" for m in ("drive_two", "drive_one")
            for f in ("drive", "_run")}
           | {"kicktimes.billiard.kernels.twins._ftle",
              "kicktimes.billiard.kernels.drive_one._simulate"})


def compiled_more_than_once(ours: dict) -> dict:
    """The kernels of ``ours`` (name -> signatures) with more signatures than they should
    have: more than 3 for a driver (`DRIVERS`), more than 1 for any other kernel except
    the buffer growth ``observe.grow_to`` (generic over the dtype)."""
    return {name: s for name, s in ours.items()
            if len(s) > (3 if name in DRIVERS else 1)
            and name != "kicktimes.billiard.kernels.observe.grow_to"}


def kicktimes_compiles(setup: str, calls: str, cache_dir) -> dict:
    """Run ``calls`` after ``setup`` in a fresh process with an empty numba cache in
    ``cache_dir``; returns kicktimes' own kernels' signatures (name -> signatures), and
    asserts what every kernel must: no kernel compiled more often than it should
    (`compiled_more_than_once`) and no numba string formatting pulled in."""
    sigs = compiled_signatures(setup, calls, cache_dir)
    ours = {name: s for name, s in sigs.items() if name.startswith("kicktimes.")}
    assert compiled_more_than_once(ours) == {}
    assert string_formatting(sigs) == []
    return ours


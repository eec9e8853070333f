"""Print a pip constraints file that pins every dependency at the lower bound that
pyproject.toml declares (the runtime ones and the named extras), for the CI run of the
oldest declared versions: ``python .ci/lower_bounds.py test > lower.txt`` and then
``pip install --only-binary=:all: -c lower.txt -e '.[test]'``.

A requirement without a ``>=`` bound is an error: a bound that is declared is a bound
that is tested.
"""

from __future__ import annotations

import re
import sys
import tomllib
from pathlib import Path

REQUIREMENT = re.compile(
    r"^\s*(?P<name>[A-Za-z0-9][A-Za-z0-9._-]*)(\[[^\]]*\])?\s*>=\s*(?P<low>[0-9][^,;\s]*)"
    r"[^;]*(?P<marker>;.*)?$"
)


def lower_bounds(pyproject, extras):
    """``name==lower ; marker`` lines for the dependencies and the given extras."""
    project = tomllib.loads(Path(pyproject).read_text(encoding="utf-8"))["project"]
    requirements = list(project["dependencies"])
    for extra in extras:
        requirements += project["optional-dependencies"][extra]
    lines = {}
    for requirement in requirements:
        match = REQUIREMENT.match(requirement.split("#")[0])
        if match is None:
            raise SystemExit(f"pyproject.toml: {requirement!r} declares no '>=' lower bound")
        name = match["name"].lower().replace("_", "-")
        line = f"{name}=={match['low']}{match['marker'] or ''}"
        if lines.setdefault(name, line) != line:
            raise SystemExit(f"pyproject.toml: {name} has two lower bounds")
    return sorted(lines.values())


if __name__ == "__main__":
    root = Path(__file__).resolve().parents[1]
    print("\n".join(lower_bounds(root / "pyproject.toml", sys.argv[1:])))

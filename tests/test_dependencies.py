"""Every third-party module that kicktimes, its tests or its notebooks import is declared.

A module imported by ``kicktimes/`` must come from a distribution named in
``pyproject.toml``'s ``dependencies`` or in one of its extras; a module imported by
``tests/`` or by the notebooks the tests execute must come from ``dependencies`` or the
``test`` extra, because the README's test command installs exactly ``.[test]``. A module
that is only on the developer's machine (``mpmath`` was, once) fails here before it fails
on a user's fresh virtual environment.

The module-to-distribution map comes from the installed metadata
(:func:`importlib.metadata.packages_distributions`), so every declared distribution must
be installed for the test to resolve its modules: the test environment is ``.[test]``.
"""

from __future__ import annotations

import ast
import re
import sys
import tomllib
from importlib.metadata import packages_distributions
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _distribution_name(requirement: str) -> str:
    """The normalised distribution name of a PEP 508 requirement (``"dask[distributed]>=1"``
    gives ``"dask"``)."""
    name = re.match(r"\s*([A-Za-z0-9][A-Za-z0-9._-]*)", requirement).group(1)
    return re.sub(r"[-_.]+", "-", name).lower()


def _declared() -> dict[str, set[str]]:
    """Declared distributions: ``"core"`` and one entry per extra."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    declared = {"core": {_distribution_name(r) for r in project["dependencies"]}}
    for extra, requirements in project.get("optional-dependencies", {}).items():
        declared[extra] = {_distribution_name(r) for r in requirements}
    # dask[distributed] brings the distributed package with it
    for names in declared.values():
        if "dask" in names:
            names.add("distributed")
    return declared


def _third_party_imports(folder: Path) -> dict[str, Path]:
    """Top-level third-party modules imported anywhere under ``folder``, each with one file
    that imports it (local helper modules beside the importing file are left out)."""
    found: dict[str, Path] = {}
    for path in sorted(folder.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for name in names:
                top = name.split(".")[0]
                if (
                    top in sys.stdlib_module_names
                    or top in {"kicktimes", "__future__"}
                    or (path.parent / f"{top}.py").exists()
                ):
                    continue
                found.setdefault(top, path)
    return found


def _undeclared(folder: str, allowed: set[str]) -> list[str]:
    """Imports under ``folder`` from no distribution in ``allowed``.

    A module that is not installed passes only if a distribution of its name is declared
    somewhere (the ``outside`` extra's ``billiards``, which
    the notebooks import only when present)."""
    distributions = packages_distributions()
    anywhere = set().union(*_declared().values())
    problems = []
    for module, path in _third_party_imports(ROOT / folder).items():
        names = {_distribution_name(d) for d in distributions.get(module, [])}
        if not names:
            if _distribution_name(module) not in anywhere:
                problems.append(
                    f"{module} (imported by {path.relative_to(ROOT)}) is neither installed "
                    "nor declared"
                )
        elif not names & allowed:
            problems.append(
                f"{module} (imported by {path.relative_to(ROOT)}, from {sorted(names)}) "
                "is not declared"
            )
    return problems


def test_the_package_imports_only_declared_distributions():
    declared = _declared()
    allowed = set().union(*declared.values())
    assert _undeclared("kicktimes", allowed) == []


@pytest.mark.parametrize("folder", ["tests", "notebooks"])
def test_the_test_command_installs_every_module_the_tests_import(folder):
    declared = _declared()
    assert _undeclared(folder, declared["core"] | declared["test"]) == []


def test_the_check_sees_a_missing_declaration():
    """The check itself: a module from a distribution outside ``.[test]`` is reported."""
    distributions = packages_distributions()
    assert "numpy" in {_distribution_name(d) for d in distributions["numpy"]}
    declared = _declared()
    assert "numpy" in declared["core"]
    assert "billiards" not in declared["core"] | declared["test"]
    assert _distribution_name("dask[distributed]>=2024.1") == "dask"
    assert _distribution_name("jupyter_client>=8") == "jupyter-client"

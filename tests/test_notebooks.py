"""The notebooks: each runs from top to bottom, and its pair agrees.

Every notebook is kept twice, as a jupytext percent script (``notebooks/X.py``, the file to
edit and review) and as ``notebooks/X.ipynb`` executed at the small size (so it renders with
its outputs). These tests execute each notebook with nbclient in a temporary working
directory (``TMPDIR`` too, so nothing is left in the repository or in /tmp) and check that
the two files hold the same cells. The default suite executes each notebook at its
``KICKTIMES_NOTEBOOK_SIZE=test`` size (seconds: every cell runs); the ``full`` marker
executes it at the ``small`` size its committed outputs show.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

jupytext = pytest.importorskip("jupytext")
nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")
pytest.importorskip("ipykernel")

NOTEBOOK_DIR = Path(__file__).resolve().parents[1] / "notebooks"
NOTEBOOKS = sorted(p.stem for p in NOTEBOOK_DIR.glob("*.py"))
CELL_TIMEOUT = 600  # seconds; a cold numba cache compiles the kernels in the first cells
KERNEL = "python3"


def _cells(nb):
    return [(cell.cell_type, cell.source.strip()) for cell in nb.cells]


@pytest.fixture(scope="module")
def kernel_env(tmp_path_factory):
    """Environment variables under which the ``python3`` kernel can be found.

    ipykernel normally provides the ``python3`` kernelspec; if it is not installed, one is
    written to a temporary prefix (pointing to this interpreter) and put on JUPYTER_PATH.
    """
    from jupyter_client.kernelspec import KernelSpecManager

    if KERNEL in KernelSpecManager().find_kernel_specs():
        return {}
    from ipykernel.kernelspec import install

    prefix = tmp_path_factory.mktemp("kernelspec")
    install(kernel_name=KERNEL, prefix=str(prefix))
    paths = [str(prefix / "share" / "jupyter"), os.environ.get("JUPYTER_PATH", "")]
    return {"JUPYTER_PATH": os.pathsep.join(p for p in paths if p)}


def test_every_notebook_is_a_paired_script_and_notebook():
    assert NOTEBOOKS, f"no notebooks found in {NOTEBOOK_DIR}"
    for name in NOTEBOOKS:
        assert (NOTEBOOK_DIR / f"{name}.ipynb").is_file(), f"{name}.py has no paired .ipynb"
        text = (NOTEBOOK_DIR / f"{name}.py").read_text()
        assert "formats: ipynb,py:percent" in text, f"{name}.py is not paired by jupytext"
    stray = {p.stem for p in NOTEBOOK_DIR.glob("*.ipynb")} - set(NOTEBOOKS)
    assert not stray, f"notebooks without a percent script: {sorted(stray)}"


@pytest.mark.parametrize("name", NOTEBOOKS)
def test_script_and_notebook_hold_the_same_cells(name):
    script = jupytext.read(NOTEBOOK_DIR / f"{name}.py")
    notebook = nbformat.read(NOTEBOOK_DIR / f"{name}.ipynb", as_version=4)
    assert _cells(script) == _cells(notebook), (
        f"{name}.py and {name}.ipynb differ; run `jupytext --sync notebooks/{name}.py` "
        "and re-execute the notebook"
    )


@pytest.mark.parametrize("name", NOTEBOOKS)
def test_committed_notebook_was_executed_without_errors(name):
    notebook = nbformat.read(NOTEBOOK_DIR / f"{name}.ipynb", as_version=4)
    code = [cell for cell in notebook.cells if cell.cell_type == "code"]
    assert code, f"{name}.ipynb has no code cells"
    unexecuted = [i for i, cell in enumerate(code) if cell.execution_count is None]
    assert not unexecuted, f"{name}.ipynb: code cells {unexecuted} were not executed"
    errors = [o for cell in code for o in cell.outputs if o.output_type == "error"]
    assert not errors, f"{name}.ipynb holds error outputs: {errors[0].get('ename')}"


@pytest.mark.parametrize("size", ["test", pytest.param("small", marks=pytest.mark.full)])
@pytest.mark.parametrize("name", NOTEBOOKS)
def test_notebook_executes_from_top_to_bottom(
    name, size, tmp_path, monkeypatch, kernel_env, record_property
):
    for key, value in kernel_env.items():
        monkeypatch.setenv(key, value)
    monkeypatch.setenv("KICKTIMES_NOTEBOOK_SIZE", size)
    monkeypatch.setenv("TMPDIR", str(tmp_path))  # the kernel's tempfile goes here
    cwd = tmp_path / "cwd"
    cwd.mkdir()
    before = sorted(p.name for p in NOTEBOOK_DIR.iterdir())
    notebook = jupytext.read(NOTEBOOK_DIR / f"{name}.py")
    client = nbclient.NotebookClient(
        notebook,
        timeout=CELL_TIMEOUT,
        kernel_name=KERNEL,
        record_timing=False,
        resources={"metadata": {"path": str(cwd)}},
    )
    t0 = time.perf_counter()
    client.execute()  # raises CellExecutionError, naming the cell, if a cell fails
    seconds = time.perf_counter() - t0
    record_property("execution_seconds", round(seconds, 1))
    print(f"{name} ({size}): executed in {seconds:.1f} s")
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    texts = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "notebook computed in" in texts, f"{name} did not reach its last cell"
    assert sorted(p.name for p in NOTEBOOK_DIR.iterdir()) == before, "files left in notebooks/"

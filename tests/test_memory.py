"""kicktimes.memory: kicktimes' own worker processes keep freed memory for reuse; the
command line and the report run the garbage collector less often."""

from __future__ import annotations

import gc
import subprocess
import sys
import weakref

import pytest

from kicktimes.memory import _GC_THRESHOLDS, fewer_collections

_FAULTS = r"""
import dataclasses, resource
from kicktimes.memory import keep_freed_memory
from kicktimes.experiment import execute_task, preset

exp = dataclasses.replace(preset("family_a"), radii=[0.02], n_ics=4, block_size=4)
task = exp.tasks()[0]

def faults():
    # page faults of one sweep task (4 ICs x 5 systems of the paper's family A)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    execute_task(exp, task)
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before

execute_task(exp, task)
plain = faults()
applied = keep_freed_memory()
execute_task(exp, task)
print(applied, plain, faults())
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt")
def test_freed_arrays_are_reused_instead_of_faulted_in_again():
    out = subprocess.run([sys.executable, "-c", _FAULTS], check=True, capture_output=True,
                         text=True).stdout.split()
    applied, plain, kept = out[0] == "True", float(out[1]), float(out[2])
    if not applied:
        pytest.skip("not glibc: the allocator is left alone")
    # by default the task's large arrays are mmap-ed afresh and returned on free: every
    # call faults their pages in again (about 12 000 faults); kept, they are reused
    assert plain > 2000
    assert kept < plain / 20


def test_the_local_pool_workers_keep_freed_memory():
    from kicktimes.experiment import runner

    with runner.local_pool(1) as pool:
        assert pool._initializer is runner._worker_init
    assert runner._worker_init.__doc__ and "keep_freed_memory" in runner._worker_init.__doc__


def test_fewer_collections_raises_the_thresholds_and_restores_them():
    before = gc.get_threshold()
    with fewer_collections():
        inside = gc.get_threshold()
    assert inside == tuple(max(a, b) for a, b in zip(_GC_THRESHOLDS, before, strict=True))
    assert inside[0] >= 100_000
    assert gc.get_threshold() == before


def test_fewer_collections_never_lowers_a_higher_setting():
    before = gc.get_threshold()
    gc.set_threshold(500_000, 5, 50)
    try:
        with fewer_collections():
            assert gc.get_threshold() == (500_000, 20, 50)
        assert gc.get_threshold() == (500_000, 5, 50)
    finally:
        gc.set_threshold(*before)


def test_reference_cycles_are_still_freed_without_an_explicit_collection():
    class Node:
        pass

    with fewer_collections():
        node = Node()
        node.self = node  # a cycle: only the collector frees it
        ref = weakref.ref(node)
        del node
        # more new containers than the youngest generation's threshold: it is collected
        keep = [[] for _ in range(3 * _GC_THRESHOLDS[0])]
        assert ref() is None
        del keep

"""Specification of the first-run compilation notice (kicktimes._compile)."""

from __future__ import annotations

import io

from kicktimes import _compile


def test_a_cold_cache_is_announced_once_with_an_estimate(monkeypatch):
    monkeypatch.setattr(_compile, "_is_cold", lambda dispatcher: True)
    stream = io.StringIO()
    seconds = _compile.announce(stream=stream)
    expected = sum(s for *_, s in _compile.SWEEP_KERNELS)
    assert abs(seconds - expected) <= 2.5 and seconds % 5 == 0
    assert stream.getvalue() == (
        f"compiling kicktimes' numba kernels (once, about {int(seconds)} s)...\n"
    )


def test_a_warm_cache_is_not_announced(monkeypatch):
    monkeypatch.setattr(_compile, "_is_cold", lambda dispatcher: False)
    stream = io.StringIO()
    assert _compile.announce(stream=stream) == 0.0
    assert stream.getvalue() == ""


def test_unknown_cache_state_says_nothing(monkeypatch):
    # numba's private cache API may change: then nothing is printed, nothing fails
    monkeypatch.setattr(_compile, "_is_cold", lambda dispatcher: None)
    assert _compile.cold_kernels() == []


def test_the_cache_probe_reads_numbas_index_of_a_real_kernel():
    from kicktimes.billiard.two_particle import simulate_two_kernel

    assert _compile._is_cold(simulate_two_kernel) in (True, False)

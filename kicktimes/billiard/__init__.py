"""Event-driven simulation of disks in the unit circular table (numba kernels + thin API)."""

from kicktimes.billiard.initial import initial_conditions
from kicktimes.billiard.one_particle import simulate_one_particle
from kicktimes.billiard.runs import OneParticleRun, TwoParticleRun, read_run
from kicktimes.billiard.two_particle import simulate_two_particle

__all__ = [
    "OneParticleRun",
    "TwoParticleRun",
    "initial_conditions",
    "read_run",
    "simulate_one_particle",
    "simulate_two_particle",
]

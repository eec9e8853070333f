"""Event-driven simulation of disks in the unit circular table or a periodic box (numba kernels
+ thin API)."""

from kicktimes.billiard.disk_states import box_side, initial_state
from kicktimes.billiard.disks_run import DisksPressure, DisksRun
from kicktimes.billiard.initial import initial_conditions
from kicktimes.billiard.kick_law import KickLaw
from kicktimes.billiard.many_disks import simulate_disks
from kicktimes.billiard.one_particle import simulate_one_particle
from kicktimes.billiard.runs import OneParticleRun, TwoParticleRun, read_run
from kicktimes.billiard.two_particle import simulate_two_particle

__all__ = [
    "DisksPressure",
    "DisksRun",
    "KickLaw",
    "OneParticleRun",
    "TwoParticleRun",
    "box_side",
    "initial_conditions",
    "initial_state",
    "read_run",
    "simulate_disks",
    "simulate_one_particle",
    "simulate_two_particle",
]

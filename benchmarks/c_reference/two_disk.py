"""Build and call the reference C loop (two_disk.c) through ctypes.

`load()` compiles two_disk.c with ``cc -O2`` into a temporary folder (``None`` with a reason
when no C compiler works); `TwoDiskC.run` returns the same arrays as
`kicktimes.simulate_two_particle` and `TwoDiskC.run_many` times the C loop over many ICs.
"""

from __future__ import annotations

import ctypes
import math
import os
import shutil
import subprocess
import tempfile

import numpy as np

from kicktimes.billiard import checks as chk
from kicktimes.billiard import geometry

HERE = os.path.dirname(os.path.abspath(__file__))
_dp = ctypes.POINTER(ctypes.c_double)
_ip = ctypes.POINTER(ctypes.c_int64)


class _Out(ctypes.Structure):
    _fields_ = [(name, _dp) for name in ("pp", "bt", "bx", "by", "bs", "stimes", "samples")] + [
        ("bp", ctypes.POINTER(ctypes.c_int8)),
        ("n_pp", ctypes.c_int64),
        ("n_b", ctypes.c_int64),
        ("ns", ctypes.c_int64),
        ("t_end", ctypes.c_double),
        ("st", ctypes.c_double * 11),
        ("status", ctypes.c_int),
    ]


def _arguments(ic, r, rule, sampling, n_steps, tau):
    """The kernel's arguments exactly as `simulate_two_particle` computes them."""
    ic = np.asarray(ic, dtype=np.float64)
    st = np.zeros(11)
    st[1:9] = ic.ravel()
    st[10] = (ic[:, 2:] ** 2).sum()
    mode = 2 if sampling == "paper" else 1
    horizon = n_steps * tau
    rho = 1.0 - r
    speed = 1.0 if rule == "mirror" else math.sqrt(st[10])
    max_events = chk.event_budget(None, horizon=horizon, horizon_name="t", speed=speed, rho=rho,
                                  n_disks=2)
    return dict(st=st, rho=rho, sigma=2.0 * r, rule=chk.RULES[rule],
                t_max=0.0 if mode == 2 else horizon, mode=mode, n_steps=n_steps, tau=tau,
                pp_cap=int(20.0 * r * speed * horizon) + 16,
                b_cap=int(3.0 * speed * horizon) + 64, max_events=max_events,
                stall_dt=chk.stall_time(rho, speed))


class TwoDiskC:
    def __init__(self, lib):
        self.lib = lib
        lib.two_disk.restype = ctypes.c_int
        lib.two_disk.argtypes = [_dp, ctypes.c_double, ctypes.c_double, ctypes.c_int,
                                 ctypes.c_double, ctypes.c_int, ctypes.c_int64, ctypes.c_double,
                                 ctypes.c_int, ctypes.c_int64, ctypes.c_int64, ctypes.c_int64,
                                 ctypes.c_double, ctypes.POINTER(_Out)]
        lib.two_disk_free.argtypes = [ctypes.POINTER(_Out)]
        lib.two_disk_many.restype = ctypes.c_int64
        lib.two_disk_many.argtypes = [_dp, ctypes.c_int64, ctypes.c_double, ctypes.c_double,
                                      ctypes.c_int, ctypes.c_double, ctypes.c_int, ctypes.c_int64,
                                      ctypes.c_double, ctypes.c_int, _ip, _ip, _ip, _dp]

    def run(self, ic, r, *, rule="mirror", sampling="uniform", n_steps, tau, track=0):
        """``dict`` of the run's arrays (copies), as `simulate_two_particle` returns them."""
        a = _arguments(ic, r, rule, sampling, n_steps, tau)
        out = _Out()
        self.lib.two_disk(a["st"].ctypes.data_as(_dp), a["rho"], a["sigma"], a["rule"],
                          a["t_max"], a["mode"], a["n_steps"], a["tau"], track, a["pp_cap"],
                          a["b_cap"], a["max_events"], a["stall_dt"], ctypes.byref(out))
        try:
            def arr(ptr, n):
                return np.ctypeslib.as_array(ptr, shape=(n,)).copy() if n else np.empty(0)

            return dict(pp_times=arr(out.pp, out.n_pp), time=arr(out.bt, out.n_b),
                        particle=arr(out.bp, out.n_b), x=arr(out.bx, out.n_b),
                        y=arr(out.by, out.n_b), sin_theta=arr(out.bs, out.n_b),
                        sample_times=arr(out.stimes, out.ns),
                        samples=arr(out.samples, 2 * out.ns).reshape(-1, 2),
                        t_max=out.t_end, final_state=np.array(out.st[1:9]).reshape(2, 4),
                        status=out.status)
        finally:
            self.lib.two_disk_free(ctypes.byref(out))

    def prepare_many(self, ics, r, *, rule="mirror", sampling="uniform", n_steps, tau):
        """The argument arrays of `run_many` (prepared outside the timed call)."""
        args = [_arguments(ic, r, rule, sampling, n_steps, tau) for ic in ics]
        a0 = args[0]
        return (np.stack([a["st"] for a in args]), len(args), a0["rho"], a0["sigma"], a0["rule"],
                a0["t_max"], a0["mode"], n_steps, tau, 0,
                np.array([a["pp_cap"] for a in args], dtype=np.int64),
                np.array([a["b_cap"] for a in args], dtype=np.int64),
                np.array([a["max_events"] for a in args], dtype=np.int64),
                np.array([a["stall_dt"] for a in args]))

    def run_many(self, prepared):
        """Run every IC of `prepare_many` in the C loop; returns the total event count."""
        st, n, *scalars, pp_cap, b_cap, max_events, stall_dt = prepared
        return self.lib.two_disk_many(st.ctypes.data_as(_dp), n, *scalars,
                                      pp_cap.ctypes.data_as(_ip), b_cap.ctypes.data_as(_ip),
                                      max_events.ctypes.data_as(_ip),
                                      stall_dt.ctypes.data_as(_dp))


def load():
    """``(TwoDiskC, None)``, or ``(None, reason)`` when two_disk.c cannot be built."""
    cc = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if not cc:
        return None, "no C compiler (cc) found"
    tmp = tempfile.mkdtemp(prefix="kicktimes-c-")
    lib_path = os.path.join(tmp, "two_disk.so")
    cmd = [cc, "-O2", "-shared", "-fPIC", f"-DSIN_GRAZE={geometry.SIN_GRAZE!r}",
           f"-DCOS_GRAZE={geometry.COS_GRAZE!r}", f"-DGRAZE_THRESHOLD={geometry.GRAZE_THRESHOLD!r}",
           "-o", lib_path, os.path.join(HERE, "two_disk.c"), "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode:
        return None, f"{' '.join(cmd)} failed: {proc.stderr.strip()[:500]}"
    return TwoDiskC(ctypes.CDLL(lib_path)), None

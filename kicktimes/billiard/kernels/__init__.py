"""The kernel layer: one event step per system, and the drivers composed around it.

docs/architecture.md, "The kernel layer", has the picture. In short:

* ``two``, ``one``: the event step of each system (find the next event, advance, resolve),
  on a state tuple that numba keeps in registers, and its array form;
* ``tangent``: the linearised event maps (how a tangent vector crosses each event);
* ``observe``: what a driver records around the step (samples, growing logs, stalls);
* ``drive_two``, ``drive_one``: the event loop of each system, with the simulation, the
  tangent vectors and the continuation as observers a caller switches on;
* ``twins``: Benettin's twin trajectories, advanced by the same steps.

All functions are ``numba.njit(cache=True)`` kernels on floats and flat float64 arrays;
the Python layers (`kicktimes.billiard.two_particle`, `.one_particle`,
`kicktimes.diagnostics.lyapunov`) check arguments and build result objects.
"""

"""Why an MPM run stops (raised by :mod:`plough.mpm.solver` and :mod:`plough.mpm.growth`)."""

from __future__ import annotations


class SimulationError(RuntimeError):
    """A run could not finish: the message names the step, the sliding distance and the likely cause."""


class InstabilityError(SimulationError):
    """The state went unstable while running (non-finite values, J out of range, a particle leaving the
    grid, kinetic energy out of proportion), as opposed to a run that cannot reach its load or loses
    contact: the workflow may record it for a finest-size run (``mpm.finest_failure``)."""

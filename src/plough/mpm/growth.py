"""The growing grid: room for material that passes an automatic face of the grid mid-run (model.md,
"The headroom and the growing grid").

Where the scene leaves the headroom automatic (``domain.headroom_m`` unset), three faces of the grid may
move out when a particle passes them, each along its own axis and up to its own limit (:data:`FACES`):
the top (a prow that keeps growing), the far end past the block's end face (fragments of a soft
coating's chip flung ahead) and the high side past the face y = R (material thrown sideways). The
solver's positions check flags a particle that left the grid (``transfers.BAD_LEFT_GRID``);
:func:`grow_to_hold` answers the flag after the step's kernels: it grows every face some particle has
passed, as far as the particles need and the limits and the memory allow, and clears the flag where the
grown grid holds every particle. Before it grows anything it settles the strays (:mod:`plough.mpm.strays`):
a particle that flowed back out of the active zone's trailing slabs is frozen, one flung past a face's limit
is retired as debris. Anything else (a particle out through the bottom, the low side, the near end, a face
that cannot grow as far, the active zone's leading slabs) is left flagged: the solver's ``check_stability``
stops the run on it.

The origin stays put, so every node keeps its (i, j, k) and position (:func:`grow_grid`); only the
grid's part of the run's constants (``solver.GrowingGrid``) and the per-node arrays change.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from plough.mpm import contact, strays, transfers
from plough.mpm.errors import InstabilityError
from plough.mpm.grid import extend_node_array, grown

if TYPE_CHECKING:
    from plough.mpm.solver import Constants, State

#: the automatic headroom is raised mid-run up to this many sphere radii above the original surface
#: (the sphere's top): a soft coating the sphere sweeps ahead can stack far above the expected
#: pile-up (H~ = 0.1 at h = 10 um: 197 um after 600 um of sliding, docs/journal/2026-11-23-preview-run.md), but
#: material above the sphere is flung, not ploughed
GRID_TOP_LIMIT_RADII = 2.0
#: with the automatic headroom the grid also lengthens past the block's far end, up to this many sphere
#: radii: a soft coating's chip sheds fragments the 1e6 mass scaling flings ahead of the sphere (H~ = 0.25 at
#: h = 5 um: up to 377 um ahead, at 4.5x the slide speed, docs/journal/2026-11-23-soft-coating-fragments.md);
#: they stay in the run
GRID_END_LIMIT_RADII = 2.0
#: each lengthening (and widening) adds room for the farthest particle plus this many sphere radii, so that
#: fragments flying on do not reallocate the grid every few steps
GRID_END_STEP_RADII = 0.25
#: with the automatic headroom the grid also widens past the block's side face y = R (the high side; with
#: the mirror plane the only one), up to this many sphere radii: the f = 0.5 coated run at h = 2.5 um threw a
#: coating particle out through it, 13 um above the surface, 567.5 um into a 600 um slide
#: (docs/journal/2026-11-24-coated-f0.5-h2.5-growing-grid.md)
GRID_SIDE_LIMIT_RADII = 2.0


@dataclass(frozen=True)
class Face:
    """A face of the grid that may grow, along ``axis`` (its high end)."""

    axis: int
    passed: str  # what a particle did, as the messages say it
    verb: str  # the growth, as the messages say it
    limit: str  # the Constants field: the farthest the face may move to, m (0: never)
    log: str  # the State list of (step, sliding distance m, new face m) of each growth
    doubles: bool  # the room above the surface at least doubles (else: the farthest particle plus GRID_END_STEP_RADII)


#: the growing faces by axis, in the order they grow on a step (the top first: its doubled room is sized
#: against the memory with the growths that follow it on the same step)
FACES = {
    2: Face(2, "rose above the grid's top", "raising", "grid_top_limit_m", "grid_raises", True),
    0: Face(0, "passed the grid's far end", "lengthening", "grid_end_limit_m", "grid_extensions", False),
    1: Face(1, "passed the grid's side", "widening", "grid_side_limit_m", "grid_widenings", False),
}


def physical_memory_bytes() -> int | None:
    """This machine's physical memory, or None where the OS does not say."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):
        return None


# ----------------------------------------------------------------------------- answering the flag
def grow_to_hold(s: State, c: Constants) -> None:
    """Answer a particle the step's positions check flagged as having left the grid (the worst flag of
    ``s.work.acc`` is ``transfers.BAD_LEFT_GRID``): grow the faces the particles passed (:func:`hold`) and
    clear the flags where the grown grid holds every particle, else name the particle still outside in the
    flag (``ACC_BAD_INDEX`` of the flagging chunk). Worse flags are left alone."""
    acc = s.work.acc
    chunk = int(np.argmax(acc[:, transfers.ACC_BAD]))
    index = int(acc[chunk, transfers.ACC_BAD_INDEX])
    if int(acc[chunk, transfers.ACC_BAD]) != transfers.BAD_LEFT_GRID or index < 0:
        return
    outside = hold(s, c, index)
    if outside < 0:
        acc[:, transfers.ACC_BAD] = transfers.BAD_NONE  # every flag was BAD_LEFT_GRID or none: all answered
    else:
        acc[chunk, transfers.ACC_BAD_INDEX] = outside


def hold(s: State, c: Constants, index: int) -> int:
    """Settle the strays (:func:`plough.mpm.strays.settle`: debris past the growth limits retired, stragglers
    behind the active zone frozen), then grow every face of :data:`FACES` the active particles passed as far as they
    need and the limits allow; the particle still outside afterwards (``index``, the one flagged, where nothing
    moved or grew), -1 if none.

    All are sized on this step's particles before any grows, and each growth's memory check counts the
    growths that follow it (:func:`grow_face`). Nothing grows where a particle is outside for a reason no
    growth mends (:func:`_outside_for_good`) or past a face that cannot grow as far as it needs: that
    particle is the one named (the far end's first, then the side's, then the top's)."""
    moved = strays.settle(s, c, beyond_reach(s, c))  # debris past the limits retired, stragglers behind the zone frozen
    stuck = _outside_for_good(s, c)
    if stuck >= 0:
        return stuck
    z = s.zone.ranges
    x = s.particles.x[z.p_lo:z.p_hi]
    layers = {axis: _layers_past(s, c, axis) for axis in FACES}
    for axis in (0, 1, 2):
        far = int(np.argmax(x[:, axis]))
        if x[far, axis] > c.grid_hi[axis] and not layers[axis]:
            return z.p_lo + far
    growths = [(axis, layers[axis]) for axis in FACES if layers[axis]]
    if not growths:
        # nothing to grow: the particle the kernel flagged, or, where strays moved (slots changed), one still out
        return _outside_index(s) if moved else index
    for i, (axis, _) in enumerate(growths):
        grow_face(s, c, axis, then=tuple(growths[i + 1:]))
    return _outside_index(s)


def grow_face(s: State, c: Constants, axis: int, then: tuple[tuple[int, int], ...] = ()) -> bool:
    """Grow the face along ``axis`` (:data:`FACES`) so that every active particle has room again; False where
    the scene set its headroom by hand (a fixed grid) or the room would pass the face's limit; stops the run
    (:func:`check_raise_memory`) where even the room the particles need would not fit in memory.

    The room reaches one cell past the farthest particle at least: on the top the room above the surface
    at least doubles (a few raises cover any prow), on the far end and the side it reaches
    ``GRID_END_STEP_RADII`` sphere radii past the farthest particle (fragments flying on do not reallocate
    the grid every few steps); it stops at the limit, and it is only the room needed where the wanted one,
    followed by the growths ``then`` ((axis, node layers), ...) the same step makes next, would not fit in
    memory. The new layers' flags are those of the old last layer (past the face they depend on the other
    two coordinates alone); see :func:`grow_grid`. Only the high side of y grows: with the mirror plane it
    is the only side; a full block's low side (y = -R) does not.
    """
    face = FACES[axis]
    limit_m = getattr(c, face.limit)
    if limit_m <= 0.0:
        return False
    far = float(s.particles.x[s.zone.ranges.p_lo:s.zone.ranges.p_hi, axis].max())
    need_m = far + c.grid.dx
    if face.doubles:
        want_m = max(2.0 * float(c.grid_hi[axis]), need_m)
    else:
        want_m = need_m + GRID_END_STEP_RADII * c.sphere_radius
    if not _grow_within(s, c, axis, need_m, want_m, limit_m, then):
        return False
    getattr(s, face.log).append((s.step, s.sphere.slid_m, float(c.grid_hi[axis])))
    return True


def _allowed_layers(limit_m: float, now_m: float, dx: float) -> int:
    """Whole node layers a face at ``now_m`` may still grow by before it passes ``limit_m``."""
    return max(math.floor((limit_m - now_m) / dx + 1e-9), 0)


def farthest_held_m(c: Constants, axis: int) -> float:
    """The farthest a particle may be along ``axis`` for the grid grown to its face's limit to hold it (a cell of
    room past it, in whole node layers, as :func:`_layers_past` counts), m."""
    now, dx = float(c.grid_hi[axis]), c.grid.dx
    return now + (_allowed_layers(getattr(c, FACES[axis].limit), now, dx) - 1) * dx


def beyond_reach(s: State, c: Constants) -> np.ndarray:
    """The active particles no growth can hold, as indices: past the grid's interior along a growing face's axis
    by more node layers than the face may still grow (the arithmetic of :func:`_layers_past`, so that a particle
    is either held or beyond reach); none along a face that does not grow (a hand-set headroom)."""
    z = s.zone.ranges
    x = s.particles.x[z.p_lo:z.p_hi]
    dx = c.grid.dx
    past = np.zeros(len(x), dtype=bool)
    for axis, face in FACES.items():
        limit_m = getattr(c, face.limit)
        if limit_m > 0.0:
            now = float(c.grid_hi[axis])
            xa = x[:, axis]
            past |= (xa > now) & (np.ceil((xa + dx - now) / dx - 1e-9) > _allowed_layers(limit_m, now, dx))
    return z.p_lo + np.flatnonzero(past)


def _outside_for_good(s: State, c: Constants) -> int:
    """An active particle outside the positions check's box other than above the grid's top, past its far
    end or past its side where the grid may widen (through the bottom, the low side, the near end, the side
    of a grid that does not widen, or out of the active zone's slabs), -1 if none."""
    z = s.zone.ranges
    x = s.particles.x[z.p_lo:z.p_hi]
    low = np.any(x < z.check_lo, axis=1)
    side = x[:, 1] > z.check_hi[1] if c.grid_side_limit_m <= 0.0 else np.zeros(len(x), dtype=bool)
    zone = (x[:, 0] > z.check_hi[0]) & (x[:, 0] <= c.grid_hi[0])
    out = np.flatnonzero(low | side | zone)
    return int(z.p_lo + out[0]) if out.size else -1


def _outside_index(s: State) -> int:
    """An active particle outside the positions check's box, -1 if none."""
    z = s.zone.ranges
    x = s.particles.x[z.p_lo:z.p_hi]
    out = np.flatnonzero(np.any((x < z.check_lo) | (x > z.check_hi), axis=1))
    return int(z.p_lo + out[0]) if out.size else -1


def _layers_past(s: State, c: Constants, axis: int) -> int:
    """Node layers the face along ``axis`` must grow by for the active particles beyond the grid's interior
    there (one cell past the farthest), 0 where none is beyond it, the face cannot grow (its limit 0) or the
    room needed would pass its limit."""
    limit_m = getattr(c, FACES[axis].limit)
    if limit_m <= 0.0:
        return 0
    far = float(s.particles.x[s.zone.ranges.p_lo:s.zone.ranges.p_hi, axis].max())
    now = float(c.grid_hi[axis])
    if far <= now:
        return 0
    need = max(_layers_to(far + c.grid.dx, now, c.grid.dx), 1)
    return need if need <= _allowed_layers(limit_m, now, c.grid.dx) else 0


def _layers_to(target_m: float, now_m: float, dx: float) -> int:
    """Whole node layers that carry the grid's interior from ``now_m`` to ``target_m`` at least."""
    return math.ceil((target_m - now_m) / dx - 1e-9)


def _grow_within(s: State, c: Constants, axis: int, need_m: float, want_m: float, limit_m: float,
                 then: tuple[tuple[int, int], ...] = ()) -> bool:
    """Grow the grid's interior along ``axis`` to ``want_m``, or less, down to ``need_m``, where the limit
    (``limit_m``) or the memory says so; False, nothing grown, where even ``need_m`` passes the limit. The
    memory counts the growths ``then`` ((axis, node layers), ...) that follow on the same step: the wanted room
    only where all fit, and where even the needed room and ``then`` do not, the run stops before any grows."""
    now, dx = float(c.grid_hi[axis]), c.grid.dx
    need, wanted = _layers_to(need_m, now, dx), _layers_to(want_m, now, dx)
    allowed = math.floor((limit_m - now) / dx + 1e-9)
    extra = min(wanted, allowed)
    if extra < max(need, 1):
        return False
    available = physical_memory_bytes()
    if available is not None and growth_bytes(s, c.grid.shape, [(axis, extra), *then]) > available:
        extra = max(need, 1)  # the wanted room does not fit in memory: the room the particles need
    check_raise_memory(s, c.grid.shape, extra, available, axis, then)
    grow_grid(s, c, axis, extra)
    return True


# ----------------------------------------------------------------------------- the grown layout
def grow_grid(s: State, c: Constants, axis: int, extra: int) -> None:
    """Add ``extra`` node layers at the high end of ``axis`` (2: the top, 0: past the far end, 1: past the side).

    The origin stays put, so every node keeps its (i, j, k) and position: the per-node arrays are copied
    into the grown layout (new layers empty, contact memory unpushed, flags copied from the old last layer)
    and the run goes on as if it had started on the grown grid. The active zone's node range, free slabs
    and positions check follow the new far end where they reached the old one. A particle outside the old
    grid on this step moved with a complete stencil on it (it was inside before the move).
    """
    g, z, w = c.grid, s.zone.ranges, s.work
    shape, new = g.shape, grown(g, extra, axis)
    w.grid_buf = extend_node_array(w.grid_buf, shape, extra, axis=1, fill=0.0, grid_axis=axis)
    w.grid_m = extend_node_array(w.grid_m, shape, extra, fill=0.0, grid_axis=axis)
    w.grid_v = extend_node_array(w.grid_v, shape, extra, fill=0.0, grid_axis=axis)
    w.grid_div = extend_node_array(w.grid_div, shape, extra, fill=0.0, grid_axis=axis)
    w.cbuf = extend_node_array(w.cbuf, shape, extra, fill=0.0, grid_axis=axis)
    w.last_push = extend_node_array(w.last_push, shape, extra, fill=contact.NEVER_PUSHED, grid_axis=axis)
    w.flags = extend_node_array(w.flags, shape, extra, grid_axis=axis)
    old_slab, new_slab = shape[1] * shape[2], new.shape[1] * new.shape[2]
    if axis in (1, 2):  # x-major: the zone's node range keeps its slabs, each slab taller or wider
        s.zone.ranges = z._replace(n_lo=z.n_lo // old_slab * new_slab, n_hi=z.n_hi // old_slab * new_slab)
    else:  # the slabs keep their size; a zone that reached the old far end reaches the new one
        s.zone.ranges = z._replace(n_hi=new.n_nodes if z.n_hi == g.n_nodes else z.n_hi,
                                   i_free_hi=new.shape[0] if z.i_free_hi == shape[0] else z.i_free_hi)
    old_hi = c.grid_hi.copy()
    c.growing.set(new)
    if z.check_hi[axis] == old_hi[axis]:
        z.check_hi[axis] = c.grid_hi[axis]


# ----------------------------------------------------------------------------- memory
def _array_bytes(obj: object) -> int:
    """Bytes of the arrays a dataclass or a named tuple (the particles) holds."""
    values = obj._asdict().values() if hasattr(obj, "_asdict") else vars(obj).values()
    return sum(v.nbytes for v in values if isinstance(v, np.ndarray))


def raise_bytes(s: State, shape: tuple[int, int, int], extra: int, axis: int = 2) -> int:
    """Bytes the run holds at the peak of growing the grid by ``extra`` node layers along ``axis``: its
    particle and per-node arrays, plus the layers added, or the new per-chunk P2G buffers while the old ones
    are still held (most of a run's node memory), whichever is more."""
    return growth_bytes(s, shape, [(axis, extra)])


def growth_bytes(s: State, shape: tuple[int, int, int], growths: list[tuple[int, int]]) -> int:
    """Bytes the run holds at the peak of growing the grid by each ``(axis, node layers)`` of ``growths`` in
    turn (:func:`raise_bytes` for each, on the grid the ones before it left)."""
    node = sum(a.nbytes for a in (s.work.grid_buf, s.work.grid_m, s.work.grid_v, s.work.grid_div, s.work.cbuf,
                                  s.work.last_push, s.work.flags))
    buffers = s.work.grid_buf.nbytes
    held = _array_bytes(s.particles) + _array_bytes(s.work)
    peak, dims = held, list(shape)
    for axis, extra in growths:
        added = node * extra // dims[axis]  # one layer is 1 / dims[axis] of the nodes
        new_buffers = buffers * (dims[axis] + extra) // dims[axis]
        peak = max(peak, held + max(added, new_buffers))
        held, node, buffers = held + added, node + added, new_buffers
        dims[axis] += extra
    return peak


def check_raise_memory(s: State, shape: tuple[int, int, int], extra: int, available: int | None,
                       axis: int = 2, then: tuple[tuple[int, int], ...] = ()) -> None:
    """Stop before growing the grid by ``extra`` node layers along ``axis``, and then by each of ``then``
    ((axis, node layers), ...), if that would not fit in ``available`` bytes, this machine's physical memory
    (:func:`growth_bytes`; ``solver.check_memory`` counted the particles alone, before the grid could grow);
    None: not known, no check. The whole machine's memory: jobs beside the run are not counted."""
    if available is None:
        return
    peak = growth_bytes(s, shape, [(axis, extra), *then])
    if peak > available:
        face = FACES[axis]
        more = "".join(f" and then {FACES[a].verb} it by {n}" for a, n in then)
        raise InstabilityError(
            f"unstable run at step {s.step} (sliding distance {s.sphere.slid_m * 1e6:.1f} um): material "
            f"{face.passed}, and {face.verb} it by {extra} node layers{more} would hold {peak / 2**30:.3g} GiB, "
            f"more than this machine's {available / 2**30:.3g} GiB of memory (a growing prow or chip: coarser "
            "particles, a smaller domain, or a hand-set domain.headroom_m to stop there)")

"""Contact of the material with the rigid analytic sphere, on the grid (model.md section 2, eq. 8).

A node near the sphere (inside it or within one cell of its surface) may approach the sphere, in
the sphere's frame along the outward normal n from the centre, by at most the gap g_i of its
closest particle in one step: v_n >= -g_i / dt, with g_i the distance from that particle's face
(half a particle size from its centre) to the sphere surface. A faster approach is cut to that
speed, and the cut is the normal impulse. Nodes that lie inside the sphere but above the free
surface (they carry a little mass from the top particles through the B-spline stencil) therefore
act only once the material is there, and the material closes on the sphere instead of being
held where it was when its first particle touched (which left one touching particle carrying the
whole load, and the contact switching on and off with it).

The tangential velocity change is a traction-limited impulse:

    J_t <= tau * A_i * dt,     A_i = | sum_p V_p grad N_i(x_p) |

with A_i the node's share of the material's surface: by the divergence theorem
sum_p V_p grad N_i(x_p) ~ integral over the body of grad N_i = integral over its boundary of N_i n dA,
so the shares of the nodes near a face add up to the face's area however many layers of nodes
touch it (for the flat top face of a lattice block exactly, to round-off: tested with 2 and 3
particles per cell). At the edge of the contact a node's share also holds some of the free surface
next to it: an error of order dx along the contact's perimeter. The interface shear strength is

    proportional:    tau = f * kappa                 (kappa = sigma_y / sqrt(3) of the material)
    constant:        tau = H0 / k0
    boundary layer:  tau = Cp * P^np                 (P in Pa, Table 5; P = -n . sigma . n of the
                                                      node's particles, mass-averaged, or with
                                                      ``interface.pressure: traction`` the node's
                                                      normal traction averaged over the hold:
                                                      held_traction)

always capped at kappa (never above the contacting material's shear strength) and never larger
than the impulse that stops the slip (so the slip never reverses). The reaction on the sphere
is minus the impulses, split into the normal-traction (ploughing) and interface-shear parts.

Why a hold: the explicit normal projection acts on a node only on the steps it approaches the
sphere, and the contact rings at the elastic-wave period (on the reference scene no node
approaches on 16% of the steps at CFL 0.3). A node pushed within the last HOLD_WAVE_TIMES
elastic-wave transits of a cell (dx / c, the ringing period's scale) stays in contact and carries
interface shear on the steps it is not pushed; a held node keeps its normal velocity.

Why not the earlier area min(F_n,i / P_i, dx^2) with a filtered F_n,i: P_i from the particles'
stress was 0.40 of the hardness at h = 10 um (the particles next to the sphere carry little of the
contact pressure, the grid does), so 82% of the normal force sat on nodes whose area was capped at
a face, and a node kept shear until its filtered force had faded, about 0.7 cell of sliding: mu_sh
followed the filter time (+0.004 per wave transit; docs/journal/2026-11-22-contact-shear-area.md).
With this hold it does not (holds of 1-8 transits: +-1.2%).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from plough.mpm.grid import FIXED, GHOST, MIRROR
from plough.mpm.shape import bspline2_grad, stencil, stencil_node
from plough.mpm.transfers import mirror_partner

INTERFACE_PROPORTIONAL, INTERFACE_CONSTANT, INTERFACE_BOUNDARY_LAYER = 0, 1, 2
#: the boundary layer with P the node's normal traction (``interface.pressure: traction``), not its particles' stress
INTERFACE_BOUNDARY_LAYER_TRACTION = 3
SQRT3 = math.sqrt(3.0)
#: a node stays in contact this many elastic-wave transits of a cell (dx / c) after its last normal push
HOLD_WAVE_TIMES = 2.0
#: last_push of a node never pushed (far enough back that step - it stays within int64)
NEVER_PUSHED = -(2**62)

# outputs of sphere_contact
OUT_FN = 0  # 0:3 force on the sphere from normal impulses, N
OUT_FT = 3  # 3:6 force on the sphere from tangential (interface) impulses, N
OUT_DISSIPATION = 6  # energy dissipated by interface slip in this step (friction times end-of-step slip), J
OUT_IMPACT = 7  # work of the normal pushes against the end-of-step approach of the nodes in this step, J
OUT_WORK = 8  # work done by the sphere on the material this step, J
OUT_NODES = 9  # number of contact nodes
OUT_AREA_XY = 10  # contact area projected on the xy plane, m^2
# diagnostics of the grid contact's interface shear (sphere_contact only; particle_contact leaves them 0;
# docs/journal/2026-12-02-interface-shear-split.md). Over the nodes in contact (pushed now or held):
OUT_SH_AREA = 11  # sum of the nodes' surface shares A_i, m^2
OUT_SH_TAU_AREA = 12  # sum of tau_i A_i (the traction the nodes could carry), N
#: the regions of a contact node: in front of the centre in x (n_x > 0, the sliding direction) or behind it,
#: and below or above the original surface z = 0 (where its ray meets the sphere: centre_z + R n_z)
REGION_FRONT, REGION_REAR, REGION_FRONT_UP, REGION_REAR_UP = 0, 1, 2, 3
N_REGIONS = 4
OUT_REGION_AREA = 13  # 13:17 sum A_i by region, m^2
OUT_REGION_FX = 17  # 17:21 x force on the sphere from tangential impulses by region, N (they add up to OUT_FT)
OUT_REGION_AREA_XY = 21  # 21:25 sum A_i |n_z| (n_z < 0) by region, m^2 (they add up to OUT_AREA_XY)
OUT_REGION_FZ = 25  # 25:29 z force on the sphere from normal impulses by region, N (they add up to OUT_FN z)
#: overlapping subsets of the contact nodes, each an area (m^2) and the x force of its tangential impulses (N):
OUT_STUCK_AREA, OUT_STUCK_FX = 29, 30  # the slip stopped (m |v_t| <= tau A_i dt: J_t = m v_t, not the traction)
OUT_CARRIED_AREA, OUT_CARRIED_FX = 31, 32  # arriving slip under half the sphere's speed (material carried along)
OUT_OUTSIDE_AREA, OUT_OUTSIDE_FX = 33, 34  # the node lies outside the sphere (within a cell of its surface)
OUT_GAP_AREA, OUT_GAP_FX = 35, 36  # its closest particle face is more than dx / 4 from the sphere
OUT_LATERAL_AREA, OUT_LATERAL_FX = 37, 38  # on the sides: |n_y| > |n_x|
N_OUT = 39
#: the fraction of the sphere's speed under which a node's arriving slip counts as carried with the sphere
CARRIED_SLIP = 0.5
#: channels of the contact scratch: 6 stress, kappa, mass weight, proximity dx - gap of the closest particle,
#: 3 the surface vector sum_p V_p grad N_i (C_AREA: C_AREA + 3); then one channel kept from step to step (not
#: scratch): the node's normal traction averaged over the hold (C_TRACTION, Pa; INTERFACE_BOUNDARY_LAYER_TRACTION)
C_AREA = 9
C_TRACTION = 12
N_CBUF = 13


@njit(cache=True, inline="always")
def face_offset(P, p, centre):
    """Particle p's offset from the sphere's centre (q0, q1, q2), its distance and its edge e = V_p^(1/3): the
    gap of its face to the sphere is dist - radius - e / 2. Reads P.x, vol0, J of particle p."""
    q0 = P.x[p, 0] - centre[0]
    q1 = P.x[p, 1] - centre[1]
    q2 = P.x[p, 2] - centre[2]
    return q0, q1, q2, math.sqrt(q0 * q0 + q1 * q1 + q2 * q2), (P.vol0[p] * P.J[p]) ** (1.0 / 3.0)


@njit(cache=True, inline="always")
def normal_pressure(n0, n1, n2, s0, s1, s2, s3, s4, s5):
    """The normal traction -n . sigma . n (Pa, > 0 in compression) of the Voigt stress (xx, yy, zz, yz, xz, xy)
    on the plane of unit normal n."""
    return -(n0 * n0 * s0 + n1 * n1 * s1 + n2 * n2 * s2 + 2.0 * (n1 * n2 * s3 + n0 * n2 * s4 + n0 * n1 * s5))


@njit(cache=True)
def _inside_box(origin, dx, shape, centre, radius):
    """Index ranges of the grid nodes that can lie inside the sphere."""
    lo = [0, 0, 0]
    hi = [0, 0, 0]
    for d in range(3):
        lo[d] = max(int(math.floor((centre[d] - radius - origin[d]) / dx)), 0)
        hi[d] = min(int(math.ceil((centre[d] + radius - origin[d]) / dx)), shape[d] - 1)
    return lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]


@njit(cache=True)
def scatter_contact_stress(P, G, S, Z, ray_local):
    """Mass-weighted stress and shear strength, and the surface vector, of the particles near the
    sphere onto nearby nodes.

    Reads P.x, stress, mass, vol0, J, the flow stress at rest ``P.sigma_y0`` (kappa = sigma_y0 /
    sqrt 3, the shear strength) and ``P.near`` (set by g2p) of the active particles Z.p_lo <= p < Z.p_hi,
    and the sphere's S.centre and S.radius. For nodes within one cell of the sphere surface (or inside
    it) writes G.cbuf[node, 0:6] += w m sigma, G.cbuf[node, 6] += w m kappa, G.cbuf[node, 7] += w m,
    G.cbuf[node, 8] = max(G.cbuf[node, 8], dx - gap) over its particles (gap = distance from the
    particle's face, half a particle size from its centre, to the sphere surface) and
    G.cbuf[node, C_AREA:C_AREA + 3] += V grad w (the node's share of the material's surface, as a
    vector). With the mirror plane (``G.mirror_j0`` >= 0, else -1) the surface vector of a ghost node
    (y < 0) goes to its partner with its y component reversed: the mirrored particles' share.
    With ``ray_local`` (``discretisation.contact: grid_local``, the default; False: ``grid``) a particle sets a
    node's proximity only if it lies within half a cell of the node's ray from the sphere's centre (the gap of the
    material *at the node*, not of its whole stencil; the stress, strength and surface sums are unchanged).
    Serial: few particles are near the sphere. ``sphere_contact`` consumes and re-zeroes these entries.
    Only particles flagged ``near`` (within ``S.near_dist`` = 3 dx of the sphere, set by g2p) are
    scattered; a node at the edge of the reach (r + dx) has stencil particles out to about r + 3.6 dx,
    so its sums miss the farthest corner particles (weights of order 1e-3): a small approximation.
    """
    x, stress, mass, near, cbuf, mirror_j0 = P.x, P.stress, P.mass, P.near, G.cbuf, G.mirror_j0
    origin, dx, centre, radius = G.origin, G.dx, S.centre, S.radius
    ny, nz = G.shape[1], G.shape[2]
    inv_dx = 1.0 / dx
    reach2 = (radius + dx) * (radius + dx)
    for p in range(Z.p_lo, Z.p_hi):
        if near[p] == 0:
            continue
        q0, q1, q2, dist, e = face_offset(P, p, centre)
        vol = P.vol0[p] * P.J[p]
        # proximity dx - gap of the particle's face to the sphere surface (> 0 within one cell)
        prox = dx - (dist - radius - 0.5 * e)
        kappa = P.sigma_y0[p] / SQRT3
        st = stencil(x, p, origin, inv_dx)
        dwx, dwy, dwz = bspline2_grad(st.g[0])[1:], bspline2_grad(st.g[1])[1:], bspline2_grad(st.g[2])[1:]
        v_dx = vol * inv_dx  # V grad w, with the derivatives in grid units
        for a in range(3):
            px = origin[0] + (st.base[0] + a) * dx - centre[0]
            for b in range(3):
                py = origin[1] + (st.base[1] + b) * dx - centre[1]
                for cc in range(3):
                    pz = origin[2] + (st.base[2] + cc) * dx - centre[2]
                    if px * px + py * py + pz * pz >= reach2:
                        continue
                    node, w = stencil_node(st, a, b, cc, ny, nz)
                    wm = w * mass[p]
                    for k in range(6):
                        cbuf[node, k] += wm * stress[p, k]
                    cbuf[node, 6] += wm * kappa
                    cbuf[node, 7] += wm
                    if prox > cbuf[node, 8]:
                        on_ray = True
                        if ray_local:
                            # lateral offset of the particle from the node's ray: |q - (q . n_i) n_i|
                            r = math.sqrt(px * px + py * py + pz * pz)
                            if r > 0.0:
                                along = (q0 * px + q1 * py + q2 * pz) / r
                                lat2 = q0 * q0 + q1 * q1 + q2 * q2 - along * along
                                on_ray = lat2 <= 0.25 * dx * dx
                        if on_ray:
                            cbuf[node, 8] = prox
                    s1 = v_dx * st.wx[a] * dwy[b] * st.wz[cc]
                    j = st.base[1] + b
                    if mirror_j0 >= 0 and j < mirror_j0:
                        j = 2 * mirror_j0 - j
                        s1 = -s1
                    target = ((st.base[0] + a) * ny + j) * nz + st.base[2] + cc
                    cbuf[target, C_AREA] += v_dx * dwx[a] * st.wy[b] * st.wz[cc]
                    cbuf[target, C_AREA + 1] += s1
                    cbuf[target, C_AREA + 2] += v_dx * st.wx[a] * st.wy[b] * dwz[cc]


@njit(cache=True)
def interface_shear(model, iparams, pressure, kappa):
    """Interface shear strength tau (Pa) of eq. 8 at one node, capped at kappa; both boundary layers
    (INTERFACE_BOUNDARY_LAYER and _TRACTION) take Cp P^np, they differ only in the ``pressure`` given."""
    if model == INTERFACE_PROPORTIONAL:
        tau = iparams[0] * kappa
    elif model == INTERFACE_CONSTANT:
        tau = iparams[0]
    else:
        tau = iparams[0] * max(pressure, 0.0) ** iparams[1]
    return min(tau, kappa)


@njit(cache=True, inline="always")
def held_traction(cbuf, node, traction, fresh, hold_steps):
    """Update the node's normal traction averaged over the contact's hold, cbuf[node, C_TRACTION] (Pa).

    ``traction``: this step's normal impulse over the node's surface share and dt (0 on a held step without a
    push); ``fresh``: the node is pushed and was not in contact before, so the average starts at this step's
    traction. Otherwise an exponential average over ``hold_steps`` steps: the contact rings at the elastic-wave
    period and pushes a node on some steps only, so one step's traction is not the pressure the node carries,
    its average over a few periods is (summed over the contact nodes, traction times share is the normal force).
    """
    if fresh:
        cbuf[node, C_TRACTION] = traction
    else:
        cbuf[node, C_TRACTION] += (traction - cbuf[node, C_TRACTION]) / max(hold_steps, 1.0)


@njit(cache=True)
def surface_share(cbuf, node, mirror_plane):
    """The node's share of the material's surface, |sum_p V_p grad N_i|, m^2.

    On the mirror plane the half body owns half of the node: the mirrored particles cancel the y
    component and double the others, so its share is the x-z part of its own particles' vector.
    """
    g0 = cbuf[node, C_AREA]
    g1 = 0.0 if mirror_plane else cbuf[node, C_AREA + 1]
    g2 = cbuf[node, C_AREA + 2]
    return math.sqrt(g0 * g0 + g1 * g1 + g2 * g2)


@njit(cache=True, inline="always")
def _record_split(out, S, speed, area, tau, force, n, slip, where, dx):
    """Add one contact node to the diagnostic channels OUT_SH_AREA..OUT_LATERAL_FX; reads only, so the contact
    is the same with or without them. ``area``: its surface share A_i; ``tau``: its interface shear strength;
    ``force`` = (fx, fz): the x force of its tangential impulse on the sphere and the z force of its normal
    impulse; ``n``: the sphere's outward normal at it; ``slip`` = (vt, stuck): its arriving slip speed and
    whether the impulse stopped the slip (J_t = m v_t, not the traction bound); ``where`` = (dist, gap): its
    distance from the centre and the gap of its closest particle face; S the sphere (centre, radius) and
    ``speed`` its speed; dx the cell."""
    fx, fz = force
    n0, n1, n2 = n
    vt, stuck = slip
    dist, gap = where
    out[OUT_SH_AREA] += area
    out[OUT_SH_TAU_AREA] += tau * area
    region = REGION_FRONT if n0 > 0.0 else REGION_REAR
    if S.centre[2] + S.radius * n2 > 0.0:
        region += 2  # the _UP regions: the sphere's surface on the node's ray lies above the original surface
    out[OUT_REGION_AREA + region] += area
    out[OUT_REGION_FX + region] += fx
    if n2 < 0.0:
        out[OUT_REGION_AREA_XY + region] += area * (-n2)
    out[OUT_REGION_FZ + region] += fz
    if stuck:
        out[OUT_STUCK_AREA] += area
        out[OUT_STUCK_FX] += fx
    if speed > 0.0 and vt < CARRIED_SLIP * speed:
        out[OUT_CARRIED_AREA] += area
        out[OUT_CARRIED_FX] += fx
    if dist > S.radius:
        out[OUT_OUTSIDE_AREA] += area
        out[OUT_OUTSIDE_FX] += fx
    if gap > 0.25 * dx:
        out[OUT_GAP_AREA] += area
        out[OUT_GAP_FX] += fx
    if abs(n1) > abs(n0):
        out[OUT_LATERAL_AREA] += area
        out[OUT_LATERAL_FX] += fx


@njit(cache=True)
def sphere_contact(G, S, law, step, dt, out):
    """Impose the sphere on the nodes inside it and measure the reaction.

    Reads G.m, G.flags, G.cbuf (from scatter_contact_stress; its scratch entries, 0:C_TRACTION, are zeroed
    here), the sphere (S.centre, S.radius, S.velocity) and the interface law (``law``,
    :class:`plough.mpm.bundles.ContactLaw`). Reads and writes the per-node contact memory G.last_push
    (the step a node's velocity was last cut by the normal projection): a node pushed at ``step``, or
    within the last ``law.hold_steps`` steps, is in contact and carries interface shear; with the traction
    boundary layer also G.cbuf[:, C_TRACTION], the node's held traction (``held_traction``). Writes G.v of
    contact nodes and out[0:N_OUT] (see the OUT_* indices; OUT_SH_AREA on, the split of the interface shear by
    region and kind of node, are diagnostics: ``_record_split``). Serial: it visits only the box of nodes
    around the sphere. It works on them whatever the active zone: nodes outside the zone's range have no
    mass and are skipped. A clamped node the sphere pushed would take the sphere's velocity; this is not
    excluded here: behind the sphere it moves away from the material (no push), and ahead the zone's end
    lies at least 2 expected contact radii and 20 h from the centre (over the workflow's runs the
    sphere's surface there is at least 5.6 um above the expected groove depth, about one contact reach
    at h = 2.5 um; docs/journal/2026-11-23-active-zone.md).
    """
    grid_m, grid_v, cbuf, flags, last_push = G.m, G.v, G.cbuf, G.flags, G.last_push
    origin, dx, shape, centre, radius, v_sphere = G.origin, G.dx, G.shape, S.centre, S.radius, S.velocity
    ny, nz = shape[1], shape[2]
    for k in range(N_OUT):
        out[k] = 0.0
    i0, i1, j0, j1, k0, k1 = _inside_box(origin, dx, shape, centre, radius + dx)
    r2 = (radius + dx) * (radius + dx)
    speed = math.sqrt(v_sphere[0] * v_sphere[0] + v_sphere[1] * v_sphere[1] + v_sphere[2] * v_sphere[2])
    traction = law.model == INTERFACE_BOUNDARY_LAYER_TRACTION  # the boundary layer reads the held traction
    for i in range(i0, i1 + 1):
        px = origin[0] + i * dx - centre[0]
        for j in range(j0, j1 + 1):
            py = origin[1] + j * dx - centre[1]
            for kk in range(k0, k1 + 1):
                pz = origin[2] + kk * dx - centre[2]
                d2 = px * px + py * py + pz * pz
                node = (i * ny + j) * nz + kk
                if d2 >= r2:
                    # a mirror-folded surface vector may land here when the partner's distance
                    # rounds differently: consume it too, so nothing carries over to the next step
                    for k in range(C_AREA, C_AREA + 3):
                        cbuf[node, k] = 0.0
                    continue
                cw = cbuf[node, 7]
                s0 = cbuf[node, 0]
                s1 = cbuf[node, 1]
                s2 = cbuf[node, 2]
                s3 = cbuf[node, 3]
                s4 = cbuf[node, 4]
                s5 = cbuf[node, 5]
                kap = cbuf[node, 6]
                prox = cbuf[node, 8]
                area = surface_share(cbuf, node, flags[node] == MIRROR)
                for k in range(C_TRACTION):
                    cbuf[node, k] = 0.0
                m = grid_m[node]
                dist = math.sqrt(d2)
                if m <= 0.0 or prox <= 0.0 or flags[node] == GHOST or dist <= 0.0:
                    continue  # ghosts (y < 0) mirror their partners: their impulse is not the body's
                held = step - last_push[node] <= law.hold_steps
                gap = max(dx - prox, 0.0)  # of the node's closest particle face
                n0 = px / dist
                n1 = py / dist
                n2 = pz / dist
                vb0 = grid_v[node, 0]
                vb1 = grid_v[node, 1]
                vb2 = grid_v[node, 2]
                r0 = vb0 - v_sphere[0]
                r1 = vb1 - v_sphere[1]
                r2v = vb2 - v_sphere[2]
                vn = r0 * n0 + r1 * n1 + r2v * n2
                vn_min = -gap / dt  # the closest particle may still approach by its gap in this step
                jn = m * (vn_min - vn) if vn < vn_min else 0.0
                if jn <= 0.0 and not held:
                    continue  # neither pushed now nor within the hold
                if traction:
                    held_traction(cbuf, node, jn / (dt * area) if area > 0.0 else 0.0, jn > 0.0 and not held,
                                  law.hold_steps)
                if jn > 0.0:
                    last_push[node] = step
                t0 = r0 - vn * n0
                t1 = r1 - vn * n1
                t2 = r2v - vn * n2
                vt = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
                if cw > 0.0:
                    inv = 1.0 / cw
                    if traction:
                        pressure = cbuf[node, C_TRACTION]
                    else:
                        pressure = normal_pressure(n0, n1, n2, s0, s1, s2, s3, s4, s5) * inv
                    kappa = kap * inv
                else:
                    pressure = 0.0
                    kappa = 0.0
                vn_after = max(vn, vn_min)
                tau = interface_shear(law.model, law.params, pressure, kappa)
                jt = 0.0
                if vt > 0.0:
                    jt = min(m * vt, tau * area * dt)
                    scale = 1.0 - jt / (m * vt)
                else:
                    scale = 0.0
                va0 = v_sphere[0] + scale * t0 + vn_after * n0
                va1 = v_sphere[1] + scale * t1 + vn_after * n1
                va2 = v_sphere[2] + scale * t2 + vn_after * n2
                grid_v[node, 0] = va0
                grid_v[node, 1] = va1
                grid_v[node, 2] = va2
                # reaction on the sphere: minus the impulses on the material, per unit time
                out[OUT_FN + 0] -= jn * n0 / dt
                out[OUT_FN + 1] -= jn * n1 / dt
                out[OUT_FN + 2] -= jn * n2 / dt
                fx = 0.0
                if vt > 0.0:
                    fx = jt * t0 / vt / dt
                    out[OUT_FT + 0] += fx
                    out[OUT_FT + 1] += jt * t1 / vt / dt
                    out[OUT_FT + 2] += jt * t2 / vt / dt
                vt_after = scale * vt
                # the contact's losses at the end-of-step relative velocity, as the stress power takes the
                # end-of-step velocity gradient: friction times slip, and a push on a node that still approaches
                # (vn_after = vn_min <= 0 where jn > 0). The node's kinetic-energy change is the work less these
                # less |J|^2 / 2m; the step leaves |F + J|^2 / 2m (F the internal force's impulse) unaccounted,
                # about 0 in a lasting contact where the push takes back what F gave, a real loss where a node
                # arrives approaching (docs/journal/2026-12-02-cfl.md)
                out[OUT_DISSIPATION] += jt * vt_after
                out[OUT_IMPACT] -= jn * vn_after
                out[OUT_WORK] += m * ((va0 - vb0) * v_sphere[0] + (va1 - vb1) * v_sphere[1]
                                      + (va2 - vb2) * v_sphere[2])
                out[OUT_NODES] += 1.0
                if n2 < 0.0:
                    out[OUT_AREA_XY] += area * (-n2)
                _record_split(out, S, speed, area, tau, (fx, -jn * n2 / dt), (n0, n1, n2),
                              (vt, vt > 0.0 and m * vt <= tau * area * dt), (dist, gap), dx)


# ----------------------------------------------------------------------------- contact on the particles
@njit(cache=True, inline="always")
def _fold(node, j, mirror_j0, ny, nz):
    """The node that holds node's velocity (itself, or its partner across the mirror plane for a ghost at
    j < mirror_j0, ``transfers.mirror_partner``: -1 off the grid) and the sign of its y component there."""
    if mirror_j0 >= 0 and j < mirror_j0:
        return mirror_partner(node, ny, nz, mirror_j0), -1.0
    return node, 1.0


@njit(cache=True)
def _apply_impulse(G, S, nodes, ysign, wts, k, jx, jy, jz, acc):
    """Scatter the impulse (jx, jy, jz) of near particle k to its nodes by its B-spline weights: node t gets
    w J / m_t (y reversed on a ghost's partner, none along y on the mirror plane). Adds to acc[0:3] the
    momentum given, acc[3] the work the sphere did (momentum . sphere velocity), acc[4] the kinetic energy
    the nodes gained."""
    grid_m, grid_v, flags, vs = G.m, G.v, G.flags, S.velocity
    for s in range(27):
        t = nodes[k, s]
        if t < 0:
            continue
        m = grid_m[t]
        w = wts[k, s] / m
        d0 = w * jx
        d1 = 0.0 if flags[t] == MIRROR else w * jy * ysign[k, s]
        d2 = w * jz
        v0, v1, v2 = grid_v[t, 0], grid_v[t, 1], grid_v[t, 2]
        acc[0] += m * d0
        acc[1] += m * d1
        acc[2] += m * d2
        acc[3] += m * (d0 * vs[0] + d1 * vs[1] + d2 * vs[2])
        acc[4] += m * (v0 * d0 + v1 * d1 + v2 * d2 + 0.5 * (d0 * d0 + d1 * d1 + d2 * d2))
        grid_v[t, 0] = v0 + d0
        grid_v[t, 1] = v1 + d1
        grid_v[t, 2] = v2 + d2


@njit(cache=True, inline="always")
def _particle_velocity(G, nodes, ysign, wts, k):
    """sum_i w_i v_i over near particle k's nodes: the velocity it will be advected with (a node the step holds
    still, or without mass, counts with velocity 0, as g2p reads it)."""
    grid_v = G.v
    u0 = 0.0
    u1 = 0.0
    u2 = 0.0
    for s in range(27):
        t = nodes[k, s]
        if t < 0:
            continue
        w = wts[k, s]
        u0 += w * grid_v[t, 0]
        u1 += w * grid_v[t, 1] * ysign[k, s]
        u2 += w * grid_v[t, 2]
    return u0, u1, u2


@njit(cache=True)
def particle_contact(P, G, S, Z, law, step, dt, last_push_p, out):
    """Impose the exact sphere on the near particles, through their own nodes, and measure the reaction.

    A particle p near the sphere has the face gap g_p = |x_p - c| - R - e_p / 2 (e_p = V_p^(1/3), the
    particle's size; n_p the sphere's outward normal at it) and is advected in this step with
    u_p = sum_i w_ip v_i. Its face must not cross the sphere by the end of the step, to first order in dt:
    (u_p - v_sphere) . n_p >= -max(g_p, 0) / dt (a particle found inside stops approaching; it is not thrown
    out, which would put energy in, as the grid contact's gap rule does). A faster approach is cut by a
    normal impulse lambda_p n_p scattered to its nodes like a body force (node i gets w_ip lambda_p n_p / m_i),
    which changes u_p by lambda_p n_p / m_eff,p, m_eff,p = 1 / sum_i (w_ip^2 / m_i). Touching particles share
    nodes, so the impulses are found by projected Gauss-Seidel over them (``law.sweeps`` sweeps, lambda_p >= 0
    accumulated; a later sweep may lower one). Only particles whose face meets the sphere act, so the
    footprint is the sphere's to within a particle, not a cell wider (``sphere_contact``).

    Interface shear acts on every particle in contact, pushed or not: one the sphere holds back (its face would
    cross the sphere in this step at the velocity it had before any contact impulse) at ``step`` or within
    ``law.hold_steps`` steps (its ``last_push_p``), or whose face ends the step within e_p^2 / (2 R) of the sphere
    (the sag of the sphere one particle size from its lowest point: the gap a flat face's particles show under
    it, which the particles' spacing does not resolve). Its own impulse is no measure of contact: touching
    particles share nodes, so a few impulses stop their neighbours too, and in steady sliding most particles
    against the sphere get none (mu_sh 0.05 against the analytical 0.19 on the tiny f = 1 scene,
    docs/journal/2026-12-02-particle-contact-shear.md). Each gets a tangential impulse against its slip,
    J_t <= min(tau A_p dt, m_eff |u_t|) (it never reverses the slip), with A_p = e_p^2 / (|n_x| + |n_y| + |n_z|),
    the area per particle of a cubic lattice's face cut by a plane of normal n, tau from ``interface_shear`` with
    kappa = sigma_y0 / sqrt 3 and the pressure -n . sigma . n of the particle itself; one pass after the normal
    sweeps.

    Reads P.x, vol0, J, stress, sigma_y0, near of the active particles Z.p_lo <= p < Z.p_hi; G.m, G.flags, the
    grid geometry and the zone's free x range (Z.i_free_lo..i_free_hi: nodes beyond it, FIXED nodes and
    nodes without mass take no impulse); the sphere S; the law. Writes G.v of the particles' nodes,
    last_push_p[p] and out[0:N_OUT]: the forces on the sphere are minus the momentum given to the nodes
    (/ dt), OUT_WORK the sphere's work (that momentum . v_sphere), OUT_IMPACT and OUT_DISSIPATION the work of
    the normal and tangential impulses less the nodes' kinetic energy gain (so the contact's energy account
    closes exactly), OUT_NODES the number of particles in contact, OUT_AREA_XY their sum A_p |n_z| (n_z < 0).
    Mirror plane (G.mirror_j0 >= 0): a stencil node at y < 0 is the ghost of its partner at -y, whose
    velocity it reads and whose velocity takes the impulse with y reversed; a node on the plane keeps v_y = 0
    (it holds the half body's mass and takes the half body's impulse). Serial: few particles are near the
    sphere, and Gauss-Seidel needs each impulse applied before the next particle reads its velocity.
    """
    x, near = P.x, P.near
    origin, dx, centre, radius, vs = G.origin, G.dx, S.centre, S.radius, S.velocity
    grid_m, flags, mirror_j0 = G.m, G.flags, G.mirror_j0
    ny, nz = G.shape[1], G.shape[2]
    inv_dx = 1.0 / dx
    for k in range(N_OUT):
        out[k] = 0.0
    # the candidates: near particles whose face lies within a cell of the sphere (a farther one would need
    # to approach faster than a cell per step)
    count = 0
    for p in range(Z.p_lo, Z.p_hi):
        if near[p] != 0:
            count += 1
    idx = np.empty(count, dtype=np.int64)
    gap = np.empty(count)
    nrm = np.empty((count, 3))
    size = np.empty(count)
    nk = 0
    for p in range(Z.p_lo, Z.p_hi):
        if near[p] == 0:
            continue
        q0, q1, q2, dist, e = face_offset(P, p, centre)
        g = dist - radius - 0.5 * e
        if g >= dx or dist <= 0.0:
            continue
        idx[nk] = p
        gap[nk] = g
        nrm[nk, 0] = q0 / dist
        nrm[nk, 1] = q1 / dist
        nrm[nk, 2] = q2 / dist
        size[nk] = e
        nk += 1
    nodes = np.full((nk, 27), -1, dtype=np.int64)
    ysign = np.ones((nk, 27))
    wts = np.zeros((nk, 27))
    inv_meff = np.zeros(nk)
    for k in range(nk):
        st = stencil(x, idx[k], origin, inv_dx)
        s = 0
        for a in range(3):
            i = st.base[0] + a
            for b in range(3):
                j = st.base[1] + b
                for cc in range(3):
                    node, w = stencil_node(st, a, b, cc, ny, nz)
                    t, sign = _fold(node, j, mirror_j0, ny, nz)
                    if (0 <= t < grid_m.size and grid_m[t] > 0.0 and flags[t] != FIXED
                            and Z.i_free_lo <= i <= Z.i_free_hi):
                        nodes[k, s] = t
                        ysign[k, s] = sign
                        wts[k, s] = w
                        inv_meff[k] += w * w / grid_m[t]
                    s += 1
    # in contact: the particles the sphere holds back, i.e. whose face would cross it in this step at the
    # velocity they had before any contact impulse (their neighbours' impulses may then stop them, so a
    # particle's own impulse is no measure), or did so within the hold
    touch = np.zeros(nk, dtype=np.bool_)
    for k in range(nk):
        if inv_meff[k] <= 0.0:
            continue
        u0, u1, u2 = _particle_velocity(G, nodes, ysign, wts, k)
        vn = (u0 - vs[0]) * nrm[k, 0] + (u1 - vs[1]) * nrm[k, 1] + (u2 - vs[2]) * nrm[k, 2]
        p = idx[k]
        if vn < -max(gap[k], 0.0) / dt:
            last_push_p[p] = step
        touch[k] = step - last_push_p[p] <= law.hold_steps
    lam = np.zeros(nk)
    acc_n = np.zeros(5)
    for _sweep in range(law.sweeps):
        for k in range(nk):
            if inv_meff[k] <= 0.0:
                continue
            u0, u1, u2 = _particle_velocity(G, nodes, ysign, wts, k)
            vn = (u0 - vs[0]) * nrm[k, 0] + (u1 - vs[1]) * nrm[k, 1] + (u2 - vs[2]) * nrm[k, 2]
            new = max(lam[k] + (-max(gap[k], 0.0) / dt - vn) / inv_meff[k], 0.0)
            d = new - lam[k]
            if d != 0.0:
                lam[k] = new
                _apply_impulse(G, S, nodes, ysign, wts, k, d * nrm[k, 0], d * nrm[k, 1], d * nrm[k, 2], acc_n)
    acc_t = np.zeros(5)
    touching = 0
    area_xy = 0.0
    for k in range(nk):
        p = idx[k]
        if inv_meff[k] <= 0.0:
            continue
        n0, n1, n2 = nrm[k, 0], nrm[k, 1], nrm[k, 2]
        u0, u1, u2 = _particle_velocity(G, nodes, ysign, wts, k)
        r0, r1, r2 = u0 - vs[0], u1 - vs[1], u2 - vs[2]
        vn = r0 * n0 + r1 * n1 + r2 * n2
        # or its face ends the step within the resolved gap of the sphere
        if not touch[k] and gap[k] + vn * dt > size[k] * size[k] / (2.0 * radius):
            continue
        area = size[k] * size[k] / (abs(n0) + abs(n1) + abs(n2))
        touching += 1
        if n2 < 0.0:
            area_xy += area * (-n2)
        sg = P.stress[p]
        pressure = normal_pressure(n0, n1, n2, sg[0], sg[1], sg[2], sg[3], sg[4], sg[5])
        tau = interface_shear(law.model, law.params, pressure, P.sigma_y0[p] / SQRT3)
        if tau <= 0.0:
            continue
        t0, t1, t2 = r0 - vn * n0, r1 - vn * n1, r2 - vn * n2
        vt = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
        if vt <= 0.0:
            continue
        jt = min(vt / inv_meff[k], tau * area * dt)
        _apply_impulse(G, S, nodes, ysign, wts, k, -jt * t0 / vt, -jt * t1 / vt, -jt * t2 / vt, acc_t)
    for d in range(3):
        out[OUT_FN + d] = -acc_n[d] / dt
        out[OUT_FT + d] = -acc_t[d] / dt
    out[OUT_WORK] = acc_n[3] + acc_t[3]
    out[OUT_IMPACT] = acc_n[3] - acc_n[4]
    out[OUT_DISSIPATION] = acc_t[3] - acc_t[4]
    out[OUT_NODES] = touching
    out[OUT_AREA_XY] = area_xy

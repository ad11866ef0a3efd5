"""A/B of plough trees from one saved mid-slide state: per-kernel times and whether the states after N steps agree
to the bit (a throwaway of the 2026-12-02 throughput entry; run from the repository root).

snap:  python ab.py snap SCENE H_UM BLOCK OUT.npz        (run in any tree: press, settle, 20 slide steps; save)
one:   python ab.py one SCENE H_UM BLOCK SNAP.npz STEPS OUT.npz   (in a tree: restore, time STEPS steps per kernel)
ab:    python ab.py ab SCENE H_UM BLOCK SNAP.npz STEPS ROUNDS TREE_A TREE_B ...
"""
import json
import os
import subprocess
import sys
import time
from dataclasses import replace

import numpy as np

PY = sys.executable
ROOT = os.getcwd()  # the scene files are this tree's


def make_scene(scene_file, h_um, block):
    from plough.mpm.scene import Scene
    scene = Scene.from_yaml(os.path.join(ROOT, scene_file))
    scene = replace(scene, discretisation=replace(scene.discretisation, particle_size_m=h_um * 1e-6))
    if block == "sized":
        scene = scene.with_sized_domain()
    return scene


SPH = ["fz_filtered", "load_error_integral", "phase", "settle_left", "slid_m"]
WORK = ["external_work", "plastic_work", "interface_dissipation", "contact_impact_loss", "heat"]
WARR = ["grid_v", "last_push", "cbuf", "grid_div", "v_grid", "acc", "contact_out"]


def snap(scene_file, h_um, block, out):
    import numba

    from plough.mpm import solver
    numba.set_num_threads(2)
    state, const = solver.init(make_scene(scene_file, float(h_um), block))
    while state.sphere.phase != "slide":
        solver.step(state, const)
    for _ in range(20):
        solver.step(state, const)
    d = {f"P_{k}": v for k, v in state.particles._asdict().items()}
    d["centre"] = state.sphere.centre
    d["velocity"] = state.sphere.velocity
    for k in SPH:
        d[f"S_{k}"] = np.array(getattr(state.sphere, k))
    for k in WORK:
        d[f"W_{k}"] = np.array(getattr(state.work, k))
    for k in WARR:
        d[f"A_{k}"] = getattr(state.work, k)
    d["step"] = np.array(state.step)
    d["time"] = np.array(state.time)
    d["n_nodes"] = np.array(const.grid.n_nodes)
    np.savez(out, **d)
    print("saved", out, state.particles.n, const.grid.n_nodes, state.step)


def one(scene_file, h_um, block, snapf, steps, out):
    import numba

    import plough
    from plough.mpm import contact, solver, transfers
    numba.set_num_threads(2)
    state, const = solver.init(make_scene(scene_file, float(h_um), block))
    d = np.load(snapf)
    assert int(d["n_nodes"]) == const.grid.n_nodes
    for k, v in state.particles._asdict().items():
        v[...] = d[f"P_{k}"]
    state.sphere.centre[:] = d["centre"]
    state.sphere.velocity[:] = d["velocity"]
    for k in SPH:
        val = d[f"S_{k}"]
        setattr(state.sphere, k, str(val) if k == "phase" else val.item())
    for k in WORK:
        setattr(state.work, k, float(d[f"W_{k}"]))
    for k in WARR:
        getattr(state.work, k)[...] = d[f"A_{k}"]
    state.step = int(d["step"])
    state.time = float(d["time"])
    solver.update_active_zone(state, const)
    # one untimed step (kernels loaded), then the timed ones
    names = [(m, n) for m, n in [(transfers, "p2g"), (transfers, "grid_update"), (contact, "scatter_contact_stress"),
                                 (contact, "sphere_contact"), (transfers, "mirror_ghosts"),
                                 (transfers, "g2p_kinematics"), (transfers, "grid_dilatation"),
                                 (transfers, "g2p_update"), (transfers, "g2p_update_p2g")] if hasattr(m, n)]
    spent = {n: 0.0 for _, n in names}

    def wrap(m, n):
        fn = getattr(m, n)

        def w(*a):
            t0 = time.perf_counter()
            r = fn(*a)
            spent[n] += time.perf_counter() - t0
            return r
        setattr(m, n, w)
    solver.step(state, const)
    for m, n in names:
        wrap(m, n)
    fz = []
    t0 = time.perf_counter()
    for _ in range(steps):
        solver.step(state, const)
        fz.append(float(state.work.contact_out[contact.OUT_FN + 2]))
    total = time.perf_counter() - t0
    np.savez(out, x=state.particles.x, v=state.particles.v, stress=state.particles.stress, J=state.particles.J,
             eps_p=state.particles.eps_p, fz=np.array(fz), acc=state.work.acc)
    res = {"tree": plough.__file__, "step_ms": 1e3 * total / steps, **{k: 1e3 * v / steps for k, v in spent.items()},
           "Mps": state.particles.n * steps / total / 1e6}
    print(json.dumps(res))


def ab(scene_file, h_um, block, snapf, steps, rounds, *trees):
    results = {t: [] for t in trees}
    outs = {}
    for r in range(int(rounds)):
        order = trees if r % 2 == 0 else trees[::-1]
        for t in order:
            out = f"{snapf}.{os.path.basename(t.rstrip('/'))}.out.npz"
            outs[t] = out
            env = {**os.environ, "PYTHONPATH": os.path.join(t, "src"), "NUMBA_NUM_THREADS": "2"}
            p = subprocess.run([PY, __file__, "one", scene_file, h_um, block, snapf, steps, out], env=env,
                               capture_output=True, text=True)
            if p.returncode:
                print(p.stderr[-3000:])
                sys.exit(1)
            results[t].append(json.loads(p.stdout.strip().splitlines()[-1]))
    keys = [k for k in results[trees[0]][0] if k != "tree"]
    print("kernel ms (median over rounds): " + " | ".join(os.path.basename(t.rstrip('/')) for t in trees))
    for k in keys:
        meds = [np.median([r.get(k, np.nan) for r in results[t]]) for t in trees]
        print(f"  {k:24s} " + "  ".join(f"{m:8.3f}" for m in meds) + f"   ratio {meds[0] / meds[-1]:.3f}")
    a = np.load(outs[trees[0]])
    for t in trees[1:]:
        b = np.load(outs[t])
        for k in a.files:
            same = np.array_equal(a[k], b[k])
            diff = np.max(np.abs(a[k] - b[k])) / max(np.max(np.abs(a[k])), 1e-300)
            print(f"  {k}: {'bitwise equal' if same else f'max rel diff {diff:.3g}'}")


if __name__ == "__main__":
    mode, *args = sys.argv[1:]
    if mode == "snap":
        snap(*args)
    elif mode == "one":
        one(*args[:4], int(args[4]), args[5])
    else:
        ab(*args)

"""The probes' shared start: zinc-coated steel (the example scene) at h = 10 um on the sized block, pressed,
settled and ``steps`` steps into the slide, on 2 threads (run the probes from the repository root)."""

from dataclasses import replace

import numba

from plough.mpm import solver
from plough.mpm.scene import Scene


def zinc_state_in_slide(steps: int) -> tuple[solver.State, solver.Constants]:
    numba.set_num_threads(2)
    scene = Scene.from_yaml("examples/zinc_coated_steel.yaml")
    scene = replace(scene, discretisation=replace(scene.discretisation, particle_size_m=10e-6)).with_sized_domain()
    state, const = solver.init(scene)
    while state.sphere.phase != "slide":
        solver.step(state, const)
    for _ in range(steps):
        solver.step(state, const)
    return state, const

"""Command line: ``plough analytical ...``, ``plough mpm SCENE.yaml ...`` and ``plough plan ...``.

Bad input gives a one-line message naming the parameter and exit code 2, never a traceback; Ctrl-C gives one
line and exit code 130, and leaves no partial file (results and snapshots are written atomically).
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

from plough import __version__

if TYPE_CHECKING:
    from plough.mpm.scene import Scene


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # argparse's own errors: one line, exit 2
        self.exit(2, f"{self.prog}: error: {message}\n")


def _add_analytical(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "analytical",
        help="analytical ploughing model (eqs. 1-5 of the paper)",
        description="Friction and ploughing depth of a rigid sphere sliding on a coated substrate, "
        "from the analytical model of Mishra et al. (2020), eqs. 1-5. Prints a table in SI and "
        "practical units.",
    )
    p.add_argument("--radius-mm", type=float, required=True, help="sphere radius r in mm")
    p.add_argument("--load-N", type=float, required=True, help="normal load Fn in N")
    p.add_argument("--thickness-um", type=float, required=True,
                   help="coating thickness t in micrometres (0 = uncoated substrate)")
    p.add_argument("--coating-hardness-MPa", type=float, required=True, help="coating hardness Hc in MPa")
    p.add_argument("--substrate-hardness-MPa", type=float, required=True,
                   help="substrate hardness Hs in MPa")
    p.add_argument("--k1", type=float, default=125.0,
                   help="effective-hardness factor k1 of eq. 1 (dimensionless, default 125; "
                   "the paper's thickness sweeps use 12.5)")
    p.add_argument("--interface", default="proportional",
                   choices=["proportional", "constant", "boundary_layer"],
                   help="interface shear model: proportional tau = f H/k0, constant tau = H0/k0, "
                   "boundary_layer tau = Cp P^np (default proportional)")
    p.add_argument("--f", type=float, default=None,
                   help="interface factor f in [0, 1] of the proportional model (default 1)")
    p.add_argument("--H0-MPa", type=float, default=None,
                   help="hardness H0 in MPa of the constant model, tau = H0/k0 (default 450)")
    p.add_argument("--Cp", type=float, default=None,
                   help="boundary-layer coefficient Cp (tau and P in Pa, default 0.32)")
    p.add_argument("--np", dest="np_exponent", type=float, default=None,
                   help="boundary-layer exponent np in [0, 1] (default 0.95)")
    p.add_argument("--correction", default="none", choices=["none", "once", "converged"],
                   help="normal-load correction of eq. 5 (default none)")
    p.set_defaults(func=_run_analytical)


#: interface model -> {its CLI options (dest): default}; an option of another model is refused
_INTERFACE_OPTIONS = {"proportional": {"f": 1.0}, "constant": {"H0_MPa": 450.0},
                      "boundary_layer": {"Cp": 0.32, "np_exponent": 0.95}}
_OPTION_FLAGS = {"f": "--f", "H0_MPa": "--H0-MPa", "Cp": "--Cp", "np_exponent": "--np"}


def _interface_options(args: argparse.Namespace) -> None:
    """Refuse options that only another interface model reads; fill every unset option with its
    default (the function takes all four; the model reads its own)."""
    own = ", ".join(_OPTION_FLAGS[d] for d in _INTERFACE_OPTIONS[args.interface])
    for model, options in _INTERFACE_OPTIONS.items():
        for dest, default in options.items():
            given = getattr(args, dest)
            if given is not None and model != args.interface:
                raise ValueError(f"{_OPTION_FLAGS[dest]} = {given:g} applies to --interface {model}, not to "
                                 f"--interface {args.interface} (its options: {own})")
            if given is None:
                setattr(args, dest, default)


#: the model's parameter names (SI) -> (the option that gives it, its attribute), to name refused values as typed
_ANALYTICAL_FLAGS = {"radius_m": ("--radius-mm", "radius_mm"), "thickness_m": ("--thickness-um", "thickness_um"),
                     "coating_hardness_Pa": ("--coating-hardness-MPa", "coating_hardness_MPa"),
                     "substrate_hardness_Pa": ("--substrate-hardness-MPa", "substrate_hardness_MPa"),
                     "load_N": ("--load-N", "load_N"), "H0_Pa": ("--H0-MPa", "H0_MPa"), "k1": ("--k1", "k1"),
                     "f": ("--f", "f"), "Cp": ("--Cp", "Cp"), "np": ("--np", "np_exponent")}
_REFUSED = re.compile(r"(\w+) = \S+ .*?(is not allowed; it must be [<>]=? 0|is outside the allowed range \[[^]]*\])")


def _run_analytical(args: argparse.Namespace) -> int:
    from plough.analytical import RESULT_META, ploughing

    _interface_options(args)
    try:
        res = ploughing(
            load_N=args.load_N, radius_m=args.radius_mm * 1e-3, thickness_m=args.thickness_um * 1e-6,
            coating_hardness_Pa=args.coating_hardness_MPa * 1e6,
            substrate_hardness_Pa=args.substrate_hardness_MPa * 1e6, k1=args.k1,
            interface=args.interface, f=args.f, H0_Pa=args.H0_MPa * 1e6, Cp=args.Cp,
            np_exponent=args.np_exponent, correction=args.correction,
        ).squeeze()
    except ValueError as exc:  # the model names its SI parameter: name the option and the value typed
        refused = _REFUSED.match(str(exc))
        if refused is None or refused.group(1) not in _ANALYTICAL_FLAGS:
            raise
        flag, dest = _ANALYTICAL_FLAGS[refused.group(1)]
        rule = refused.group(2).replace("it must be", "it must be a finite number")  # 1e303 MPa is inf in Pa
        raise ValueError(f"{flag} = {getattr(args, dest):g} {rule}") from None
    scale = {"m": (1e6, "um"), "m2": (1e12, "um^2"), "Pa": (1e-6, "MPa"), "N": (1.0, "N"), "1": (1.0, "")}
    print(f"plough {__version__} - analytical ploughing model (Mishra et al. 2020, eqs. 1-5)")
    print(f"r = {args.radius_mm:g} mm, Fn = {args.load_N:g} N, t = {args.thickness_um:g} um, "
          f"Hc = {args.coating_hardness_MPa:g} MPa, Hs = {args.substrate_hardness_MPa:g} MPa, "
          f"k1 = {args.k1:g}, interface = {args.interface}, correction = {args.correction}")
    for name, value in res.as_dict().items():
        units, long_name = RESULT_META[name]
        factor, shown = scale[units]
        text = f"{int(value)}" if name == "regime" else f"{value * factor:.6g}"
        print(f"  {name:<13} {text:>14} {shown:<5} {long_name}")
    return 0


def _add_mpm(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("mpm", help="run a 3D MPM ploughing simulation from a scene file",
                       description="Run the 3D material point method ploughing model on a scene "
                       "file (YAML) and write the results as netCDF.")
    p.add_argument("scene", help="scene file (YAML), see examples/")
    p.add_argument("-o", "--output", required=True, help="netCDF file to write")
    p.add_argument("--snapshots", default=None, help="directory for particle snapshots (.vtp)")
    p.add_argument("--threads", type=int, default=None, help="numba threads (default: all cores)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    from plough.mpm.scene import PRESETS  # light: no numba

    p.add_argument("--preset", default=None, choices=PRESETS,
                   help="paper: the paper's 0.2 x 1 mm block, 0.6 mm slide, 0.1 m/s, mass scaling 1e6; "
                   "sized: the block sized from the expected contact radius")
    p.set_defaults(func=_run_mpm)


def _run_mpm(args: argparse.Namespace) -> int:
    try:
        from plough.mpm.run import run_scene_file
    except ImportError as exc:  # pragma: no cover - until the solver lands
        raise ValueError(f"the MPM solver is not available in this build: {exc}") from None
    path = run_scene_file(args.scene, args.output, snapshots_dir=args.snapshots, threads=args.threads,
                          progress=not args.quiet, preset=args.preset, on_scene=_note_interface,
                          on_defaults=_note_defaults)
    print(summarise_result(path))
    return 0


def summarise_result(path: str | Path) -> str:
    """The few numbers a user reads first from a result file: the steady-state friction and its parts, the
    groove, how well the load was held, whether the window was steady, and what the run cost. A quantity
    the file does not hold is left out of the summary."""
    import xarray as xr

    with xr.open_dataset(path) as ds:
        def value(name: str, scale: float = 1.0, fmt: str = ".3f") -> str:
            if name not in ds:
                return "-"
            text = f"{float(ds[name]) * scale:{fmt}}"
            se = f"{name}_standard_error"
            return text + (f" +- {float(ds[se]) * scale:.2g}" if se in ds else "")

        scene = json.loads(ds.attrs.get("scene", "{}"))
        lines = [f"{scene.get('name', Path(path).stem)}: wrote {path}",
                 f"  mu  {value('mu')}   (ploughing mu_pl {value('mu_pl')}, interface shear mu_sh {value('mu_sh')})",
                 f"  dp  {value('dp', 1e6, '.3g')} um   (groove dg {value('dg', 1e6, '.3g')} um, "
                 f"pile-up hpu {value('hpu', 1e6, '.3g')} um)"]
        state = []
        if "Fz_mean" in ds and "load_N" in scene:
            state.append(f"mean Fz / load {float(ds['Fz_mean']) / scene['load_N']:.3f}")
        if "steady" in ds:
            drift = f" (mu drift {float(ds['mu_drift']):+.1%})" if "mu_drift" in ds else ""
            state.append("window steady" if int(ds["steady"]) else f"window NOT steady{drift}")
        if "resolution" in ds.attrs:
            state.append(str(ds.attrs["resolution"]))
        if state:
            lines.append("  " + "; ".join(state))
        if {"cost_particles", "cost_steps", "cost_wall_time_s"} <= set(ds.attrs):
            lines.append(f"  {int(ds.attrs['cost_particles']):,} particles, {int(ds.attrs['cost_steps']):,} steps, "
                         f"{float(ds.attrs['cost_wall_time_s']):.0f} s")
        return "\n".join(lines)


def _note_defaults(defaults: dict[str, Any]) -> None:
    """Say which keys the scene file left out and the defaults the run takes for them (also recorded in the
    result as ``scene_defaults``)."""
    from plough.mpm.scene import describe_defaults

    print(f"plough: note: keys not in the scene file take their defaults (docs/scenes.md): "
          f"{describe_defaults(defaults)}", file=sys.stderr)


def _note_interface(scene: Scene) -> None:
    """Tell the user when the scene's mu will follow the simulated speed (``Scene.interface_sticks``)."""
    if scene.interface_sticks:
        print(f"plough: note: the interface (tau = {scene.sticking_ratio:.3g} kappa) is at or above the wave limit "
              f"cos^2 alpha = {scene.wave_limit_ratio:.3g} of a perfectly plastic surface: no steady state "
              "expected, and mu measured to follow the simulated speed and mass scaling without settling "
              "(docs/model.md, 3.8 The interface regime and the wave limit)", file=sys.stderr)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="plough", description="plough: a hard sphere ploughing through a coated "
                     "metal sheet - analytical model and 3D MPM solver (Mishra et al., Wear 2020).")
    parser.add_argument("--version", action="version", version=f"plough {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    _add_analytical(sub)
    _add_mpm(sub)
    _add_plan(sub)
    return parser


def _add_plan(sub: argparse._SubParsersAction) -> None:
    from plough.study.plan import add_arguments, run_plan  # light: the matrix and the cost model load on use

    p = sub.add_parser("plan", help="projected wall time of the workflow, per figure and in total, before it runs",
                       description="Project the wall time of `snakemake --cores N [--configfile FILE ...]`, per "
                       "figure and in total, here and per cluster job, from the cost model calibrated by the "
                       "measured workflow runs (plough.study.plan). Run it in the repository root.")
    add_arguments(p)
    p.set_defaults(func=run_plan)


#: exit status after Ctrl-C, as a shell reports a process ended by SIGINT (128 + 2)
EXIT_INTERRUPTED = 130


def _interrupted(args: argparse.Namespace) -> str:
    """What Ctrl-C left: the result is written atomically (and snapshots too), so no partial file."""
    if args.command != "mpm":
        return "interrupted (Ctrl-C)"
    kept = f"; the complete snapshots so far stay in {args.snapshots}" if args.snapshots else ""
    return f"interrupted (Ctrl-C); no result written, no partial file left{kept}"


def _show_warning(message: Warning | str, category: type[Warning], filename: str, lineno: int,
                  file: TextIO | None = None, line: str | None = None) -> None:
    """plough's own warnings (an unsteady window, an under-resolved contact) as one line each; others as usual."""
    if getattr(category, "__module__", "").startswith("plough."):
        print(f"plough: warning: {message}", file=sys.stderr)
    else:
        _default_show_warning(message, category, filename, lineno, file, line)


_default_show_warning = warnings.showwarning


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    func: Callable[[argparse.Namespace], int] = args.func
    try:
        with warnings.catch_warnings():
            warnings.showwarning = _show_warning
            return func(args)
    # RuntimeError: an unstable MPM run; OSError: a file that cannot be read or written (a full disk says so)
    except (ValueError, OSError, RuntimeError) as exc:
        print(f"plough {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"plough {args.command}: {_interrupted(args)}", file=sys.stderr)
        return EXIT_INTERRUPTED


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

import subprocess
import sys

import pytest

from plough.cli import main

ARGS = ["analytical", "--radius-mm", "0.2", "--load-N", "3", "--thickness-um", "25",
        "--coating-hardness-MPa", "450", "--substrate-hardness-MPa", "900", "--k1", "12.5"]


def test_analytical_table(capsys):
    assert main(ARGS) == 0
    out = capsys.readouterr().out
    assert "mu_pl" in out and "dp" in out
    line = next(s for s in out.splitlines() if s.split()[0] == "dp")
    assert abs(float(line.split()[1]) - 8.97297) < 1e-4  # um


def test_bad_value_is_one_line_and_exit_2(capsys):
    args = list(ARGS)
    args[args.index("--load-N") + 1] = "-3"
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--load-N = -3 is not allowed; it must be a finite number > 0" in err


@pytest.mark.parametrize("flag, value, message", [
    ("--radius-mm", "0", "--radius-mm = 0 is not allowed; it must be a finite number > 0"),
    ("--thickness-um", "-1", "--thickness-um = -1 is not allowed; it must be a finite number >= 0"),
    ("--substrate-hardness-MPa", "nan", "--substrate-hardness-MPa = nan is not allowed; it must be a finite"),
    ("--coating-hardness-MPa", "1e303", "--coating-hardness-MPa = 1e+303 is not allowed; it must be a finite number"),
])
def test_analytical_refusal_names_the_option_and_the_value_as_typed(flag, value, message, capsys):
    args = list(ARGS)
    args[args.index(flag) + 1] = value
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message in err


def test_python_m_and_help():
    out = subprocess.run([sys.executable, "-m", "plough", "analytical", "--help"],
                         capture_output=True, text=True, check=True).stdout
    for unit in ("in mm", "in N", "micrometres", "in MPa"):
        assert unit in out
    bad = subprocess.run([sys.executable, "-m", "plough", *ARGS, "--interface", "sticky"],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and "invalid choice" in bad.stderr


def test_mpm_preset_reaches_the_solver(monkeypatch, tmp_path, capsys):
    """``plough mpm --preset paper`` runs the paper's block; the solver is replaced by a recorder."""
    from pathlib import Path

    import plough.mpm.run as run

    seen = []

    def record(scene, **_kw):
        seen.append(scene)
        raise ValueError("recorded")

    monkeypatch.setattr(run, "simulate", record)
    text = (Path(__file__).resolve().parents[1] / "examples" / "coated_rigid_plastic.yaml").read_text()
    assert "domain: {radius_um: 200, length_um: 1000," in text
    scene = tmp_path / "scene.yaml"  # a block that is neither the paper's nor sized
    scene.write_text(text.replace("domain: {radius_um: 200, length_um: 1000,", "domain: {radius_um: 300, "
                                  "length_um: 1200,"))
    out = tmp_path / "r.nc"
    assert main(["mpm", str(scene), "-o", str(out), "--preset", "sized", "--quiet"]) == 2
    assert main(["mpm", str(scene), "-o", str(out), "--preset", "paper", "--quiet"]) == 2
    assert seen[0].domain.radius_m == pytest.approx(170e-6)  # sized from the contact at h = 10 um
    assert (seen[1].domain.radius_m, seen[1].domain.length_m) == (200e-6, 1000e-6)
    assert not out.exists()
    err = capsys.readouterr().err
    assert "recorded" in err
    # the example's f = 1 on a perfectly plastic coating: the user is told mu follows the simulated speed
    assert err.count("note: the interface (tau = 1 kappa) is at or above the wave limit cos^2 alpha = 0.894") == 2
    scene.write_text(scene.read_text().replace("f: 1.0", "f: 0.9"))  # measured to wander too (README)
    assert main(["mpm", str(scene), "-o", str(out), "--quiet"]) == 2
    assert "note: the interface (tau = 0.9 kappa) is at or above" in capsys.readouterr().err
    scene.write_text(scene.read_text().replace("f: 0.9", "f: 0.8"))  # measured to settle
    assert main(["mpm", str(scene), "-o", str(out), "--quiet"]) == 2
    assert "note: the interface" not in capsys.readouterr().err  # (the scene's defaults are noted, not this)


@pytest.mark.parametrize("extra, message", [
    (["--interface", "constant", "--f", "0.5"], "--f = 0.5 applies to --interface proportional, not to --interface "
                                                "constant (its options: --H0-MPa)"),
    (["--np", "-1"], "--np = -1 applies to --interface boundary_layer, not to --interface proportional"),
    (["--interface", "boundary_layer", "--np", "-1"], "np = -1 is outside the allowed range [0, 1]"),
    (["--f", "1.5"], "f = 1.5 is outside the allowed range [0, 1]"),
])
def test_analytical_interface_options_are_checked_or_refused(extra, message, capsys):
    assert main(ARGS + extra) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message in err


def test_analytical_interface_defaults_apply_to_the_chosen_model(capsys):
    def mu(extra):
        assert main(ARGS + extra) == 0
        out = capsys.readouterr().out
        return float(next(s for s in out.splitlines() if s.split()[0] == "mu").split()[1])

    assert mu([]) == mu(["--f", "1"])
    assert mu(["--interface", "constant"]) == mu(["--interface", "constant", "--H0-MPa", "450"])
    bl = ["--interface", "boundary_layer"]
    assert mu(bl) == mu(bl + ["--Cp", "0.32", "--np", "0.95"])
    assert mu(["--f", "0.5"]) < mu([])


@pytest.mark.parametrize("scene_text, message", [
    ("name: x\nsphere: {radius_um: 200\n", "not valid YAML at line"),
    (None, "is a directory"),
])
def test_mpm_unreadable_scene_is_one_line_and_exit_2(scene_text, message, tmp_path, capsys):
    scene = tmp_path
    if scene_text is not None:
        scene = tmp_path / "scene.yaml"
        scene.write_text(scene_text)
    assert main(["mpm", str(scene), "-o", str(tmp_path / "r.nc"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message in err


def test_mpm_bad_thread_count_names_the_option(tmp_path, capsys):
    from pathlib import Path

    scene = Path(__file__).resolve().parents[1] / "examples" / "stability_small.yaml"
    assert main(["mpm", str(scene), "-o", str(tmp_path / "r.nc"), "--quiet", "--threads", "0"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "threads = 0 is outside the allowed range 1.." in err
    assert not (tmp_path / "r.nc").exists()


def _refuse_to_simulate(monkeypatch):
    import plough.mpm.run as run

    def fail(*_a, **_kw):
        raise AssertionError("the run started although its output cannot be written")

    monkeypatch.setattr(run, "simulate", fail)


@pytest.mark.parametrize("case, message", [
    ("output is a directory", "is a directory; give a file name"),
    ("output folder is a file", "output folder"),
    ("snapshots is a file", "snapshots"),
])
def test_mpm_unwritable_output_is_refused_before_the_run(case, message, monkeypatch, tmp_path, capsys):
    from pathlib import Path

    _refuse_to_simulate(monkeypatch)
    scene = Path(__file__).resolve().parents[1] / "examples" / "stability_small.yaml"
    a_file = tmp_path / "afile"
    a_file.write_text("")
    out, snaps = tmp_path / "r.nc", None
    if case == "output is a directory":
        out.mkdir()
    elif case == "output folder is a file":
        out = a_file / "r.nc"
    else:
        snaps = a_file
    argv = ["mpm", str(scene), "-o", str(out), "--quiet"] + (["--snapshots", str(snaps)] if snaps else [])
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message in err and "Traceback" not in err


@pytest.mark.parametrize("steady, expected", [(1, "window steady"), (0, "window NOT steady (mu drift -5.4%)")])
def test_mpm_prints_the_result_summary(steady, expected, tmp_path):
    """After a run, ``plough mpm`` prints mu and dp with their standard errors, the load held and steadiness."""
    import json

    import xarray as xr

    from plough.cli import summarise_result

    values = {"mu": 0.342, "mu_pl": 0.2267, "mu_sh": 0.1153, "dp": 6.1e-6, "dg": 4.48e-6, "hpu": 1.61e-6,
              "Fz_mean": 3.08, "steady": steady, "mu_drift": -0.054, "mu_standard_error": 0.013,
              "dp_standard_error": 1.6e-6}
    ds = xr.Dataset({k: ((), v) for k, v in values.items()})
    ds.attrs.update(scene=json.dumps({"name": "quick", "load_N": 3.0}), cost_particles=3200, cost_steps=3411,
                    cost_wall_time_s=17.2, resolution="contact radius 3.3 particle sizes: resolved")
    path = tmp_path / "r.nc"
    ds.to_netcdf(path)
    text = summarise_result(path)
    assert "quick: wrote" in text
    assert "mu  0.342 +- 0.013" in text and "mu_pl 0.227" in text and "mu_sh 0.115" in text
    assert "dp  6.1 +- 1.6 um" in text and "dg 4.48 um" in text and "hpu 1.61 um" in text
    assert "mean Fz / load 1.027" in text and expected in text and "resolved" in text
    assert "3,200 particles, 3,411 steps, 17 s" in text


def test_mpm_summary_leaves_out_what_the_file_does_not_hold(tmp_path):
    import xarray as xr

    from plough.cli import summarise_result

    path = tmp_path / "r.nc"
    xr.Dataset({"mu": ((), 0.5)}).to_netcdf(path)
    text = summarise_result(path)
    assert "mu  0.500" in text and "dp  - um" in text and "steady" not in text

"""Reliability: bad input, a full disk, Ctrl-C, silent defaults and the analytical model's precision (issue 31,
items 5-8). Each test names the case it holds; none runs the workflow's MPM matrix (the disk is never really
filled: the writers are made to fail as a full disk makes them fail)."""

from __future__ import annotations

import copy
import errno
import json
import math
import re
import shutil
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import xarray as xr
import yaml

from plough import cli
from plough.analytical import ploughing
from plough.materials import K0
from plough.mpm import io as mpm_io
from plough.mpm import run as run_module
from plough.study import matrix

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"
SCENE = """\
name: tiny
load_N: 1.5
sphere: {radius_um: 200}
layers: {substrate: {rigid_plastic_hardness_MPa: 900}}
interface: {model: proportional, f: 0.5}
domain: {radius_um: 80, length_um: 400, symmetric: true}
sliding: {distance_um: 200, speed_m_s: 0.1, experiment_speed_m_s: 0.001}
discretisation: {particle_size_um: 10, particles_per_cell: 2, cfl: 0.3, mass_scaling: 1.0e+6}
outputs: {steady_window: [0.5, 1.0], records: 40}
"""


def _one_line(text: str) -> str:
    lines = [s for s in text.splitlines() if s.strip()]
    assert len(lines) == 1, text
    assert "Traceback" not in text
    return lines[0]


def _scene_file(folder: Path, text: str = SCENE) -> Path:
    """The scene with every key written out (no defaults to note), tau below the wave limit (no note either)."""
    from plough.mpm.scene import Scene

    path = folder / "s.yaml"
    Scene.from_yaml(text).to_yaml(path)
    return path


def _fake_result(scene, **_kw) -> xr.Dataset:
    """What simulate returns, small: the writers are under test, not the solver."""
    return xr.Dataset({"mu": ((), 0.5, {"units": "1"}), "Fx": (("record",), np.arange(1000.0), {"units": "N"})},
                      attrs={"scene": json.dumps({"name": scene.name})})


def _main(argv: list[str]) -> int:
    try:
        return cli.main(argv)
    except KeyboardInterrupt:
        pytest.fail("KeyboardInterrupt escaped plough's main: the user sees a traceback")


def _files(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.rglob("*"))


# ----------------------------------------------------------------------------- 5. full disk, Ctrl-C
def test_full_disk_while_writing_the_result_is_named_with_the_path(monkeypatch, tmp_path, capsys):
    """ENOSPC from the netCDF writer: one line naming the full disk and the file; no file, no .part left."""
    scene = _scene_file(tmp_path)
    out_dir = tmp_path / "out"
    out = out_dir / "run.nc"
    monkeypatch.setattr(run_module, "simulate", _fake_result)

    def full(self, path, *args, **kwargs):
        Path(path).write_bytes(b"CDF\x01 half a file")
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(xr.Dataset, "to_netcdf", full)
    assert _main(["mpm", str(scene), "-o", str(out), "--quiet"]) == 2
    line = _one_line(capsys.readouterr().err)
    assert "no space left on device" in line.lower() and str(out) in line
    assert _files(out_dir) == []


def test_hdf_error_on_a_full_disk_is_named_as_a_full_disk(monkeypatch, tmp_path, capsys):
    """netCDF's "NetCDF: HDF error" (what a full disk gives, after the whole run) is diagnosed from the free space."""
    scene = _scene_file(tmp_path)
    out = tmp_path / "run.nc"
    monkeypatch.setattr(run_module, "simulate", _fake_result)
    # free space as the disk shows it while the writer runs: room at first, none once the file has grown
    real_usage = shutil.disk_usage
    state = {"free": 10**9}

    def usage(path):
        return real_usage(path)._replace(free=state["free"])

    def hdf_error(self, path, *args, **kwargs):
        Path(path).write_bytes(b"\x89HDF partial")
        state["free"] = 100  # the write filled the disk; its .part is deleted, the disk stays nearly full
        raise RuntimeError("NetCDF: HDF error")

    monkeypatch.setattr(shutil, "disk_usage", usage)
    monkeypatch.setattr(xr.Dataset, "to_netcdf", hdf_error)
    assert _main(["mpm", str(scene), "-o", str(out), "--quiet"]) == 2
    line = _one_line(capsys.readouterr().err)
    assert "no space left on device" in line.lower() and str(out) in line and "HDF error" in line
    assert _files(tmp_path) == ["s.yaml"]


def test_a_full_disk_is_refused_before_the_result_is_written(monkeypatch, tmp_path):
    """A folder with less room than the dataset needs: refused at once, naming the room, nothing written."""
    real_usage = shutil.disk_usage
    monkeypatch.setattr(shutil, "disk_usage", lambda p: real_usage(p)._replace(free=1000))
    ds = _fake_result(SimpleNamespace(name="x"))
    with pytest.raises(OSError, match="no space left on device") as err:
        mpm_io.write_result(ds, tmp_path / "run.nc")
    assert err.value.errno == errno.ENOSPC and str(tmp_path / "run.nc") in str(err.value)
    assert _files(tmp_path) == []


def _particles(n: int = 50) -> SimpleNamespace:
    rng = np.random.default_rng(0)
    return SimpleNamespace(n=n, x=rng.random((n, 3)), v=rng.random((n, 3)), stress=rng.random((n, 6)),
                           mat_a=np.zeros(n, np.int32), frac_a=np.ones(n), eps_p=rng.random(n),
                           temperature=np.full(n, 293.0), vol0=np.full(n, 1e-15), J=np.ones(n))


def _half_write(exc: BaseException):
    """A Path.write_text that writes half of the text, then fails as a full disk (or Ctrl-C) makes it fail."""
    def write_text(self, data, *args, **kwargs):
        with open(self, "w") as f:
            f.write(data[: len(data) // 2])
        raise exc
    return write_text


def test_snapshot_on_a_full_disk_leaves_no_truncated_file(monkeypatch, tmp_path):
    """A snapshot is written under a temporary name and renamed: a full disk leaves nothing under its final name."""
    target = tmp_path / "snaps" / "tiny_0000000000nm.vtp"
    monkeypatch.setattr(Path, "write_text", _half_write(OSError(errno.ENOSPC, "No space left on device")))
    with pytest.raises(OSError, match="no space left on device") as err:
        mpm_io.write_snapshot(_particles(), target, np.zeros(3), 1e-4)
    assert str(target) in str(err.value)
    assert _files(target.parent) == []


def test_a_snapshot_that_fits_is_complete_under_its_final_name(tmp_path):
    target = tmp_path / "a.vtp"
    mpm_io.write_snapshot(_particles(), target, np.zeros(3), 1e-4)
    assert _files(tmp_path) == ["a.vtp"] and target.read_text().rstrip().endswith("</VTKFile>")


def test_ctrl_c_while_writing_a_snapshot_is_one_line_and_leaves_no_partial_file(monkeypatch, tmp_path, capsys):
    scene = _scene_file(tmp_path)
    snaps = tmp_path / "snaps"

    def interrupted_run(scene, *, snapshots_dir=None, **_kw):
        mpm_io.write_snapshot(_particles(), Path(snapshots_dir) / "first.vtp", np.zeros(3), 1e-4)
        monkeypatch.setattr(Path, "write_text", _half_write(KeyboardInterrupt()))
        mpm_io.write_snapshot(_particles(), Path(snapshots_dir) / "second.vtp", np.zeros(3), 1e-4)
        return _fake_result(scene)

    monkeypatch.setattr(run_module, "simulate", interrupted_run)
    assert _main(["mpm", str(scene), "-o", str(tmp_path / "run.nc"), "--snapshots", str(snaps), "--quiet"]) == 130
    line = _one_line(capsys.readouterr().err)
    assert "interrupted" in line and "no result written" in line
    assert _files(snaps) == ["first.vtp"]  # the complete snapshot stays, the half-written one is gone
    assert not (tmp_path / "run.nc").exists()


def test_ctrl_c_while_writing_the_result_leaves_no_part_file(monkeypatch, tmp_path, capsys):
    scene = _scene_file(tmp_path)
    out_dir = tmp_path / "out"
    monkeypatch.setattr(run_module, "simulate", _fake_result)

    def interrupted(self, path, *args, **kwargs):
        Path(path).write_bytes(b"CDF\x01 half a file")
        raise KeyboardInterrupt

    monkeypatch.setattr(xr.Dataset, "to_netcdf", interrupted)
    assert _main(["mpm", str(scene), "-o", str(out_dir / "run.nc"), "--quiet"]) == 130
    assert "interrupted" in _one_line(capsys.readouterr().err)
    assert _files(out_dir) == []


# ----------------------------------------------------------------------------- 6. config gaps
def _smoke() -> dict:
    return yaml.safe_load((ROOT / "config" / "smoke.yaml").read_text())


def _set(config: dict, path: str, value) -> dict:
    config = copy.deepcopy(config)
    *parents, last = path.split(".")
    node = config
    for key in parents:
        node = node[key]
    node[last] = value
    return config


def _refusal(config: dict) -> str | None:
    """What the workflow says about a config before any job: the schema (Snakefile), then the matrix (common.smk)."""
    from snakemake.utils import validate

    try:
        validate(config, str(SCHEMA))
        matrix.all_runs(config)
    except Exception as exc:  # noqa: BLE001 - the message is what is tested
        return str(exc)
    return None


NAN = float("nan")


@pytest.mark.parametrize("key, value, named", [
    ("analytical.thickness_um", {"start": -5.0, "stop": 40.0, "num": 21}, "['analytical']['thickness_um']['start']"),
    ("analytical.thickness_um", {"start": NAN, "stop": 40.0, "num": 21}, "analytical.thickness_um.start = nan"),
    ("analytical.thickness_um", [0.0, NAN], "analytical.thickness_um[1] = nan"),
    ("analytical.thickness_um", [0.0, -4.0], "['analytical']['thickness_um'][1]"),
    ("analytical.load_N", NAN, "analytical.load_N = nan"),
    ("analytical.load_N", -5.0, "['analytical']['load_N']"),
    ("analytical.radius_mm", math.inf, "analytical.radius_mm = inf"),
    ("power_law.load_N", {"start": -1.0, "stop": 46.0, "num": 10}, "['power_law']['load_N']['start']"),
    ("analytical.thickness_um", {"start": 0.0, "stop": 40.0, "num": 21, "log": True},
     "['analytical']['thickness_um']['start']"),
    ("analytical.ratio_sweep.hardness_ratio", {"start": 0.0, "stop": 10.0, "num": 21, "log": True},
     "['analytical']['ratio_sweep']['hardness_ratio']['start']"),
    ("mpm.rigid_plastic.ratio_sweep.hardness_ratio", [0.5, NAN],
     "mpm.rigid_plastic.ratio_sweep.hardness_ratio[1] = nan"),
    ("mpm.numerics.speed_m_s", math.inf, "mpm.numerics.speed_m_s = inf"),
])
def test_config_bad_numbers_are_refused_naming_the_key(key, value, named):
    message = _refusal(_set(_smoke(), key, value))
    assert message is not None, f"{key} = {value!r} was accepted"
    assert named in message
    assert "share the key" not in message


def test_config_refusals_are_one_line_from_the_matrix():
    message = _refusal(_set(_smoke(), "mpm.rigid_plastic.ratio_sweep.hardness_ratio", [0.5, NAN]))
    assert len(message.splitlines()) == 1 and "not a finite number" in message


@pytest.mark.parametrize("key, value, named, scene_key", [
    ("mpm.numerics.sliding_distance_um", 20.0, "mpm.numerics.sliding_distance_um", "sliding.distance_m"),
    ("mpm.numerics.mass_scaling", 1.0e9, "mpm.numerics.mass_scaling", "discretisation.mass_scaling"),
    ("mpm.real_materials.loads_N", [5000.0], "mpm.real_materials.loads_N", "load_N"),
    ("mpm.numerics.steady_window", [0.9, 0.5], "mpm.numerics.steady_window", "outputs.steady_window"),
])
def test_config_mpm_errors_at_dag_time_name_the_config_key(key, value, named, scene_key):
    message = _refusal(_set(_smoke(), key, value))
    assert message is not None and named in message, message
    assert not message.startswith(scene_key) and f" {scene_key} =" not in message, message


def test_config_number_written_as_3e_1_is_read_as_scene_files_read_it():
    text = (ROOT / "config" / "smoke.yaml").read_text()
    assert "    cfl: 0.3\n" in text
    config = yaml.safe_load(text.replace("    cfl: 0.3\n", "    cfl: 3e-1\n"))
    assert config["mpm"]["numerics"]["cfl"] == "3e-1"  # YAML 1.1, as Snakemake reads config files
    assert _refusal(config) is None
    assert config["mpm"]["numerics"]["cfl"] == 0.3
    runs = matrix.all_runs(config)
    assert {d["discretisation"]["cfl"] for d in runs.values()} == {0.3}
    # text is range-checked once read as a number, naming the key
    too_big = yaml.safe_load(text.replace("    cfl: 0.3\n", "    cfl: 3e1\n"))
    message = _refusal(too_big)
    assert message is not None and "mpm.numerics.cfl" in message and "30" in message
    assert _refusal(yaml.safe_load(text.replace("    cfl: 0.3\n", "    cfl: three\n"))) is not None


def test_config_checks_run_in_the_workflow_before_any_job(tmp_path):
    """The same checks through Snakemake (a dry run in a copy): NaN refused naming the key, 3e-1 accepted."""
    import subprocess
    import sys

    for name in ("Snakefile", "config", "workflow"):
        src = ROOT / name
        (shutil.copytree if src.is_dir() else shutil.copy)(src, tmp_path / name)
    (tmp_path / "src").symlink_to(ROOT / "src")
    smoke = (ROOT / "config" / "smoke.yaml").read_text()
    assert "  k1: 12.5\n" in smoke and "    cfl: 0.3\n" in smoke

    def dry_run(text: str) -> subprocess.CompletedProcess:
        (tmp_path / "c.yaml").write_text(text)
        return subprocess.run([sys.executable, "-m", "snakemake", "--cores", "1", "--configfile=c.yaml", "-n"],
                              cwd=tmp_path, capture_output=True, text=True, timeout=600)

    bad = dry_run(smoke.replace("  k1: 12.5\n", "  k1: .nan\n"))
    assert bad.returncode != 0 and "config: analytical.k1 = nan is not a finite number" in bad.stdout + bad.stderr
    good = dry_run(smoke.replace("    cfl: 0.3\n", "    cfl: 3e-1\n"))
    assert good.returncode == 0, good.stderr[-3000:]


def test_config_every_number_in_the_schema_has_a_range():
    """Every numeric value of the schema has a sign or range (or is an enum); the axes (sweeps) too."""
    schema = yaml.safe_load(SCHEMA.read_text())
    open_ended = []

    def walk(node, where):
        if isinstance(node, dict):
            if node.get("$ref") == "#/definitions/axis" and "items" not in node:  # an axis without its range
                open_ended.append(where)
            elif node.get("$ref") == "#/definitions/number" or node.get("type") in ("number", "integer"):
                if not {"minimum", "exclusiveMinimum", "enum", "const"} & set(node):
                    open_ended.append(where)
            for k, v in node.items():
                if k == "anyOf" and {"minimum", "exclusiveMinimum"} & set(node):  # the range applies to each
                    continue
                walk(v, f"{where}.{k}")
        elif isinstance(node, list):
            for i, v in enumerate(node):
                walk(v, f"{where}[{i}]")

    for name in ("properties",):
        walk(schema[name], name)
    for name, definition in schema["definitions"].items():
        if name not in ("number", "axis"):  # the generic building blocks; their users set the range
            walk(definition, f"definitions.{name}")
    assert open_ended == []


# ----------------------------------------------------------------------------- 7. silent defaults, resolution
def test_scene_defaults_are_printed_and_recorded(monkeypatch, tmp_path, capsys):
    """A scene without load_N, sphere, particle_size or interface runs with the defaults, and says which."""
    scene = tmp_path / "s.yaml"
    scene.write_text("name: bare\nlayers: {substrate: {rigid_plastic_hardness_MPa: 900}}\n"
                     "discretisation: {cfl: 0.3}\n")
    out = tmp_path / "run.nc"
    monkeypatch.setattr(run_module, "simulate", _fake_result)
    assert _main(["mpm", str(scene), "-o", str(out), "--quiet"]) == 0
    err = capsys.readouterr().err
    note = next(s for s in err.splitlines() if "default" in s)
    for shown in ("load_N = 3 N", "sphere.radius_m = 0.0002 m", "discretisation.particle_size_m = 1e-05 m",
                  "interface = proportional, f = 1"):
        assert shown in note, note
    assert "discretisation.cfl" not in note  # given
    with xr.open_dataset(out) as ds:
        recorded = json.loads(ds.attrs["scene_defaults"])
    assert recorded["load_N"] == 3.0 and recorded["sphere.radius_m"] == 200e-6
    assert recorded["discretisation.particle_size_m"] == 10e-6
    assert recorded["interface"] == {"model": "proportional", "f": 1.0}
    assert "discretisation.cfl" not in recorded and "layers.substrate" not in recorded


def test_a_complete_scene_records_no_defaults(monkeypatch, tmp_path, capsys):
    scene = _scene_file(tmp_path)  # to_yaml writes every key
    out = tmp_path / "run.nc"
    monkeypatch.setattr(run_module, "simulate", _fake_result)
    assert _main(["mpm", str(scene), "-o", str(out), "--quiet"]) == 0
    assert "default" not in capsys.readouterr().err
    with xr.open_dataset(out) as ds:
        assert json.loads(ds.attrs["scene_defaults"]) == {}


UNDER_RESOLVED = SCENE.replace("particle_size_um: 10", "particle_size_um: 20")  # a = 32.6 um = 1.6 h


def test_an_under_resolved_contact_warns_before_the_run(monkeypatch):
    from plough.mpm import solver
    from plough.mpm.scene import Scene

    class Stop(Exception):
        pass

    def stop(*_a, **_k):
        raise Stop

    monkeypatch.setattr(solver, "init", stop)  # the warning comes before any step
    with pytest.warns(run_module.ResolutionWarning, match=r"expected contact radius a = 32.6 um is 1.63 particle "
                                                          r"sizes \(h = 20 um\)"), pytest.raises(Stop):
        run_module.simulate(Scene.from_yaml(UNDER_RESOLVED), progress=False)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", run_module.ResolutionWarning)  # a = 3.3 h: no warning
        with pytest.raises(Stop):
            run_module.simulate(Scene.from_yaml(SCENE), progress=False)


def test_an_under_resolved_run_records_its_resolution_and_is_not_steady_without_comment():
    import warnings

    from plough.mpm.scene import Scene

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = run_module.simulate(Scene.from_yaml(UNDER_RESOLVED), progress=False, threads=1)
    assert ds.attrs["contact_radius_particles"] == pytest.approx(1.63, abs=0.005)
    assert "under-resolved" in ds.attrs["resolution"] and "1.63 particle sizes" in ds.attrs["resolution"]
    if int(ds.steady):
        assert "under-resolved" in ds["steady"].attrs["comment"]


# ----------------------------------------------------------------------------- 8. the analytical model
def test_analytical_tiny_load_keeps_the_small_contact_limit():
    """Fn = 1e-15 N: a / r ~ 1e-9, where r - sqrt(r^2 - a^2) cancels to 0 and mu came out 0."""
    r, H = 0.5e-3, 1e9
    res = ploughing(1e-15, r, 0.0, H, H, interface="proportional", f=0.0)
    a = math.sqrt(2e-15 / (math.pi * H))
    assert float(res.a) == pytest.approx(a, rel=1e-12)
    assert float(res.dp) == pytest.approx(a * a / (2 * r), rel=1e-9)
    # mu_pl -> 4 a / (3 pi r) for a << r (segment (4/3) a dp over Axy = pi a^2 / 2)
    assert float(res.mu) == pytest.approx(4 * a / (3 * math.pi * r), rel=1e-9)


def test_analytical_huge_radius_is_finite():
    """r = 1e300 m: r^2 overflowed and dp came out -inf (exit 0 in the CLI)."""
    res = ploughing(3.0, 1e300, 0.0, 1e9, 1e9, f=1.0)
    for name, value in res.as_dict().items():
        assert np.all(np.isfinite(value)), name
    assert float(res.dp) >= 0 and float(res.mu) == pytest.approx(1.0 / K0, rel=1e-12)


def test_analytical_cli_huge_radius_prints_no_inf(capsys):
    args = ["analytical", "--radius-mm", "1e303", "--load-N", "3", "--thickness-um", "25",
            "--coating-hardness-MPa", "450", "--substrate-hardness-MPa", "900"]
    assert _main(args) == 0
    out = capsys.readouterr().out
    assert not re.search(r"\b-?inf\b|\bnan\b", out), out


@pytest.mark.parametrize("load, t", [(1e-6, 0.0), (1e-3, 0.0), (3.0, 0.0), (3.0, 25e-6), (3.0, 2e-6),
                                     (50.0, 25e-6), (0.01, 5e-6)])
@pytest.mark.parametrize("interface", ["proportional", "constant", "boundary_layer"])
def test_analytical_stable_form_agrees_with_the_textbook_form_in_the_physical_range(load, t, interface):
    """Where a / r is not small the old and the cancellation-free forms agree to round-off."""
    r, Hc, Hs, k1 = 0.5e-3, 450e6, 900e6, 12.5
    res = ploughing(load, r, t, Hc, Hs, k1=k1, interface=interface)
    Hcs = Hc + (Hs - Hc) * math.exp(-k1 * t / r)
    a1 = math.sqrt(2 * load / Hcs / math.pi)
    dp1 = r - math.sqrt(r * r - a1 * a1)
    if dp1 <= t:  # case 1: the textbook eq. 2.2 and segment
        a, h = a1, r - dp1
        seg = r * r * math.atan2(a, h) - a * h
        assert float(res.dp) == pytest.approx(dp1, rel=1e-9)
        assert float(res.Ayz) == pytest.approx(seg, rel=1e-7)
    for name, value in res.as_dict().items():
        assert np.all(np.isfinite(value)), name


@pytest.mark.parametrize("exponents", [(-15, -3, 9), (-12, 300, 9), (0, -6, 300), (300, 0, 300), (-300, -300, 9),
                                       (0, 0, -300)])
def test_analytical_finite_for_extreme_finite_input(exponents):
    """Loads, radii and hardnesses over the double range: finite output, or a one-line refusal."""
    load, r, H = (10.0 ** e for e in exponents)
    try:
        res = ploughing(load, r, 0.1 * r, 0.5 * H, H, f=0.5)
    except ValueError as exc:
        assert len(str(exc).splitlines()) == 1
        return
    for name, value in res.as_dict().items():
        assert np.all(np.isfinite(value)), name
    assert float(res.mu) > 0 and 0 <= float(res.dp) < r


def test_analytical_ctrl_c_is_one_line(monkeypatch, capsys):
    import plough.analytical as analytical

    def interrupted(*_a, **_k):
        raise KeyboardInterrupt

    monkeypatch.setattr(analytical, "ploughing", interrupted)
    args = ["analytical", "--radius-mm", "0.5", "--load-N", "3", "--thickness-um", "25",
            "--coating-hardness-MPa", "450", "--substrate-hardness-MPa", "900"]
    assert _main(args) == 130
    assert "interrupted" in _one_line(capsys.readouterr().err)

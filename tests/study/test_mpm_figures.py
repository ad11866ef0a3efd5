"""Tests of plough.study.mpm_figures on fake run results (no MPM solver).

Every fake run holds what a real result file holds (plough.mpm.io: the steady scalars of STEADY_META,
force histories, profiles, picture variables and the attributes the figure datasets read). Its
steady values follow f = f0 + c h^p in the particle size h with a known order p, where the limit f0
is a function of the run's *physics* read from its scene dict (load, ball, thickness, materials,
interface): a dataset that puts a run at the wrong coordinate, or extrapolates wrongly, shows up as a
wrong number at a coordinate the test computes from the config.
"""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from plough.figures import plot
from plough.figures.style import header
from plough.io import to_json, write_netcdf_atomic
from plough.mpm.io import SERIES_META, STANDARD_ERROR_META, STEADY_META
from plough.study import matrix
from plough.study.extrapolation import Method, extrapolate
from plough.study.mpm_figures import build_dataset

ROOT = Path(__file__).resolve().parents[2]
SMOKE = yaml.safe_load((ROOT / "config" / "smoke.yaml").read_text())
MPM = SMOKE["mpm"]
SIZES = [float(h) for h in MPM["particle_sizes_um"]]  # 20, 14, 10
SCENES = matrix.all_runs(SMOKE)  # run id -> scene: what a marker records, as the workflow writes it
ORDER = 1.5
C = 0.002  # relative size of the discretisation error per um**ORDER
NOISE = 0.15  # added at the middle size of noisy points: the values are then not monotone in h
BASE = {"mu": 0.2, "mu_pl": 0.05, "mu_sh": 0.15, "Fz_mean": 1.0, "Fx_mean": 0.2, "penetration": 2e-6,
        "dg": 1e-6, "hpu": 0.5e-6, "dp": 1.5e-6, "max_particle_penetration": 1e-7}
assert set(BASE) == set(STEADY_META)
NAMED = {"dx56": 0.0, "zinc_bulk": 1.0, "zinc_coating": 2.0}
IFACE = {"constant": 0.0, "proportional": 1.0, "boundary_layer": 2.0}


def signature(load_N: float, radius_um: float, t_um: float, substrate: str | float, ratio: float, iface: str) -> float:
    """A number that differs between the physical points of the smoke matrix (substrate: name or H in MPa)."""
    sub = NAMED[substrate] if isinstance(substrate, str) else substrate / 1000.0
    return 1.0 + 0.1 * load_N + 0.001 * radius_um + 0.01 * t_um + 0.2 * sub + 0.3 * ratio + 0.05 * IFACE[iface]


def _hardness_MPa(material: dict) -> float | None:
    flow = material["flow"]
    return 3.0 * flow["sigma_y_Pa"] / 1e6 if flow["model"] == "constant" else None


def signature_of(scene: dict) -> float:
    lay = scene["layers"]
    hs = _hardness_MPa(lay["substrate"])
    substrate = lay["substrate"]["name"] if hs is None else hs
    ratio = 0.0
    if lay["coating"] is not None and hs is not None:
        ratio = _hardness_MPa(lay["coating"]) / hs
    return signature(scene["load_N"], scene["sphere"]["radius_m"] * 1e6, lay["coating_thickness_m"] * 1e6,
                     substrate, ratio, scene["interface"]["model"])


def is_noisy(scene: dict) -> bool:
    """The steel at the highest load: its fake values oscillate in h."""
    lay = scene["layers"]
    return (lay["substrate"]["name"] == "dx56" and lay["coating"] is None
            and scene["load_N"] == max(float(x) for x in MPM["real_materials"]["loads_N"]))


def limit(o: str, sig: float) -> float:
    return BASE[o] * sig


def value(o: str, sig: float, h: float, noisy: bool = False) -> float:
    v = BASE[o] * (sig + C * h**ORDER)
    if noisy and h == sorted(SIZES)[1]:
        v += BASE[o] * NOISE
    return v


def se_value(name: str, sig: float, h: float) -> float:
    """A fake run's sampling standard error: differs between points and sizes."""
    return (1e-6 if name.startswith("dp") else 1e-3) * sig * h


def fake_run(scene: dict) -> xr.Dataset:
    """A result file as plough.mpm.io.build_dataset writes it, with made-up numbers."""
    h_m = scene["discretisation"]["particle_size_m"]
    h = round(h_m * 1e6, 9)
    sig, noisy = signature_of(scene), is_noisy(scene)
    slide = scene["sliding"]["distance_m"]
    coated = scene["layers"]["coating"] is not None
    n_rec, n_y = 20, (8 if coated else 11)  # two cases of a figure differ in size
    s = np.linspace(0.0, slide, n_rec)
    y = (np.arange(n_y) + 0.5) * h_m
    ds = xr.Dataset(
        {name: (("record",), sig * (1.0 + 0.01 * k) * (1.0 - np.exp(-s / (0.1 * slide))), {"units": u, "long_name": ln})
         for k, (name, (u, ln)) in enumerate(SERIES_META.items())},
        coords={"sliding_distance": (("record",), s, {"units": "m", "long_name": "sliding distance"}),
                "y": (("y",), y, {"units": "m", "long_name": "lateral position"}),
                "hx": (("hx",), np.arange(6) * h_m, {"units": "m"}),
                "hy": (("hy",), np.arange(4) * h_m, {"units": "m"})},
    )
    ds["in_steady_window"] = (("record",), s >= 0.5 * slide, {"units": "1", "long_name": "steady window"})
    ds["profile_z"] = (("y",), -1e-6 * sig * np.exp(-((y / (3 * h_m)) ** 2)), {"units": "m", "long_name": "z"})
    ds["buried_profile_z"] = (("y",), -15e-6 + 0.5 * ds["profile_z"].values, {"units": "m", "long_name": "z"})
    ds["height_map"] = (("hx", "hy"), np.linspace(-1e-6, 1e-6, 24).reshape(6, 4), {"units": "m", "long_name": "z"})
    rng = np.random.default_rng(int(sig * 1e6))
    for part, n in (("midplane", 30), ("section", 25)):
        u_name = "x" if part == "midplane" else "y"
        ds[f"{part}_{u_name}"] = ((f"{part}_particle",), rng.uniform(0, 1e-4, n).astype(np.float32), {"units": "m"})
        ds[f"{part}_z"] = ((f"{part}_particle",), rng.uniform(-5e-5, 0, n).astype(np.float32), {"units": "m"})
        ds[f"{part}_coating"] = ((f"{part}_particle",), (np.arange(n) % 2).astype(np.float32), {"units": "1"})
        ds[f"{part}_eps_p"] = ((f"{part}_particle",), rng.uniform(0, 0.5, n).astype(np.float32), {"units": "1"})
    for o, (u, ln) in STEADY_META.items():
        ds[o] = ((), value(o, sig, h, noisy), {"units": u, "long_name": ln})
    ds["steady"] = ((), np.int8(not noisy), {"units": "1", "long_name": "steady window (fake: 0 for the noisy runs)"})
    for name, (u, ln) in STANDARD_ERROR_META.items():
        if not (noisy and name == "dp_standard_error"):  # a run whose dp error could not be estimated
            ds[name] = ((), se_value(name, sig, h), {"units": u, "long_name": ln})
    ds.attrs.update(cost_wall_time_s=100.0 / h, scene=to_json(scene),
                    coating_representation=f"fake representation of {scene['name']}",
                    sphere_centre_end_m=np.array([2e-4, 0.0, 4.9e-4]), midplane_section_x_m=1e-4)
    return ds


@pytest.fixture(scope="module")
def run_files(tmp_path_factory):
    """run id -> result file, for every run of the smoke matrix."""
    d = tmp_path_factory.mktemp("runs")
    paths = {}
    for rid, scene in matrix.all_runs(SMOKE).items():
        paths[rid] = d / f"{rid}.nc"
        fake_run(scene).to_netcdf(paths[rid])
    return paths


@pytest.fixture(scope="module")
def smoke_dataset(run_files):
    """figure -> ``build_dataset(SMOKE, figure, run_files)`` for the module's unchanged run files, built once per
    figure (most tests read the same datasets); each call returns its own deep copy."""
    built: dict[str, xr.Dataset] = {}

    def dataset(figure: str) -> xr.Dataset:
        if figure not in built:
            built[figure] = build_dataset(SMOKE, figure, run_files)
        return built[figure].copy(deep=True)

    return dataset


def _written(ds: xr.Dataset, tmp_path: Path) -> xr.Dataset:
    """Through the workflow's atomic writer (which refuses undeclared NaN) and back."""
    path = write_netcdf_atomic(ds, tmp_path / "figure.nc")
    return xr.load_dataset(path)


def _draws(figure: str, ds: xr.Dataset, tmp_path: Path) -> None:
    png = tmp_path / "f.png"
    plot(figure, ds, [png])
    assert png.exists() and png.stat().st_size > 10_000


def _with_marker(run_files, tmp_path: Path, rid: str, marker: xr.Dataset) -> dict:
    """The run files with run ``rid`` replaced by ``marker`` (a skip or failure marker, atomically written)."""
    paths = dict(run_files)
    paths[rid] = tmp_path / f"{rid}.nc"
    write_netcdf_atomic(marker, paths[rid])
    return paths


def _recording() -> dict:
    """The smoke config with mpm.finest_failure: record (the smoke config itself stops)."""
    config = copy.deepcopy(SMOKE)
    config["mpm"]["finest_failure"] = "record"
    return config


def _zinc_block_lightest():
    """The zinc block at the lowest load and the first ball: its loads, ball radius and finest run id."""
    real = MPM["real_materials"]
    loads = [float(x) for x in real["loads_N"]]
    r1 = float(real["ball_radii_um"][0])
    return loads, r1, matrix.run_id(matrix.real_point(real, "zinc_block", loads[0], r1), min(SIZES))


def _check_extrapolation(ds, o, sel, sig, suffix="", noisy=False):
    f0 = limit(o, sig)
    per_size = ds[o + suffix].sel(sel)
    for h in SIZES:
        assert float(per_size.sel(h=h)) == pytest.approx(value(o, sig, h, noisy), rel=1e-12), (o, sel, h)
    h0 = ds[f"{o}_h0{suffix}"].sel(sel)
    method = int(ds[f"{o}_h0_method{suffix}"].sel(sel))
    flagged = int(ds[f"{o}_h0_flagged{suffix}"].sel(sel))
    unc = float(ds[f"{o}_h0_uncertainty{suffix}"].sel(sel))
    if noisy:
        assert method == Method.LEAST_SQUARES and flagged == 1, (o, sel)
        assert float(ds[f"{o}_h0_order{suffix}"].sel(sel)) == 1.0  # the assumed order of the fallback
        values = [value(o, sig, h, noisy) for h in SIZES]
        assert unc >= max(values) - min(values) - 1e-12 * abs(f0)  # never tighter than the spread
    else:
        assert method == Method.RICHARDSON and flagged == 0, (o, sel)
        assert float(h0) == pytest.approx(f0, rel=1e-9), (o, sel)
        assert float(ds[f"{o}_h0_order{suffix}"].sel(sel)) == pytest.approx(ORDER, rel=1e-7)
        h1, h2 = sorted(SIZES)[:2]
        r = h2 / h1
        e21 = value(o, sig, h1) - value(o, sig, h2)
        # order 1.5 is not the formal order 1: Roache's Fs = 3 with the band's order bounded to 1
        assert unc == pytest.approx(3.0 * abs(e21) / (r - 1), rel=1e-7)


# ----------------------------------------------------------------------------- sweep figures
def test_fig15_per_size_values_extrapolation_and_analytical(smoke_dataset, tmp_path):
    ds = smoke_dataset("fig15")
    real = MPM["real_materials"]
    loads = [float(x) for x in real["loads_N"]]
    assert ds["dp"].dims == ("material", "load_N", "h")
    assert list(ds["material"].values) == ["zinc_block", "steel"]
    assert list(ds["load_N"].values) == loads
    assert list(ds["h"].values) == sorted(SIZES, reverse=True)
    assert ds["dp_h0"].dims == ("material", "load_N")
    assert ds["dp_h0_method"].attrs["flag_meanings"].split()[Method.LEAST_SQUARES] == "least_squares"
    assert "Oberkampf" in ds["mu_h0_uncertainty"].attrs["comment"]  # the file says which rule made its bars
    r1 = float(real["ball_radii_um"][0])
    substrates = {"zinc_block": "zinc_bulk", "steel": "dx56"}
    n_noisy = 0
    for label, substrate in substrates.items():
        for load in loads:
            sel = {"material": label, "load_N": load}
            sig = signature(load, r1, 0.0, substrate, 0.0, "boundary_layer")
            noisy = label == "steel" and load == max(loads)
            n_noisy += noisy
            for o in matrix.OUTPUTS:
                _check_extrapolation(ds, o, sel, sig, noisy=noisy)
            assert float(ds["Fz_mean"].sel(sel).sel(h=SIZES[0])) == pytest.approx(value("Fz_mean", sig, SIZES[0],
                                                                                         noisy))
            for h in SIZES:
                assert float(ds["wall_time_s"].sel(sel).sel(h=h)) == pytest.approx(100.0 / h)
                assert float(ds["steady"].sel(sel).sel(h=h)) == float(not noisy)  # each run's own flag
                assert float(ds["mu_standard_error"].sel(sel).sel(h=h)) == pytest.approx(
                    se_value("mu", sig, h), rel=1e-12)
                dp_se = float(ds["dp_standard_error"].sel(sel).sel(h=h))
                assert np.isnan(dp_se) if noisy else dp_se == pytest.approx(se_value("dp", sig, h), rel=1e-12)
            # the runs' errors carried to the limit: d mu_h0 / d mu(h) by differencing extrapolate() on the
            # dataset's own per-size values, times each run's error
            hs = ds["h"].values
            mu_h = ds["mu"].sel(sel).values
            jac = []
            for k in range(hs.size):
                d = np.zeros(hs.size)
                d[k] = 1e-7
                jac.append((float(extrapolate(hs, mu_h + d).value) - float(extrapolate(hs, mu_h - d).value)) / 2e-7)
            expected = np.sqrt(np.sum((np.array(jac) * [se_value("mu", sig, h) for h in hs]) ** 2))
            assert float(ds["mu_h0_sampling_error"].sel(sel)) == pytest.approx(expected, rel=1e-5)
            assert bool(np.isnan(float(ds["dp_h0_sampling_error"].sel(sel)))) == noisy  # a run's dp error missing
            expected = matrix.analytical_values(matrix.real_point(real, label, load, r1))
            for o, v in expected.items():
                assert np.isfinite(v)
                assert float(ds[f"{o}_analytical"].sel(sel)) == pytest.approx(v, rel=1e-12), (o, sel)
    assert n_noisy == 1
    assert int(ds["mu_h0_flagged"].sum()) == 1
    assert ds.attrs["figure"] == "fig15" and ds.attrs["title"].startswith("Fig. 15")
    assert ds.attrs["plough_version"] and ds.attrs["git_commit"]
    assert json.loads(ds.attrs["config"]) == json.loads(to_json(MPM))
    _draws("fig15", _written(ds, tmp_path), tmp_path)


def test_fig11_has_two_panels_with_suffixed_variables(smoke_dataset, tmp_path):
    ds = smoke_dataset("fig11")
    rp = MPM["rigid_plastic"]
    rs, ts = rp["ratio_sweep"], rp["thickness_sweep"]
    assert ds.attrs["panels"] == "a,b"
    assert "dp" not in ds and "dp_h0" not in ds
    assert ds["dp_a"].dims == ("interface", "hardness_ratio", "h")
    assert ds["dp_b"].dims == ("coating", "thickness_um", "h")
    assert list(ds["hardness_ratio"].values) == [float(x) for x in rs["hardness_ratio"]]
    assert list(ds["thickness_um"].values) == [float(x) for x in ts["thickness_um"]]
    assert list(ds["interface"].values) == list(rs["interfaces"])
    assert list(ds["coating"].values) == ["soft", "hard"]
    for name in ("dp_h0_a", "dp_h0_uncertainty_b", "dp_h0_order_a", "dp_h0_method_b", "dp_h0_flagged_a",
                 "mu_analytical_b", "wall_time_s_a", "steady_a", "steady_b"):
        assert name in ds, name
    assert ds["steady_a"].dims == ds["dp_a"].dims and "steady" not in ds
    assert ds.attrs["ratio_sweep_thickness_um"] == float(rs["thickness_um"])

    hs_a, t_a = float(rs["substrate_hardness_MPa"]), float(rs["thickness_um"])
    for iface in rs["interfaces"]:
        for x in rs["hardness_ratio"]:
            # the constant law at or above both hardnesses is the proportional point's run (capped at kappa)
            runs_as = ("proportional" if iface == "constant" and float(rp["H0_MPa"]) >= hs_a * max(float(x), 1.0)
                       else iface)
            sig = signature(rp["load_N"], rp["radius_um"], t_a, hs_a, float(x), runs_as)
            for o in ("dp", "mu"):
                _check_extrapolation(ds, o, {"interface": iface, "hardness_ratio": float(x)}, sig, "_a")
    for case in ("soft", "hard"):
        c = ts[case]
        for t in ts["thickness_um"]:
            ratio = float(c["hardness_ratio"]) if t > 0 else 0.0
            sig = signature(rp["load_N"], rp["radius_um"], float(t), float(c["substrate_hardness_MPa"]), ratio,
                            ts["interface"])
            for o in ("dp", "mu"):
                _check_extrapolation(ds, o, {"coating": case, "thickness_um": float(t)}, sig, "_b")

    # the hard t = 25 um point of panel b is panel a's proportional H~ = 2 run: same MPM values, but the
    # analytical line of each panel uses that panel's k1
    sel_a = {"interface": "proportional", "hardness_ratio": 2.0}
    sel_b = {"coating": "hard", "thickness_um": 25.0}
    assert float(ds["dp_h0_a"].sel(sel_a)) == float(ds["dp_h0_b"].sel(sel_b))
    for sel, suffix, k1 in ((sel_a, "_a", rs["k1"]), (sel_b, "_b", ts["k1"])):
        point = matrix.rigid_plastic_point(rp, 2.0, 450, 25, "proportional", k1)
        for o, v in matrix.analytical_values(point).items():
            assert float(ds[f"{o}_analytical{suffix}"].sel(sel)) == pytest.approx(v, rel=1e-12), (o, suffix)
    assert float(ds["mu_analytical_a"].sel(sel_a)) != pytest.approx(float(ds["mu_analytical_b"].sel(sel_b)))
    _draws("fig11", _written(ds, tmp_path), tmp_path)


def test_thickness_panel_keeps_every_mark_in_view_and_the_key_off_the_marks(smoke_dataset):
    """Fig. 11b: a per-size dp far above the analytical lines and the dp = t line's reach stays in view (the
    axis used to end at 1.3x the largest per-size value, hiding extrapolated marks above it); the t axis is
    linear to THICKNESS_LINEAR_UM and logarithmic beyond, starting left of t = 0; the panel has no legend of
    its own, its entries go to the figure's key, which lies above the axes, where it covers no mark."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from plough.figures import mpm as mpm_figures

    ds = smoke_dataset("fig11")
    high = float(ds["dp_b"].max()) * 7.0  # an extrapolated mark far above every per-size value
    ds["dp_h0_b"][{"coating": 0, "thickness_um": 1}] = high
    ds["dp_h0_b"][{"coating": 1, "thickness_um": 1}] = -0.5 * high  # an extrapolation below zero
    fig, ax = plt.subplots(layout="constrained")
    entries = mpm_figures._sweep_panel(ax, ds, "dp", "_b", thickness_axis=True, panel="b")
    header(fig, "fig11", entries)
    lo, hi = ax.get_ylim()
    assert lo <= -0.5 * high * 1e6 and hi >= high * 1e6
    t = ds["thickness_um"].values
    assert ax.get_xscale() == "symlog" and ax.get_xlim()[0] < 0 < t.max() < ax.get_xlim()[1]
    assert set(ax.get_xticks()) >= {0.0, 10.0} and t.min() == 0
    fig.canvas.draw()
    assert ax.get_legend() is None
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert {"(b) soft coating", "(b) hard coating", "dotted: dp = t"} <= set(labels)
    assert fig.legends[0].get_window_extent().y0 >= ax.get_tightbbox().y1 - 1  # above the axes and their title
    plt.close(fig)
    # thicknesses all past the linear range: no empty linear stretch at the left
    fig, ax = plt.subplots()
    mpm_figures._thickness_axis(ax, np.array([15.0, 30.0, 55.0]))
    assert ax.get_xlim()[0] == pytest.approx(15.0 / 1.15) and list(ax.get_xticks()) == [20, 50]
    plt.close(fig)


def _drawn_figure(figure: str, ds: xr.Dataset, monkeypatch):
    """The figure ``figure``'s plotter hands to save (what the PNG and PDF are written from)."""
    from plough.figures import mpm as mpm_figures

    drawn = []
    monkeypatch.setattr(mpm_figures, "save", lambda fig, outputs: drawn.append(fig))
    mpm_figures.PLOTTERS[figure](ds, ["unused.png"])
    assert len(drawn) == 1
    return drawn[0]


def test_fig13_has_a_row_for_mu_and_for_each_of_its_parts(smoke_dataset, tmp_path, monkeypatch):
    """Issue 32: at strong interface shear the MPM's mu_sh is not expected to equal the analytical one (the
    contact grows under shear), its mu_pl is; so Fig. 13 draws mu (a, b), mu_pl (c, d) and mu_sh (e, f), each
    against H~ (left) and t (right): every panel's trend is its own quantity's h -> 0 values, its dashed lines
    that quantity's analytical values, its y label and title name it. One key, with the note on mu_sh; Fig. 11
    keeps its single row of dp."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import to_rgb

    from plough.figures import mpm as mpm_figures

    ds = _written(smoke_dataset("fig13"), tmp_path)
    fig = _drawn_figure("fig13", ds, monkeypatch)
    assert len(fig.axes) == 6
    series = {"_a": ("interface", "hardness_ratio"), "_b": ("coating", "thickness_um")}
    for r, quantity in enumerate(("mu", "mu_pl", "mu_sh")):
        for c, suffix in enumerate(("_a", "_b")):
            ax = fig.axes[2 * r + c]
            letter = "abcdef"[2 * r + c]
            assert ax.get_ylabel() == mpm_figures.QUANTITY[quantity][0]
            assert ax.get_title().startswith(f"({letter}) {mpm_figures.ROW_TITLES[quantity]} vs "), ax.get_title()
            assert (ax.get_xlabel() != "") == (r == 2)  # the x axes labelled once, under the last row
            dim, axis = series[suffix]
            x = ds[axis].values
            lines = [line for line in ax.lines if np.asarray(line.get_xdata()).size == x.size]
            for i, label in enumerate(ds[dim].values):
                colour = to_rgb(mpm_figures.SERIES_COLOURS[i])  # the two interfaces share the analytical mu_pl
                for style, name in (("-", f"{quantity}_h0{suffix}"), ("--", f"{quantity}_analytical{suffix}")):
                    want = ds[name].sel({dim: label}).values
                    hits = [line for line in lines if line.get_linestyle() == style
                            and to_rgb(line.get_color()) == colour
                            and np.allclose(np.asarray(line.get_ydata(), dtype=float), want)]
                    assert len(hits) == 1, (letter, label, name)
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert {"(a, c, e) constant interface", "(b, d, f) hard coating", "dashed: analytical model"} <= set(labels)
    notes = [text for text in labels if text.startswith("note:")]
    assert len(notes) == 1 and "mu_sh" in notes[0] and "Fn / H" in notes[0]
    assert "docs/journal/2026-12-02-interface-shear-split.md" in notes[0]
    plt.close(fig)

    fig = _drawn_figure("fig11", _written(smoke_dataset("fig11"), tmp_path), monkeypatch)
    assert [ax.get_ylabel() for ax in fig.axes] == [mpm_figures.QUANTITY["dp"][0]] * 2
    assert [ax.get_title() for ax in fig.axes] == ["(a) vs hardness ratio H~", "(b) vs coating thickness t"]
    assert not [t for t in fig.legends[0].get_texts() if t.get_text().startswith("note:")]
    plt.close(fig)


def test_fig13_png_holds_the_three_rows(smoke_dataset, tmp_path):
    """The saved PNG is the three-row figure: taller than Fig. 11's single row at the same width."""
    import matplotlib.image

    sizes = {}
    for figure in ("fig11", "fig13"):
        png = tmp_path / f"{figure}.png"
        plot(figure, _written(smoke_dataset(figure), tmp_path), [png])
        sizes[figure] = matplotlib.image.imread(png).shape[:2]
    assert sizes["fig13"][1] == sizes["fig11"][1] and sizes["fig13"][0] > 2 * sizes["fig11"][0]


def test_fig18_thickness_panel_and_bulk_panel(smoke_dataset, tmp_path):
    ds = smoke_dataset("fig18")
    rts = MPM["real_materials"]["thickness_sweep"]
    assert ds.attrs["panels"] == "t,bulk"
    assert ds["dp_t"].dims == ("coated_system", "thickness_um", "h")
    assert ds["dp_bulk"].dims == ("block", "load_N", "h")
    assert list(ds["thickness_um"].values) == [float(x) for x in rts["thickness_um"]]
    assert list(ds["load_N"].values) == [float(rts["load_N"])]
    for t in rts["thickness_um"]:
        sig = signature(rts["load_N"], rts["radius_um"], float(t), "dx56", 0.0, "boundary_layer")
        _check_extrapolation(ds, "dp", {"coated_system": "coated", "thickness_um": float(t)}, sig, "_t")
    sig = signature(rts["load_N"], rts["radius_um"], 0.0, "zinc_bulk", 0.0, "boundary_layer")
    _check_extrapolation(ds, "dp", {"block": "zinc_block", "load_N": float(rts["load_N"])}, sig, "_bulk")
    _draws("fig18", _written(ds, tmp_path), tmp_path)


def test_fig22_fits_with_the_mpm_points_of_fig21(smoke_dataset, tmp_path):
    ds = smoke_dataset("fig22")
    real = MPM["real_materials"]
    loads = [float(x) for x in real["loads_N"]]
    assert ds["mu_mpm"].dims == ("ball_diameter_mm", "mpm_load_N")
    assert list(ds["mpm_load_N"].values) == loads
    assert list(ds["ball_diameter_mm"].values) == [float(x) for x in SMOKE["power_law"]["ball_diameters_mm"]]
    assert "mu_fit" in ds and ds["mu_fit"].dims == ("ball_diameter_mm", "load_N")
    for r in real["ball_radii_um"]:
        for load in loads:
            sig = signature(load, float(r), float(real["coating_thickness_um"]), "dx56", 0.0, "boundary_layer")
            sel = {"ball_diameter_mm": 2 * float(r) / 1000, "mpm_load_N": load}
            assert float(ds["mu_mpm"].sel(sel)) == pytest.approx(limit("mu", sig), rel=1e-9)
            assert float(ds["mu_mpm_uncertainty"].sel(sel)) > 0
    fig21 = smoke_dataset("fig21")
    np.testing.assert_array_equal(ds["mu_mpm"].values, fig21["mu_h0"].values)
    assert json.loads(ds.attrs["config"])["mpm"] == json.loads(to_json(MPM))
    _draws("fig22", _written(ds, tmp_path), tmp_path)


def test_a_missing_run_is_an_error_naming_it(run_files, tmp_path):
    rid = matrix.figure_runs(SMOKE, "fig15")[3]
    paths = dict(run_files)
    paths[rid] = tmp_path / "absent.nc"
    with pytest.raises(FileNotFoundError, match=rid.replace(".", r"\.")):
        build_dataset(SMOKE, "fig15", paths)
    del paths[rid]
    with pytest.raises(FileNotFoundError, match=rid.replace(".", r"\.")):
        build_dataset(SMOKE, "fig15", paths)


def test_an_unknown_figure_is_refused(run_files):
    with pytest.raises(ValueError, match="not an MPM figure"):
        build_dataset(SMOKE, "fig03", run_files)


# ----------------------------------------------------------------------------- single-run figures
def _finest_run(point: matrix.Point) -> str:
    return matrix.run_id(point, min(SIZES))


def test_fig19_keeps_the_finest_run_of_its_case(smoke_dataset, run_files, tmp_path):
    ds = smoke_dataset("fig19")
    real = MPM["real_materials"]
    pic = real["picture"]
    point = matrix.real_point(real, "coated", pic["load_N"], pic["radius_um"])
    rid = _finest_run(point)
    run = xr.load_dataset(run_files[rid])
    assert list(ds["case"].values) == ["coated"]
    assert ds.attrs["particle_size_um"] == min(SIZES)
    assert ds["Fx"].dims == ("case", "record")
    sub = ds.sel(case="coated")
    for name in ("Fx", "Fz", "Fx_pl", "Fx_sh", "depth"):
        np.testing.assert_array_equal(sub[name].values, run[name].values)
    np.testing.assert_array_equal(ds["sliding_distance"].values, run["sliding_distance"].values)
    np.testing.assert_array_equal(sub["in_steady_window"].values.astype(bool), run["in_steady_window"].values)
    for o in (*matrix.OUTPUTS, "Fz_mean", "steady"):
        assert float(sub[o]) == float(run[o]), o
    for o, v in matrix.analytical_values(point).items():
        assert float(sub[f"{o}_analytical"]) == pytest.approx(v, rel=1e-12), o
    assert "profile_z" not in ds and "height_map" not in ds and "hx" not in ds.coords
    assert ds.attrs["scene_coated"] == run.attrs["scene"]
    assert json.loads(ds.attrs["scene_coated"])["name"] == rid
    assert ds.attrs["coating_representation_coated"] == f"fake representation of {rid}"
    assert ds.attrs["figure"] == "fig19" and ds.attrs["plough_version"]
    _draws("fig19", _written(ds, tmp_path), tmp_path)


def test_fig17_stacks_two_cases_of_different_size(smoke_dataset, run_files, tmp_path):
    ds = smoke_dataset("fig17")
    real = MPM["real_materials"]
    pic = real["picture"]
    assert list(ds["case"].values) == ["coated", "zinc_block"]
    runs = {case: xr.load_dataset(run_files[_finest_run(matrix.real_point(real, case, pic["load_N"],
                                                                            pic["radius_um"]))])
            for case in ds["case"].values}
    n = {case: run.sizes["y"] for case, run in runs.items()}
    assert n["coated"] < n["zinc_block"]
    assert ds.sizes["y"] == n["zinc_block"]  # the union of both cases' sections
    for case, run in runs.items():
        for var in ("profile_z", "buried_profile_z"):
            z = ds[var].sel(case=case)
            np.testing.assert_array_equal(z.sel(y=run["y"].values).values, run[var].values)
            assert int(np.isnan(z.values).sum()) == ds.sizes["y"] - n[case]  # padded, declared missing
            assert ds[var].attrs["allow_missing"] == 1
        assert float(ds["dp"].sel(case=case)) == float(run["dp"])
        assert ds.attrs[f"scene_{case}"] == run.attrs["scene"]
    _draws("fig17", _written(ds, tmp_path), tmp_path)


@pytest.mark.parametrize("figure", ["fig12", "fig14"])
def test_picture_figures_draw(smoke_dataset, run_files, tmp_path, figure):
    ds = smoke_dataset(figure)
    point = matrix.figure_points(SMOKE, figure)["coated"]
    run = xr.load_dataset(run_files[_finest_run(point)])
    for name in ("midplane_x", "midplane_coating") if figure == "fig12" else ("height_map", "section_z"):
        np.testing.assert_array_equal(ds[name].sel(case="coated").values, run[name].values)
    if figure == "fig14":
        np.testing.assert_array_equal(ds["hx"].values, run["hx"].values)
    _draws(figure, _written(ds, tmp_path), tmp_path)


def test_sphere_position_reaches_the_fig12_picture(smoke_dataset):
    """plot_fig12 draws the sphere from the run's attribute sphere_centre_end_m, kept per case."""
    ds = smoke_dataset("fig12")
    np.testing.assert_allclose(ds.attrs["sphere_centre_end_m_coated"], [2e-4, 0.0, 4.9e-4])


def test_a_picture_run_under_another_law_than_configured_says_so(smoke_dataset):
    """The smoke Fig. 12 picture (constant H0 = 450 MPa on a 225 on 450 MPa coating) is the f = 1 point's run
    (matrix.solver_interface); its dataset keeps the configured law beside the run's scene, Fig. 14's none."""
    pic = SMOKE["mpm"]["rigid_plastic"]["picture"]
    assert pic["interface"] == "constant"
    ds = smoke_dataset("fig12")
    assert json.loads(ds.attrs["scene_coated"])["interface"] == {"model": "proportional", "f": 1.0}
    assert json.loads(ds.attrs["interface_configured_coated"]) == {
        "model": "constant", "H0_Pa": float(SMOKE["mpm"]["rigid_plastic"]["H0_MPa"]) * 1e6}
    assert not any(k.startswith("interface_configured") for k in smoke_dataset("fig14").attrs)


@pytest.mark.parametrize("figure", ["fig15", "fig19"])
def test_result_files_from_before_the_steadiness_check_still_build(smoke_dataset, run_files, tmp_path, figure):
    """Cached runs written before io.steadiness existed have no 'steady': the figure's dataset
    is built without it (no all-missing variable), everything else unchanged."""
    old = {}
    for rid, path in run_files.items():
        old[rid] = tmp_path / f"{rid}.nc"
        xr.load_dataset(path).drop_vars("steady").to_netcdf(old[rid])
    without = build_dataset(SMOKE, figure, old)
    with_check = smoke_dataset(figure)
    assert "steady" in with_check and "steady" not in without
    xr.testing.assert_identical(without, with_check.drop_vars("steady"))


def test_a_mix_of_old_and_new_result_files(smoke_dataset, run_files, tmp_path):
    """Some runs from before the steadiness check: a sweep keeps the flag of the others and leaves
    the old ones missing; a single-run figure drops the flag unless every case has it."""
    sweep_old = set()
    paths = dict(run_files)
    for k, rid in enumerate(sorted(run_files)):
        if k % 2:
            paths[rid] = tmp_path / f"{rid}.nc"
            xr.load_dataset(run_files[rid]).drop_vars("steady").to_netcdf(paths[rid])
            sweep_old.add(rid)
    ds = build_dataset(SMOKE, "fig15", paths)
    flags = ds["steady"].values
    assert np.isnan(flags).any() and np.isfinite(flags).any()
    real = MPM["real_materials"]
    r1 = float(real["ball_radii_um"][0])
    substrates = {"zinc_block": "zinc_bulk", "steel": "dx56"}
    for label in substrates:
        for load in (float(x) for x in real["loads_N"]):
            for h in SIZES:
                rid = matrix.run_id(matrix.real_point(real, label, load, r1), h)
                v = float(ds["steady"].sel(material=label, load_N=load, h=h))
                assert np.isnan(v) if rid in sweep_old else v == float(xr.load_dataset(run_files[rid])["steady"])
    assert ds["steady"].attrs["allow_missing"] == 1
    cases = matrix.figure_points(SMOKE, "fig17")  # two cases
    finest = sorted(matrix.run_id(p, min(SIZES)) for p in cases.values())
    assert len(finest) >= 2
    one_old = dict(run_files)
    one_old[finest[0]] = tmp_path / "one_old.nc"
    xr.load_dataset(run_files[finest[0]]).drop_vars("steady").to_netcdf(one_old[finest[0]])
    assert "steady" in smoke_dataset("fig17")
    assert "steady" not in build_dataset(SMOKE, "fig17", one_old)


def test_sweep_datasets_do_not_depend_on_the_paths_order(smoke_dataset, run_files):
    reordered = dict(reversed(list(run_files.items())))
    a = smoke_dataset("fig16")
    b = build_dataset(copy.deepcopy(SMOKE), "fig16", reordered)
    xr.testing.assert_identical(a, b)


def test_a_finest_run_its_decision_did_not_ask_for_is_extrapolated_from_the_two_coarser_sizes(run_files, tmp_path):
    """A gated finest run that its refinement decision did not ask for (not_needed, the checkpoint mpm_refine) is
    not read: that point's h -> 0 value is the two-size Richardson extrapolation (order 1, safety factor 3),
    flagged; its finest per-size values are missing (NaN, declared), every other point is untouched; the dataset
    passes the atomic writer and draws. A run the config does not gate is refused as not needed."""
    loads, r1, finest = _zinc_block_lightest()
    paths = {rid: path for rid, path in run_files.items() if rid != finest}

    with pytest.raises(ValueError, match=f"run '{finest}' is named as not needed .* the config does not gate it"):
        build_dataset(SMOKE, "fig15", paths, not_needed=[finest])  # skip_finest_tolerance null: nothing gated
    with pytest.raises(FileNotFoundError, match=finest):
        build_dataset(SMOKE, "fig15", paths)
    config = copy.deepcopy(SMOKE)
    config["mpm"]["skip_finest_tolerance"] = 0.05
    assert finest in matrix.skippable_runs(config)
    ds = build_dataset(config, "fig15", paths, not_needed=[finest])
    sel = {"material": "zinc_block", "load_N": loads[0]}
    sig = signature(loads[0], r1, 0.0, "zinc_bulk", 0.0, "boundary_layer")
    h3, h2 = sorted(SIZES, reverse=True)[:2]  # 20, 14
    for o in matrix.OUTPUTS:
        f3, f2 = value(o, sig, h3), value(o, sig, h2)
        gain = 1.0 / (h3 / h2 - 1.0)
        assert float(ds[f"{o}_h0"].sel(sel)) == pytest.approx(f2 + (f2 - f3) * gain, rel=1e-12), o
        assert float(ds[f"{o}_h0_uncertainty"].sel(sel)) == pytest.approx(3.0 * abs(f2 - f3) * gain, rel=1e-12)
        assert int(ds[f"{o}_h0_method"].sel(sel)) == Method.TWO_SIZES_ASSUMED_ORDER
        assert int(ds[f"{o}_h0_flagged"].sel(sel)) == 1
        assert np.isnan(float(ds[o].sel(sel).sel(h=min(SIZES))))
        if o in ("mu", "dp"):  # the runs' errors through the two-size extrapolation: (1 + g) s2, g s3
            expected = np.hypot((1 + gain) * se_value(o, sig, h2), gain * se_value(o, sig, h3))
            assert float(ds[f"{o}_h0_sampling_error"].sel(sel)) == pytest.approx(expected, rel=1e-12), o
        _check_extrapolation(ds, o, {"material": "zinc_block", "load_N": loads[1]},
                             signature(loads[1], r1, 0.0, "zinc_bulk", 0.0, "boundary_layer"))
    assert int(ds["skipped_finest"].sum()) == 1 and int(ds["skipped_finest"].sel(sel)) == 1
    _draws("fig15", _written(ds, tmp_path), tmp_path)


def _old_skip_marker(scene: dict) -> xr.Dataset:
    """A skip marker as the workflow wrote one before refinement became a checkpoint."""
    from plough.io import provenance_attrs
    from plough.study import skipping

    return xr.Dataset(attrs={skipping.SKIPPED_ATTR: 1, "skip_reason": "within skip_finest_tolerance = 0.1",
                             **provenance_attrs(scene, key="scene")})


@pytest.mark.parametrize("finest", [False, True])
def test_an_old_skip_marker_is_refused_with_the_command_that_remakes_it(run_files, tmp_path, finest):
    """The workflow no longer writes skip markers; one left in results/runs/ (at any size, gated or not) is
    refused, naming the run and the --forcerun command."""
    real = MPM["real_materials"]
    point = matrix.real_point(real, "zinc_block", float(real["loads_N"][0]), float(real["ball_radii_um"][0]))
    rid = matrix.run_id(point, (min if finest else max)(SIZES))
    paths = dict(run_files)
    paths[rid] = tmp_path / f"{rid}.nc"
    write_netcdf_atomic(_old_skip_marker(SCENES[rid]), paths[rid])
    config = copy.deepcopy(SMOKE)
    config["mpm"]["skip_finest_tolerance"] = 0.05
    assert (rid in matrix.skippable_runs(config)) == finest
    with pytest.raises(ValueError, match=f"run '{rid}' is a skip marker, which this workflow no longer writes.*"
                                         f"--forcerun results/runs/{rid}.nc"):
        build_dataset(config, "fig15", paths)


def test_sweep_figure_crosses_the_runs_that_were_not_steady(smoke_dataset):
    """The per-size points of runs with steady = 0 (the fake noisy steel runs) get a cross, once in the legend;
    without the flag (files from before the check) no cross is drawn."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from plough.figures import mpm as mpm_figures

    ds = smoke_dataset("fig15")
    n_bad = int((ds["steady"] == 0).sum())
    assert n_bad == len(SIZES)  # the steel at the highest load, at every size
    for data, crosses in ((ds, n_bad), (ds.drop_vars("steady"), 0)):
        fig, ax = plt.subplots()
        mpm_figures._sweep_panel(ax, data, "mu", "")
        crossed = [line for line in ax.lines if line.get_marker() == "x"]
        assert sum(len(line.get_xdata()) for line in crossed) == crosses
        labels = [line.get_label() for line in crossed if not line.get_label().startswith("_")]
        assert len(labels) == (1 if crosses else 0)
        plt.close(fig)


def test_sweep_figure_draws_the_trend_over_lighter_bars(smoke_dataset):
    """Trend first: each series' extrapolated values are joined by one line in its colour, drawn above
    their bars, which are lighter and thinner than that line; the per-size values are faint; the y axis
    follows the marks and lines (zero included), not the bars."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import to_rgb

    from plough.figures import mpm as mpm_figures

    ds = smoke_dataset("fig15")
    fig, ax = plt.subplots()
    mpm_figures._sweep_panel(ax, ds, "dp", "")
    bars = [c.lines[2][0] for c in ax.containers if c.lines[2] and c.lines[2][0].get_alpha() is None]
    assert len(bars) == ds["material"].size
    marks = [ds["dp"].values * 1e6, ds["dp_h0"].values * 1e6, ds["dp_analytical"].values * 1e6]
    tops = []
    for i, label in enumerate(ds["material"].values):
        colour = np.array(to_rgb(mpm_figures.SERIES_COLOURS[i]))
        val = ds["dp_h0"].sel(material=label).values * 1e6
        trend = [line for line in ax.lines if line.get_linestyle() == "-" and line.get_xdata().size == val.size
                 and np.allclose(line.get_ydata(), val)]
        assert len(trend) == 1 and np.allclose(to_rgb(trend[0].get_color()), colour)
        own = [b for b in bars if np.allclose([seg[:, 1].mean() for seg in b.get_segments()], val)]
        assert len(own) == 1
        bar_colour = np.array(own[0].get_color()[0][:3])
        assert np.all(bar_colour >= colour) and bar_colour.sum() > colour.sum()  # lighter: towards white
        assert own[0].get_zorder() < trend[0].get_zorder()
        assert own[0].get_linewidth()[0] < trend[0].get_linewidth()
        tops.append(max(float(np.max(seg[:, 1])) for seg in own[0].get_segments()))
    faint = [line for line in ax.lines if line.get_alpha() == mpm_figures.FAINT
             and line.get_marker() in mpm_figures.SIZE_MARKERS]
    assert len(faint) == ds["material"].size * ds["h"].size
    lo, hi = ax.get_ylim()
    every = np.concatenate([m.ravel() for m in marks])
    assert lo <= min(0.0, every.min()) and hi >= every.max()
    assert hi <= every.max() + 0.1 * (every.max() - min(0.0, every.min())) < max(tops)  # a bar runs past it
    plt.close(fig)


@pytest.mark.parametrize("figure", [*matrix.MPM_FIGURES, "fig22"])
def test_every_mpm_figure_has_one_key_under_its_question(smoke_dataset, tmp_path, figure, monkeypatch):
    """No legend inside a panel: one key for the figure, above the panels, titled with the figure's
    question in one line."""
    from plough.figures import analytical as analytical_figures
    from plough.figures import mpm as mpm_figures
    from tests.figures.test_style import check_header

    module = analytical_figures if figure == "fig22" else mpm_figures
    drawn = []
    monkeypatch.setattr(module, "save", lambda fig, outputs: drawn.append(fig))
    module.PLOTTERS[figure](_written(smoke_dataset(figure), tmp_path), [tmp_path / "f.png"])
    check_header(drawn[0], figure)
    import matplotlib.pyplot as plt

    plt.close(drawn[0])


def test_sweep_figure_draws_each_runs_sampling_error(smoke_dataset):
    """Every per-size point gets a bar of +- its run's standard error (none where it was not estimable:
    the noisy run's dp); files without the errors draw no bars."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from plough.figures import mpm as mpm_figures

    ds = smoke_dataset("fig15")
    for quantity, scale in (("mu", 1.0), ("dp", 1e6)):
        fig, ax = plt.subplots()
        mpm_figures._sweep_panel(ax, ds, quantity, "")
        half = []  # half-lengths of the per-size bars (the faint ones, alpha 0.3)
        for container in ax.containers:
            bars = container.lines[2]
            if bars and bars[0].get_alpha() == 0.3:
                half.extend(np.ptp(seg[:, 1]) / 2 for seg in bars[0].get_segments())
        expected = np.nan_to_num(ds[f"{quantity}_standard_error"].values * scale, nan=0.0)
        np.testing.assert_allclose(sorted(half), sorted(expected.ravel()), rtol=1e-9)
        assert (expected == 0).sum() == (len(SIZES) if quantity == "dp" else 0)
        plt.close(fig)
    # the extrapolated marks' bars: the GCI and the propagated sampling error in quadrature
    fig, ax = plt.subplots()
    mpm_figures._sweep_panel(ax, ds, "mu", "")
    half = sorted(np.ptp(seg[:, 1]) / 2 for c in ax.containers if c.lines[2] and c.lines[2][0].get_alpha() is None
                  for seg in c.lines[2][0].get_segments())
    expected = np.hypot(ds["mu_h0_uncertainty"].values, np.nan_to_num(ds["mu_h0_sampling_error"].values)).ravel()
    np.testing.assert_allclose(half, sorted(expected), rtol=1e-9)
    assert np.all(np.asarray(half) > ds["mu_h0_uncertainty"].values.min())
    plt.close(fig)
    fig, ax = plt.subplots()
    mpm_figures._sweep_panel(ax, ds.drop_vars(["mu_standard_error"]), "mu", "")
    assert not [c for c in ax.containers if c.lines[2] and c.lines[2][0].get_alpha() == 0.3]
    plt.close(fig)


def test_a_failed_finest_run_is_extrapolated_from_the_two_coarser_sizes(run_files, tmp_path):
    """A failure marker at the finest size (mpm.finest_failure: record): the point's h -> 0 value is the
    two-size extrapolation, flagged failed_finest (not skipped_finest); refused with finest_failure: stop
    and at a coarser size."""
    from plough.study import skipping

    loads, r1, finest = _zinc_block_lightest()
    paths = _with_marker(run_files, tmp_path, finest, skipping.failure_marker(SCENES[finest], finest, "unstable run",
                                                                              []))
    record = _recording()
    assert finest in matrix.failure_recordable_runs(record)
    ds = build_dataset(record, "fig15", paths)
    sel = {"material": "zinc_block", "load_N": loads[0]}
    sig = signature(loads[0], r1, 0.0, "zinc_bulk", 0.0, "boundary_layer")
    h3, h2 = sorted(SIZES, reverse=True)[:2]
    gain = 1.0 / (h3 / h2 - 1.0)
    for o in matrix.OUTPUTS:
        f3, f2 = value(o, sig, h3), value(o, sig, h2)
        assert float(ds[f"{o}_h0"].sel(sel)) == pytest.approx(f2 + (f2 - f3) * gain, rel=1e-12), o
        assert int(ds[f"{o}_h0_method"].sel(sel)) == Method.TWO_SIZES_ASSUMED_ORDER
        assert np.isnan(float(ds[o].sel(sel).sel(h=min(SIZES))))
        _check_extrapolation(ds, o, {"material": "zinc_block", "load_N": loads[1]},
                             signature(loads[1], r1, 0.0, "zinc_bulk", 0.0, "boundary_layer"))
    assert int(ds["failed_finest"].sum()) == 1 and int(ds["failed_finest"].sel(sel)) == 1
    assert int(ds["skipped_finest"].sum()) == 0
    _draws("fig15", _written(ds, tmp_path), tmp_path)

    with pytest.raises(ValueError, match="is a failure marker .*unstable run.*mpm.finest_failure is stop"):
        build_dataset(SMOKE, "fig15", paths)  # the smoke config stops on a failed run
    coarse = finest.replace(f"_h{matrix.fmt(min(SIZES))}", f"_h{matrix.fmt(max(SIZES))}")
    assert coarse in run_files
    paths = _with_marker(run_files, tmp_path, coarse, skipping.failure_marker(SCENES[coarse], coarse, "unstable run",
                                                                              []))
    with pytest.raises(ValueError, match=f"run '{coarse}' is a failure marker"):
        build_dataset(record, "fig15", paths)


def test_sweep_figure_rings_the_points_whose_finest_run_failed(run_files, tmp_path):
    """A point extrapolated without its failed finest run gets a ring, once in the legend; none without one."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from plough.figures import mpm as mpm_figures
    from plough.study import skipping

    _, _, finest = _zinc_block_lightest()
    paths = _with_marker(run_files, tmp_path, finest, skipping.failure_marker(SCENES[finest], finest, "unstable run",
                                                                              []))
    record = _recording()
    for data, rings in ((build_dataset(record, "fig15", paths), 1), (build_dataset(record, "fig15", run_files), 0)):
        fig, ax = plt.subplots()
        mpm_figures._sweep_panel(ax, data, "dp", "")
        ringed = [line for line in ax.lines if line.get_marker() == "o" and line.get_markersize() == 11]
        assert sum(len(line.get_xdata()) for line in ringed) == rings
        assert sum(1 for line in ringed if not line.get_label().startswith("_")) == rings
        plt.close(fig)


def test_fig22_carries_and_draws_a_failed_finest_run_of_fig21(run_files, tmp_path):
    """Fig. 22's MPM points keep Fig. 21's flags: a point whose finest run failed is flagged, marked failed
    and ringed in the plot; the others are not."""
    import matplotlib

    matplotlib.use("Agg")

    from plough.figures import analytical as analytical_figures
    from plough.study import skipping

    record = _recording()
    real = MPM["real_materials"]
    loads = [float(x) for x in real["loads_N"]]
    r_last = float(real["ball_radii_um"][-1])
    finest = matrix.run_id(matrix.real_point(real, "coated", loads[-1], r_last), min(SIZES))
    assert finest in matrix.failure_recordable_runs(record)
    paths = _with_marker(run_files, tmp_path, finest, skipping.failure_marker(SCENES[finest], finest, "unstable run",
                                                                              []))
    ds = build_dataset(record, "fig22", paths)
    sel = {"ball_diameter_mm": 2 * r_last / 1000, "mpm_load_N": loads[-1]}
    assert int(ds["mu_mpm_failed_finest"].sum()) == 1 and int(ds["mu_mpm_failed_finest"].sel(sel)) == 1
    assert int(ds["mu_mpm_flagged"].sel(sel)) == 1
    fig21 = build_dataset(record, "fig21", paths)
    np.testing.assert_array_equal(ds["mu_mpm_flagged"].values, fig21["mu_h0_flagged"].values)
    rings = []
    real_save = analytical_figures.save
    try:
        analytical_figures.save = lambda fig, outputs: rings.extend(
            line for ax in fig.axes for line in ax.lines if line.get_marker() == "o" and line.get_markersize() == 11)
        analytical_figures.plot_fig22(_written(ds, tmp_path), [tmp_path / "f.png"])
    finally:
        analytical_figures.save = real_save
    assert sum(len(line.get_xdata()) for line in rings) == 1


def test_a_marker_at_a_pictures_run_is_refused_naming_it(run_files, tmp_path):
    """A picture draws its finest run itself: a failure or skip marker there (a copied results/runs/) is an
    error naming the run and its reason, not a KeyError."""
    from plough.study import skipping

    rid = matrix.figure_runs(SMOKE, "fig19")[0]
    marker = skipping.failure_marker(SCENES[rid], rid, "a particle left the grid", [])
    paths = _with_marker(run_files, tmp_path, rid, marker)
    with pytest.raises(ValueError, match=f"run '{rid}' is a failure marker .*a particle left the grid.*fig19 draws"):
        build_dataset(SMOKE, "fig19", paths)
    write_netcdf_atomic(_old_skip_marker(SCENES[rid]), paths[rid])
    with pytest.raises(ValueError, match=f"run '{rid}' is a skip marker.*--forcerun results/runs/{rid}.nc"):
        build_dataset(SMOKE, "fig19", paths)

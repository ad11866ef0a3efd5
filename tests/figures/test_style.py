"""plough.figures.style: every figure has a one-line question for a title and one shared key above its
panels, and the analytical figures draw that way; the report caption renders for every figure."""

from __future__ import annotations

import types
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
import yaml  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

from plough.figures import PLOTTERS, analytical  # noqa: E402
from plough.figures.style import QUESTIONS, header, new_figure, note_entry  # noqa: E402
from plough.study.analytical_figures import build_dataset, config_section  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
CONFIGS = {name: yaml.safe_load((ROOT / "config" / f"{name}.yaml").read_text()) for name in ("config", "smoke")}


def check_header(fig, figure: str) -> None:
    """The figure's only legend is the figure-level key, titled with its question in one line; the
    key lies inside the figure and off every panel."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    assert all(ax.get_legend() is None for ax in fig.axes), "a legend inside a panel"
    assert len(fig.legends) == 1
    legend = fig.legends[0]
    assert legend.get_title().get_text() == QUESTIONS[figure]
    assert "\n" not in QUESTIONS[figure]
    box = legend.get_window_extent(renderer)
    assert box.x0 >= 0 and box.x1 <= fig.bbox.width and box.y0 >= 0 and box.y1 <= fig.bbox.height
    for ax in fig.axes:
        panel = ax.get_tightbbox(renderer)  # the axes with their title and tick labels
        assert box.y0 >= panel.y1 - 1 or not box.overlaps(panel), f"the key covers a panel of {figure}"


def test_every_figure_has_a_one_line_question():
    assert set(QUESTIONS) == set(PLOTTERS)
    for figure, question in QUESTIONS.items():
        assert "\n" not in question and question.endswith("?") and len(question) <= 100, figure


@pytest.mark.parametrize("width", [6.5, 7.0, 10.0])
def test_the_longest_question_fits_the_narrowest_figure_that_may_carry_it(width):
    """Each question drawn as the key's title stays inside a figure of the width it is drawn at (the
    single-panel figures are 6.5 and 7 inches wide, the others 10)."""
    fig, axes = new_figure(1, 1, width=width)
    axes[0, 0].plot([0, 1], [0, 1], label="a line")
    figures = [f for f in QUESTIONS if width == 10.0 or f in ("fig15", "fig16", "fig18", "fig19", "fig20", "fig21",
                                                             "fig23")]
    for figure in figures:
        for legend in list(fig.legends):
            legend.remove()
        header(fig, figure, [(axes[0, 0].lines[0], "a line")])
        check_header(fig, figure)
    plt.close(fig)


def test_header_reads_row_by_row_and_drops_repeated_labels():
    fig, _ = new_figure(1, 1)
    entries = [(Line2D([], []), f"entry {i}") for i in range(7)]
    legend = header(fig, "fig15", [*entries, (Line2D([], []), "entry 2"), (note_entry("tab:red"), "a note")], ncol=3)
    texts = [t.get_text() for t in legend.get_texts()]
    assert sorted(texts) == sorted([f"entry {i}" for i in range(7)] + ["a note"])
    # a legend fills column by column: the first column holds entries 0, 3, 6 when they read row by row
    assert texts[:3] == ["entry 0", "entry 3", "entry 6"]
    note = next(t for t in legend.get_texts() if t.get_text() == "a note")
    assert np.allclose(matplotlib.colors.to_rgb(note.get_color()), matplotlib.colors.to_rgb("tab:red"))
    plt.close(fig)


@pytest.mark.parametrize(("figure", "width"), [("fig15", 6.5), ("fig11", 10.0)])
def test_a_key_of_long_labels_takes_fewer_columns_and_fits(figure, width):
    """Thirteen labels of 60 characters asked for in four columns: the key drops columns until it fits."""
    fig, axes = new_figure(1, 2, width=width)
    entries = [(Line2D([], [], color="k"), f"entry {i:2d}: " + "a long explanation of a mark " * 2) for i in range(13)]
    legend = header(fig, figure, entries, ncol=4)
    assert legend._ncols < 4
    check_header(fig, figure)
    plt.close(fig)


@pytest.mark.parametrize("figure", ["fig03", "fig04", "fig22"])
def test_analytical_figures_have_one_key_and_a_question(figure, tmp_path):
    ds = build_dataset(figure, CONFIGS["smoke"][config_section(figure)])
    drawn = []
    real_save = analytical.save
    try:
        analytical.save = lambda fig, outputs: drawn.append(fig)
        analytical.PLOTTERS[figure](ds, [tmp_path / "f.png"])
    finally:
        analytical.save = real_save
    check_header(drawn[0], figure)
    plt.close(drawn[0])


@pytest.mark.parametrize("config", sorted(CONFIGS))
def test_the_report_caption_renders_for_every_figure(config):
    """workflow/report/figure.rst (Jinja, then reStructuredText, as snakemake --report renders it): every
    figure gets its description, the method where it has one and the paper's finding, without an rst
    warning."""
    from docutils.core import publish_doctree
    from jinja2 import Environment

    template = Environment(trim_blocks=True, lstrip_blocks=True).from_string(
        (ROOT / "workflow" / "report" / "figure.rst").read_text())
    sizes = ", ".join(f"{h:g}" for h in CONFIGS[config]["mpm"]["particle_sizes_um"])
    for figure in PLOTTERS:
        smk = types.SimpleNamespace(wildcards=types.SimpleNamespace(figure=figure), config=CONFIGS[config])
        text = template.render(snakemake=smk)
        assert text.startswith(f"Fig. {int(figure[3:])}"), figure
        assert "\nPaper: " in text, figure
        if figure in ("fig11", "fig13", "fig15", "fig16", "fig18", "fig20", "fig21", "fig22", "fig23"):
            assert f"h = {sizes} µm" in text, figure
        publish_doctree(text, settings_overrides={"report_level": 1, "halt_level": 2})  # a warning raises

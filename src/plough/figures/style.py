"""Shared look of plough's figures: Agg backend, sizes, colours, a one-line title (the figure's
question) and one shared key per figure."""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.artist import Artist  # noqa: E402
from matplotlib.colors import to_rgb  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.legend import Legend  # noqa: E402
from matplotlib.legend_handler import HandlerTuple  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

from plough.io import temporary_beside  # noqa: E402

COLOURS = {"mu": "k", "mu_pl": "tab:blue", "mu_sh": "tab:orange", "soft": "tab:blue", "hard": "tab:red",
           "none": "k", "once": "tab:green", "converged": "tab:purple"}
LABELS = {"mu": r"$\mu$", "mu_pl": r"$\mu_{pl}$", "mu_sh": r"$\mu_{sh}$"}
WORN_COLOUR = "0.88"


def new_figure(nrows: int, ncols: int, width: float = 10.0, height_per_row: float = 3.6):
    fig, axes = plt.subplots(nrows, ncols, figsize=(width, height_per_row * nrows + 0.9), squeeze=False,
                             layout="constrained")
    return fig, axes


#: each figure's title: the question it answers, in one line. What was computed and how (particle sizes,
#: extrapolation, what the marks and flags mean, the paper's finding) is its caption in the report
#: (workflow/report/figure.rst).
QUESTIONS = {
    "fig03": "Fig. 3: How does the analytical friction change with the coating's thickness and hardness?",
    "fig04": "Fig. 4: How deep does the sphere plough as the coating's thickness and hardness change?",
    "fig11": "Fig. 11: Does the MPM ploughing depth follow the analytical model over hardness and thickness?",
    "fig12": "Fig. 12: Does the soft coating pile up ahead of the sphere, and do the forces settle?",
    "fig13": "Fig. 13: Which part of the MPM friction follows the analytical model over hardness and thickness?",
    "fig14": "Fig. 14: Where does the zinc coating go when the ball ploughs it?",
    "fig15": "Fig. 15: Does zinc plough deeper than DX56 steel as the load rises?",
    "fig16": "Fig. 16: Does the larger ball plough less into zinc-coated steel?",
    "fig17": "Fig. 17: Is the coated steel's groove shallower than the zinc block's, at the surface and below?",
    "fig18": "Fig. 18b: Does the groove deepen towards bulk zinc's as the coating thickens?",
    "fig19": "Fig. 19: Do the forces on the sphere settle while it slides?",
    "fig20": "Fig. 20: Does zinc give more friction than DX56 steel as the load rises?",
    "fig21": "Fig. 21: How does the friction change with load for the two ball sizes?",
    "fig22": "Fig. 22: Do the paper's power-law fits describe the MPM friction?",
    "fig23": "Fig. 23a: Which gives the lowest friction: zinc-coated steel, zinc or DX56 steel?",
}

#: font size of the one-line title (the figure's question) and of the shared key
TITLE_FONTSIZE = 11.0
KEY_FONTSIZE = 8.0


def header(fig: Figure, figure: str, entries: list[tuple[Artist, str]], ncol: int | None = None) -> Legend:
    """The figure's question (QUESTIONS) in one line and, under it, the figure's one key, above the
    panels (never a legend per panel). ``entries``: (handle, label) pairs in reading order, row by
    row; a label seen before is dropped, so panels may each hand in the same entry. The question is
    the key's title, so that the layout stacks the two (a suptitle and a figure legend overlap)."""
    handles, labels = [], []
    for handle, label in entries:
        if label not in labels:
            handles.append(handle)
            labels.append(label)
    if ncol is None:  # as many columns as the width takes at about 2.4 inches an entry
        ncol = int(fig.get_figwidth() // 2.4)
    ncol = max(1, min(len(handles), ncol))
    while True:  # fewer columns until the key fits the figure's width (long labels make wide columns)
        order = _row_major(len(handles), ncol)
        legend = fig.legend([handles[i] for i in order], [labels[i] for i in order], loc="outside upper center",
                            ncol=ncol, fontsize=KEY_FONTSIZE, frameon=False, columnspacing=1.2, handlelength=2.2,
                            title=QUESTIONS[figure], title_fontsize=TITLE_FONTSIZE, alignment="center",
                            handler_map={SideBySide: HandlerTuple(ndivide=None)})
        width = legend.get_window_extent(fig.canvas.get_renderer()).width
        if ncol == 1 or width <= 0.98 * fig.bbox.width:
            break
        legend.remove()
        ncol -= 1
    for i, text in zip(order, legend.get_texts(), strict=True):
        if isinstance(handles[i], Artist) and handles[i].get_gid() == "note":
            text.set_color(handles[i].get_color())
    return legend


def _row_major(n: int, ncol: int) -> list[int]:
    """The order in which to hand n entries to a legend of ncol columns (which fills column by column,
    the first columns one longer) so that they read row by row."""
    nrows = -(-n // ncol)
    return [r * ncol + c for c in range(ncol) for r in range(nrows) if r * ncol + c < n]


class SideBySide(tuple):
    """A key handle of several markers drawn side by side (a plain tuple overlays them)."""


def axes_entries(axes) -> list[tuple[Artist, str]]:
    """The (handle, label) pairs of every labelled artist of ``axes``, for header(): a panel's own entries
    ('(a) soft coating') first, shaded regions last."""
    entries = []
    for ax in np.ravel(axes):
        handles, labels = ax.get_legend_handles_labels()
        entries.extend(zip(handles, labels, strict=True))
    return sorted(entries, key=lambda e: 0 if e[1].startswith("(") else 2 if e[1].startswith("shaded") else 1)


def note_entry(colour: str = "k") -> Artist:
    """A key handle that draws nothing: its entry is a note, its text in ``colour`` (header() colours it)."""
    return Line2D([], [], ls="none", marker="none", color=colour, gid="note")


def lighter(colour: str, amount: float = 0.55) -> tuple[float, float, float]:
    """``colour`` mixed with white (``amount`` 0: unchanged, 1: white), for error bars behind their marks."""
    rgb = np.asarray(to_rgb(colour))
    return tuple(rgb + (1.0 - rgb) * amount)


def shade_where(ax, x, mask, label: str | None = None) -> None:
    """Shade the x ranges where ``mask`` is true (e.g. the coating-wear region dp > t)."""
    ax.fill_between(x, 0, 1, where=mask, transform=ax.get_xaxis_transform(), color=WORN_COLOUR,
                    step="mid", label=label, zorder=0, linewidth=0)


#: legend of the ring around an MPM point whose finest run stopped unstable (mpm.finest_failure: record)
FAILED_FINEST_LABEL = "ringed: finest run failed, from two sizes"


def ring(ax, x, y, label: str | None = None) -> None:
    """A ring around the points (x, y): their finest run stopped unstable and two sizes stand in for it."""
    ax.plot(x, y, ls="none", marker="o", ms=11, mfc="none", mec="k", mew=0.8, label=label)


def save(fig: Figure, outputs: list[str | os.PathLike[str]]) -> None:
    """Save to each output (PNG, PDF...) atomically: temporary file, then rename."""
    for out in outputs:
        out = Path(out)
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = temporary_beside(out, suffix=out.suffix)  # the suffix tells savefig the format
        try:
            fig.savefig(tmp, dpi=150)
            os.replace(tmp, out)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
    plt.close(fig)

"""Shared look of plough's figures: Agg backend, sizes, colours, caption-like titles."""

from __future__ import annotations

import os
import textwrap
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from plough.io import temporary_beside  # noqa: E402

COLOURS = {"mu": "k", "mu_pl": "tab:blue", "mu_sh": "tab:orange", "soft": "tab:blue", "hard": "tab:red",
           "none": "k", "once": "tab:green", "converged": "tab:purple"}
LABELS = {"mu": r"$\mu$", "mu_pl": r"$\mu_{pl}$", "mu_sh": r"$\mu_{sh}$"}
WORN_COLOUR = "0.88"


def new_figure(nrows: int, ncols: int, width: float = 10.0, height_per_row: float = 3.6):
    fig, axes = plt.subplots(nrows, ncols, figsize=(width, height_per_row * nrows + 0.9), squeeze=False,
                             layout="constrained")
    return fig, axes


#: caption characters per inch of figure width at its 9.5 pt font (130 on the 10-inch two-panel figures)
CAPTION_CHARS_PER_INCH = 13.0


def caption(fig: Figure, text: str) -> None:
    """The figure's caption above the panels, wrapped to the figure's width (a fixed width cut the
    captions of the 6.5-inch single-panel figures at the right edge)."""
    width = int(CAPTION_CHARS_PER_INCH * fig.get_figwidth())
    fig.suptitle("\n".join(textwrap.wrap(text, width)), fontsize=9.5, ha="left", x=0.01)


def shade_where(ax, x, mask, label: str | None = None) -> None:
    """Shade the x ranges where ``mask`` is true (e.g. the coating-wear region dp > t)."""
    ax.fill_between(x, 0, 1, where=mask, transform=ax.get_xaxis_transform(), color=WORN_COLOUR,
                    step="mid", label=label, zorder=0, linewidth=0)


#: legend of the ring around an MPM point whose finest run stopped unstable (mpm.finest_failure: record)
FAILED_FINEST_LABEL = "finest run stopped unstable: from the two coarser sizes"


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

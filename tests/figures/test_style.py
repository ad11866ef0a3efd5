"""plough.figures.style: the caption fits the figure it captions."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

from plough.figures.style import caption, new_figure  # noqa: E402

TEXT = ("Fig. 15 - ploughing depth vs load, zinc block and DX56 steel. Particle sizes h = 20, 14, 10 um; marks: "
        "extrapolated to h -> 0 (Richardson; bars: Roache GCI and the runs' sampling errors carried to the limit, "
        "in quadrature; hollow = fallback, flagged), faint: per size with the run's sampling standard error; "
        "lines: analytical model. Paper: zinc ploughs deeper at every load and its dp grows faster.")


@pytest.mark.parametrize("width", [6.5, 7.0, 10.0])
def test_caption_stays_inside_the_figure(width):
    """The wrapped caption's drawn extent lies within the figure (the 6.5-inch figures were cut at 130
    characters a line), and a wider figure takes longer lines."""
    fig, _ = new_figure(1, 1, width=width)
    caption(fig, TEXT)
    fig.canvas.draw()
    box = fig._suptitle.get_window_extent(fig.canvas.get_renderer())
    assert box.x0 >= 0 and box.x1 <= fig.bbox.width
    longest = max(len(line) for line in fig._suptitle.get_text().split("\n"))
    assert longest > 0.75 * 13.0 * width  # the lines use most of the width, not a fixed short wrap
    plt.close(fig)

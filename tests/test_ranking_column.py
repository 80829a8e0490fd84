"""The ranking page's text column (friction_uq.report.diagnose_pages.column_text): its words stay on the page, right
of the ranking and above the ranking's label and legend, whatever the ranking's tick labels and the text's length."""

import pytest
from matplotlib.transforms import ScaledTranslation

from friction_uq.report.diagnose_pages import LEGEND_DROP, column_text
from friction_uq.report.style import figure

SENTENCE = ("Unexplained misfit on the tube hoop gauge, rise phase: no cause of the catalogue explains it clearly, "
            "over the whole record and better than every other. Fitted together, channel_timing and bandwidth do not "
            "explain it either: their gain over the round's reference model is carried by a few blocks.")
LONG_LABEL = "1: gauge_gain[external_output_bar] + gauge_gain[internal_output_bar] together (not named)"


def _page(label: str, n_lines: int):
    """A page laid out as the ranking page: the ranking with its two-line label and its legend below, the column."""
    fig, axes = figure("a ranking page", nrows=1, ncols=2, gridspec_kw={"width_ratios": [3, 2]})
    ax = axes[0]
    ax.barh(range(3), [1.0, 2.0, 3.0])
    ax.set_yticks(range(3), [label, "b", "c"])
    ax.set_xlabel("dELPD over the round's reference model, sign(d) log10(1 + |d|), bars +- 2 SE;\n"
                  "left of 0: predicts the record worse than the reference (its parameters cost more "
                  "than they explain)",
                  fontsize=8)
    ax.legend(["bars"], loc="upper left", bbox_to_anchor=(0.0, 0.0), fontsize=7, title_fontsize=7,
              bbox_transform=ax.transAxes + ScaledTranslation(0.0, -LEGEND_DROP / 72.0, fig.dpi_scale_trans),
              title="w: " + "y" * 150)
    axes[1].axis("off")
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    column_text(fig, ax, [SENTENCE] * n_lines)
    fig.canvas.draw()
    return fig, ax, fig.texts[-1]


@pytest.mark.parametrize("label,n_lines", [("1: a + b together (not named)", 2), (LONG_LABEL, 2), ("1: short", 12),
                                           ("1: short", 20), (LONG_LABEL, 20), ("1: short", 30), ("1: short", 200)])
def test_the_column_stays_on_the_page_right_of_the_ranking_and_above_its_legend(label, n_lines):
    fig, ax, text = _page(label, n_lines)
    r = fig.canvas.get_renderer()
    box = text.get_window_extent(r)
    assert box.x0 > ax.get_window_extent(r).x1 and box.x1 <= fig.bbox.width
    legend, xlabel = ax.get_legend().get_window_extent(r), ax.xaxis.label.get_window_extent(r)
    assert legend.y1 < xlabel.y0  # the legend below the axis label
    if n_lines <= 30:  # the type shrinks to fit down to 5.5 pt; 200 sentences cannot fit at any size
        assert box.y0 >= legend.y1 and box.y0 >= xlabel.y1
    assert 5.5 <= text.get_fontsize() <= 8.0
    assert (text.get_fontsize() == 8.0) == (n_lines <= 12)
    assert (text.get_fontsize() == 5.5) == (n_lines == 200)


def test_the_type_is_the_largest_that_fits():
    """A quarter point larger would run past the foot: the size steps down from 8 pt, rewrapped each time."""
    fig, ax, text = _page("1: short", 30)
    size = text.get_fontsize()
    assert 5.5 < size < 8.0
    r = fig.canvas.get_renderer()
    limit = max(ax.get_legend().get_window_extent(r).y1, ax.xaxis.label.get_window_extent(r).y1)
    assert text.get_window_extent(r).y0 >= limit
    text.remove()
    column_text(fig, ax, [SENTENCE] * 30, size=size + 0.25, smallest=size + 0.25)
    fig.canvas.draw()
    assert fig.texts[-1].get_window_extent(r).y0 < limit

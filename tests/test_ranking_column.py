"""The ranking page's text column (friction_uq.report.diagnose_pages.column_text): its words stay on the page, right
of the ranking and above the ranking's label and legend, whatever the ranking's tick labels and the text's length."""

import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402

from friction_uq.report.diagnose_pages import column_text  # noqa: E402
from friction_uq.report.style import figure  # noqa: E402

SENTENCE = ("Unexplained misfit on the tube hoop gauge, rise phase: no cause of the catalogue explains it clearly, over "
            "the whole record and better than every other. Fitted together, channel_timing and bandwidth do not "
            "explain it either: their gain over the round's reference model is carried by a few blocks.")


def _page(label: str, n_lines: int):
    fig, axes = figure("a ranking page", nrows=1, ncols=2, gridspec_kw={"width_ratios": [3, 2]})
    ax = axes[0]
    ax.barh(range(3), [1.0, 2.0, 3.0])
    ax.set_yticks(range(3), [label, "b", "c"])
    ax.set_xlabel("dELPD over the round's reference model, sign(d) log10(1 + |d|), bars +- 2 SE;\n"
                  "left of 0: predicts the record worse than the reference (its parameters cost more than they explain)",
                  fontsize=8)
    ax.legend(["bars"], loc="upper left", bbox_to_anchor=(0.0, -0.1), title="w: " + "y" * 150, fontsize=7,
              title_fontsize=7)
    axes[1].axis("off")
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    column_text(fig, ax, [SENTENCE] * n_lines)
    fig.canvas.draw()
    return fig, ax, fig.texts[-1]


@pytest.mark.parametrize("label,n_lines", [("1: a + b together (not named)", 2), ("1: gauge_gain[external_output_bar] + gauge_gain[internal_output_bar] together (not named)", 2),
                                           ("1: short", 30), ("1: short", 200)])
def test_the_column_stays_on_the_page_right_of_the_ranking_and_above_its_legend(label, n_lines):
    fig, ax, text = _page(label, n_lines)
    r = fig.canvas.get_renderer()
    box = text.get_window_extent(r)
    assert box.x0 >= ax.get_window_extent(r).x1 and box.x1 <= fig.bbox.width
    if n_lines <= 30:  # the type shrinks to fit down to 5.5 pt; 200 sentences cannot fit at any size
        assert box.y0 >= ax.get_legend().get_window_extent(r).y1
        assert box.y0 >= ax.xaxis.label.get_window_extent(r).y1
    assert 5.5 <= text.get_fontsize() <= 8.0
    assert (text.get_fontsize() == 8.0) == (n_lines <= 2)

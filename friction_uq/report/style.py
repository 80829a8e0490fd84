"""Shared matplotlib settings: readable when printed (A4, >= 9 pt)."""

from __future__ import annotations

import logging
import os
from pathlib import Path

import matplotlib

from .._atomic import write_bytes

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402

RC = {
    "font.size": 10,
    "axes.titlesize": 11,
    "axes.labelsize": 10,
    "xtick.labelsize": 9,
    "ytick.labelsize": 9,
    "legend.fontsize": 9,
    "figure.titlesize": 13,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "pdf.fonttype": 42,
}
A4_LANDSCAPE = (11.69, 8.27)
#: The PDF's text in the PDF standard's own fonts (Helvetica, Courier: every reader has them, nothing is
#: embedded): a third less time per page than embedding a TrueType subset. Their encoding has no
#: Unicode minus sign: tick labels use the ASCII hyphen-minus (else they read "?20"). Dense clouds of
#: points are drawn as images (``rasterized``: thousands of vector markers cost a PDF page half a second);
#: at 200 dpi they print sharp.
CORE_FONTS = {"pdf.use14corefonts": True, "axes.unicode_minus": False, "savefig.dpi": 200, "pdf.compression": 1}


class _SameFontOtherWeight(logging.Filter):
    """Drops matplotlib's notice that a font's only weight is used for another asked for: the standard
    fonts' metric files know "medium" alone, and every text asks for "normal"."""

    def filter(self, record: logging.LogRecord) -> bool:
        return not str(record.msg).startswith("findfont: Failed to find font weight")


logging.getLogger("matplotlib.font_manager").addFilter(_SameFontOtherWeight())


#: Longest run of characters without a space in a page title: matplotlib wraps a title at spaces only.
TITLE_WORD = 40
#: Longest page title, in characters: two lines of the title's font across an A4 page, above the page's text.
TITLE_CHARS = 200


def title_text(title: str) -> str:
    """``title`` as the core fonts can print it and matplotlib can wrap it: characters outside Latin-1 (which the core
    fonts print as '?': a Hebrew or Chinese test id read "???? ????") written as escapes such as \\u05d0, at most
    :data:`TITLE_CHARS` characters, and words longer than :data:`TITLE_WORD` characters (a test id of 100 letters ran
    off both sides of the page) broken."""
    text = title.encode("latin-1", "backslashreplace").decode("latin-1")
    if len(text) > TITLE_CHARS:  # at most two lines: the page's own text starts below them
        text = text[:TITLE_CHARS - 3] + "..."
    words = []
    for word in text.split(" "):
        words += [word[i:i + TITLE_WORD] for i in range(0, len(word), TITLE_WORD)] or [word]
    return " ".join(words)


def figure(title: str, *, nrows: int = 1, ncols: int = 1, **kw):
    """A titled A4-landscape figure with a grid of axes; the title wrapped within the page (:func:`title_text`)."""
    with plt.rc_context(RC):
        fig, axes = plt.subplots(nrows, ncols, figsize=A4_LANDSCAPE, **kw)
    fig.suptitle(title_text(title), wrap=True)
    return fig, axes


def save_figure(fig, path: str | os.PathLike[str]) -> Path:
    """Save ``fig`` atomically (format from the suffix, PDF by default) and close it."""
    import io

    out = Path(path)
    buf = io.BytesIO()  # rendered in memory, then written at once: a disk that fills mid-file is one OSError
    try:
        fig.savefig(buf, format=out.suffix.lstrip(".") or "pdf")
    finally:
        plt.close(fig)
    return write_bytes(out, buf.getvalue())

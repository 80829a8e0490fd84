"""The checks an import makes on the record it wrote, said in terms of SETUP.toml.

A gauge wired the other way round, a bridge read with the opposite sign, two output channels
swapped or a scale off by a factor (a gauge factor, an amplifier gain or a unit) shows in the forces
at the cell (:func:`friction_uq.gauge_check.record_gauge_check`). At import such a contradiction is
refused, with the evidence and the line of SETUP.toml to mend; a balance a few percent off is only
a warning.
"""

from __future__ import annotations

from ..gauge_balance import GaugeFinding
from ..gauge_check import record_gauge_check
from ..record import Record
from .setup_file import Setup


def _fix(g: GaugeFinding, setup: Setup) -> str:
    name = setup.path.name
    if g.kind == "reversed" and g.channel in setup.channels:
        sign = setup.channels[g.channel].sign
        return f"; if so, write sign = {-sign:+d} in [channels.{g.channel}] of {name}"
    if g.kind == "swapped":
        return (f"; if so, exchange the column (and file) of [channels.internal_output_bar] and "
                f"[channels.external_output_bar] in {name}")
    if g.kind == "scale" and g.channel in setup.channels:
        return f"; see [channels.{g.channel}] in {name}"
    return ""


def import_findings(record: Record, setup: Setup) -> tuple[list[tuple[str, str]], list[str]]:
    """(refusals as (channel or "", sentence), warnings); each fault with the fix in ``setup``'s terms.

    A sentence about one channel leaves out its ``/signals/<channel>`` (the caller names the file and column).
    """
    faults, notes = record_gauge_check(record)
    out = []
    for g in faults:
        text = g.sentence + _fix(g, setup)
        if g.channel:
            text = text.removeprefix(f"/signals/{g.channel}").removeprefix(":").strip()
        out.append((g.channel, text))
    return out, [g.sentence for g in notes if g.kind != "ok"]

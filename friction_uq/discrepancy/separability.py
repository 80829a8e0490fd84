"""What one record cannot tell apart, and what would: the first round's named mechanism against its rivals (the
mechanisms not separable from it, the other gauges on which the same mechanism does as well), and the test or
calibration that would separate them."""

from __future__ import annotations

from .verdict import Verdict

#: What would separate two mechanisms that one record cannot.
SEPARATE_BY = {
    frozenset({"velocity_friction", "pressure_friction"}):
        "tests at another striker speed on another internal output bar (p and V rise together in one set-up)",
    frozenset({"velocity_friction", "slip_friction"}):
        "a test at another striker speed (slip and speed grow together through one test)",
    frozenset({"pressure_friction", "slip_friction"}):
        "a test at another striker speed (the load and the slip grow together through one test)",
    frozenset({"clearance", "end_friction"}):
        "the hoop gauge's start (a clearance delays it) or a test with another sample length",
    frozenset({"channel_timing", "bandwidth"}):
        "the amplifier's response to a sharp step (a calibration pulse through the channel) and the digitisers' "
        "trigger times",
    frozenset({"gauge_gain", "bar_modulus"}):
        "the bar's wave speed timed on the bar itself (a striker on the bar alone), and a shunt calibration of the "
        "gauge",
    frozenset({"channel_timing", "bar_modulus"}):
        "the bar's wave speed timed on the bar itself and the gauge's distance measured again",
    frozenset({"bandwidth", "dispersion"}):
        "the amplifier's response to a sharp step (dispersion is the bar's, the same on every amplifier)",
}
DEFAULT_SEPARATION = "another test of the campaign (another striker speed or another internal output bar)"


def separability(verdict: Verdict) -> tuple[tuple[str, ...], tuple[str, ...], str | None]:
    """Who explains the record about as well as the named model (the verdict's rivals): the mechanisms not
    separable from it (with it first; empty when none), the other gauges on which the same mechanism does (a
    gauge_gain: the mechanism is named, its gauge is not certain), and what would separate the mechanisms."""
    by = {c.label: c for c in verdict.candidates}
    best = by[verdict.named]
    close = [by[label] for label in verdict.rivals]
    channels = tuple(c.channel for c in close if c.mechanism == best.mechanism and c.channel)
    others = [c.mechanism for c in close if c.mechanism != best.mechanism]
    if not others:
        return (), channels, None
    names = tuple(dict.fromkeys([best.mechanism, *others]))
    return names, channels, SEPARATE_BY.get(frozenset(names[:2]), DEFAULT_SEPARATION)

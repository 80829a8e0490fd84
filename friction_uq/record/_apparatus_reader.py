"""Read and cross-check the ``/apparatus`` group of a record into an :class:`Apparatus`."""

from __future__ import annotations

from typing import Any

from ..apparatus import DEFAULT_BAR_POISSON_RATIO, Apparatus, Bar, Plug, Sample, Tube
from ._checks import Reader

_BAR_ATTRS = ("young_modulus", "wave_speed", "diameter", "length")
_APPARATUS_SCHEMA: dict[str, tuple[str, ...]] = {
    "striker": _BAR_ATTRS,
    "input_bar": _BAR_ATTRS + ("gauge_distance",),
    "internal_output_bar": _BAR_ATTRS + ("gauge_distance",),
    "external_output_bar": (
        "young_modulus", "wave_speed", "outer_diameter", "inner_diameter", "length", "gauge_distance",
    ),
    "tube": (
        "young_modulus", "poisson_ratio", "inner_diameter", "outer_diameter", "length",
        "gauge_offset", "gauge_width",
    ),
    "sample": ("material", "diameter", "length", "young_modulus", "density"),
}
_PLUG_ATTRS = ("length", "young_modulus", "density")
# attributes that may be zero or negative
_SIGNED = {"gauge_offset"}


def read_apparatus(app: Any, r: Reader) -> Apparatus:
    """The checked apparatus of the open ``/apparatus`` group ``app``; ``r`` names the file in errors."""
    parts = _read_parts(app, r)
    plug = None
    g = r.member(app, "plug", "/apparatus/plug")
    if g is not None:
        import h5py

        if not isinstance(g, h5py.Group):
            raise r.fail("/apparatus/plug", "must be a group")
        plug = Plug(**{n: r.positive(g, "/apparatus/plug", n) for n in _PLUG_ATTRS})
    _cross_check(parts, r)
    return _apparatus(parts, plug)


def _read_parts(app: Any, r: Reader) -> dict[str, dict[str, Any]]:
    """Each required part's attributes, each checked alone (a bar's Poisson ratio defaults when absent)."""
    import h5py

    parts: dict[str, dict[str, Any]] = {}
    for part, names in _APPARATUS_SCHEMA.items():
        where = f"/apparatus/{part}"
        g = r.member(app, part, where)
        if g is None:
            raise r.fail(where, "required group is missing")
        if not isinstance(g, h5py.Group):
            raise r.fail(where, "must be a group")
        vals: dict[str, Any] = {}
        for name in names:
            if name == "material":
                vals[name] = r.attr(g, where, name, "str")
            elif name in _SIGNED:
                vals[name] = r.attr(g, where, name, "float")
            else:
                vals[name] = r.positive(g, where, name)
        if part in ("striker", "input_bar", "internal_output_bar", "external_output_bar"):
            nu = r.attr(g, where, "poisson_ratio", "float", required=False)
            if nu is not None and not -1.0 < nu < 0.5:
                raise r.fail(f"{where}@poisson_ratio", f"must lie in (-1, 0.5), got {nu!r}")
            vals["poisson_ratio"] = DEFAULT_BAR_POISSON_RATIO if nu is None else nu
        parts[part] = vals

    return parts


def _cross_check(parts: dict[str, dict[str, Any]], r: Reader) -> None:
    """The checks between parts' attributes: gauges on their bars, diameters that fit, the sample in the tube."""
    for part in ("input_bar", "internal_output_bar", "external_output_bar"):
        v = parts[part]
        if v["gauge_distance"] >= v["length"]:
            raise r.fail(
                f"/apparatus/{part}@gauge_distance",
                f"is {v['gauge_distance']!r} m, beyond the bar's length {v['length']!r} m",
            )
    eob = parts["external_output_bar"]
    if eob["inner_diameter"] >= eob["outer_diameter"]:
        raise r.fail(
            "/apparatus/external_output_bar@inner_diameter",
            f"is {eob['inner_diameter']!r} m, not smaller than outer_diameter {eob['outer_diameter']!r} m",
        )
    tube = parts["tube"]
    if tube["inner_diameter"] >= tube["outer_diameter"]:
        raise r.fail(
            "/apparatus/tube@inner_diameter",
            f"is {tube['inner_diameter']!r} m, not smaller than outer_diameter {tube['outer_diameter']!r} m",
        )
    if not -1.0 < tube["poisson_ratio"] < 0.5:
        raise r.fail("/apparatus/tube@poisson_ratio", f"must lie in (-1, 0.5), got {tube['poisson_ratio']!r}")
    sample = parts["sample"]
    if sample["diameter"] > tube["inner_diameter"] * (1 + 1e-9):
        raise r.fail(
            "/apparatus/sample@diameter",
            f"is {sample['diameter']!r} m, larger than the tube's inner_diameter {tube['inner_diameter']!r} m",
        )
    if sample["length"] >= tube["length"]:
        raise r.fail(
            "/apparatus/sample@length",
            f"is {sample['length']!r} m, not shorter than the tube's length {tube['length']!r} m",
        )
    if parts["internal_output_bar"]["diameter"] > tube["inner_diameter"] * (1 + 1e-9):
        raise r.fail(
            "/apparatus/internal_output_bar@diameter",
            f"is {parts['internal_output_bar']['diameter']!r} m, too large to slide in the tube "
            f"(inner_diameter {tube['inner_diameter']!r} m)",
        )
    if eob["inner_diameter"] <= parts["internal_output_bar"]["diameter"]:
        raise r.fail(
            "/apparatus/external_output_bar@inner_diameter",
            f"is {eob['inner_diameter']!r} m, not larger than the internal output bar's diameter "
            f"{parts['internal_output_bar']['diameter']!r} m (the bars are coaxial)",
        )
    if abs(tube["gauge_offset"]) >= tube["length"] / 2:
        raise r.fail(
            "/apparatus/tube@gauge_offset",
            f"is {tube['gauge_offset']!r} m, outside the tube (half length {tube['length'] / 2!r} m)",
        )



def _apparatus(parts: dict[str, dict[str, Any]], plug: Plug | None) -> Apparatus:
    """The apparatus of checked parts."""
    def bar(name: str) -> Bar:
        v = parts[name]
        return Bar(
            name=name,
            young_modulus=v["young_modulus"],
            wave_speed=v["wave_speed"],
            outer_diameter=v.get("outer_diameter", v.get("diameter")),
            inner_diameter=v.get("inner_diameter", 0.0),
            length=v["length"],
            gauge_distance=v.get("gauge_distance"),
            poisson_ratio=v["poisson_ratio"],
        )

    return Apparatus(
        striker=bar("striker"),
        input_bar=bar("input_bar"),
        internal_output_bar=bar("internal_output_bar"),
        external_output_bar=bar("external_output_bar"),
        tube=Tube(**parts["tube"]),
        sample=Sample(**parts["sample"]),
        plug=plug,
    )

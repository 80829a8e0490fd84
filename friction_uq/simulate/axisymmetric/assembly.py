"""The cell of a configuration as a mesh with its surfaces, contact areas, gauge weights and time step.

The sizes were checked when the configuration was read (:func:`.settings.check_sizes`); here a
mesh too large to run is refused, naming ``model.element_size``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import ConfigError
from ..config import SimulationConfig
from .kernels import critical_time_step, highest_frequency
from .mesh import PLUG, SAMPLE, TUBE, Block, Material, Mesh, build_mesh, divisions, face_areas, segment_lengths
from .settings import check_sizes

#: Steel plug's Poisson ratio (the record contract gives the plug's E and density only).
PLUG_POISSON_RATIO = 0.29
#: Most elements of a mesh (memory and run time of one record).
MAX_ELEMENTS = 200_000


@dataclass
class Cell:
    """Mesh, surfaces (node index arrays) and per-node data of the contacts, bar faces and hoop gauge."""

    mesh: Mesh
    plug_front: np.ndarray
    sample_in: np.ndarray
    sample_out: np.ndarray
    sample_outer: np.ndarray
    sample_area: np.ndarray
    plug_outer: np.ndarray
    plug_area: np.ndarray
    plug_extra: np.ndarray
    tube_inner: np.ndarray
    tube_end: np.ndarray
    in_face: np.ndarray
    share_in: np.ndarray
    share_out: np.ndarray
    share_tube: np.ndarray
    hoop_nodes: np.ndarray
    hoop_w: np.ndarray
    hoop_radius: float
    sample_rows: np.ndarray
    body_nodes: np.ndarray
    offset_sample: float
    offset_plug: float
    critical_step: float


def _fail(source: str, key: str, problem: str) -> ConfigError:
    return ConfigError(f"{source}: key '{key}' {problem}.")


def build_cell(config: SimulationConfig) -> Cell:
    """Mesh the configuration's plug, sample and tube (checks in the module docstring)."""
    ms, app = config.model, config.apparatus
    check_sizes(ms, app, source=config.source)
    sample, tube, plug = app.sample, app.tube, app.plug
    h = ms.element_size
    radius, length = sample.radius, sample.length
    a, b = tube.inner_diameter / 2.0, tube.outer_diameter / 2.0
    has_plug = plug is not None and plug.length > 0.0
    lp = plug.length if has_plug else 0.0
    z_t = -ms.plug_insertion if has_plug else 0.0
    z_gauge = 0.5 * length + tube.gauge_offset
    nr_s, nz_s = divisions(radius, h), divisions(length, h)
    counts = nr_s * nz_s
    blocks = []
    if has_plug:
        steel = Material(plug.young_modulus, PLUG_POISSON_RATIO, plug.density)
        nz_p = divisions(lp, h)
        blocks.append(Block(PLUG, 0.0, a - ms.plug_clearance, -lp, 0.0, nr_s, nz_p, steel))
        counts += nr_s * nz_p
    plastic = ms.sample_plasticity == "drucker_prager"
    blocks.append(Block(SAMPLE, 0.0, radius, 0.0, length, nr_s, nz_s, Material(
        sample.young_modulus, config.poisson_ratio, sample.density,
        ms.cohesion if plastic else 0.0, ms.dp_alpha if plastic else 0.0)))
    if ms.tube:
        nr_t, nz_t = divisions(b - a, h), divisions(tube.length, h)
        blocks.append(Block(TUBE, a, b, z_t, z_t + tube.length, nr_t, nz_t,
                            Material(tube.young_modulus, tube.poisson_ratio, config.tube_density)))
        counts += nr_t * nz_t
    if counts > MAX_ELEMENTS:
        raise _fail(config.source, "model.element_size", f"is {h * 1e3:g} mm, which needs {counts} elements (at most "
                    f"{MAX_ELEMENTS})")
    mesh = build_mesh(blocks)
    return _surfaces(mesh, config, has_plug=has_plug, z_gauge=z_gauge, radius=radius, a=a, b=b)


def _surfaces(mesh: Mesh, config: SimulationConfig, *, has_plug: bool, z_gauge: float, radius: float, a: float,
              b: float) -> Cell:
    ms, X = config.model, mesh.X
    empty = np.zeros(0, dtype=np.int64)
    none = np.zeros(0)
    s_outer = mesh.outer(SAMPLE)
    s_area = 2.0 * math.pi * radius * segment_lengths(X[s_outer, 1])
    sample_in, sample_out = mesh.bottom(SAMPLE), mesh.top(SAMPLE)
    if has_plug:
        plug_front, p_outer = mesh.top(PLUG), mesh.outer(PLUG)
        p_area = 2.0 * math.pi * X[p_outer[0], 0] * segment_lengths(X[p_outer, 1])
        inside = X[p_outer, 1] >= -ms.plug_insertion - 1e-12
        trib = segment_lengths(X[p_outer, 1]) * inside
        p_extra = trib / trib.sum() if trib.sum() > 0 else inside / max(1, inside.sum())
        in_face = mesh.bottom(PLUG)
    else:
        plug_front, p_outer, p_area, p_extra, in_face = empty, empty, none, none, sample_in
    if ms.tube:
        t_inner, t_end, t_outer = mesh.inner(TUBE), mesh.top(TUBE), mesh.outer(TUBE)
        hoop_w = gauge_weights(X[t_outer, 1], z_gauge, config.apparatus.tube.gauge_width)
        keep = hoop_w != 0.0
        hoop_nodes, hoop_w, hoop_r = t_outer[keep], hoop_w[keep], b
        share_tube = _shares(X[t_end, 0])
    else:
        t_inner, t_end, hoop_nodes, hoop_w, hoop_r, share_tube = empty, empty, empty, none, 0.0, none
    nr_s = mesh.blocks[SAMPLE].nr
    e0 = int(np.flatnonzero(mesh.body_of_element == SAMPLE)[0])
    rows = np.array([(e0 + iz * nr_s, nr_s) for iz in range(mesh.blocks[SAMPLE].nz)], dtype=np.int64)
    body_nodes = np.zeros((3, 2), dtype=np.int64)
    for body, grid in mesh.grids.items():
        body_nodes[body] = grid.min(), grid.max() + 1
    axis = mesh.axis
    omega = highest_frequency(mesh.mass, mesh.conn, mesh.geo, mesh.mat, ms.hourglass, axis)
    return Cell(
        mesh=mesh, plug_front=plug_front, sample_in=sample_in, sample_out=sample_out, sample_outer=s_outer,
        sample_area=s_area, plug_outer=p_outer, plug_area=p_area, plug_extra=p_extra, tube_inner=t_inner,
        tube_end=t_end, in_face=in_face, share_in=_shares(X[in_face, 0]), share_out=_shares(X[sample_out, 0]),
        share_tube=share_tube, hoop_nodes=hoop_nodes, hoop_w=hoop_w, hoop_radius=hoop_r, sample_rows=rows,
        body_nodes=body_nodes, offset_sample=(a - radius) - config.gap, offset_plug=0.0,
        critical_step=critical_time_step(omega, damping=ms.damping),
    )


def _shares(r: np.ndarray) -> np.ndarray:
    area = face_areas(r)
    return area / area.sum()


def gauge_weights(z: np.ndarray, centre: float, width: float, *, points: int = 401) -> np.ndarray:
    """Weights w_j with sum_j w_j u_j = the mean over [centre - width/2, centre + width/2] of the nodal
    field ``u`` interpolated linearly between nodes at ``z`` (ascending); the value at ``centre`` when width is 0.

    >>> [round(float(w), 3) for w in gauge_weights(np.array([0.0, 1.0, 2.0]), 1.0, 1.0)]
    [0.125, 0.75, 0.125]
    """
    zs = np.array([centre]) if width <= 0.0 else np.linspace(centre - width / 2, centre + width / 2, points)
    eye = np.eye(z.size)
    vals = np.array([np.interp(zs, z, eye[j]) for j in range(z.size)])  # (n_nodes, n_points)
    if width <= 0.0:
        return vals[:, 0]
    return np.trapezoid(vals, zs, axis=1) / width

"""The simulator configuration the tests hide effects in: every gauge with white + AR(1) noise and an
offset, as a lab's record has them."""

from __future__ import annotations

from types import MappingProxyType

from friction_uq.simulate import SimulationConfig
from friction_uq.simulate.config import ChannelSpec


def noisy_config(**kw) -> SimulationConfig:
    """A :class:`SimulationConfig` with the tests' gauge noise; ``channels`` replaces some gauges' specs."""
    ch = {
        "input_bar": ChannelSpec(white=3e-6, ar1=2e-6, ar1_coef=0.5, offset=1e-5),
        "internal_output_bar": ChannelSpec(white=2e-6, ar1=2e-6, ar1_coef=0.4, offset=-5e-6),
        "external_output_bar": ChannelSpec(white=1e-6, ar1=1e-6, ar1_coef=0.6, offset=1e-6),
        "tube_hoop": ChannelSpec(white=2e-6, ar1=1e-6, ar1_coef=0.3),
    }
    ch.update(kw.pop("channels", {}))
    return SimulationConfig(channels=MappingProxyType(ch), **kw)

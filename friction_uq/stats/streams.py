"""Named random streams: one seeded Generator per purpose of an analysis, derived from its seed.

A stream is keyed by the analysis' seed, the purpose's fixed number (:data:`PURPOSES`) and, where
models are fitted in parallel, the model's label (its CRC-32): a model's draws are then the same
whichever process fits it and in whatever order, and no two purposes share bits. The numbers are
part of what a seed means: changing one changes every result drawn from it.
"""

from __future__ import annotations

import zlib

import numpy as np

#: purpose -> its word in the seed sequence
PURPOSES = {
    "whole-record check": 8,  # the whole-record fit of the stationary analysis' model (discrepancy.check)
    "extended fit": 9,  # one extended model's whole-record fit (discrepancy.extended)
    "exact posterior": 11,  # importance sampling / emcee behind the final model's Laplace fit
    "effective prior": 13,  # the prior of f_effective, computed by simulation when the draws are written
    "mixture": 14,  # the stacking mixture's draws of f when diagnose names no single cause (discrepancy.verdict)
    "nu cut": 15,  # a model's conditional fit at the windows' nu (discrepancy.nu_cut)
    "nu cut draws": 16,  # the windows' draws of nu paired with that fit's draws
    "nu cut exact": 17,  # the windows' draws of nu paired with the exact posterior's draws
    "nu window": 18,  # nu's normal approximation from the stationary windows (discrepancy.nu_cut)
}


def stream(seed: int, purpose: str, label: str | None = None) -> np.random.Generator:
    """The Generator of ``purpose`` (of the model ``label`` when given) under ``seed`` (module docstring).

    >>> float(stream(1, "extended fit", "baseline").random()) == float(stream(1, "extended fit", "baseline").random())
    True
    """
    key = [seed, PURPOSES[purpose]] + ([zlib.crc32(label.encode())] if label is not None else [])
    return np.random.default_rng(np.random.SeedSequence(key))


def legacy_state(rng: np.random.Generator) -> np.random.RandomState:
    """A legacy ``RandomState`` (what emcee draws its moves from) seeded by one draw of ``rng``."""
    return np.random.RandomState(int(rng.integers(2**31)))

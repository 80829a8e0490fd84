"""Checkpoints of a sampler run: the chain so far and the random state, saved every few seconds.

A checkpoint is one ``.npz`` file (numpy's zip format, written by Python, not by the HDF5
library: a full disk gives an ordinary ``OSError``, never a crash), replaced atomically (written
to a temporary name, then renamed), so a kill leaves the previous checkpoint or the new one,
never half of one. It carries a fingerprint of everything that determines the chain (data,
priors, parameters, seed, settings, format): a checkpoint from another run, or one that cannot be
read, is removed and the run starts afresh, with a one-line notice.
"""

from __future__ import annotations

import hashlib
import os
import zipfile
from collections.abc import Callable
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._atomic import atomic_path
from ..priors import Priors
from ..window import StationaryData
from .results import SamplerSettings

#: Bumped whenever the sampler's algorithm or the file layout changes (old files are then stale).
FORMAT = "friction-uq-checkpoint-2"


def fingerprint(data: StationaryData, priors: Priors, names: tuple[str, ...], seed: int,
                settings: SamplerSettings) -> str:
    """sha256 of what determines the chain: data, priors, parameter names, seed, sampler settings."""
    h = hashlib.sha256(FORMAT.encode())
    for arr in (data.F_io, data.F_eo, data.slip) + ((data.hoop,) if data.hoop is not None else ()):
        h.update(np.ascontiguousarray(arr, float).tobytes())
    h.update(repr((data.sd_io, data.sd_eo, data.rho_io, data.rho_eo, data.sd_hoop, data.rho_hoop)).encode())
    h.update(priors.describe().encode())
    h.update(repr((names, seed, settings.nwalkers, settings.n_ensembles, settings.check_every)).encode())
    return h.hexdigest()


@dataclass(frozen=True)
class Checkpoint:
    """A saved chain: positions (steps, walkers, ndim), log densities, acceptances, random state."""

    chain: np.ndarray
    log_prob: np.ndarray
    accepted: np.ndarray
    random_state: tuple

    @property
    def iteration(self) -> int:
        return int(self.chain.shape[0])


def save(path: str | os.PathLike[str], fp: str, ck: Checkpoint) -> None:
    """Write ``ck`` to ``path`` atomically (see the module docstring)."""
    name, keys, pos, has_gauss, cached = ck.random_state
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez(fh, fingerprint=np.array(fp), chain=ck.chain, log_prob=ck.log_prob, accepted=ck.accepted,
                 rs_name=np.array(name), rs_keys=np.asarray(keys), rs_pos=np.array(pos),
                 rs_has_gauss=np.array(has_gauss), rs_cached=np.array(cached))


def load(path: str | os.PathLike[str], fp: str, *, nwalkers: int, ndim: int,
         notify: Callable[[str], None] | None = None) -> Checkpoint | None:
    """The checkpoint at ``path`` if it belongs to this run (fingerprint ``fp``), else None.

    A file of another run (other data, priors, seed or settings) or one that cannot be read
    (truncated, not a checkpoint, wrong shapes) is removed, and ``notify`` gets one line saying so.
    """
    p = Path(path)
    if not p.exists():
        return None
    why = None
    try:
        with open(p, "rb") as fh, np.load(fh, allow_pickle=False) as z:
            if str(z["fingerprint"]) != fp:
                why = "was written for other data, priors, seed, window or settings"
            else:
                ck = Checkpoint(np.array(z["chain"], float), np.array(z["log_prob"], float),
                                np.array(z["accepted"], float),
                                (str(z["rs_name"]), np.array(z["rs_keys"], np.uint32), int(z["rs_pos"]),
                                 int(z["rs_has_gauss"]), float(z["rs_cached"])))
                n = ck.iteration
                if (n < 1 or ck.chain.shape[1:] != (nwalkers, ndim) or ck.log_prob.shape != (n, nwalkers)
                        or ck.accepted.shape != (nwalkers,) or not np.all(np.isfinite(ck.chain))):
                    why = "has the wrong shape for this run"
                else:
                    return ck
    except (OSError, ValueError, KeyError, EOFError, AttributeError, zipfile.BadZipFile) as exc:
        why = f"cannot be read ({type(exc).__name__}: {exc})"
    discard(p)
    if notify is not None:
        notify(f"the checkpoint {p} {why}; it is removed and sampling starts afresh")
    return None


def discard(path: str | os.PathLike[str]) -> None:
    """Remove a checkpoint file if it exists."""
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass


@dataclass
class Store:
    """Where the checkpoint goes (None: nowhere), its call's fingerprint, and when it was last written."""

    path: str | Path | None
    fingerprint: str
    last: float = field(default_factory=time.perf_counter)

    def write(self, backend) -> None:
        """Write the chain so far of ``backend`` (an emcee backend; a no-op without a path)."""
        if self.path is not None:
            save(self.path, self.fingerprint, Checkpoint(
                backend.get_chain(), backend.get_log_prob(), np.asarray(backend.accepted, float),
                backend.random_state))
            self.last = time.perf_counter()

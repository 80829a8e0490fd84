"""Differential-evolution move for several independent ensembles stepped as one emcee ensemble."""

from __future__ import annotations

import numpy as np
from emcee.moves import RedBlueMove
from emcee.state import State


class BlockDEMove(RedBlueMove):
    """emcee's ``DEMove`` (Nelson et al. 2013) applied inside blocks of walkers.

    The ``n_blocks * walkers_per_block`` walkers of one emcee ensemble form ``n_blocks``
    independent ensembles: walker ``i`` belongs to block ``i // walkers_per_block`` and its
    proposals use only walkers of its own block (the red-blue halves are the even and odd walkers
    of each block), so the blocks never interact and each is an ensemble of its own, while one
    vectorised log-density call evaluates all of them (one call per half step instead of one per
    ensemble and half step). The proposal is ``s + gamma (c_a - c_b)`` with ``gamma = gamma0 (1 +
    sigma N(0, 1))``, ``gamma0 = 2.38 / sqrt(2 ndim)``, as in ``emcee.moves.DEMove``; the
    acceptance is the ordinary Metropolis rule, drawn for all walkers of a half at once.
    """

    def __init__(self, n_blocks: int, *, sigma: float = 1.0e-5, gamma0: float | None = None) -> None:
        super().__init__(nsplits=2, randomize_split=False)
        self.n_blocks = int(n_blocks)
        self.sigma = sigma
        self.gamma0 = gamma0

    def propose(self, model, state: State) -> tuple[State, np.ndarray]:  # noqa: ANN001 (emcee's Model tuple)
        nwalkers, ndim = state.coords.shape
        per = nwalkers // self.n_blocks
        if per * self.n_blocks != nwalkers or per % 2 or per < 2 * ndim:
            raise ValueError(f"{nwalkers} walkers do not split into {self.n_blocks} even blocks of >= {2 * ndim}")
        g0 = self.gamma0 if self.gamma0 is not None else 2.38 / np.sqrt(2 * ndim)
        half = per // 2
        idx = np.arange(nwalkers).reshape(self.n_blocks, per)
        accepted = np.zeros(nwalkers, dtype=bool)
        random = model.random
        for split in range(2):
            s_idx = idx[:, split::2].reshape(-1)  # this half of every block, block-major
            c_idx = idx[:, 1 - split::2]  # (n_blocks, half): the complementary half of each block
            block = np.repeat(np.arange(self.n_blocks), half)
            a = random.randint(half, size=len(s_idx))
            b = random.randint(half - 1, size=len(s_idx))
            b = b + (b >= a)  # two distinct partners
            diff = state.coords[c_idx[block, b]] - state.coords[c_idx[block, a]]
            gamma = g0 * (1.0 + self.sigma * random.randn(len(s_idx), 1))
            q = state.coords[s_idx] + gamma * diff
            new_lp, new_blobs = model.compute_log_prob_fn(q)
            ok = new_lp - state.log_prob[s_idx] > np.log(random.rand(len(s_idx)))
            mask = np.zeros(nwalkers, dtype=bool)
            mask[s_idx[ok]] = True
            accepted |= mask
            coords = state.coords.copy()
            log_prob = state.log_prob.copy()
            coords[s_idx[ok]] = q[ok]
            log_prob[s_idx[ok]] = new_lp[ok]
            state = State(coords, log_prob=log_prob, blobs=None, random_state=state.random_state)
        return state, accepted

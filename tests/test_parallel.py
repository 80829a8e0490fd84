"""Work on the other core: the same value forked or in line, exceptions carried back."""

from __future__ import annotations

import threading
from types import MappingProxyType

import numpy as np
import pytest

from friction_uq import _parallel
from friction_uq._parallel import Background, can_fork


def _draws(config, *, seed):
    return np.random.default_rng(seed).normal(config["mean"], 1.0, 5)


def _fails():
    raise ValueError("a column too stiff to integrate")


@pytest.mark.parametrize("fork", [True, False])
def test_the_value_is_the_same_forked_or_in_line(fork, monkeypatch):
    if not fork:
        monkeypatch.setattr(_parallel, "can_fork", lambda: False)
    elif not can_fork():
        pytest.skip("this process may not fork (threads running, or a daemon)")
    config = MappingProxyType({"mean": 3.0})  # does not pickle: the worker inherits it
    job = Background(_draws, config, seed=7)
    assert job.forked is fork
    assert np.array_equal(job.result(), _draws(config, seed=7))


def test_an_exception_in_the_worker_is_raised_by_result():
    job = Background(_fails)
    with pytest.raises(ValueError, match="too stiff"):
        job.result()


def test_no_fork_while_other_threads_run():
    stop = threading.Event()
    t = threading.Thread(target=stop.wait)
    t.start()
    try:
        assert not can_fork()
        assert not Background(_draws, {"mean": 0.0}, seed=1).forked
    finally:
        stop.set()
        t.join()

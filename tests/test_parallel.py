"""Work on the other core: the same value forked or in line, exceptions carried back."""

from __future__ import annotations

import os
import subprocess
import sys
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


def _slow(seconds):
    import time

    time.sleep(seconds)
    return seconds


def test_result_is_computed_once_and_close_before_result_runs_it_in_line():
    job = Background(_draws, {"mean": 1.0}, seed=3)
    job.close()  # the child stopped before its value was taken
    assert not job.forked
    first = job.result()
    assert np.array_equal(first, _draws({"mean": 1.0}, seed=3)) and job.result() is first
    assert Background(None).result() is None


def _in_fresh_interpreter(tmp_path, source: str) -> subprocess.CompletedProcess:
    """Run ``source`` as a script in a new Python process with the project on its path (a fresh interpreter
    runs no threads, so it may fork where this one, deep in the suite, may not)."""
    script = tmp_path / "script.py"
    script.write_text(source)
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    return subprocess.run([sys.executable, str(script)], capture_output=True, text=True, cwd=root, timeout=60,
                          env=os.environ | {"PYTHONPATH": root})


def test_a_child_that_dies_is_one_sentence_not_a_traceback(tmp_path):
    """A child killed (or out of memory) before its value: a FrictionUQError, which the CLI says in one line.
    In a fresh interpreter: this one may run threads by now, and then it does not fork."""
    out = _in_fresh_interpreter(
        tmp_path,
        "import os\n"
        "from friction_uq._parallel import Background\n"
        "from friction_uq.errors import FrictionUQError\n"
        "def dies():\n"
        "    os._exit(3)  # as if killed: no value is sent back\n"
        "job = Background(dies)\n"
        "print(job.forked)\n"
        "try:\n"
        "    job.result()\n"
        "except FrictionUQError as exc:\n"
        "    print(type(exc).__name__, '|', exc)\n")
    forked, said = out.stdout.strip().split("\n")
    if forked != "True":
        pytest.skip("a fresh interpreter could not fork here")
    assert out.returncode == 0, out.stderr
    assert said == ("BackgroundError | the process working beside this one (dies) ended without handing back its "
                    "result: it was killed, or ran out of memory")


def test_the_child_ends_when_its_parent_is_killed(tmp_path):
    """A killed run must not leave its child behind (it would keep what the run had open)."""
    import time

    out = _in_fresh_interpreter(
        tmp_path,
        "import os, sys, time\n"
        "from tests.test_parallel import _slow\n"
        "from friction_uq._parallel import Background\n"
        "job = Background(_slow, 1.0)\n"
        "print(job._proc.pid if job.forked else -1, flush=True)\n"
        "os._exit(0)  # as if killed: no clean-up runs\n")
    pid = int(out.stdout.split()[0])
    if pid < 0:
        pytest.skip("the parent could not fork")
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return
        try:  # reap it if it became ours (it does not: it is reparented), else wait
            os.waitpid(pid, os.WNOHANG)
        except ChildProcessError:
            pass
        time.sleep(0.2)
    pytest.fail(f"the child {pid} still runs 20 s after its parent was killed")


def _seeded(item):
    seed, lam = item
    return os.getpid(), np.random.default_rng(seed).exponential(lam, 3)


def test_a_forked_map_gives_in_order_the_values_of_a_map_in_line():
    items = [(s, 1.0 + s) for s in range(5)]
    forked = _parallel.forked_map(_seeded, items, workers=2)
    in_line = _parallel.forked_map(_seeded, items, workers=1)
    for (_, a), (_, b) in zip(forked, in_line):
        np.testing.assert_array_equal(a, b)
    if can_fork():  # the work was done by other processes
        assert {pid for pid, _ in forked} != {os.getpid()}
    assert {pid for pid, _ in in_line} == {os.getpid()}


@pytest.mark.slow  # a campaign's law comparison twice: in the default suite it kept that suite over 10 minutes (53 s in a CI run)
def test_the_campaign_law_comparison_is_the_same_on_one_or_two_processes(monkeypatch):
    from friction_uq.campaigns import analysis, law_comparison

    tests = _campaign_tests()
    runs = []
    for workers in (1, 2):
        monkeypatch.setattr(law_comparison, "LAW_WORKERS", workers)
        ca = analysis.analyse_tests(tests, {}, seed=3)
        runs.append(({r["model"]: r["elpd"] for r in ca.ranking}, ca.weights))
    assert runs[0] == runs[1]


def _campaign_tests():
    """Six tests of a velocity-weakening wall on one set-up, drawn once."""
    from friction_uq.campaigns.analysis import RecordPosterior
    from friction_uq.prior_loader import PRIORS_DIR

    rng = np.random.default_rng(2)
    out = []
    for k, V in enumerate(np.linspace(6.0, 12.0, 6)):
        kappa = (0.035 + 0.04 * np.exp(-V / 8)) * 0.4 / 0.6
        kd, nu = rng.normal(kappa, 0.02 * kappa, 400), rng.normal(0.4, 0.013, 400)
        out.append(RecordPosterior(f"A-{k}", "A", kd * (1 - nu) / nu, kd, nu, rng.normal(9e6 * V, 4e5, 400),
                                   {"mean": V, "sd": 1e-3, "q05": V, "q50": V, "q95": V},
                                   str(PRIORS_DIR / "I1.toml")))
    return out


def test_a_forked_pool_gives_the_values_in_order_and_in_line_where_it_may_not_fork(monkeypatch):
    offset = MappingProxyType({"c": 2.5})  # does not pickle: the workers inherit the function by the fork
    fn = lambda x: float(np.sum(x ** 2)) + offset["c"]  # noqa: E731 - a closure, as a likelihood's is
    rows = np.random.default_rng(3).normal(size=(37, 3))
    expected = [fn(r) for r in rows]
    may_fork = can_fork()
    with _parallel.ForkedPool(fn, workers=2) as pool:
        assert pool.forked is may_fork
        assert pool.map(rows) == expected
        assert pool.map(rows[:5]) == expected[:5]  # many calls on one pool
    assert _parallel._POOLED is None and can_fork() is may_fork  # its threads are gone: later work may fork
    monkeypatch.setattr(_parallel, "can_fork", lambda: False)
    with _parallel.ForkedPool(fn, workers=2) as pool:
        assert not pool.forked and pool.map(rows) == expected


def test_an_exception_in_a_pool_worker_reaches_the_caller_and_the_pool_is_released():
    def fn(x):
        if x == 3:
            raise ValueError("a column too stiff to integrate")
        return x

    with pytest.raises(ValueError, match="too stiff"):
        with _parallel.ForkedPool(fn, workers=2) as pool:
            pool.map(range(8))
    assert _parallel._POOLED is None


def test_a_pool_that_cannot_be_made_leaves_nothing_behind(monkeypatch):
    def no_fork(workers):
        raise OSError("Cannot allocate memory")

    monkeypatch.setattr(_parallel, "can_fork", lambda: True)  # no process is forked: the fork itself fails
    monkeypatch.setattr(_parallel, "_executor", no_fork)
    with pytest.raises(OSError, match="allocate"):
        with _parallel.ForkedPool(abs, workers=2):
            pass
    assert _parallel._POOLED is None  # a later pool may be made


KILLED_WORKER = """
import os, signal
from friction_uq import _parallel
from friction_uq.errors import BackgroundError
parent = os.getpid()

def dies_at_three(x):
    if x == 3 and os.getpid() != parent:  # only ever in a worker
        os.kill(os.getpid(), signal.SIGKILL)
    return x

assert _parallel.can_fork()
try:
    with _parallel.ForkedPool(dies_at_three, workers=2) as pool:
        pool.map(range(8))
except BackgroundError as exc:
    print("pool:", exc)
assert _parallel._POOLED is None
try:
    _parallel.forked_map(dies_at_three, range(8), workers=2)
except BackgroundError as exc:
    print("map:", exc)
print("later:", _parallel.forked_map(dies_at_three, [0, 1, 2], workers=2))
"""


def test_a_worker_killed_is_one_sentence_not_a_wait_for_ever():
    """A worker killed (out of memory, a user's kill) ends the wait with BackgroundError, in a pool of many calls
    and in a map of one; a multiprocessing.Pool waited for ever for its values. In a fresh interpreter (one
    thread, so it may fork), with a time limit: a wait for ever fails the test instead of hanging the suite."""
    out = subprocess.run([sys.executable, "-c", KILLED_WORKER], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert lines[0].startswith("pool: a process working beside this one (dies_at_three) ended without handing back")
    assert "it was killed, ran out of memory" in lines[0]
    assert lines[1].startswith("map: a process working beside this one (dies_at_three)")
    assert lines[2] == "later: [0, 1, 2]"


LEFT_ON_ERROR = """
import time
from friction_uq import _parallel

def fails_first(x):
    if x == 0:
        raise ValueError("a column too stiff to integrate")
    time.sleep(60)  # the other worker's share: nothing of it is wanted once the map has failed
    return x

assert _parallel.can_fork()  # else the map runs in line and fails at once: the test would test nothing

def in_a_pool():
    with _parallel.ForkedPool(fails_first, workers=2) as pool:
        return pool.map(range(4))

for run in (lambda: _parallel.forked_map(fails_first, range(4), workers=2), in_a_pool):
    try:
        run()
    except ValueError as exc:
        print(exc)
"""


def test_an_error_stops_the_other_workers_at_once():
    """A map that fails (or a Ctrl-C) stops the workers still busy instead of waiting for their shares, which they
    would finish (they ignore Ctrl-C). Each worker's other share takes a minute: a wait fails the time limit."""
    out = subprocess.run([sys.executable, "-c", LEFT_ON_ERROR], capture_output=True, text=True, timeout=40)
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines() == ["a column too stiff to integrate"] * 2

"""The libraries' warnings go to the output folder's log, not to the terminal (friction_uq._logfile)."""

from __future__ import annotations

import logging
import warnings

from friction_uq._logfile import LOG_NAME, libraries_to_log


def test_library_warnings_and_log_records_reach_the_log_not_the_terminal(tmp_path, capsys):
    lg = logging.getLogger("distributed")
    before = (lg.handlers[:], lg.propagate, logging.getLogger("py.warnings").handlers[:])
    with libraries_to_log(tmp_path):
        warnings.warn("a library's deprecation", DeprecationWarning, stacklevel=1)
        logging.getLogger("distributed.nanny").warning("Worker process still alive after 4.0 seconds, killing")
    err = capsys.readouterr().err
    assert "killing" not in err and "deprecation" not in err
    text = (tmp_path / LOG_NAME).read_text()
    assert "distributed.nanny WARNING: Worker process still alive" in text and "a library's deprecation" in text
    # afterwards the loggers are as they were
    assert (lg.handlers, lg.propagate, logging.getLogger("py.warnings").handlers) == before


def test_nothing_is_written_without_a_message_or_without_the_folder(tmp_path):
    with libraries_to_log(tmp_path):
        pass
    assert not (tmp_path / LOG_NAME).exists()
    missing = tmp_path / "never-made"
    with libraries_to_log(missing):
        logging.getLogger("numba").warning("something")
    assert not missing.exists()  # a refused command leaves nothing behind


def test_a_command_that_fails_writes_no_log_even_into_a_folder_that_was_there(tmp_path):
    # a library's message during a run that then fails (a forked worker's warning, say): the folder stays as it was
    try:
        with libraries_to_log(tmp_path):
            warnings.warn("This process is multi-threaded, use of fork() may lead to deadlocks", DeprecationWarning,
                          stacklevel=1)
            raise ValueError("the run failed")
    except ValueError:
        pass
    assert not any(tmp_path.iterdir())


def test_a_library_that_installs_its_handlers_later_is_rerouted(tmp_path, capsys):
    from friction_uq._logfile import reroute

    with libraries_to_log(tmp_path):
        late = logging.StreamHandler()  # as dask.distributed does when it is first imported
        logging.getLogger("distributed").handlers = [late]
        reroute()
        logging.getLogger("distributed.nanny").warning("killing")
    assert "killing" not in capsys.readouterr().err and "killing" in (tmp_path / LOG_NAME).read_text()

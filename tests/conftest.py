"""Shared fixtures: one good closed-form record per session, and throw-away copies of it."""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

import pytest

from friction_uq.synthetic import ClosedFormTest, write_closed_form_record

#: Seed of the session's good record (fixed: every run builds the same file).
GOOD_RECORD_SEED = 20160301


@pytest.fixture(scope="session")
def good_record(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A closed-form record that follows the contract (paper's apparatus, hoop gauge, ``/truth``).

    Shared by the whole session: never open it for writing, take a :func:`record_copy`.
    """
    path = tmp_path_factory.mktemp("good") / "good.h5"
    return write_closed_form_record(path, ClosedFormTest(), seed=GOOD_RECORD_SEED, test_id="A-01", campaign="A")


@pytest.fixture
def record_copy(good_record: Path, tmp_path: Path) -> Callable[..., Path]:
    """``record_copy(name="record.h5")``: a fresh copy of the good record in this test's tmp_path."""

    def copy(name: str = "record.h5") -> Path:
        dest = tmp_path / name
        shutil.copyfile(good_record, dest)
        return dest

    return copy

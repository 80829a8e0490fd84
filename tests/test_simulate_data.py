"""The bundled synthetic campaigns: each file reads under the contract and is what its config makes."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from friction_uq.record import read_record, read_truth
from friction_uq.simulate import load_config, simulate

DATA = Path(__file__).resolve().parent.parent / "data"
CONFIGS = sorted((DATA / "configs").glob("?-??.toml"))  # the campaigns' records


def test_both_campaigns_have_five_records() -> None:
    names = [p.stem for p in CONFIGS]
    assert names == [f"{c}-{i:02d}" for c in "AB" for i in range(1, 6)]


@pytest.mark.parametrize("cfg_path", CONFIGS, ids=lambda p: p.stem)
def test_record_reads_and_matches_its_configuration(cfg_path: Path) -> None:
    cfg = load_config(cfg_path)
    path = DATA / cfg.campaign / f"{cfg.test_id}.h5"
    assert path.stat().st_size < 1_000_000
    rec = read_record(path)
    assert (rec.test_id, rec.campaign) == (cfg.test_id, cfg.campaign)
    assert rec.duration >= 1.2e-3 and -rec.t0 >= 40e-6
    truth = read_truth(path)
    assert truth["seed"] == cfg.seed and truth["friction_law"] == cfg.friction_law
    assert truth["striker_velocity"] == cfg.striker_velocity and truth["gap"] == cfg.gap


@pytest.mark.parametrize("test_id", ["A-03", "B-05"])
def test_regenerating_a_record_gives_the_same_samples(test_id: str) -> None:
    cfg = load_config(DATA / "configs" / f"{test_id}.toml")
    sim = simulate(cfg)  # the config's seed
    with h5py.File(DATA / cfg.campaign / f"{test_id}.h5") as fh:
        for name, strain in sim.noisy.items():
            ds = fh["signals"][name]
            unit = {"strain": 1.0, "microstrain": 1e-6}.get(ds.attrs["units"], ds.attrs.get("strain_per_volt"))
            expected = (-strain / unit).astype(np.float32)
            assert np.array_equal(ds[()], expected), name

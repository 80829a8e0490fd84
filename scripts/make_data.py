"""Regenerate the bundled synthetic campaigns from their checked-in configurations.

    python scripts/make_data.py            # write data/<campaign>/<test_id>.h5 for data/configs/*.toml
    python scripts/make_data.py --check    # regenerate in a temporary folder, compare sha256 with data/

Every record is simulated with the seed of its configuration (``record.seed``), so the files are
reproduced bit for bit by the same version of friction-uq; each written file is read back with
:func:`friction_uq.record.read_record` (the contract's checks). Exit status 1 when a check fails.
"""

from __future__ import annotations

import argparse
import hashlib
import sys
import tempfile
from pathlib import Path

from friction_uq.record import read_record
from friction_uq.simulate import load_config, simulate_to_file

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "data"


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def make(out_root: Path) -> dict[str, str]:
    """Simulate every configuration into ``out_root``; returns relative path -> sha256."""
    digests: dict[str, str] = {}
    for cfg_path in sorted((DATA / "configs").glob("?-??.toml")):  # the campaigns (not paper-axisymmetric)
        cfg = load_config(cfg_path)
        rel = Path(cfg.campaign) / f"{cfg.test_id}.h5"
        path = simulate_to_file(cfg, out_root / rel)
        read_record(path)  # raises RecordError if the file breaks the contract
        digests[str(rel)] = sha256(path)
        print(f"{rel}  {path.stat().st_size / 1024:6.0f} KiB  sha256 {digests[str(rel)][:16]}")
    return digests


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="regenerate in a temporary folder and compare")
    args = parser.parse_args(argv)
    if not args.check:
        make(DATA)
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        fresh = make(Path(tmp))
    bad = [rel for rel, digest in fresh.items() if not (DATA / rel).exists() or sha256(DATA / rel) != digest]
    for rel in bad:
        print(f"differs from the checked-in file: data/{rel}", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())

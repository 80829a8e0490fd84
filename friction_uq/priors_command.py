"""``friction-uq priors``: list the materials that have prior files, or start the files of a new one.

The parser and the command's body; :mod:`friction_uq.cli` registers them.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from .cli_arguments import path_argument

HELP = "list the materials with prior files, or write starting prior files for a new sample material"
DESCRIPTION = (
    "Without MATERIAL: the materials whose prior files come with friction-uq (and those in --out), each with its "
    "alternative nu priors. With MATERIAL, --nu and --nu-sd: write MATERIAL.toml (the default priors) and "
    "MATERIAL-nu-tight.toml, MATERIAL-nu-wide.toml (the alternatives a run compares) into --out, commented for "
    "you to edit; then 'friction-uq run test.h5 --priors MATERIAL.toml'. Format: docs/priors.md."
)


#: Longest material name: MATERIAL-nu-tight.toml and a writer's temporary name stay within a file system's 255 bytes.
MAX_MATERIAL_CHARS = 200


def _material(text: str) -> str:
    """The rule ``run`` looks a record's material up by (:func:`~friction_uq.plausible.is_name`), so that every file
    written here can be found."""
    from .plausible import is_name

    if not is_name(text) or "-nu-" in text:
        raise argparse.ArgumentTypeError(f"material {text!r} must be a name of letters, digits, '_' and '-' "
                                         "(as in the record's /apparatus/sample@material), without '-nu-'")
    if len(text) > MAX_MATERIAL_CHARS:
        raise argparse.ArgumentTypeError(f"material {text[:20]!r}... is {len(text)} characters long, more than the "
                                         f"{MAX_MATERIAL_CHARS} a prior file's name leaves room for")
    return text


def add_parser(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("priors", help=HELP, description=DESCRIPTION)
    s.add_argument("material", nargs="?", type=_material, help="sample material, as the record names it")
    s.add_argument("--nu", type=float, help="your estimate of the sample's Poisson ratio, in (0, 0.5)")
    s.add_argument("--nu-sd", type=float, help="its uncertainty (one standard deviation), e.g. 0.03")
    s.add_argument("--source", default="", help="where the estimate comes from (written into the files)")
    s.add_argument("--out", type=path_argument, default=Path("."), help="folder to write to (default: the current folder)")
    s.add_argument("--force", action="store_true", help="replace files of the same names")


def _listing(folder: Path) -> str:
    from .prior_loader import PRIORS_DIR, prior_files

    folders = [(PRIORS_DIR, "come with friction-uq")]
    if folder.resolve() != PRIORS_DIR.resolve() and prior_files(folder):
        folders.append((folder, f"are in {folder}"))
    lines = []
    for where, label in folders:
        lines.append(f"materials whose prior files {label} ({where}):")
        for m, alts in prior_files(where).items():
            lines.append(f"  {m:<16} nu alternatives: {', '.join(a.removeprefix(m + '-') for a in alts) or 'none'}")
    lines.append("a new material: friction-uq priors MATERIAL --nu ESTIMATE --nu-sd UNCERTAINTY")
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    from ._atomic import write_bytes
    from .errors import FrictionUQError, OutputError
    from .prior_template import prior_texts
    from .prior_loader import parse_priors

    if args.material is None:
        print(_listing(args.out))
        return 0
    if args.nu is None or args.nu_sd is None:
        raise FrictionUQError(f"priors {args.material}: give --nu (your estimate of the Poisson ratio) and --nu-sd "
                              "(its uncertainty, one standard deviation)")
    try:
        texts = prior_texts(args.material, args.nu, args.nu_sd, args.source)
    except ValueError as exc:
        raise FrictionUQError(f"priors {args.material}: {exc}") from None
    paths = {args.out / name: text for name, text in texts.items()}
    if args.out.exists() and not args.out.is_dir():
        raise OutputError(f"{args.out}: --out must be a folder, and this is a file")
    for p in paths:  # every refusal before the first file is written
        if p.exists() and not p.is_file():
            raise OutputError(f"{p}: exists and is not a file (a folder?), which --force does not replace; choose "
                              "another --out")
        if p.exists() and not args.force:
            raise OutputError(f"{p}: exists; choose another --out or give --force to replace it")
    import tomllib

    for p, text in paths.items():
        parse_priors(tomllib.loads(text), path=p)  # what is written reads back
    for p, text in paths.items():
        write_bytes(p, text.encode("utf-8"))
        print(f"wrote {p}")
    print(f"next: friction-uq run test.h5 --priors {args.out / (args.material + '.toml')}")
    return 0

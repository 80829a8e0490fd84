"""``friction-uq import``: oscilloscope files and a SETUP.toml to a checked test record.

The parser and the command's body; :mod:`friction_uq.cli` registers them. Nothing heavy is imported
until the command runs.
"""

from __future__ import annotations

import argparse
import os

from .cli_arguments import path_argument

HELP = "oscilloscope files (CSV, TSV, TDMS, LeCroy .trc, Tektronix/Rigol .wfm) to a test record (test.h5)"
DESCRIPTION = (
    "Read oscilloscope exports as SETUP.toml describes them (columns, units, volts to strain, signs, the "
    "apparatus) and write one test record, checked against the record contract and for gauges whose sign or "
    "scale contradicts the others. 'friction-uq import --template > SETUP.toml' starts a set-up file. "
    "Guide: docs/import.md."
)


def add_parser(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("import", help=HELP, description=DESCRIPTION)
    s.add_argument("files", type=path_argument, nargs="*", metavar="FILE",
                   help="one file with every channel, or one file per channel")
    s.add_argument("--setup", type=path_argument, metavar="SETUP.toml", help="what the files hold and the apparatus")
    s.add_argument("-o", "--output", type=path_argument, help="record to write (test.h5)")
    s.add_argument("--template", action="store_true", help="print a commented SETUP.toml (the paper's set-up) and exit")
    s.add_argument("--show", action="store_true",
                   help="print what each FILE holds (layout, columns or channels, first values) and exit: "
                   "what SETUP.toml refers to")
    s.add_argument("--overwrite", action="store_true", help="replace the record -o names if it exists (refused otherwise)")
    s.add_argument("--no-check", action="store_true",
                   help="write the record even when a gauge's sign or scale contradicts the others (warnings only)")


def run(args: argparse.Namespace, parser: argparse.ArgumentParser, output_check) -> int:
    """Body of the command; ``output_check(path, suffixes, what)`` refuses a bad output name."""
    if args.template:
        from .acquisition.template import TEMPLATE

        print(TEMPLATE, end="")
        return 0
    if args.show:
        if not args.files:
            parser.error("import --show needs FILE: friction-uq import scope.csv --show")
        from .acquisition.binary import BINARY_SUFFIXES, describe_binary
        from .acquisition.delimited import describe_text
        from .errors import ScopeFileError
        from .plausible import not_regular

        for f in args.files:
            if not f.is_file():
                raise ScopeFileError(f"{f}: {not_regular(f) or 'file not found'}")
            lines = describe_binary(f) if f.suffix.lower() in BINARY_SUFFIXES else describe_text(f)
            print("\n".join(lines))
        return 0
    missing = [n for n, v in (("FILE", args.files), ("--setup", args.setup), ("-o", args.output)) if not v]
    if missing:
        parser.error(f"import needs {', '.join(missing)}: friction-uq import FILE... --setup SETUP.toml -o test.h5 "
                     "(friction-uq import --template prints a SETUP.toml to start from)")
    output_check(args.output, (".h5", ".hdf5"), "record")
    for given in (*args.files, args.setup):  # --overwrite replaces an earlier record, never what is being read
        if given.exists() and args.output.exists() and os.path.samefile(given, args.output):  # a link too
            from .errors import OutputError

            raise OutputError(f"{args.output}: is one of the files being imported; give the record another name")
    if args.output.exists() and not args.overwrite:  # a lab's record is not replaced by a second import unasked
        from .errors import OutputError

        raise OutputError(f"{args.output}: a file of that name exists; give another name, or --overwrite to replace it")
    from .acquisition import describe, import_scope_files

    outcome = import_scope_files(args.files, args.setup, args.output, check=not args.no_check)
    print("\n".join(describe(outcome)))
    return 0

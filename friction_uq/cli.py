"""The ``friction-uq`` command. Thin: parse, call one library function, print or write.

Every error the package raises on purpose (:class:`~friction_uq.errors.FrictionUQError`), every
operating-system error (no space, read-only, permission, a directory in the way) and every usage
error is printed as one sentence on stderr with exit status 2, without a traceback. Seeds, output
names and formats, and the type of every input file are checked before any work.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Sequence
from pathlib import Path

from . import __version__, import_command, priors_command
from .errors import FrictionUQError, OutputError, os_error_text
from .cli_arguments import (FIGURE_SUFFIXES, RECORD_SUFFIXES, config_file, nu_argument, output_file, path_argument,
                            seed_argument, striker_velocity_argument, window_argument, workers_argument)

EXIT_BAD_INPUT = 2
#: Exit status of an unexpected error (a bug), said in one line; FRICTION_UQ_TRACEBACK=1 shows its traceback.
EXIT_INTERNAL = 3
#: Environment variables that set BLAS's threads (OpenBLAS, as numpy's wheels ship it; MKL).
BLAS_THREADS = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


class _Parser(argparse.ArgumentParser):
    """argparse with usage errors as one line (``friction-uq: error: ...``), exit status 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(EXIT_BAD_INPUT, f"friction-uq: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(
        prog="friction-uq",
        description="Friction coefficient with honest uncertainty from confined friction tests on "
        "split Hopkinson bars (Durand et al. 2016).",
    )
    p.add_argument("--version", action="version", version=f"friction-uq {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", required=True)

    s = sub.add_parser("inspect", help="summarise a test record: ids, channels, apparatus, arrivals, noise",
                       description="Print a readable summary of a test record.")
    s.add_argument("file", type=path_argument, help="test record (test.h5)")

    s = sub.add_parser("analyze", help="the lab's deterministic analysis (eq. 17) for a given nu",
                       description="Deterministic identification of f from eq. 17 over the stationary window.")
    s.add_argument("file", type=path_argument, help="test record (test.h5)")
    s.add_argument("--nu", type=nu_argument, default=0.4, help="sample Poisson ratio (default 0.4)")
    s.add_argument("--window", type=window_argument, help="stationary window T0:T1 on the record's time base, in seconds or with a unit: 400us:600us, "
                       "0.4ms:0.6ms, 4e-4:6e-4 (default: automatic); write --window=T0:T1 when T0 is negative")
    s.add_argument("--dispersion", action="store_true", help="apply the Pochhammer-Chree correction")
    s.add_argument("--json", action="store_true", help="print one JSON object (SI units) instead of a table")

    s = sub.add_parser("design", help="draw the paper's figure 4 (p_mean and V against f) for a record",
                       description="Design relations eq. 15-16 for a record's apparatus and striker speed.")
    s.add_argument("file", type=path_argument, help="test record (test.h5)")
    s.add_argument("-o", "--output", type=path_argument, required=True, help="figure file (PDF or PNG)")
    s.add_argument("--nu", type=nu_argument, default=0.4, help="sample Poisson ratio (default 0.4)")
    s.add_argument("--striker-velocity", type=striker_velocity_argument,
                   help="m/s (default: the record's, else from the incident wave)")

    s = sub.add_parser("simulate", help="simulate a whole test into a record",
                       description="Simulate a confined friction test from a TOML configuration.")
    s.add_argument("config", type=path_argument, help="simulation configuration (TOML)")
    s.add_argument("-o", "--output", type=path_argument, help="record to write (test.h5); required unless --compare")
    s.add_argument("--seed", type=seed_argument, help="noise seed, 0 <= seed < 2**64 (default: the config's)")
    s.add_argument("--compare", type=path_argument, metavar="PDF",
                   help="also run the 1-D and the axisymmetric model on the configuration and draw them side by side "
                        "per phase into this PDF (table on stdout)")

    s = sub.add_parser("compare", help="compare tests across campaigns from run results (JSON)",
                       description="Table and figure of kappa and f against sliding velocity and wall "
                       "pressure for several tests, with weighted trend fits.")
    s.add_argument("results", type=path_argument, nargs="+", help="<campaign>_<test_id>.json files written by run")
    s.add_argument("-o", "--output", type=path_argument, help="figure file (PDF or PNG)")

    _add_campaign_parser(sub)
    import_command.add_parser(sub)
    priors_command.add_parser(sub)

    run_help = ("run", "joint posterior of f and nu, uncertainty propagation, PDF report",
                "The main job: sample the posterior of f and nu for one record and write "
                "<campaign>_<test_id>.nc, .json and .pdf.")
    diagnose_help = ("diagnose", "run, then name the cause of a misfit: each mechanism fitted and compared",
                     "The main job plus the mechanism catalogue: each extension of the baseline fitted to the whole "
                     "record, ranked by expected log predictive density; the cause named when the evidence is "
                     "decisive. Same outputs as run, with a 'discrepancy' block.")
    for name, short, long in (run_help, diagnose_help):  # one job, one set of options
        s = sub.add_parser(name, help=short, description=long)
        s.add_argument("file", type=path_argument, help="test record (test.h5)")
        s.add_argument("--priors", type=path_argument, help="prior file (TOML; default: the package's <material>.toml)")
        s.add_argument("--out", type=path_argument, default=Path("reports"),
                       help="output directory (default reports/)")
        s.add_argument("--seed", type=seed_argument, default=20161, help="random seed, 0 <= seed < 2**64 (default 20161)")
        s.add_argument("--window", type=window_argument, help="stationary window T0:T1 on the record's time base, in seconds or with a unit: 400us:600us, "
                       "0.4ms:0.6ms, 4e-4:6e-4 (default: automatic); write --window=T0:T1 when T0 is negative")
        s.add_argument("--dispersion", action="store_true", help="apply the Pochhammer-Chree correction")
        s.add_argument("--no-hoop", action="store_true", help="leave the tube hoop gauge out of the likelihood")
        s.add_argument("--no-pdf", action="store_true", help="skip the PDF report")
        s.add_argument("--quiet", action="store_true", help="no progress on stderr")
        if name == "run":
            s.add_argument("--diagnose", action="store_true",
                           help="also fit each mechanism of the catalogue and name the cause of a misfit")
    return p


def main(argv: Sequence[str] | None = None) -> int:
    try:  # an argument type's unexpected error too is one line, not a traceback (SystemExit passes through)
        args = build_parser().parse_args(argv)
        out = getattr(args, "out", None)
        if args.command in ("run", "diagnose", "campaign") and out is not None:
            from ._logfile import libraries_to_log

            with libraries_to_log(out):
                return _dispatch(args)
        return _dispatch(args)
    except FrictionUQError as exc:
        return _error(str(exc))
    except OSError as exc:  # a system error no writer turned into a sentence: still one line
        where = exc.filename or ""
        return _error(f"{where}{': ' if where else ''}{os_error_text(exc)}")
    except (RecursionError, UnicodeDecodeError) as exc:
        return _error(f"an input file cannot be read ({type(exc).__name__}: {exc})")
    except MemoryError:
        return _error("out of memory; an input is larger than this machine can analyse (docs/limits.md)")
    except KeyboardInterrupt:
        print("friction-uq: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # noqa: BLE001 - a bug: one line naming where, the traceback on request
        if os.environ.get("FRICTION_UQ_TRACEBACK"):
            raise
        import traceback

        last = traceback.extract_tb(exc.__traceback__)[-1]
        _error(f"internal error ({type(exc).__name__}: {exc}; {Path(last.filename).name} line {last.lineno}); this "
               "is a bug: please report it with the input (FRICTION_UQ_TRACEBACK=1 shows the traceback)")
        return EXIT_INTERNAL


def _error(message: str) -> int:
    """Print ``message`` as one line (control characters from a file's text escaped) and return exit status 2."""
    from .plausible import escaped

    print(f"friction-uq: error: {escaped(message)}", file=sys.stderr)
    return EXIT_BAD_INPUT


def _inspect(args: argparse.Namespace) -> int:
    from .record import read_record
    from .summary import inspect_text

    print(inspect_text(read_record(args.file)))
    return 0


def _analyze(args: argparse.Namespace) -> int:
    from .analysis import identify, prepare
    from .record import read_record
    from .summary import identification_table

    rec = read_record(args.file)
    prep = prepare(rec, window=args.window, dispersion=args.dispersion)
    ident = identify(prep, nu=args.nu)
    notes = prep.gauge_notes + prep.flat_runs + prep.speed_notes
    if args.json:
        out = ident.to_json()
        out["test_id"], out["campaign"] = rec.test_id, rec.campaign
        out["gauge_notes"] = list(notes)
        out["window_automatic"], out["dispersion_correction"] = prep.window.automatic, prep.forces.dispersion
        print(json.dumps(out))
    else:
        print(identification_table(rec, ident) + "".join(f"\ngauge note: {n}" for n in notes))
    return 0


def _design(args: argparse.Namespace) -> int:
    output_file(args.output, FIGURE_SUFFIXES, "figure")
    from .record import read_record
    from .report.design_figure import design_figure

    rec = read_record(args.file)
    path = design_figure(rec, args.output, nu=args.nu, striker_velocity=args.striker_velocity)
    print(f"wrote {path}")
    return 0


def _simulate(args: argparse.Namespace) -> int:
    if args.output is None and args.compare is None:
        raise OutputError("simulate: give -o RECORD.h5, --compare PAGES.pdf, or both")
    if args.output is not None:
        output_file(args.output, RECORD_SUFFIXES, "record")
        if args.config.exists() and args.output.exists() and args.output.resolve() == args.config.resolve():
            raise OutputError(f"{args.output}: is the configuration being read; write the record to another file")
    if args.compare is not None:
        output_file(args.compare, (".pdf",), "comparison")
    config_file(args.config)
    from .simulate import load_config, simulate_to_file

    cfg = load_config(args.config)
    if args.output is not None:
        print(f"wrote {simulate_to_file(cfg, args.output, seed=args.seed)}")
    if args.compare is not None:
        from .report.axisymmetric_pages import compare_to_pdf

        print(compare_to_pdf(cfg, args.compare))
    return 0


def _compare(args: argparse.Namespace) -> int:
    if args.output:
        output_file(args.output, FIGURE_SUFFIXES, "figure")
    from .campaigns import compare, comparison_table

    comp = compare(args.results)
    print(comparison_table(comp))
    if args.output:
        from .report.campaign_figure import campaign_figure

        print(f"wrote {campaign_figure(comp, args.output)}")
    return 0


def _run(args: argparse.Namespace) -> int:
    """``run`` and ``diagnose``: a bad record or prior file is refused before the analysis' libraries load."""
    from .record import read_record

    rec = read_record(args.file, hoop=not args.no_hoop)
    from .prior_loader import load_priors, record_prior_path

    load_priors(args.priors or record_prior_path(rec.path, rec.apparatus.sample.material))
    from .record_run import run_file

    run_file(
        args.file, priors_path=args.priors, out_dir=args.out, seed=args.seed, window=args.window,
        dispersion=args.dispersion, hoop=not args.no_hoop,
        pdf=not args.no_pdf, progress=not args.quiet,
        diagnose=args.command == "diagnose" or args.diagnose,
    )
    return 0


def _dispatch(args: argparse.Namespace) -> int:
    """The subcommand's function (argparse restricts the choices)."""
    commands = {"inspect": _inspect, "analyze": _analyze, "design": _design, "simulate": _simulate,
                "compare": _compare, "campaign": _campaign, "run": _run, "diagnose": _run,
                "import": lambda a: import_command.run(a, build_parser(), output_file),
                "priors": priors_command.run}
    return commands[args.command](args)


def _add_campaign_parser(sub) -> None:
    s = sub.add_parser("campaign", help="many records in parallel (Dask), pooled, the friction law across set-ups",
                       description="Analyse records on Dask (a local cluster or a scheduler), skip those up to "
                       "date, pool f and kappa from the stored draws, compare friction laws by leave-one-test-out "
                       "ELPD and flag set-ups off the shared law. Writes DIR/campaign.json, .nc, .pdf and "
                       "DIR/records/. Exit 0 when every record was analysed, 1 when some were refused (the "
                       "summary says why), 2 on bad input.")
    s.add_argument("records", type=path_argument, nargs="*", help="record files (test.h5) or folders of them")
    s.add_argument("--out", type=path_argument, required=True, help="campaign output directory")
    s.add_argument("--workers", type=workers_argument, default=2, help="local worker processes (default 2)")
    s.add_argument("--scheduler", help="address of a running Dask scheduler (e.g. tcp://10.0.0.5:8786) "
                   "instead of a local cluster")
    s.add_argument("--seed", type=seed_argument, default=20161, help="campaign seed, 0 <= seed < 2**64 (default 20161)")
    s.add_argument("--priors", type=path_argument, help="prior file for every record (default: priors/<material>.toml)")
    s.add_argument("--dispersion", action="store_true", help="apply the Pochhammer-Chree correction")
    s.add_argument("--no-hoop", action="store_true", help="leave the tube hoop gauge out of the likelihood")
    s.add_argument("--no-pdf", action="store_true", help="no per-record PDF reports (campaign.pdf is always written)")
    s.add_argument("--diagnose", action="store_true",
                   help="diagnose each record (run --diagnose) and tally the causes named per set-up")
    s.add_argument("--quiet", action="store_true", help="no progress bar on stderr")


def _campaign(args: argparse.Namespace) -> int:
    from .campaigns import run_campaign, summary_text

    outcome = run_campaign(args.records, args.out, workers=args.workers, scheduler=args.scheduler, seed=args.seed,
                           priors_path=args.priors, dispersion=args.dispersion, hoop=not args.no_hoop,
                           pdf=not args.no_pdf, progress=not args.quiet, diagnose=args.diagnose)
    print(summary_text(outcome.doc))
    for path in outcome.outputs.values():
        print(f"wrote {path}")
    return 1 if outcome.doc["counts"]["failed"] else 0


def console() -> None:  # pragma: no cover - the installed command; tests call main
    """The installed ``friction-uq`` command: :func:`main`, then out without the interpreter's teardown.

    BLAS runs one thread per process unless the environment says otherwise: a run keeps both cores busy
    with its own two processes (and a campaign with one worker process per core), and BLAS threads on top
    of them oversubscribe the cores (the whole-record check beside the sampling took 2.2 s instead of 1.4).
    Everything a command opens is closed by then (outputs written and renamed, background processes and
    Dask clusters stopped); what is left is clearing the modules of scipy, numba, arviz and dask, which
    costs half a second on every run and releases nothing the operating system would not."""
    for var in BLAS_THREADS:  # read once, when numpy loads: before any import of it
        os.environ.setdefault(var, "1")
    code = main()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


if __name__ == "__main__":  # pragma: no cover
    console()

"""The ``intervalkin`` command: a thin layer over the library.

Exit status: 0 on success; 2 on bad input, with one line on stderr and no
traceback; 1 on an internal failure (one line too).  What counts as bad input:

* a command line argparse cannot read (unknown command or option, a missing or
  extra argument, a non-integer depth): argparse's usage line, then one error
  line;
* a value the library refuses (geometry file, joint vector, pose, depth range,
  output folder, certificate folder): one error line, raised as
  :class:`~intervalkin.core.errors.IntervalkinError` before any work where it
  can be checked then;
* a file-system failure while reading or writing (``OSError``): one line
  naming the file;
* ``verify`` on certificates that do not all re-prove (or on an output
  folder whose workspace paving holds a label that does not re-prove): the
  verdicts on stdout, one error line on stderr; a malformed
  ``pavings/workspace.npz`` is bad input (one line).

Each sub-command has one ``_cmd_*`` function that parses nothing itself.
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
from typing import Callable, NoReturn, Sequence

from intervalkin.app.commands import run_analyze, run_joint, run_pave, run_trajectory
from intervalkin.app.label import run_label, run_locate
from intervalkin.app.options import (BARRIER_FACES, CHAIN_DEPTHS, JOINT_DEPTHS, PAVE_DEPTHS, depth_help,
                                     geometry_from_option)
from intervalkin.app.sweep_command import run_sweep
from intervalkin.app.table1 import format_table1, table1_comparison
from intervalkin.app.text import format_dkp_table
from intervalkin.certify.separation_claims import PATTERN_BUDGET
from intervalkin.core.errors import IntervalkinError
from intervalkin.core.version import __version__
from intervalkin.pipeline import DEFAULT_DEPTH, verify
from intervalkin.solve.dkp import parse_joint_vector, solve

__all__ = ['build_parser', 'main']

#: Default depth of the commands that run the chain for one question (label, locate, trajectory).
QUESTION_DEPTH = 7


class _Parser(argparse.ArgumentParser):
    """argparse whose errors are the usage on one line, one error line, and exit status 2."""

    def error(self, message: str) -> NoReturn:  # type: ignore[override]
        # the usage on ONE line whatever the terminal width, so that a script sees two lines
        formatter = argparse.HelpFormatter(prog=self.prog, width=1 << 16)
        formatter.add_usage(self.usage, self._actions, self._mutually_exclusive_groups)
        usage = " ".join(formatter.format_help().split())
        sys.stderr.write(f"{usage}\nintervalkin: error: {message}\n")
        sys.exit(2)


def _print_json(obj) -> None:
    sys.stdout.write(json.dumps(obj, indent=None) + "\n")


# --------------------------------------------------------------------------------------
# Sub-commands
# --------------------------------------------------------------------------------------
def _cmd_dkp(args: argparse.Namespace) -> int:
    geometry = geometry_from_option(args.geometry)
    rho = parse_joint_vector(geometry, [args.r1, args.r2, args.r3])
    result = solve(geometry, rho)
    if args.json:
        _print_json(result.to_json())
    else:
        sys.stdout.write(format_dkp_table(result) + "\n")
    return 0


def _cmd_table1(args: argparse.Namespace) -> int:
    comparison = table1_comparison()
    if args.json:
        _print_json(comparison.to_json())
    else:
        sys.stdout.write(format_table1(comparison) + "\n")
    return 0


def _cmd_pave(args: argparse.Namespace) -> int:
    return run_pave(args.geometry, args.depth, args.out, force=args.force, quiet=args.quiet)


def _cmd_joint(args: argparse.Namespace) -> int:
    return run_joint(args.geometry, args.depth, args.out, force=args.force, quiet=args.quiet)


def _cmd_analyze(args: argparse.Namespace) -> int:
    return run_analyze(args.geometry, args.depth, args.out, force=args.force, quiet=args.quiet, as_json=args.json,
                       refine_to=args.refine_to, barrier_faces=args.barrier_faces, retract=args.retraction)


def _cmd_paper(args: argparse.Namespace) -> int:
    return run_analyze(None, args.depth, args.out, force=args.force, quiet=args.quiet, as_json=args.json, paper=True,
                       refine_to=args.refine_to, barrier_faces=args.barrier_faces, retract=args.retraction)


def _cmd_label(args: argparse.Namespace) -> int:
    return run_label(args.geometry, [args.x, args.y, args.phi], args.depth, source=args.source, as_json=args.json)


def _cmd_locate(args: argparse.Namespace) -> int:
    return run_locate(args.geometry, [args.r1, args.r2, args.r3], args.depth, as_json=args.json)


def _cmd_trajectory(args: argparse.Namespace) -> int:
    return run_trajectory(args.geometry, args.rho, args.i_from, args.i_to, depth=args.depth, out=args.out,
                          as_json=args.json, quiet=args.quiet, force=args.force)


def _cmd_sweep(args: argparse.Namespace) -> int:
    return run_sweep(args.file, args.out, scheduler=args.scheduler, workers=args.workers, force=args.force,
                     quiet=args.quiet, dashboard=not args.no_dashboard)


def _cmd_verify(args: argparse.Namespace) -> int:
    results = verify(args.dir).results  # DIR: the certificate folder, or an output folder holding one
    for r in results:
        sys.stdout.write(r.line() + "\n")
    failed = [r for r in results if not r.verified]
    if failed:
        first = failed[0]
        sys.stderr.write(f"intervalkin: error: {len(results) - len(failed)} of {len(results)} claims verified; "
                         f"{len(failed)} FAILED, the first {first.file}#{first.claim} ({first.kind})\n")
        return 2
    sys.stderr.write(f"{len(results)} of {len(results)} claims verified\n")
    return 0


_COMMANDS: dict[str, Callable[[argparse.Namespace], int]] = {
    "joint": _cmd_joint,
    "analyze": _cmd_analyze,
    "paper": _cmd_paper,
    "label": _cmd_label,
    "locate": _cmd_locate,
    "dkp": _cmd_dkp,
    "table1": _cmd_table1,
    "pave": _cmd_pave,
    "trajectory": _cmd_trajectory,
    "verify": _cmd_verify,
    "sweep": _cmd_sweep,
}


def _three(p: argparse.ArgumentParser, names: Sequence[str], helps: Sequence[str]) -> None:
    """Three positional numbers, one argument each: usage and errors then name the one missing."""
    for name, text in zip(names, helps):
        p.add_argument(name.lower(), metavar=name, help=text)


def _out_options(p: argparse.ArgumentParser, default: str | None, what: str = "output folder") -> None:
    """--out, --force and --quiet, the same on every command that writes a folder."""
    p.add_argument("--out", default=default, metavar="DIR",
                   help=f"{what} (default {default})" if default else what)
    p.add_argument("--force", action="store_true",
                   help="write into a non-empty folder: an earlier output's files are replaced, others are kept")
    p.add_argument("--quiet", action="store_true", help="no progress and no table (progress shows only on a terminal)")


def build_parser() -> argparse.ArgumentParser:
    """The parser of every sub-command (also used by the tests to list them)."""
    parser = _Parser(
        prog="intervalkin",
        description="Certified definition sets of the planar 3-RPR parallel manipulator (Wenger & Chablat 1997).",
        epilog="Exit status: 0 success, 2 bad input (one line on stderr), 1 internal failure.",
    )
    parser.add_argument("--version", action="version", version=f"intervalkin {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser, metavar="COMMAND")
    geometry_help = "geometry TOML file (default: the paper's manipulator)"
    chain_depth = depth_help("depth of the regions paving", CHAIN_DEPTHS, QUESTION_DEPTH)

    p = sub.add_parser("dkp", help="certified direct kinematics: every assembly mode of a joint vector")
    _three(p, ("R1", "R2", "R3"), [f"length of leg {i} (exact decimal)" for i in (1, 2, 3)])
    p.add_argument("--geometry", metavar="FILE", help=geometry_help)
    p.add_argument("--json", action="store_true", help="print one JSON object")

    p = sub.add_parser("table1", help="the paper's Table 1 beside the certified solutions")
    p.add_argument("--json", action="store_true", help="print one JSON object")

    p = sub.add_parser("pave", help="certified pavings of the workspace, singular surface and aspects")
    p.add_argument("--geometry", metavar="FILE", help=geometry_help)
    p.add_argument("--depth", type=int, default=6, metavar="N",
                   help=depth_help("workspace octree depth", PAVE_DEPTHS, 6) + "; memory is checked first")
    _out_options(p, "intervalkin-pave")

    p = sub.add_parser("joint", help="joint space: enclosure of g(S) and cells of certified solution count")
    p.add_argument("--geometry", metavar="FILE", help=geometry_help)
    p.add_argument("--depth", type=int, default=6, metavar="N",
                   help=depth_help("2**N voxels per joint-space axis", JOINT_DEPTHS, 6))
    _out_options(p, "intervalkin-joint")

    for name, text in (("analyze", "the whole chain for any geometry: aspects, basic regions, uniqueness domains"),
                       ("paper", "regenerate the paper's results on its manipulator, with a report")):
        p = sub.add_parser(name, help=text)
        if name == "analyze":
            p.add_argument("--geometry", metavar="FILE", help=geometry_help)
        p.add_argument("--depth", type=int, default=DEFAULT_DEPTH, metavar="N",
                       help=depth_help("workspace octree depth", CHAIN_DEPTHS, DEFAULT_DEPTH))
        _out_options(p, "intervalkin-paper" if name == "paper" else "intervalkin-analysis")
        p.add_argument("--json", action="store_true", help="print summary.json on stdout")
        p.add_argument("--refine-to", type=int, metavar="M", default=None,
                       help=f"deepen the regions paving, up to depth M in N..{CHAIN_DEPTHS[1]}, until every sheet of "
                            "every counted cell holds certified boxes (Proposition 1 seen in full)")
        p.add_argument("--barrier-faces", type=int, metavar="F", default=None,
                       help=f"faces the pattern barriers may relate in all, {BARRIER_FACES[0]}..{BARRIER_FACES[1]} "
                            f"(default {PATTERN_BUDGET}); about 5 ms a face: 400000 (about 12 minutes more) also "
                            "certifies a 4-solution cell on limits [10.5, 32]")
        p.add_argument("--retraction", action="store_true",
                       help="also retract the joint paving's open layer towards its cells (summary.json: "
                            "basic_regions.undecided.retraction), the local step of an upper bound that closes on no "
                            "geometry yet; about two minutes more at the default depth")

    p = sub.add_parser("label", help="certified aspect, basic region and uniqueness domain of a pose")
    _three(p, ("X", "Y", "PHI"), ("x of the platform point B1", "y of B1",
                                  "angle of B1B2 in radians (any value: reduced modulo 2 pi)"))
    p.add_argument("--geometry", metavar="FILE", help=geometry_help)
    p.add_argument("--depth", type=int, default=QUESTION_DEPTH, metavar="N", help=chain_depth)
    p.add_argument("--from", dest="source", metavar="DIR",
                   help="read the pavings of an earlier analyze/paper output instead of running the analysis")
    p.add_argument("--json", action="store_true", help="print one JSON object")

    p = sub.add_parser("locate", help="the joint cell of a joint vector and its certified number of solutions")
    _three(p, ("R1", "R2", "R3"), [f"length of leg {i} (exact decimal)" for i in (1, 2, 3)])
    p.add_argument("--geometry", metavar="FILE", help=geometry_help)
    p.add_argument("--depth", type=int, default=QUESTION_DEPTH, metavar="N", help=chain_depth)
    p.add_argument("--json", action="store_true", help="print one JSON object")

    p = sub.add_parser("trajectory", help="certified non-singular motion between two solutions of one aspect")
    p.add_argument("--rho", nargs=3, required=True, metavar=("R1", "R2", "R3"), help="leg lengths (exact decimals)")
    p.add_argument("--from", dest="i_from", type=int, required=True, metavar="I", help="start solution (as `dkp` numbers it)")
    p.add_argument("--to", dest="i_to", type=int, required=True, metavar="J", help="goal solution")
    p.add_argument("--geometry", metavar="FILE", help=geometry_help)
    p.add_argument("--depth", type=int, default=QUESTION_DEPTH, metavar="N", help=chain_depth)
    _out_options(p, None, "write trajectory.json and the figures into this folder")
    p.add_argument("--json", action="store_true", help="print one JSON object")

    p = sub.add_parser("sweep", help="analyse a family of designs (a sweep file) on Dask: table, plots, best designs")
    p.add_argument("file", metavar="FILE", help="sweep TOML file: base geometry, parameters to vary, analysis settings")
    _out_options(p, "intervalkin-sweep",
                 "output folder; an earlier sweep's folder is resumed (its cached designs are reused)")
    p.add_argument("--scheduler", metavar="ADDRESS", default=None,
                   help="address of a running Dask scheduler (default: a LocalCluster on this machine)")
    p.add_argument("--workers", type=int, metavar="N", default=None,
                   help="worker processes of the LocalCluster (default: one per core)")
    p.add_argument("--no-dashboard", action="store_true", help="do not serve the Dask dashboard")

    p = sub.add_parser("verify", help="re-check a certificate folder with the independent checker (arb), and "
                                      "every box label of the workspace paving beside it")
    p.add_argument("dir", metavar="DIR",
                   help="an output folder holding certificates/ (its summary.json is compared too, and every "
                        "W and det A label of pavings/workspace.npz is re-proved), "
                        "or a folder holding index.json and the claim files")
    for p in sub.choices.values():
        p.set_defaults(subparser=p)  # so that extra arguments are refused with the sub-command's usage
    return parser


def _parse(parser: argparse.ArgumentParser, argv: Sequence[str] | None) -> argparse.Namespace:
    """Parse ``argv``; arguments left over are refused by the sub-command's parser (its usage, not the top one)."""
    args, extra = parser.parse_known_args(argv)
    if extra:
        args.subparser.error(f"unrecognized arguments: {' '.join(extra)}")
    return args


def _terminate(signum, frame):  # pragma: no cover - exercised through a subprocess test
    # SIGTERM becomes an exception, so atomic writers remove their temporary files
    raise SystemExit(128 + signum)


def main(argv: Sequence[str] | None = None) -> int:
    args = _parse(build_parser(), argv)
    try:
        signal.signal(signal.SIGTERM, _terminate)
    except ValueError:  # not the main thread (e.g. called from a test runner thread)
        pass
    try:
        return _COMMANDS[args.command](args)
    except IntervalkinError as exc:
        sys.stderr.write(f"intervalkin: error: {exc}\n")
        return 2
    except BrokenPipeError:  # stdout closed by a pager or `head`: nothing more to say
        return 0
    except OSError as exc:  # the file system refused (permissions, a full disk): not a bug of the program
        where = f"{exc.filename}: " if exc.filename else ""
        sys.stderr.write(f"intervalkin: error: {where}{exc.strerror or exc}\n")
        return 2
    except KeyboardInterrupt:
        sys.stderr.write("intervalkin: interrupted\n")
        return 130
    except Exception as exc:  # an internal failure: one line, status 1
        sys.stderr.write(f"intervalkin: internal error: {type(exc).__name__}: {exc}\n")
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

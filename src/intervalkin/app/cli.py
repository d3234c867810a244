"""The ``intervalkin`` command: a thin layer over the library.

Exit status: 0 on success, 2 on bad input (one line on stderr, no traceback),
1 on an internal failure.  Each sub-command has one ``_cmd_*`` function that
parses nothing itself: argparse validates the shapes, the library validates the
values and raises :class:`~intervalkin.core.errors.IntervalkinError` subclasses.
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
from typing import Callable, Sequence

from intervalkin.app.commands import run_analyze, run_joint, run_pave, run_trajectory
from intervalkin.app.label import run_label
from intervalkin.app.options import geometry_from_option
from intervalkin.app.table1 import format_table1, table1_comparison
from intervalkin.app.text import format_dkp_table
from intervalkin.core.errors import IntervalkinError
from intervalkin.pipeline import DEFAULT_DEPTH, verify
from intervalkin.solve.dkp import parse_joint_vector, solve

__all__ = ['build_parser', 'main']


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit status 2."""

    def error(self, message: str):  # type: ignore[override]
        sys.stderr.write(f"intervalkin: error: {message}\n")
        sys.exit(2)


def _print_json(obj) -> None:
    sys.stdout.write(json.dumps(obj, indent=None) + "\n")


# --------------------------------------------------------------------------------------
# Sub-commands
# --------------------------------------------------------------------------------------
def _cmd_dkp(args: argparse.Namespace) -> int:
    geometry = geometry_from_option(args.geometry)
    rho = parse_joint_vector(geometry, args.rho)
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
    return run_pave(geometry_path=args.geometry, depth=args.depth, out=args.out)


def _cmd_joint(args: argparse.Namespace) -> int:
    return run_joint(args.geometry, args.depth, args.out, force=args.force, quiet=args.quiet)


def _cmd_analyze(args: argparse.Namespace) -> int:
    return run_analyze(args.geometry, args.depth, args.out, force=args.force, quiet=args.quiet, as_json=args.json,
                       refine_to=args.refine_to)


def _cmd_paper(args: argparse.Namespace) -> int:
    return run_analyze(None, args.depth, args.out, force=args.force, quiet=args.quiet, as_json=args.json, paper=True,
                       refine_to=args.refine_to)


def _cmd_label(args: argparse.Namespace) -> int:
    return run_label(args.geometry, args.pose, args.depth, source=args.source, as_json=args.json)


def _cmd_trajectory(args: argparse.Namespace) -> int:
    return run_trajectory(args.geometry, args.rho, args.i_from, args.i_to, depth=args.depth, out=args.out,
                          as_json=args.json)


def _cmd_verify(args: argparse.Namespace) -> int:
    results = verify(args.dir).results  # DIR: the certificate folder, or an output folder holding one
    for r in results:
        sys.stdout.write(r.line() + "\n")
    failed = sum(1 for r in results if not r.verified)
    sys.stderr.write(f"{len(results) - failed} of {len(results)} claims verified\n")
    return 1 if failed else 0


_COMMANDS: dict[str, Callable[[argparse.Namespace], int]] = {
    "joint": _cmd_joint,
    "analyze": _cmd_analyze,
    "paper": _cmd_paper,
    "label": _cmd_label,
    "dkp": _cmd_dkp,
    "table1": _cmd_table1,
    "pave": _cmd_pave,
    "trajectory": _cmd_trajectory,
    "verify": _cmd_verify,
}


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="intervalkin",
        description="Certified definition sets of the planar 3-RPR parallel manipulator (Wenger & Chablat 1997).",
    )
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    p = sub.add_parser("dkp", help="certified direct kinematics: every assembly mode of a joint vector")
    # one metavar string: argparse (3.11) crashes on a tuple metavar of a positional in --help and in
    # its "arguments are required" message
    p.add_argument("rho", nargs=3, metavar="RHO", help="the three leg lengths R1 R2 R3 (exact decimals)")
    p.add_argument("--geometry", metavar="FILE", help="geometry TOML file (default: the paper's manipulator)")
    p.add_argument("--json", action="store_true", help="print one JSON object")

    p = sub.add_parser("table1", help="the paper's Table 1 beside the certified solutions")
    p.add_argument("--json", action="store_true", help="print one JSON object")

    p = sub.add_parser("pave", help="certified pavings of the workspace, singular surface and aspects")
    p.add_argument("--geometry", metavar="FILE")
    p.add_argument("--depth", type=int, default=6, metavar="N", help="octree depth (default 6)")
    p.add_argument("--out", default="intervalkin-pave", metavar="DIR", help="output folder")

    p = sub.add_parser("joint", help="joint space: enclosure of g(S) and cells of certified solution count")
    p.add_argument("--geometry", metavar="FILE")
    p.add_argument("--depth", type=int, default=6, metavar="N", help="2**N voxels per axis (default 6)")
    p.add_argument("--out", default="intervalkin-joint", metavar="DIR", help="output folder")
    p.add_argument("--force", action="store_true", help="write into a non-empty folder")
    p.add_argument("--quiet", action="store_true", help="no progress, no table")

    for name, text in (("analyze", "the whole chain for any geometry: aspects, basic regions, uniqueness domains"),
                       ("paper", "regenerate the paper's results on its manipulator, with a report")):
        p = sub.add_parser(name, help=text)
        if name == "analyze":
            p.add_argument("--geometry", metavar="FILE")
        p.add_argument("--depth", type=int, default=DEFAULT_DEPTH, metavar="N",
                       help=f"workspace octree depth (default {DEFAULT_DEPTH})")
        p.add_argument("--out", default="intervalkin-paper" if name == "paper" else "intervalkin-analysis",
                       metavar="DIR", help="output folder")
        p.add_argument("--force", action="store_true", help="write into a non-empty folder that is not an earlier output")
        p.add_argument("--quiet", action="store_true", help="no progress, no table")
        p.add_argument("--json", action="store_true", help="print summary.json on stdout")
        p.add_argument("--refine-to", type=int, metavar="M", default=None,
                       help="deepen the regions paving, up to depth M, until every sheet of every counted cell "
                            "holds certified boxes (Proposition 1 seen in full)")

    p = sub.add_parser("label", help="certified aspect, basic region and uniqueness domain of a pose")
    p.add_argument("pose", nargs=3, metavar="POSE", help="the pose X Y PHI: B1 = (X, Y), angle PHI in radians")
    p.add_argument("--geometry", metavar="FILE")
    p.add_argument("--depth", type=int, default=7, metavar="N", help="depth of the analysis (default 7)")
    p.add_argument("--from", dest="source", metavar="DIR", help="read the pavings of an earlier analyze/paper output")
    p.add_argument("--json", action="store_true")

    p = sub.add_parser("trajectory", help="certified non-singular motion between two solutions of one aspect")
    p.add_argument("--rho", nargs=3, required=True, metavar=("R1", "R2", "R3"), help="leg lengths (exact decimals)")
    p.add_argument("--from", dest="i_from", type=int, required=True, metavar="I", help="start solution (as `dkp` numbers it)")
    p.add_argument("--to", dest="i_to", type=int, required=True, metavar="J", help="goal solution")
    p.add_argument("--geometry", metavar="FILE")
    p.add_argument("--depth", type=int, default=7, metavar="N", help="workspace octree depth (default 7)")
    p.add_argument("--out", metavar="DIR", help="write trajectory.json and the figures here")
    p.add_argument("--json", action="store_true", help="print one JSON object")

    p = sub.add_parser("verify", help="re-check a certificate folder with the independent checker (arb only)")
    p.add_argument("dir", metavar="DIR",
                   help="folder holding index.json and the claim files, or an output folder holding certificates/")
    return parser


def _terminate(signum, frame):  # pragma: no cover - exercised through a subprocess test
    # SIGTERM becomes an exception, so atomic writers remove their temporary files
    raise SystemExit(128 + signum)


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        signal.signal(signal.SIGTERM, _terminate)
    except ValueError:  # not the main thread (e.g. called from a test runner thread)
        pass
    try:
        return _COMMANDS[args.command](args)
    except IntervalkinError as exc:
        sys.stderr.write(f"intervalkin: error: {exc}\n")
        return 2
    except KeyboardInterrupt:
        sys.stderr.write("intervalkin: interrupted\n")
        return 130
    except BrokenPipeError:
        return 0
    except Exception as exc:  # an internal failure: one line, status 1
        sys.stderr.write(f"intervalkin: internal error: {type(exc).__name__}: {exc}\n")
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

"""The command line contract: exit status 0 / 2 / 1, one line on stderr for bad input, never a traceback.

Bad input is tried on every sub-command that can receive it, in process through
``intervalkin.app.cli.main`` (fast), and through ``python3 -m intervalkin`` for the
cases the issue tracker reported as crashing with a traceback.  Every case here
is refused before any paving starts, so the whole file runs in a few seconds.
"""

from __future__ import annotations

import subprocess
import sys

import pytest

from intervalkin.app.cli import build_parser, main
from intervalkin.certify.writer import write_certificates
from intervalkin.core.geometry import default_geometry
from intervalkin.solve.dkp import parse_joint_vector, solve

TABLE1 = ["14.98", "15.38", "12.0"]
SUBCOMMANDS = ("dkp", "table1", "pave", "joint", "analyze", "paper", "label", "locate", "trajectory", "verify", "sweep")


def _run(argv) -> int:
    """main(argv) as the shell sees it: argparse's own errors leave through SystemExit."""
    try:
        return main(argv)
    except SystemExit as exc:  # argparse: --help (0) and usage errors (2)
        return exc.code


def _one_line_error(capsys, fragment: str | None = None) -> str:
    """Assert nothing on stdout and exactly one 'intervalkin: error: ...' line on stderr; return it."""
    out, err = capsys.readouterr()
    assert out == "", out
    assert "Traceback" not in err
    lines = err.splitlines()
    assert len(lines) == 1 and err.endswith("\n"), err
    assert lines[0].startswith("intervalkin: error: "), err
    if fragment is not None:
        assert fragment in lines[0], (fragment, lines[0])
    return lines[0]


def _usage_error(capsys, command: str | None, fragment: str) -> str:
    """Assert argparse's refusal: nothing on stdout; on stderr the usage on one line, then one error line."""
    out, err = capsys.readouterr()
    assert out == "", out
    assert "Traceback" not in err
    lines = err.splitlines()
    assert len(lines) == 2 and err.endswith("\n"), err
    assert lines[0].startswith("usage: intervalkin" + (f" {command} " if command else " ")), lines[0]
    assert lines[1].startswith("intervalkin: error: ") and fragment in lines[1], (fragment, lines[1])
    return lines[1]


def _cli(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "intervalkin", *args], capture_output=True, text=True,
                          timeout=timeout)


# --------------------------------------------------------------------------------------
# Geometry files that must be refused (one line naming the field, status 2)
# --------------------------------------------------------------------------------------
def _geometry(tmp_path, name: str, old: str, new: str):
    text = default_geometry().to_toml()
    assert old in text
    path = tmp_path / f"{name}.toml"
    path.write_text(text.replace(old, new))
    return str(path)


@pytest.fixture
def bad_geometries(tmp_path):
    """(file, fragment of the expected message) for a missing key, NaN limits, reversed limits, a non-TOML file."""
    binary = tmp_path / "binary.toml"
    binary.write_bytes(bytes(range(256)))
    return [
        (_geometry(tmp_path, "missing", "a2 = [15.91, 0]\n", ""), "base.a2"),
        (_geometry(tmp_path, "nan", "rho_max = 32", "rho_max = nan"), "finite"),
        (_geometry(tmp_path, "reversed", "rho_min = 10\nrho_max = 32", "rho_min = 32\nrho_max = 10"),
         "rho_min < rho_max"),
        (str(binary), "binary.toml"),
        (str(tmp_path / "absent.toml"), "not found"),
    ]


# argv after the sub-command, for each command that takes --geometry (cheap values elsewhere)
_WITH_GEOMETRY = {
    "dkp": ["dkp", *TABLE1],
    "pave": ["pave", "--depth", "3"],
    "joint": ["joint", "--depth", "3"],
    "analyze": ["analyze", "--depth", "3"],
    "label": ["label", "1", "2", "0.5", "--depth", "3"],
    "locate": ["locate", *TABLE1, "--depth", "3"],
    "trajectory": ["trajectory", "--rho", *TABLE1, "--from", "2", "--to", "3", "--depth", "3"],
}


@pytest.mark.parametrize("command", sorted(_WITH_GEOMETRY))
def test_bad_geometry_file_is_refused_by_every_command(command, bad_geometries, tmp_path, capsys):
    """Each command reads --geometry through the validating loader: status 2, one line, no output folder.

    Would catch: a command that catches GeometryError too broadly (status 1), prints a
    traceback, or starts writing its folder before the geometry is read.
    """
    for path, fragment in bad_geometries:
        out = tmp_path / f"out-{command}"
        argv = _WITH_GEOMETRY[command] + ["--geometry", path]
        if command in ("pave", "joint", "analyze", "trajectory"):
            argv += ["--out", str(out)]
        assert _run(argv) == 2, (argv, capsys.readouterr())
        _one_line_error(capsys, fragment)
        assert not out.exists()


# --------------------------------------------------------------------------------------
# Values out of range: NaN, joint vectors outside the limits, depths
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("argv, fragment", [
    (["dkp", "15", "nan", "15"], "rho_2"),
    (["dkp", "15", "15", "inf"], "rho_3"),
    (["dkp", "9.99", "15", "15"], "rho_1"),
    (["dkp", "15", "32.001", "15", "--json"], "rho_2"),
    (["dkp", "15", "15", "-12"], "rho_3"),
    (["dkp", "15", "15", "1e999999"], "rho_3"),
    (["trajectory", "--rho", "15", "nan", "15", "--from", "1", "--to", "2"], "rho_2"),
    (["trajectory", "--rho", "40", "15", "15", "--from", "1", "--to", "2"], "rho_1"),
    (["trajectory", "--rho", *TABLE1, "--from", "2", "--to", "7"], "--to: expected a solution number"),
    (["trajectory", "--rho", *TABLE1, "--from", "0", "--to", "3"], "--from: expected a solution number"),
    (["trajectory", "--rho", *TABLE1, "--from", "3", "--to", "3"], "--from and --to both name solution 3"),
    (["trajectory", "--rho", *TABLE1, "--from", "1", "--to", "2"], "different aspects"),
    (["label", "1", "2", "nan", "--depth", "3"], "pose"),
    (["label", "1", "2", "x", "--from", "/nonexistent"], "pose"),
])
def test_bad_values_are_refused_in_one_line(argv, fragment, capsys):
    """NaN, infinities and joint vectors outside [rho_min, rho_max] are bad input (status 2), named in one line.

    Would catch: NaN slipping through a comparison (every comparison with NaN is
    False, so ``not lo <= v <= hi`` is the only safe form), an exception escaping as
    status 1, or a message without the offending coordinate.
    """
    assert _run(argv) == 2
    line = _one_line_error(capsys, fragment)
    if argv[0] == "dkp" and fragment.startswith("rho"):
        assert "[10, 32]" in line  # the allowed range is named


@pytest.mark.parametrize("argv, fragment", [
    (["pave", "--depth", "0"], "depth"),
    (["pave", "--depth", "99"], "depth"),
    (["joint", "--depth", "1"], "--depth"),
    (["joint", "--depth", "9"], "--depth"),
    # the chain's depths are checked by the library, whose messages name parameters, not flags
    (["analyze", "--depth", "2"], "depth: expected an integer in 3..9, got 2"),
    (["analyze", "--depth", "10"], "depth: expected an integer in 3..9, got 10"),
    (["paper", "--depth", "2"], "depth: expected an integer in 3..9, got 2"),
    (["paper", "--depth", "3", "--refine-to", "2"], "refine_to: expected an integer in 3..9, got 2"),
    (["label", "1", "2", "3", "--depth", "1"], "depth: expected an integer in 3..9, got 1"),
    (["trajectory", "--rho", *TABLE1, "--from", "2", "--to", "3", "--depth", "0"], "depth: expected"),
])
def test_depth_out_of_range_is_refused_before_any_work(argv, fragment, tmp_path, capsys):
    """Depths outside a command's range: status 2, one line naming the depth, and no output folder created.

    Would catch: a range check moved after prepare_output_dir (a stray empty folder),
    an off-by-one in a bound, or a ValueError from int() reaching the user.
    """
    out = tmp_path / "o"
    if argv[0] in ("pave", "joint", "analyze", "paper", "trajectory"):
        argv = argv + ["--out", str(out)]
    assert _run(argv) == 2
    _one_line_error(capsys, fragment)
    assert not out.exists()


@pytest.mark.parametrize("argv", [["pave", "--depth", "x"], ["analyze", "--depth", "4.5"], ["label", "1", "2", "3",
                                                                                          "--depth", "seven"]])
def test_depth_that_is_not_an_integer_is_a_usage_error(argv, tmp_path, capsys):
    """argparse refuses a depth that is not an integer: usage line, one error line naming --depth, status 2."""
    out = tmp_path / "o"
    assert _run(argv + (["--out", str(out)] if argv[0] != "label" else [])) == 2
    _usage_error(capsys, argv[0], "--depth")
    assert not out.exists()


# --------------------------------------------------------------------------------------
# --out pointing into a file
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("argv", [
    ["pave", "--depth", "3"],
    ["joint", "--depth", "3"],
    ["analyze", "--depth", "3"],
    ["paper", "--depth", "3"],
    ["trajectory", "--rho", *TABLE1, "--from", "2", "--to", "3", "--depth", "3"],
])
@pytest.mark.parametrize("where", ["the file", "below the file"])
def test_out_into_a_file_is_refused(argv, where, tmp_path, capsys):
    """--out naming an existing file, or a folder below one: status 2, one line naming --out; the file is kept.

    Would catch: a writer that replaces the user's file, or an OSError reported as an
    internal failure (status 1).
    """
    f = tmp_path / "afile"
    f.write_text("keep me")
    target = f if where == "the file" else f / "sub"
    assert _run(argv + ["--out", str(target)]) == 2
    _one_line_error(capsys, "--out")
    assert f.read_text() == "keep me"


def test_verify_refuses_what_is_not_a_certificate_folder(tmp_path, capsys):
    """verify on a missing path, a plain file, and an empty folder: status 2, one line each."""
    f = tmp_path / "afile"
    f.write_text("x")
    for target in (tmp_path / "nowhere", f, tmp_path):
        assert _run(["verify", str(target)]) == 2
        _one_line_error(capsys)


def test_verify_accepts_an_output_folder_or_its_certificates(tmp_path, capsys):
    """verify DIR and verify DIR/certificates check the same claims: status 0, the same lines.

    Would catch the command reading DIR alone again (status 2, "index.json missing" for an
    output folder), as the README's one-liner on an output folder needs it not to.
    """
    certificates = tmp_path / "run" / "certificates"
    g = default_geometry()
    write_certificates(certificates, g, dkp_results=[solve(g, parse_joint_vector(g, TABLE1))])
    outputs = []
    for target in (tmp_path / "run", certificates):
        assert _run(["verify", str(target)]) == 0
        out, err = capsys.readouterr()
        assert out and err.endswith("claims verified\n") and "error" not in err, err
        outputs.append(out)
    assert outputs[0] == outputs[1]


def test_label_of_a_pose_beyond_float_range_is_bad_input(tmp_path, capsys):
    """A pose coordinate such as 1e400 is read exactly but cannot be placed in a float paving: status 2."""
    import numpy as np

    (tmp_path / "pavings").mkdir()
    np.savez(tmp_path / "pavings" / "workspace.npz", lo=np.zeros((1, 3)), hi=np.ones((1, 3)),
             in_workspace=np.ones(1, np.int8), det_sign=np.ones(1, np.int8), basic_region=np.zeros(1, np.int32),
             uniqueness_domain=np.zeros(1, np.int32))
    assert _run(["label", "0.5", "0.5", "0.5", "--from", str(tmp_path), "--json"]) == 0  # the folder is readable
    capsys.readouterr()
    assert _run(["label", "1", "2", "1e400", "--from", str(tmp_path)]) == 2
    _one_line_error(capsys)


# --------------------------------------------------------------------------------------
# Unknown commands, missing arguments, --help
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("argv, fragment", [
    (["frobnicate"], "invalid choice"),
    ([], "required"),
    (["dkp"], "required: R1, R2, R3"),
    (["dkp", "14.98", "15.38"], "required: R3"),
    (["dkp", "14.98", "15.38", "12", "13"], "unrecognized"),
    (["label", "1", "2"], "required: PHI"),
    (["locate", "15"], "required: R2, R3"),
    (["trajectory", "--rho", "1", "--from", "1", "--to", "2"], "--rho"),
    (["table1", "--bogus"], "unrecognized"),
    (["sweep"], "required: FILE"),
    (["sweep", "s.toml", "--workers", "two"], "--workers"),
])
def test_usage_errors_show_the_usage_and_one_error_line(argv, fragment, capsys):
    """argparse's own errors: the command's usage on one line, one error line naming what is wrong, status 2.

    Would catch: the tuple metavar of a 3-value positional (``dkp 14.98 15.38`` and a bare
    ``dkp`` raised TypeError while argparse listed the missing arguments), a usage wrapped
    over several lines (a script reading stderr sees more than two lines), or an error line
    that does not say which argument is missing.
    """
    assert _run(argv) == 2
    command = argv[0] if argv and argv[0] in SUBCOMMANDS else None
    _usage_error(capsys, command, fragment)


def test_version(capsys):
    """``intervalkin --version`` prints the package version and exits 0."""
    from intervalkin.core.version import __version__

    assert _run(["--version"]) == 0
    assert capsys.readouterr().out == f"intervalkin {__version__}\n"


@pytest.mark.parametrize("command", SUBCOMMANDS)
def test_help_of_every_subcommand_exits_0(command, capsys):
    """``intervalkin CMD --help`` prints the usage of CMD on stdout and exits 0.

    Would catch: a tuple metavar on a positional (ValueError in the help formatter:
    ``dkp --help`` and ``label --help`` crashed), or a help string with a stray
    ``%`` (argparse formats help strings with %).
    """
    assert _run([command, "--help"]) == 0
    out, err = capsys.readouterr()
    assert out.startswith(f"usage: intervalkin {command}") and err == ""


def test_every_subcommand_is_listed_in_the_parser():
    """The sub-commands tested here are exactly the ones the parser offers (a new one needs its tests)."""
    sub = next(a for a in build_parser()._actions if a.dest == "command")
    assert set(sub.choices) == set(SUBCOMMANDS)


@pytest.mark.parametrize("args, status", [
    (["dkp", "--help"], 0),
    (["label", "--help"], 0),
    (["dkp", "14.98", "15.38"], 2),
    (["dkp"], 2),
    (["dkp", "15", "nan", "15"], 2),
    (["frobnicate"], 2),
])
def test_reported_crashes_through_the_real_entry_point(args, status):
    """``python3 -m intervalkin``: the four commands the tracker reported, and two bad inputs, never a traceback."""
    r = _cli(*args)
    assert r.returncode == status, r.stderr
    assert "Traceback" not in r.stderr
    if status == 0:
        assert r.stdout.startswith(f"usage: intervalkin {args[0]}") and r.stderr == ""
    else:
        lines = r.stderr.splitlines()
        assert r.stdout == "" and lines[-1].startswith("intervalkin: error: ")
        # a value refused by intervalkin: one line; a command line argparse cannot read: usage + one line
        assert len(lines) == (1 if "nan" in args else 2) and (len(lines) == 1 or lines[0].startswith("usage: "))


def test_internal_failure_is_status_1_in_one_line(monkeypatch, capsys):
    """An unexpected exception inside a command: status 1, one 'internal error' line naming the exception."""
    from intervalkin.app import cli

    def boom(args):
        raise RuntimeError("simulated failure")

    monkeypatch.setitem(cli._COMMANDS, "table1", boom)
    assert _run(["table1"]) == 1
    out, err = capsys.readouterr()
    assert out == "" and err == "intervalkin: internal error: RuntimeError: simulated failure\n"

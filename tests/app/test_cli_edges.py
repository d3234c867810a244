"""Every sub-command at its edges: --help, no argument, and each class of bad input.

The contract (README "Commands", issue 15): ``--help`` exits 0 with the usage;
a command line argparse cannot read gives the usage on one line, one error line
and status 2; every bad value gives ONE line on stderr and status 2; never a
traceback; and a refused command leaves no file behind, neither in the output
folder it was given nor in the working directory.  Every case here is refused
before any paving, so the file runs in seconds.
"""

from __future__ import annotations

import json
import os
import re
import shutil
from pathlib import Path

import pytest

from intervalkin.app.cli import QUESTION_DEPTH, build_parser, main
from intervalkin.app.options import CHAIN_DEPTHS, JOINT_DEPTHS, PAVE_DEPTHS, check_joint_depth
from intervalkin.certify.writer import write_certificates
from intervalkin.core.geometry import default_geometry
from intervalkin.paving.budget import check_depth
from intervalkin.pipeline import check_chain_depth
from intervalkin.solve.dkp import parse_joint_vector, solve

TABLE1 = ["14.98", "15.38", "12.0"]
COMMANDS = ("dkp", "table1", "pave", "joint", "analyze", "paper", "label", "locate", "trajectory", "verify", "sweep")
#: A cheap valid command line of each command that writes a folder (the folder flag added by the tests).
WRITERS = {
    "pave": ["pave", "--depth", "3"],
    "joint": ["joint", "--depth", "3"],
    "analyze": ["analyze", "--depth", "3"],
    "paper": ["paper", "--depth", "3"],
    "trajectory": ["trajectory", "--rho", *TABLE1, "--from", "2", "--to", "3", "--depth", "3"],
}
#: A cheap valid command line of each command that reads --geometry.
WITH_GEOMETRY = {
    "dkp": ["dkp", *TABLE1],
    "pave": WRITERS["pave"],
    "joint": WRITERS["joint"],
    "analyze": WRITERS["analyze"],
    "label": ["label", "1", "2", "0.5", "--depth", "3"],
    "locate": ["locate", *TABLE1, "--depth", "3"],
    "trajectory": WRITERS["trajectory"],
}
#: Each command that takes a joint vector, with the vector's place in its command line.
WITH_RHO = {
    "dkp": lambda r: ["dkp", *r],
    "locate": lambda r: ["locate", *r, "--depth", "3"],
    "trajectory": lambda r: ["trajectory", "--rho", *r, "--from", "1", "--to", "2", "--depth", "3"],
}
#: Each command that takes --depth, with its range.
DEPTHS = {"pave": PAVE_DEPTHS, "joint": JOINT_DEPTHS, "analyze": CHAIN_DEPTHS, "paper": CHAIN_DEPTHS,
          "label": CHAIN_DEPTHS, "locate": CHAIN_DEPTHS, "trajectory": CHAIN_DEPTHS}


def _files(root: Path) -> set[str]:
    return {str(p.relative_to(root)) for p in root.rglob("*")}


@pytest.fixture
def refused(tmp_path, monkeypatch, capsys):
    """Run a command in an empty working directory; assert status 2, the error lines, no traceback, no new file.

    Returns a function (argv, fragment, usage=False) -> the error line.
    """
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)

    def run(argv, fragment: str | None = None, usage: bool = False) -> str:
        before = _files(tmp_path)
        try:
            status = main(argv)
        except SystemExit as exc:  # argparse leaves through SystemExit
            status = exc.code
        out, err = capsys.readouterr()
        assert status == 2, (argv, status, err)
        assert "Traceback" not in err and out == "", (out, err)
        lines = err.splitlines()
        assert err.endswith("\n") and len(lines) == (2 if usage else 1), err
        if usage:
            assert lines[0].startswith("usage: intervalkin"), lines[0]
        assert lines[-1].startswith("intervalkin: error: "), lines[-1]
        if fragment is not None:
            assert fragment in lines[-1], (fragment, lines[-1])
        assert _files(tmp_path) == before, _files(tmp_path) ^ before  # no file left behind
        return lines[-1]

    return run


# --------------------------------------------------------------------------------------
# --help, no argument, --version
# --------------------------------------------------------------------------------------
def test_the_parser_offers_exactly_these_commands():
    sub = next(a for a in build_parser()._actions if a.dest == "command")
    assert set(sub.choices) == set(COMMANDS)


@pytest.mark.parametrize("command", COMMANDS)
def test_help_prints_the_usage_and_every_depth_range(command, capsys):
    """``CMD --help``: status 0, the usage on stdout, nothing on stderr; a --depth option shows its range."""
    with pytest.raises(SystemExit) as exc:
        main([command, "--help"])
    assert exc.value.code == 0
    out, err = capsys.readouterr()
    assert out.startswith(f"usage: intervalkin {command}") and err == ""
    if command in DEPTHS:
        lo, hi = DEPTHS[command]
        help_text = " ".join(out.split())
        assert re.search(rf"--depth N .{{0,120}}?\b{lo}\.\.{hi}\b", help_text), help_text


@pytest.mark.parametrize("command", ["dkp", "label", "locate", "trajectory", "verify", "sweep"])
def test_no_argument_is_a_usage_error(command, refused):
    refused([command], "required", usage=True)


@pytest.mark.parametrize("command", ["pave", "joint", "analyze", "paper"])
def test_no_argument_means_defaults_the_checks_accept(command):
    """Commands whose arguments are all optional run with defaults inside the ranges their --help shows."""
    args = build_parser().parse_args([command])
    lo, hi = DEPTHS[command]
    assert lo <= args.depth <= hi and args.force is False and args.out
    {"pave": check_depth, "joint": check_joint_depth}.get(command, check_chain_depth)(args.depth)


def test_label_and_locate_default_to_the_question_depth():
    for command in ("label", "locate"):
        args = build_parser().parse_args([command, "1", "2", "3"])
        assert args.depth == QUESTION_DEPTH and CHAIN_DEPTHS[0] <= QUESTION_DEPTH <= CHAIN_DEPTHS[1]


def test_version_and_the_top_level_help(capsys):
    from intervalkin.core.version import __version__

    for argv, start in ((["--version"], f"intervalkin {__version__}"), (["--help"], "usage: intervalkin")):
        with pytest.raises(SystemExit) as exc:
            main(argv)
        assert exc.value.code == 0 and capsys.readouterr().out.startswith(start)


# --------------------------------------------------------------------------------------
# Geometry files: malformed, empty, missing, degenerate
# --------------------------------------------------------------------------------------
def _geometry_cases(folder: Path) -> list[tuple[str, str]]:
    text = default_geometry().to_toml()
    cases = {
        "malformed.toml": ("name = [unclosed", "malformed TOML"),
        "empty.toml": ("", "missing"),
        "coincident_base.toml": (text.replace("a2 = [15.91, 0]", "a2 = [0, 0]"), "distinct"),
        "flat_platform.toml": (text.replace("b3b1 = 20.84", "b3b1 = 33.58"), "platform"),
        "limits.toml": (text.replace("rho_min = 10", "rho_min = -1"), "rho_min"),
    }
    out = []
    for name, (body, fragment) in cases.items():
        assert body != text or name in ("malformed.toml", "empty.toml")
        (folder / name).write_text(body)
        out.append((str(folder / name), fragment))
    out.append((str(folder / "absent.toml"), "not found"))
    return out


@pytest.mark.parametrize("command", sorted(WITH_GEOMETRY))
def test_bad_geometry_files(command, tmp_path, refused):
    geo = tmp_path / "geometries"
    geo.mkdir()
    for path, fragment in _geometry_cases(geo):
        argv = WITH_GEOMETRY[command] + ["--geometry", path]
        if command in WRITERS:
            argv += ["--out", str(tmp_path / "out")]
        refused(argv, fragment)


# --------------------------------------------------------------------------------------
# Joint vectors and poses
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("command", sorted(WITH_RHO))
@pytest.mark.parametrize("rho, fragment", [
    (["15", "nan", "15"], "rho_2"), (["15", "15", "inf"], "rho_3"), (["-15", "15", "15"], "rho_1"),
    (["15", "32.5", "15"], "rho_2"), (["9.99", "15", "15"], "rho_1"), (["15", "15", "abc"], "rho_3"),
])
def test_bad_joint_vectors(command, rho, fragment, refused):
    refused(WITH_RHO[command](rho), fragment)  # "-15" reads as a number: the parser has no such option


@pytest.mark.parametrize("pose, fragment", [
    (["1", "2", "nan"], "pose"), (["inf", "2", "0"], "pose"), (["1", "2", "1e400"], "pose"),
    (["60", "0", "0"], "outside the paved domain"), (["0", "-40", "0"], "outside the paved domain"),
])
def test_bad_poses(pose, fragment, refused):
    refused(["label", *pose, "--depth", "3"], fragment)


# --------------------------------------------------------------------------------------
# Depths
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("command", sorted(DEPTHS))
def test_depths_outside_the_range_are_refused_before_any_work(command, tmp_path, refused):
    base = {**WRITERS, **WITH_GEOMETRY}[command]
    base = [a for i, a in enumerate(base) if a != "--depth" and (i == 0 or base[i - 1] != "--depth")]
    lo, hi = DEPTHS[command]
    for depth in (lo - 1, hi + 1, -3, 40):
        argv = base + ["--depth", str(depth)]
        if command in WRITERS:
            argv += ["--out", str(tmp_path / "out")]
        refused(argv, "depth")
    refused(base + ["--depth", "deep"] + (["--out", str(tmp_path / "out")] if command in WRITERS else []),
            "--depth", usage=True)


@pytest.mark.parametrize("command", ["analyze", "paper"])
def test_a_barrier_face_budget_out_of_range_is_refused_at_once(command, tmp_path, refused):
    out = tmp_path / "out"
    for n in ("-1", "4000001"):
        refused([command, "--barrier-faces", n, "--out", str(out)], "--barrier-faces")
    refused([command, "--barrier-faces", "many", "--out", str(out)], "--barrier-faces", usage=True)


def test_the_barrier_face_budget_reaches_the_pattern_floods(monkeypatch, tmp_path):
    """--barrier-faces goes from the command line through the analysis's certificate writer to the process that
    runs the pattern floods (each hop recorded, nothing computed)."""
    from types import SimpleNamespace

    import intervalkin.app.cli as cli
    import intervalkin.certify.writer as writer
    import intervalkin.pipeline as pipeline
    from intervalkin.app.output import write_analysis_certificates
    from intervalkin.core.geometry import default_geometry

    seen = {}
    monkeypatch.setattr(cli, "run_analyze", lambda *a, **k: seen.setdefault("cli", k["barrier_faces"]) and 0)
    main(["paper", "--barrier-faces", "1234", "--out", str(tmp_path / "o")])

    class Stop(Exception):
        pass

    def beside(fn, *args):
        seen["beside"] = (fn.__name__, args[-1])
        raise Stop

    monkeypatch.setattr(writer, "Beside", beside)
    with pytest.raises(Stop):
        writer.write_certificates(tmp_path / "c", default_geometry(), joint_cells=object(), barrier_faces=77)
    monkeypatch.setattr(pipeline, "write_certificates", lambda *a, **k: seen.setdefault("pipeline", k) and [])
    a = SimpleNamespace(geometry=SimpleNamespace(name="x"), joint=None, regions=None, counts=lambda: None,
                        aspect_topology=None, cells=None)
    a.write_certificates = lambda *x, **k: pipeline.Analysis.write_certificates(a, *x, **k)
    write_analysis_certificates(a, tmp_path, barrier_faces=55)
    assert seen["cli"] == 1234 and seen["beside"] == ("pattern_barriers", 77)
    assert seen["pipeline"]["barrier_faces"] == 55


def test_the_retraction_runs_only_when_asked(monkeypatch, tmp_path):
    """--retraction goes from the command line to the analysis (each hop recorded, nothing computed there); the
    analysis retracts the joint paving's open layer when asked and leaves it alone by default, and summary.json
    says so by the presence of basic_regions.undecided.retraction."""
    import intervalkin
    import intervalkin.app.cli as cli
    import intervalkin.app.commands as commands
    from intervalkin.app.summary import chain_summary

    seen = []
    monkeypatch.setattr(cli, "run_analyze", lambda *a, **k: seen.append(k["retract"]) or 0)
    for command in ("analyze", "paper"):
        for extra in ([], ["--retraction"]):
            assert main([command, "--depth", "4", "--out", str(tmp_path / "o"), "--quiet", *extra]) == 0
    assert seen == [False, True, False, True]

    class Stop(Exception):
        pass

    def analyse(*a, **k):
        seen.append(k["retract"])
        raise Stop

    monkeypatch.setattr(commands, "analyse", analyse)
    with pytest.raises(Stop):
        commands.run_analyze(None, 4, tmp_path / "p", quiet=True, paper=True, retract=True)
    assert seen[-1] is True

    plain, retracted = intervalkin.analyse(depth=4), intervalkin.analyse(depth=4, retract=True)
    assert plain.cells.retraction is None and retracted.cells.retraction is not None
    assert "retraction" not in chain_summary(plain)["basic_regions"]["undecided"]
    block = chain_summary(retracted)["basic_regions"]["undecided"]["retraction"]
    assert block["nodes"] == block["sinks"] + block["resolved"] + block["unresolved"] and not block["closed"]
    # the retraction changes no cell and no count
    assert [c.signature for c in plain.cells.cells] == [c.signature for c in retracted.cells.cells]
    for name in ("aspects", "basic_regions", "uniqueness_domains"):
        a, b = getattr(plain.counts(), name), getattr(retracted.counts(), name)
        assert (a.found, a.lower, a.upper, a.exact) == (b.found, b.lower, b.upper, b.exact)
        assert {k: v for k, v in (b.undecided or {}).items() if k != "retraction"} == (a.undecided or {})


@pytest.mark.parametrize("command", ["analyze", "paper"])
def test_refine_to_out_of_range_is_refused_at_once(command, tmp_path, refused):
    out = tmp_path / "out"
    refused([command, "--refine-to", "30", "--out", str(out)], "refine_to")
    refused([command, "--depth", "5", "--refine-to", "4", "--out", str(out)], "refine_to")


# --------------------------------------------------------------------------------------
# Output folders: unwritable, into a file, non-empty without --force
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("command", sorted(WRITERS))
def test_unwritable_output_folders(command, tmp_path, refused):
    f = tmp_path / "afile"
    f.write_text("keep me")
    targets = [f, f / "below"]
    if Path("/proc").is_dir():
        targets.append(Path("/proc/intervalkin-cannot-write-here"))
    if os.geteuid() != 0:  # root writes anywhere: a read-only folder refuses only other users
        ro = tmp_path / "readonly"
        ro.mkdir(mode=0o555)
        targets.append(ro / "out")
    for target in targets:
        refused(WRITERS[command] + ["--out", str(target)], "--out")
    assert f.read_text() == "keep me"


@pytest.mark.parametrize("command", sorted(WRITERS))
def test_non_empty_folders_need_force(command, tmp_path, refused):
    foreign = tmp_path / "thesis"
    foreign.mkdir()
    (foreign / "thesis.tex").write_text("precious")
    earlier = tmp_path / "earlier"
    earlier.mkdir()
    (earlier / ".intervalkin-output").write_text(json.dumps({"format": "intervalkin-output", "files": []}))
    (earlier / "summary.json").write_text("{}")
    refused(WRITERS[command] + ["--out", str(foreign)], "--force")
    refused(WRITERS[command] + ["--out", str(earlier)], "earlier intervalkin output")
    assert (foreign / "thesis.tex").read_text() == "precious" and (earlier / "summary.json").read_text() == "{}"


# --------------------------------------------------------------------------------------
# verify: missing, malformed and tampered certificates
# --------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def certificates(tmp_path_factory):
    folder = tmp_path_factory.mktemp("certs") / "run" / "certificates"
    g = default_geometry()
    write_certificates(folder, g, dkp_results=[solve(g, parse_joint_vector(g, TABLE1))])
    return folder


def _copy(src: Path, tmp_path: Path) -> Path:
    d = tmp_path / "copy" / "certificates"
    shutil.copytree(src, d)
    return d


def test_missing_certificates(certificates, tmp_path, refused):
    refused(["verify", str(tmp_path / "nowhere")], "no such directory")
    empty = tmp_path / "empty"
    empty.mkdir()
    refused(["verify", str(empty)], "missing")
    d = _copy(certificates, tmp_path)
    (d / "dkp.json").unlink()  # listed in index.json, gone
    refused(["verify", str(d)], "dkp.json: missing")
    (d / "index.json").unlink()
    refused(["verify", str(d)], "index.json: missing")


def test_malformed_certificate(certificates, tmp_path, refused):
    d = _copy(certificates, tmp_path)
    (d / "dkp.json").write_text("{not json")
    refused(["verify", str(d)], "not valid JSON")


def test_tampered_certificate_fails_with_status_2(certificates, tmp_path, capsys, monkeypatch):
    """A changed number in a claim: the verdicts on stdout (FAILED first), one error line on stderr, status 2."""
    d = _copy(certificates, tmp_path)
    doc = json.loads((d / "dkp.json").read_text())
    doc["claims"][0]["rho"][0] = "14.99"  # another joint vector: its six boxes no longer hold solutions
    (d / "dkp.json").write_text(json.dumps(doc))
    assert main(["verify", str(d)]) == 2
    out, err = capsys.readouterr()
    assert out.startswith("FAILED: dkp.json#q-0 (dkp) because ")
    assert err.count("\n") == 1 and err.startswith("intervalkin: error: 0 of 1 claims verified")
    assert "Traceback" not in err
    # the untouched folder still verifies, through the output folder too
    assert main(["verify", str(certificates.parent)]) == 0
    assert capsys.readouterr().err == "1 of 1 claims verified\n"

"""Geometry files: exact reading, the paper's default, and one-line validation errors."""

from __future__ import annotations

from fractions import Fraction

import pytest
from flint import arb, ctx

from intervalkin.app.cli import main
from intervalkin.core.errors import GeometryError
from intervalkin.core.geometry import default_geometry, load_geometry

from ..conftest import DATA

PAPER = """
name = "test"
[base]
a1 = [0, 0]
a2 = [15.91, 0]
a3 = [0, 10]
[platform]
b1b2 = 17.04
b2b3 = 16.54
b3b1 = 20.84
b3_side = "left"
[limits]
rho_min = 10
rho_max = 32
"""


def _write(tmp_path, text):
    p = tmp_path / "g.toml"
    p.write_text(text)
    return p


def test_default_is_the_paper_manipulator_exactly(paper_geometry):
    g = paper_geometry
    assert g.base[1] == (Fraction(1591, 100), Fraction(0))
    assert g.l2.coef == Fraction(1704, 100) and g.l2.radicand == 1
    # |B1B3| and |B2B3| recovered exactly from the platform-frame coordinates.
    assert g.platform_radius_sq(2) == Fraction(2084, 100) ** 2
    p3x, p3y = g.platform_point(2)
    d23 = (p3x.coef - g.l2.coef) ** 2 + p3y.square()
    assert d23 == Fraction(1654, 100) ** 2
    assert float(p3y) > 0  # B3 to the left of B1 -> B2
    assert g.rho_min == (10, 10, 10) and g.rho_max == (32, 32, 32)
    assert dict(g.decimals)["base.a2[0]"] == "15.91"


def test_theta_is_about_50_57_degrees(paper_geometry):
    old = ctx.prec
    ctx.prec = 128
    try:
        p3x, p3y = paper_geometry.platform_point(2)
        theta = arb.atan2(p3y.arb(), p3x.arb()) * 180 / arb.pi()
    finally:
        ctx.prec = old
    assert abs(float(theta.mid()) - 50.57) < 0.01


def test_right_side_mirrors_b3(tmp_path):
    g = load_geometry(_write(tmp_path, PAPER.replace('"left"', '"right"')))
    assert float(g.p3y) == -float(default_geometry().p3y)


def test_coordinates_platform_equals_side_lengths(tmp_path):
    """A platform given by coordinates gives the same exact frame as its side lengths."""
    text = PAPER.replace(
        'b1b2 = 17.04\nb2b3 = 16.54\nb3b1 = 20.84\nb3_side = "left"',
        "b1 = [1, 2]\nb2 = [4, 6]\nb3 = [-2, 6]",
    )
    g = load_geometry(_write(tmp_path, text))
    assert g.l2.square() == 25
    assert g.platform_radius_sq(2) == 9 + 16
    assert float(g.p3y) > 0  # (-3, 4) is to the left of (3, 4)
    text2 = PAPER.replace(
        'b1b2 = 17.04\nb2b3 = 16.54\nb3b1 = 20.84\nb3_side = "left"',
        'b1b2 = 5\nb2b3 = 6\nb3b1 = 5\nb3_side = "left"',
    )
    g2 = load_geometry(_write(tmp_path, text2))
    assert abs(float(g.p3x) - float(g2.p3x)) < 1e-12 and abs(float(g.p3y) - float(g2.p3y)) < 1e-12


def test_shipped_example_files_load(tmp_path, paper_geometry):
    """The example geometries load, differ from the paper's, and survive a to_toml round trip exactly."""
    seen = []
    for name in ("offset_right.toml", "coords_platform.toml", "concurrent_legs.toml"):
        g = load_geometry(DATA / name)
        assert g.name and g != paper_geometry and g not in seen
        assert load_geometry(_write(tmp_path, g.to_toml())) == g
        seen.append(g)


def test_to_toml_round_trips(tmp_path, paper_geometry):
    p = _write(tmp_path, paper_geometry.to_toml())
    assert load_geometry(p) == paper_geometry


BAD = [
    (PAPER.replace("a3 = [0, 10]", "a3 = [15.91, 0]"), "base.a2, base.a3"),
    (PAPER.replace("b3b1 = 20.84", "b3b1 = 33.58"), "triangle"),
    (PAPER.replace("b3b1 = 20.84", "b3b1 = 40"), "triangle"),
    (PAPER.replace('b1b2 = 17.04\nb2b3 = 16.54\nb3b1 = 20.84\nb3_side = "left"', "b1 = [0, 0]\nb2 = [1, 1]\nb3 = [2, 2]"), "collinear"),
    (PAPER.replace("rho_min = 10", "rho_min = 40"), "rho_min < rho_max"),
    (PAPER.replace("rho_min = 10", "rho_min = 0"), "rho_min"),
    (PAPER.replace("rho_min = 10", "rho_min = [10, 11]"), "limits.rho_min"),
    (PAPER.replace("rho_min = 10", "rho_min = nan"), "finite"),
    (PAPER.replace("rho_max = 32", "rho_max = inf"), "finite"),
    (PAPER.replace("rho_max = 32", 'rho_max = "32"'), "expected a number"),
    (PAPER.replace('"left"', '"up"'), "b3_side"),
    (PAPER.replace("a1 = [0, 0]\n", ""), "base.a1: missing"),
    (PAPER.replace("[limits]", "[limits]\nspeed = 3"), "limits.speed: unknown key"),
    (PAPER + "\ncolour = 1\n", "colour: unknown key"),
    (PAPER.replace("b1b2 = 17.04", "b1b2 = 17.04\nb1 = [0, 0]"), "either"),
    (PAPER.replace("a2 = [15.91, 0]", "a2 = [15.91]"), "base.a2"),
    ("name = [\n", "malformed TOML"),
]


@pytest.mark.parametrize("text,fragment", BAD)
def test_bad_geometry_gives_one_line_error(tmp_path, text, fragment):
    with pytest.raises(GeometryError) as exc:
        load_geometry(_write(tmp_path, text))
    msg = str(exc.value)
    assert fragment in msg
    assert "\n" not in msg


def test_missing_file(tmp_path):
    with pytest.raises(GeometryError, match="not found"):
        load_geometry(tmp_path / "nope.toml")


@pytest.mark.parametrize("text,fragment", BAD[:3] + BAD[-1:])
def test_cli_reports_bad_geometry_with_status_2(tmp_path, capsys, text, fragment):
    p = _write(tmp_path, text)
    status = main(["dkp", "14.98", "15.38", "12.0", "--geometry", str(p)])
    err = capsys.readouterr().err
    assert status == 2
    assert err.count("\n") == 1 and fragment in err
    assert "Traceback" not in err

"""The sweep file: designs, exact values, content keys, degenerate designs and one-line errors."""

from __future__ import annotations

from decimal import Decimal

import pytest
import tomllib

from intervalkin.core.geometry import default_geometry
from intervalkin.sweeps.spec import Settings, SweepFileError, design_key, load_sweep, parse_sweep
from tests.sweeps.shared import GRID



def _doc(text: str) -> dict:
    return tomllib.loads(text, parse_float=Decimal)


def test_product_of_a_range_and_a_list_gives_every_combination_exactly():
    spec = parse_sweep(_doc(GRID))
    assert spec.parameters == ("platform.scale", "limits.rho_max")
    assert [d.values for d in spec.designs[:5]] == [("0.8", "34"), ("0.8", "36"), ("0.8", "38"), ("0.8", "40"),
                                                    ("1.0", "34")]
    assert len(spec.designs) == 12 and len({d.key for d in spec.designs}) == 12
    first = tomllib.loads(spec.designs[0].geometry_toml)
    assert first["platform"]["b1b2"] == 13.632 and first["limits"]["rho_max"] == 34  # 17.04 * 0.8, exactly
    assert first["base"]["a2"] == [15.91, 0]  # the paper's base is untouched


def test_the_paper_design_has_the_key_of_the_paper_geometry_whatever_its_spelling():
    spec = parse_sweep(_doc(GRID.replace("[34, 36, 38, 40]", "[32.000]").replace('stop = 1.2', 'stop = 1.0')))
    paper = [d for d in spec.designs if d.values == ("1.0", "32.000")][0]
    assert paper.key == design_key(default_geometry(), Settings(4))
    assert paper.key != design_key(default_geometry(), Settings(5))


def test_zip_pairs_values_and_one_leg_limit_becomes_a_list():
    spec = parse_sweep(_doc('combine = "zip"\n[vary]\n"limits.rho_max[1]" = [30, 34]\n"base.a2[0]" = [15, 16]'))
    assert [d.values for d in spec.designs] == [("30", "15"), ("34", "16")]
    g = tomllib.loads(spec.designs[1].geometry_toml)
    assert g["limits"]["rho_max"] == [32, 34, 32] and g["base"]["a2"] == [16, 0]


def test_a_design_that_is_not_a_manipulator_is_degenerate_not_an_error():
    spec = parse_sweep(_doc('[vary]\n"platform.b1b2" = [17.04, 40]'))
    ok, flat = spec.designs
    assert ok.key and not ok.degenerate
    assert flat.key == "" and flat.geometry_toml == "" and "triangle inequality" in flat.degenerate


@pytest.mark.parametrize("text, field", [
    ("", "[vary]"),
    ("[vary]\nbogus = [1]", "vary.'bogus'"),
    ('[vary]\n"platform.b3_side" = [1]', "vary.'platform.b3_side'"),
    ('[vary]\n"limits.rho_max[3]" = [1]', "vary.'limits.rho_max[3]'"),
    ('[vary]\n"limits.rho_max" = []', "vary.'limits.rho_max'"),
    ('[vary]\n"limits.rho_max" = ["32"]', "vary.'limits.rho_max'[0]"),
    ('[vary]\n"limits.rho_max" = { start = 30, stop = 28, step = 1 }', "vary.'limits.rho_max'"),
    ('[vary]\n"limits.rho_max" = { start = 30, stop = 32 }', "vary.'limits.rho_max'"),
    ('combine = "zip"\n[vary]\n"limits.rho_max" = [30, 32]\n"limits.rho_min" = [5]', 'combine = "zip"'),
    ('combine = "outer"\n[vary]\n"limits.rho_max" = [30]', "combine"),
    ('[analysis]\ndepth = 12\n[vary]\n"limits.rho_max" = [30]', "analysis.depth"),
    ('[analysis]\ndepth = 5\nrefine_to = 4\n[vary]\n"limits.rho_max" = [30]', "analysis.refine_to"),
    ('[analysis]\nspeed = 1\n[vary]\n"limits.rho_max" = [30]', "analysis.speed"),
    ('[best]\nby = "beauty"\n[vary]\n"limits.rho_max" = [30]', "best.by"),
    ('[best]\norder = "up"\n[vary]\n"limits.rho_max" = [30]', "best.order"),
    ('geometry = 3\n[vary]\n"limits.rho_max" = [30]', "geometry"),
    ('geometry = "missing.toml"\n[vary]\n"limits.rho_max" = [30]', "geometry"),
    ('colour = "red"\n[vary]\n"limits.rho_max" = [30]', "colour"),
    ('[vary]\n"limits.rho_max" = { start = 1, stop = 1000000, step = 1 }', "vary.'limits.rho_max'"),
    ('[vary]\n"limits.rho_max" = { start = 1, stop = 1000, step = 1 }\n'
     '"limits.rho_min" = { start = 1, stop = 1000, step = 1 }',
     "[vary]"),
])
def test_a_bad_file_is_one_line_naming_its_field(text, field, tmp_path):
    with pytest.raises(SweepFileError) as err:
        parse_sweep(_doc(text), folder=tmp_path)
    message = str(err.value)
    assert message.startswith(field) and "\n" not in message, message


def test_a_geometry_file_is_read_relative_to_the_sweep_file(tmp_path):
    (tmp_path / "g.toml").write_text(default_geometry().to_toml().replace("rho_max = 32", "rho_max = 30"))
    (tmp_path / "s.toml").write_text('geometry = "g.toml"\n[vary]\n"platform.scale" = [1]')
    spec = load_sweep(tmp_path / "s.toml")
    assert tomllib.loads(spec.designs[0].geometry_toml)["limits"]["rho_max"] == 30
    (tmp_path / "bad.toml").write_text("[vary\n")
    with pytest.raises(SweepFileError, match="malformed TOML"):
        load_sweep(tmp_path / "bad.toml")
    with pytest.raises(SweepFileError, match="not found"):
        load_sweep(tmp_path / "none.toml")

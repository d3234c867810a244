"""report.md and report.html: every paper figure cited, links only to files that exist, a self-contained
page whose 3-D views render in a real headless browser.

The output folder is written once (tests/app/shared.py, depth 6) with the calls of the paper
command.  The browser test drives Chromium (``--headless --dump-dom``): the page records in its
own DOM which views rendered and any script error, so the dumped DOM tells both.  Without a
Chromium on the PATH the browser test is skipped, saying so (CI installs only Python packages;
``apt-get install chromium`` runs it locally).
"""

from __future__ import annotations

import html
import json
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from intervalkin.app.figures import PAPER_FIGURES
from intervalkin.app.markdown_html import links, to_html
from intervalkin.app.palette import colour_of
from intervalkin.app.report_html import HTML_SCENES

from .shared import paper_folder

BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")


@pytest.fixture(scope="module")
def folder():
    return paper_folder(6)


def html_links(page: str) -> list[str]:
    """Every src and href of an HTML page's elements (inside scripts: not links; anchors, data: URIs and web
    addresses left out)."""
    page = re.sub(r"<script\b[^>]*>.*?</script>", "", page, flags=re.S)
    found = re.findall(r'(?:src|href)="([^"]+)"', page)
    return [html.unescape(u) for u in found if not u.startswith(("#", "data:", "http://", "https://"))]


def missing_links(out: Path) -> list[str]:
    """The links of report.md and report.html in ``out`` that point at no file of ``out``."""
    targets = links((out / "report.md").read_text()) + html_links((out / "report.html").read_text())
    return [t for t in targets if not (out / t).is_file()]


def test_reports_link_only_to_files_that_exist(folder):
    """Every image and link of report.md and report.html is a file of the output folder.

    Would catch a report citing a figure that was not written (or written under another name),
    or a trajectory folder from an earlier run.
    """
    out, _ = folder
    md = links((out / "report.md").read_text())
    page = html_links((out / "report.html").read_text())
    assert len(md) >= 15 and len(page) >= 15
    assert missing_links(out) == []


def test_the_link_check_finds_a_dead_link(tmp_path):
    """The check above can fail: a report pointing at a missing figure is caught."""
    (tmp_path / "figures").mkdir()
    (tmp_path / "figures" / "here.png").write_bytes(b"png")
    (tmp_path / "report.md").write_text("![a](figures/here.png)\n\n![b](figures/gone.png)\n")
    (tmp_path / "report.html").write_text('<img src="figures/here.png"><a href="trajectories/2-3/x.png">x</a>'
                                          '<a href="#top">top</a><img src="data:image/png;base64,AA">')
    assert missing_links(tmp_path) == ["figures/gone.png", "trajectories/2-3/x.png"]


def test_report_cites_every_octree_figure_of_the_paper_with_its_numbers(folder):
    """A passage per paper figure (2, 3, 5, 6, 9-13): what it shows, the redrawn files, the certified numbers."""
    out, summary = folder
    text = (out / "report.md").read_text()
    for f in PAPER_FIGURES:
        start = text.index(f"**The paper's Figure {f.number}** shows {f.shows}.")
        passage = text[start:text.index("\n**The paper's", start + 1) if "\n**The paper's" in text[start + 1:]
                       else len(text)]
        assert any(f"](figures/{name})" in passage for name in f.files), f.number
        assert re.search(r"\d", passage.split("shows", 1)[1]), f.number  # a number comes with it
    assert f"{summary['basic_regions']['count']} basic regions found" in text
    assert "| Fig. 13 |" in text  # the figure table


def test_report_html_is_self_contained(folder):
    """One file: plotly.js inlined, no script or style fetched from elsewhere, one view per scene with its
    surfaces as Mesh3d traces in the palette's colours, and the tables of report.md."""
    out, _ = folder
    page = (out / "report.html").read_text()
    assert not re.search(r'<script[^>]+src=', page) and not re.search(r'<link[^>]+href="http', page)
    assert "Plotly" in page and len(page) > 3_000_000  # plotly.js itself is several MB
    views = dict(re.findall(r'<script type="application/json" data-view="view-([a-z_]+)">(.*?)</script>', page,
                            flags=re.S))
    assert list(views) == list(HTML_SCENES)
    regions = json.loads(views["basic_regions"].replace("<\\/", "</"))
    assert regions["data"] and all(t["type"] == "mesh3d" for t in regions["data"])
    for t in regions["data"]:
        rid = int(re.match(r"region (\d+):", t["name"]).group(1))
        assert t["color"] == colour_of("region", rid)
    md = (out / "report.md").read_text()
    assert md.count("\n|---") == page.count("<thead>")  # every table of report.md


def _chromium() -> str | None:
    for name in BROWSERS:
        if exe := shutil.which(name):
            return exe
    return None


def browser_dom(page: Path, tmp_path: Path) -> tuple[str, str]:
    """The DOM of ``page`` after its scripts ran in headless Chromium (software WebGL), and the browser's log."""
    exe = _chromium()
    cmd = [exe, "--headless", "--no-sandbox", "--use-gl=swiftshader", "--enable-unsafe-swiftshader",
           f"--user-data-dir={tmp_path / 'profile'}", "--virtual-time-budget=30000", "--enable-logging=stderr",
           "--v=0", "--dump-dom", page.resolve().as_uri()]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=180)
    return r.stdout, r.stderr


def page_problems(dom: str, log: str, views) -> list[str]:
    """What went wrong in a dumped page: views that did not render, script errors, uncaught exceptions."""
    problems = []
    for key in views:
        tag = re.search(rf'<div[^>]*id="view-{key}"[^>]*>', dom)
        if tag is None or 'data-rendered="1"' not in tag.group(0):
            problems.append(f"view {key} did not render")
    errors = re.search(r'<pre id="js-errors">(.*?)</pre>', dom, flags=re.S)
    if errors is None or errors.group(1).strip():
        problems.append(f"script errors: {errors.group(1).strip() if errors else 'no error element'}")
    problems += [ln for ln in log.splitlines() if "CONSOLE" in ln and "Uncaught" in ln]
    return problems


@pytest.mark.skipif(_chromium() is None, reason="no Chromium on the PATH (install it, e.g. `apt-get install "
                                                "chromium`, to run the browser test of report.html)")
def test_report_html_renders_in_a_headless_browser(folder, tmp_path):
    """The page loads without a script error and every 3-D view draws on a WebGL canvas; a broken page
    is reported as broken (the check can fail)."""
    out, _ = folder
    dom, log = browser_dom(out / "report.html", tmp_path)
    assert page_problems(dom, log, HTML_SCENES) == []
    broken = tmp_path / "broken.html"
    page = (out / "report.html").read_text()
    # the same page with one view's data corrupted and a failing script
    page = page.replace('data-view="view-aspects">{', 'data-view="view-aspects">{oops', 1)
    broken.write_text(page.replace("</body>", "<script>undefinedFunction();</script></body>"))
    dom, log = browser_dom(broken, tmp_path)
    problems = page_problems(dom, log, HTML_SCENES)
    assert "view aspects did not render" in problems and any("undefinedFunction" in p for p in problems)


def test_markdown_subset():
    """Headings, tables, lists, images, emphasis and code of report.md become HTML; the rest is escaped."""
    out = to_html("## A <b>\n\nSome *x* and **y** with `a<b`.\n\n- one\n- [two](t.png)\n\n![cap](figures/f.png)\n")
    assert "<h2>A &lt;b&gt;</h2>" in out
    assert "<p>Some <em>x</em> and <strong>y</strong> with <code>a&lt;b</code>.</p>" in out
    assert '<ul>\n<li>one</li>\n<li><a href="t.png">two</a></li>\n</ul>' in out
    assert '<img src="figures/f.png" alt="cap"' in out
    assert links("![cap](figures/f.png) and [t](x/y.md)") == ["figures/f.png", "x/y.md"]


def test_open_places_are_reported_with_their_reasons(folder):
    """The report names why each listed place is open, with the leaves per reason, and the totals by reason."""
    from intervalkin.app.report_joint import joint_cells_passage

    why = {"cusp_window": {"leaves": 3, "volume": 0.5}, "slope_not_certified": {"leaves": 2, "volume": 0.25}}
    place = {"lo": [10.0, 10.0, 10.0], "hi": [11.0, 11.0, 11.0], "volume": 0.75, "leaves": 5, "without_model": 0,
             "on_face": True, "why": why}
    summary = json.loads(json.dumps(folder[1]))  # a copy
    summary["joint_cells"]["open_places"] = {"count": 1, "volume_without_model": 0.0, "volume_window_model": 0.75,
                                             "by_reason": why, "largest": [place]}
    text = "\n".join(joint_cells_passage(summary, ([10.0] * 3, [32.0] * 3)))
    assert "By reason: cusp window 3 leaves (0.50); one pair window (slope not certified) 2 leaves (0.25)." in text
    row = next(line for line in text.splitlines() if line.startswith("| 0.750"))
    assert row.endswith("| cusp window 3, one pair window (slope not certified) 2 |")
    assert "retraction" not in folder[1]["basic_regions"]["undecided"]  # an analysis retracts only when asked
    text = "\n".join(joint_cells_passage(summary, ([10.0] * 3, [32.0] * 3)))
    assert "Retraction towards the cells" not in text and "was not retracted towards the cells (`--retraction`" in text
    summary["basic_regions"]["undecided"]["retraction"] = {
        "closed": False, "nodes": 100, "sinks": 60, "resolved": 30, "unresolved": 10, "leaves_unresolved": 7,
        "volume_unresolved": 0.5, "by_source": {"pair_pattern": {"nodes": 20, "unresolved": 4},
                                                "no_piece_model": {"nodes": 6, "unresolved": 6},
                                                "clear": {"nodes": 60, "unresolved": 0}}}
    text = "\n".join(joint_cells_passage(summary, ([10.0] * 3, [32.0] * 3)))
    assert ("Retraction towards the cells (proofs/lemma-joint-retraction.md): 30 of 40 nodes off the cells are ranked; "
            "7 leaves (volume 0.50) still hold a node that is not, so no upper bound: pair-window patterns 4, "
            "leaves without pieces 6.") in text


def test_the_pavings_made_again_between_joined_cells_are_reported(folder):
    """A separation block with zone passes says how often the joint box was paved again and which paving
    stands; without passes nothing is said of them."""
    from intervalkin.app.report_joint import joint_cells_passage

    summary = json.loads(json.dumps(folder[1]))
    sep = summary["joint_cells"]["separations"]
    sep["by_signature"] = [{"signature": [4, 2, 2], "groups": [[1], [3]], "components_at_least": 2}]
    limits = ([10.0] * 3, [32.0] * 3)
    sep["zone_passes"] = []
    assert "paved again" not in "\n".join(joint_cells_passage(summary, limits))
    sep["zone_passes"] = [{"boxes": 14, "levels": 4, "volume": 0.53, "cells_found": 10, "old_cells_kept": True,
                           "components_at_least": 10, "basic_regions_at_least": 28,
                           "kept": True}]
    text = "\n".join(joint_cells_passage(summary, limits))
    assert ("The joint box was paved again 1 time, finer between cells still joined (14 boxes of the uniform level, "
            "volume 0.53, split 4 more times); 1 of these pavings kept every cell and proved more apart, and the last "
            "one kept (10 cells) is the one reported.") in text
    sep["zone_passes"][0]["kept"] = False
    assert "none was kept: the first paving is the one reported" in "\n".join(joint_cells_passage(summary, limits))

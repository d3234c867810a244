"""``report.html``: the paper report with rotatable 3-D views, one self-contained file.

The page holds the text and tables of ``report.md`` (converted by
:mod:`intervalkin.app.markdown_html`) and one interactive plotly view per scene of
:mod:`intervalkin.app.scenes`: the workspace, the singular layer, the aspects, the
basic regions, the uniqueness domains and the joint cells, each a set of
triangulated boundary surfaces (marching cubes on the label grid) drawn as
``Mesh3d`` traces in the colours of every other figure.  plotly.js is inlined, so
the page needs no network; the PNG figures it shows are the files of ``figures/``
beside it (relative links, checked by the tests).

Each view records that it rendered (``data-rendered="1"`` on its element) and
any script error is written into the element ``#js-errors``: a headless browser
can check both from the page itself (tests/app/test_report.py).
"""

from __future__ import annotations

import html
import json
from pathlib import Path

import numpy as np

from intervalkin.app.markdown_html import to_html
from intervalkin.app.scenes import Scene, joint_scenes, paving_scenes, region_scenes
from intervalkin.core.files import atomic_write_bytes

__all__ = ["scene_figure", "html_views", "write_report_html", "HTML_SCENES"]

#: The scenes of the interactive report, in page order.
HTML_SCENES = ("workspace", "singular", "aspects", "basic_regions", "uniqueness_domains", "joint_cells")

_STYLE = """
body { font-family: system-ui, sans-serif; max-width: 1150px; margin: 1.5em auto; padding: 0 1em; color: #222; }
table { border-collapse: collapse; margin: 0.8em 0; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.5em; text-align: left; vertical-align: top; }
th { background: #f2f2f2; }
figure { margin: 0.5em 0; } figure img { max-width: 100%; border: 1px solid #eee; }
code { background: #f4f4f4; padding: 0 0.2em; }
.view { width: 100%; height: 620px; border: 1px solid #ddd; margin: 0.5em 0 1.5em 0; }
nav a { margin-right: 1em; }
#js-errors:empty { display: none; } #js-errors { color: #b00; }
"""

# Errors are collected before anything else runs, so a failing script is seen by the page itself.
_ERROR_HOOK = """
window.__errors = [];
function __report(msg) {
  window.__errors.push(String(msg));
  var el = document.getElementById('js-errors');
  if (el) { el.textContent = window.__errors.join('\\n'); }
}
window.addEventListener('error', function (e) { __report(e.message || e); });
window.addEventListener('unhandledrejection', function (e) { __report(e.reason); });
(function () {
  var original = console.error;
  console.error = function () { __report(Array.prototype.join.call(arguments, ' ')); original.apply(console, arguments); };
})();
"""

_RENDER = """
document.querySelectorAll('script[data-view]').forEach(function (tag) {
  var div = document.getElementById(tag.dataset.view);
  try {
    var fig = JSON.parse(tag.textContent);
    Plotly.newPlot(div, fig.data, fig.layout, {responsive: true, displaylogo: false})
      .then(function () {
        // rendered: a WebGL canvas holds the scene and every surface became a trace
        var canvas = div.querySelector('.gl-container canvas');
        var ok = canvas && canvas.width > 0 && div._fullData.length === fig.data.length;
        div.dataset.rendered = ok ? '1' : 'no-canvas';
        if (!ok) { __report(tag.dataset.view + ': no WebGL canvas after plotting'); }
      })
      .catch(function (e) { __report(tag.dataset.view + ': ' + e); });
  } catch (e) { __report(tag.dataset.view + ': ' + e); }
});
"""


def _index_dtype(n_vertices: int):
    """The smallest unsigned index type for ``n_vertices`` (typed arrays keep the page light)."""
    return np.uint16 if n_vertices < 65536 else np.uint32


def scene_figure(scene: Scene):
    """A plotly figure of a scene: one Mesh3d trace per layer, legend by layer, a cubic box."""
    import plotly.graph_objects as go

    traces = []
    for layer in scene.layers:
        s = layer.surface
        if s.is_empty():
            continue
        v = s.vertices.astype(np.float32)
        f = s.faces.astype(_index_dtype(len(v)))
        traces.append(go.Mesh3d(
            x=v[:, 0], y=v[:, 1], z=v[:, 2], i=f[:, 0], j=f[:, 1], k=f[:, 2], color=layer.colour,
            name=layer.name, showlegend=True, legendgroup=layer.group or layer.name, flatshading=True,
            opacity=layer.opacity,
            lighting={"ambient": 0.55, "diffuse": 0.7, "specular": 0.05}, hoverinfo="name"))
    axis = [{"title": {"text": t}} for t in scene.axes]
    layout = go.Layout(
        title={"text": f"{scene.title} (cf. the paper's {scene.paper_figure})"
                       + (f"<br><sub>{html.escape(scene.note)}</sub>" if scene.note else ""), "font": {"size": 15}},
        scene={"xaxis": axis[0], "yaxis": axis[1], "zaxis": axis[2], "aspectmode": "cube"},
        legend={"font": {"size": 11}, "itemsizing": "constant"}, margin={"l": 0, "r": 0, "t": 60, "b": 0},
        height=620)
    return go.Figure(traces, layout)


def html_views(scenes: list[Scene]) -> str:
    """HTML of the interactive views: a heading, a div and the figure's JSON per scene."""
    import plotly.io as pio

    parts = []
    for sc in scenes:
        div = f"view-{sc.key}"
        data = pio.to_json(scene_figure(sc), validate=False).replace("</", "<\\/")
        parts.append(f'<h3 id="h-{div}">{html.escape(sc.title)} ({html.escape(sc.paper_figure)})</h3>\n'
                     f'<div class="view" id="{div}"></div>\n'
                     f'<script type="application/json" data-view="{div}">{data}</script>')
    return "\n".join(parts)


def write_report_html(analysis, summary: dict, out, markdown: str | None = None) -> str:
    """Write ``out/report.html``: report.md's text and tables, and the interactive 3-D views.

    ``markdown`` is the text of report.md (read from ``out/report.md`` when not given, so call
    this after :func:`~intervalkin.app.report.write_report`).  Returns the file name,
    ``"report.html"``, for summary.json's list of files.
    """
    import plotly.offline

    out = Path(out)
    if markdown is None:
        path = out / "report.md"
        markdown = path.read_text() if path.is_file() else ""
    scenes = {s.key: s for s in paving_scenes(analysis.regions.paving) + region_scenes(analysis.regions)
              + joint_scenes(analysis.joint)}
    chosen = [scenes[k] for k in HTML_SCENES if k in scenes]
    head, rest = _split_after_claims(markdown)
    nav = " ".join(f'<a href="#h-view-{s.key}">{html.escape(s.title)}</a>' for s in chosen)
    title = "Wenger & Chablat (1997), regenerated with certified interval arithmetic"
    page = f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{html.escape(title)}</title>
<style>{_STYLE}</style>
<script>{_ERROR_HOOK}</script>
<script>{plotly.offline.get_plotlyjs()}</script>
</head>
<body>
<pre id="js-errors"></pre>
{to_html(head)}
<h2>Interactive 3-D views</h2>
<p>Drag to rotate, scroll to zoom, click a legend entry to hide a set (double-click: show only it).
Each surface bounds the grid cells that carry a certified label (x, y in length units, φ in degrees);
the same colours as in the PNG figures. The rest of <code>report.md</code> (tables and figures) follows
the views.</p>
<nav>{nav}</nav>
{html_views(chosen)}
<hr>
{to_html(rest)}
<script>{_RENDER}</script>
<script type="application/json" id="report-summary">{json.dumps(_summary_counts(summary))}</script>
</body>
</html>
"""
    atomic_write_bytes(out / "report.html", page.encode("utf-8"))
    return "report.html"


def _split_after_claims(markdown: str) -> tuple[str, str]:
    """report.md cut after its claims table (the title, the figure list, the summary), and the rest."""
    at = markdown.find("\n## Table 1")
    return (markdown, "") if at < 0 else (markdown[:at], markdown[at:])


def _summary_counts(summary: dict) -> dict:
    """The count blocks of summary.json, embedded for scripts that read the page."""
    return {k: summary[k] for k in ("aspects", "basic_regions", "uniqueness_domains") if k in summary}

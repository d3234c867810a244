"""The small Markdown subset of ``report.md``, turned into HTML for ``report.html``.

report.md is written by :mod:`intervalkin.app.report` with a handful of constructs:
headings (``#``, ``##``), pipe tables, ``-`` lists, images on their own line,
paragraphs, and inline ``*emphasis*``, ``**strong**``, ```code``` and ``[links](path)``.
This converter handles exactly those (escaping everything else), so the HTML report
shows the same tables without a Markdown dependency.

>>> to_html("# Title\\n\\n| a | b |\\n|---|---|\\n| 1 | *x* |\\n")
'<h1>Title</h1>\\n<table>\\n<thead><tr><th>a</th><th>b</th></tr></thead>\\n<tbody>\\n<tr><td>1</td><td><em>x</em></td></tr>\\n</tbody>\\n</table>'
"""

from __future__ import annotations

import html
import re

__all__ = ["to_html", "inline", "links"]

_IMAGE = re.compile(r"^!\[([^\]]*)\]\(([^)\s]+)\)$")
_LINK = re.compile(r"(!?)\[([^\]]*)\]\(([^)\s]+)\)")


def inline(text: str) -> str:
    """Escape ``text`` and render its inline code, links, strong and emphasis."""
    parts = re.split(r"(`[^`]*`)", text)  # code spans first: nothing inside them is rendered
    out = []
    for part in parts:
        if part.startswith("`") and part.endswith("`") and len(part) >= 2:
            out.append(f"<code>{html.escape(part[1:-1])}</code>")
            continue
        s = html.escape(part, quote=False)
        s = _LINK.sub(lambda m: (f'<img src="{html.escape(m.group(3))}" alt="{m.group(2)}">' if m.group(1)
                                 else f'<a href="{html.escape(m.group(3))}">{m.group(2)}</a>'), s)
        s = re.sub(r"\*\*([^*]+)\*\*", r"<strong>\1</strong>", s)
        s = re.sub(r"(?<![\w*])\*([^*\s][^*]*?)\*(?![\w*])", r"<em>\1</em>", s)
        out.append(s)
    return "".join(out)


def _cells(line: str) -> list[str]:
    return [c.strip() for c in line.strip().strip("|").split("|")]


def to_html(markdown: str) -> str:
    """HTML for the Markdown subset of report.md (see the module docstring)."""
    lines = markdown.splitlines()
    out: list[str] = []
    para: list[str] = []

    def flush():
        if para:
            out.append(f"<p>{inline(' '.join(para))}</p>")
            para.clear()

    i = 0
    while i < len(lines):
        line = lines[i].rstrip()
        if not line.strip():
            flush()
            i += 1
            continue
        if m := re.match(r"^(#{1,4}) (.*)$", line):
            flush()
            level = len(m.group(1))
            out.append(f"<h{level}>{inline(m.group(2))}</h{level}>")
            i += 1
            continue
        if m := _IMAGE.match(line.strip()):
            flush()
            src = html.escape(m.group(2))
            out.append(f'<figure><a href="{src}"><img src="{src}" alt="{html.escape(m.group(1))}" loading="lazy">'
                       "</a></figure>")
            i += 1
            continue
        if line.lstrip().startswith("|") and i + 1 < len(lines) and re.match(r"^\s*\|[-:| ]+\|\s*$", lines[i + 1]):
            flush()
            head = "".join(f"<th>{inline(c)}</th>" for c in _cells(line))
            rows = []
            i += 2
            while i < len(lines) and lines[i].lstrip().startswith("|"):
                rows.append("<tr>" + "".join(f"<td>{inline(c)}</td>" for c in _cells(lines[i])) + "</tr>")
                i += 1
            out.append("<table>\n<thead><tr>" + head + "</tr></thead>\n<tbody>\n" + "\n".join(rows)
                       + "\n</tbody>\n</table>")
            continue
        if line.lstrip().startswith("- "):
            flush()
            items = []
            while i < len(lines) and lines[i].lstrip().startswith("- "):
                items.append(f"<li>{inline(lines[i].lstrip()[2:])}</li>")
                i += 1
            out.append("<ul>\n" + "\n".join(items) + "\n</ul>")
            continue
        para.append(line.strip())
        i += 1
    flush()
    return "\n".join(out)


def links(markdown: str) -> list[str]:
    """Every link and image target of a Markdown text (what must exist beside report.md)."""
    return [m.group(3) for m in _LINK.finditer(markdown)]

"""The figure passages of report.md: each octree figure of the paper beside its redrawing and numbers.

For every entry of :data:`~intervalkin.app.figures.PAPER_FIGURES` the report says,
in our words, what the paper's figure shows, which files redraw it from certified
labels, and the certified numbers behind it (volumes, counts, bounds).  Images
are linked only when the file was written (``files``, the run's list), so the
report never points at a missing file.
"""

from __future__ import annotations

import numpy as np

from intervalkin.app.boxes import cell_by_id, joint_boxes
from intervalkin.app.figures import PAPER_FIGURES, PaperFigure
from intervalkin.app.scenes import top_cell
from intervalkin.paving.labels import Label
from intervalkin.space.singular_surface import may_be_singular

__all__ = ["figures_table", "figure_passage", "joint_shares"]


def _by_number(number: int) -> PaperFigure:
    return next(f for f in PAPER_FIGURES if f.number == number)


def figures_table(files) -> str:
    """A Markdown table: paper figure, what it shows, the files that redraw it (those written)."""
    have = set(files)
    rows = ["| paper | what it shows | redrawn in |", "|---|---|---|"]
    for f in PAPER_FIGURES:
        links = ", ".join(f"[{n}](figures/{n})" for n in f.files if f"figures/{n}" in have) or "(not written)"
        rows.append(f"| Fig. {f.number} | {f.shows} | {links} |")
    return "\n".join(rows) + "\n"


def joint_shares(joint) -> dict:
    """Share of the joint box (by volume) per certified count, and the undecided share (may meet g(S))."""
    jb = joint_boxes(joint)
    vol = np.prod((jb.hi - jb.lo).astype(np.float64), axis=1)
    total = float(vol.sum())
    count, cell = jb.columns["count"], jb.columns["cell"]
    out = {int(k): float(vol[(count == k) & (cell >= 0)].sum()) / total for k in np.unique(count[cell >= 0])}
    out["undecided"] = float(vol[cell < 0].sum()) / total
    return out


def _numbers(number: int, analysis, summary: dict) -> str:
    """The certified numbers that go with the paper's figure ``number``."""
    ra, jp = analysis.regions, analysis.joint
    p = ra.paving
    vol = summary.get("W", {}).get("volume", {})
    if number == 2:
        sh = joint_shares(jp)
        parts = ", ".join(f"{k} solutions {100 * v:.1f}%" for k, v in sorted((k, v) for k, v in sh.items()
                                                                             if k != "undecided"))
        q = sum(v for k, v in sh.items() if k != "undecided" and k > 0)
        zero = sh.get(0, 0.0)
        return (f"Certified cells with at least one solution fill {100 * q:.1f}% of the joint box ({parts}); "
                f"{100 * sh['undecided']:.1f}% is the undecided layer around g(S). The figure draws the joint box "
                f"minus the {100 * zero:.1f}% certified to have no solution: an outer enclosure of Q.")
    if number == 3:
        return (f"W certified inside: volume {vol.get('inside', 0):.1f}; undecided: {vol.get('boundary', 0):.1f} "
                "(x, y in length units, phi in radians).")
    if number == 5:
        sing = may_be_singular(p.labels) & (p.labels["W"] != Label.OUTSIDE)
        return (f"{int(sing.sum())} boxes (volume {float(p.volume()[sing].sum()):.1f}) may hold a pose with "
                "det A = 0; every other box of W is certified free of type-2 singularities.")
    if number == 6:
        per = summary.get("aspects", {}).get("components_per_sign", {})
        a1 = summary.get("WA1", {}).get("volume", {}).get("inside", 0.0)
        a2 = summary.get("WA2", {}).get("volume", {}).get("inside", 0.0)
        return (f"WA1 (det A > 0): {per.get('WA1', '?')} components, volume {a1:.1f}; WA2 (det A < 0): "
                f"{per.get('WA2', '?')} components, volume {a2:.1f}; two aspects certified distinct (opposite signs).")
    if number == 9:
        return (f"Layer that may meet the characteristic surfaces (both aspects): volume "
                f"{summary.get('characteristic_layer_volume', 0.0):.1f}, an outer enclosure.")
    if number == 10:
        br = summary.get("basic_regions", {})
        return (f"{br.get('count', len(ra.regions))} basic regions found, at least {br.get('lower_bound', '?')} "
                f"certified distinct; {sum(1 for r in ra.regions if r.n_boxes == 0)} hold no certified box at this "
                "depth (their atlas panels say so).")
    if number == 11:
        by: dict[int, list[int]] = {}
        for c in jp.cells:
            if c.count > 0:
                # a cell of one voxel (or box) is most likely a piece of a bigger cell cut off by the layer
                by.setdefault(c.count, [0, 0])[0 if getattr(c, "n_voxels", getattr(c, "boxes", 2)) > 1 else 1] += 1
        return ("Cells with a certified count (and single-voxel cells): " + "; ".join(
            f"{k} solutions: {n} (+{one})" for k, (n, one) in sorted(by.items()))
                + ". Thin cells are zoomed in the bottom row of the sections.")
    if number == 12:
        ud = summary.get("uniqueness_domains", {})
        return (f"{ud.get('count', len(ra.domains))} uniqueness domains found, certified lower bound "
                f"{ud.get('lower_bound', '?')}.")
    if number == 13:
        cid = top_cell(ra, jp)
        if cid is None:
            return "No joint cell carries certified regions at this depth."
        regs = [r.id for r in ra.regions if r.cell == cid]
        c = cell_by_id(jp)[cid]
        return (f"Cell {cid} has {c.count} certified solutions ({c.n_wa1} in WA1, {c.n_wa2} in WA2); the basic "
                f"regions above it: {regs}.")
    return ""


def figure_passage(number: int, analysis, summary: dict, files) -> str:
    """The report.md passage of the paper's figure ``number``: its content, our files, the numbers."""
    f = _by_number(number)
    have = set(files)
    lines = [f"**The paper's Figure {number}** shows {f.shows}. {_numbers(number, analysis, summary)}\n"]
    for name in f.files:
        path = f"figures/{name}"
        if path in have:
            lines.append(f"![Fig. {number} redrawn: {name}]({path})\n")
        else:
            lines.append(f"*({name} was not written in this run)*\n")
    return "\n".join(lines)

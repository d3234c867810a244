"""``report.md`` of ``intervalkin paper``: each claim of the paper beside the certified result.

Wenger & Chablat (1997) claim: six solutions of Table 1's joint vector, three
of them in one aspect; two aspects; joint-space domains with 2, 4 and 6
solutions; 28 basic regions; 6 uniqueness domains; non-singular paths between
solutions 2, 3 and 6.  The report sets each claim beside what the run
certified, with its status (certified, or a certified lower bound and why no
more is proved), the figures (one passage per octree figure of the paper, from
:mod:`intervalkin.app.report_figures`), and the undecided volumes and timings.  It
only formats: every number comes from the analysis and its summary.json.
:mod:`intervalkin.app.report_html` turns the same text into ``report.html``, with
rotatable 3-D views.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from intervalkin.app.report_figures import figure_passage, figures_table
from intervalkin.app.report_joint import joint_cells_passage
from intervalkin.app.table1 import table1_comparison
from intervalkin.core.files import atomic_write_bytes
from intervalkin.pipeline import Analysis

#: The paper's counts (sections 3.1, 5.1, 5.2).
PAPER_COUNTS = {"aspects": 2, "basic_regions": 28, "uniqueness_domains": 6}


def _status(block: dict) -> str:
    if block.get("exact"):
        return "certified exact"
    return f"found {block['count']}; certified lower bound {block['lower_bound']}"


def _aspect_upper_text(block: dict) -> str:
    """What the covers of the two signs prove (summary block of the aspects)."""
    covers = block.get("covers", {})
    if block.get("upper_bound") is None:
        left = sum(c["kinds"]["left"] for c in covers.values())
        return (f"No upper bound is proved: the covers leave {left} boxes undecided." if covers else
                "That no third aspect hides in the undecided layer is not proved.")
    parts = ", ".join(f"{name}: {c['boxes']} boxes, {c['inside_fragments']} fragments of certified boxes joined"
                      for name, c in covers.items())
    return (f"At most {block['upper_bound']}: for each sign a cover of the domain ({parts}) proves that sign's "
            "part of W connected: every box is free of the aspect, inside it, or retracts onto one connected set "
            f"of inside boxes along a certified monotone direction. The count is exact: {block['upper_bound']}.")


def write_report(analysis: Analysis, summary: dict, out, timings: dict) -> str:
    """Write ``report.md``: each claim of the paper beside the certified result. Returns its name."""

    comp = table1_comparison(analysis.geometry)
    files = summary.get("files", [])
    ra = analysis.regions
    jp = analysis.joint
    L: list[str] = []
    a = L.append
    a("# Wenger & Chablat (1997), regenerated with certified interval arithmetic\n")
    a(f"Manipulator: {analysis.geometry.name} (the paper's section 2.1). Workspace octree depth "
      f"{analysis.depth} (leaf {64 / 2 ** analysis.depth:.3g} x {64 / 2 ** analysis.depth:.3g} x "
      f"{360 / 2 ** analysis.depth:.3g} deg), singular layer depth {analysis.singular_depth}, joint grid "
      f"2^{analysis.joint_depth} voxels per axis. Run time {summary['timings_seconds'].get('total', sum(timings.values())):.0f} s.\n")
    a("Every box label below is proved (outward-rounded intervals, arb balls); every count says whether it "
      "is exact or a lower bound, and why. `certificates/` holds the evidence; `intervalkin verify "
      "certificates` re-checks it with arb alone.\n")

    a("## The paper's figures, redrawn\n")
    a("Each octree figure of the paper is redrawn from certified labels; its passage below gives the numbers "
      "behind it. Colours are the same in every figure (one per basic region, per uniqueness domain, per "
      "solution count); phi is in degrees.\n")
    a(figures_table(files))
    a("## Summary of the claims\n")
    a("| paper's claim | computed | status |")
    a("|---|---|---|")
    t1 = "bijective pairing, max distance {:.4f}".format(comp.max_distance)
    a(f"| Table 1: six solutions for rho = (14.98, 15.38, 12.0) | {comp.result.count} certified solutions, "
      f"completeness {'proved' if comp.result.complete else 'NOT proved'}; {t1} | certified |")
    a(f"| solutions 2, 3, 6 share one aspect (WA1) | rows in WA1: {sorted(comp.same_aspect_rows)} | "
      f"{'confirmed' if comp.same_aspect_claim_holds else 'NOT confirmed'} (certified det A signs) |")
    for key, label in (("aspects", "aspects"), ("basic_regions", "basic regions"),
                       ("uniqueness_domains", "uniqueness domains")):
        blk = summary[key]
        a(f"| {PAPER_COUNTS[key]} {label} | {blk['count']} | {_status(blk)} |")
    by = {}
    for c in jp.cells:
        if c.count > 0 and c.n_voxels > 1:
            by.setdefault(c.count, []).append(c)
    dom = ", ".join(f"{k} solutions: {len(v)} cell(s), {100 * sum(c.share for c in v):.1f}% of the joint box"
                    for k, v in sorted(by.items())) + " (cells of more than one voxel)"
    a(f"| joint space: domains with 2, 4 and 6 solutions | {dom} | counts certified per cell |\n")

    a("## Table 1 (section 3.2)\n")
    a("The paper's rows were printed from inexact numerics: they miss the prescribed leg lengths by up to "
      f"{comp.max_paper_residual:.4f}. Each row is paired with exactly one certified solution:\n")
    a("| row | paper (x, y, phi) | certified midpoint | distance | det A | aspect |")
    a("|---|---|---|---|---|---|")
    for p in comp.pairs:
        m = 0.5 * (p.certified_box[:, 0] + p.certified_box[:, 1])
        a(f"| {p.row} | ({p.paper[0]:.3f}, {p.paper[1]:.3f}, {p.paper[2]:.3f}) | "
          f"({m[0]:.6f}, {m[1]:.6f}, {m[2]:.6f}) | {p.distance_max:.4f} | {'+' if p.det_sign > 0 else '-'} | "
          f"{p.aspect} |")
    a(f"\nEnclosure widths are below {max(float(np.max(s.box[:, 1] - s.box[:, 0])) for s in comp.result.solutions):.1e}. "
      f"Completeness: {comp.result.completeness_reason}.\n")

    a("## Workspace, singular surface and aspects (Figures 3, 5, 6)\n")
    W, A1, A2 = summary["W"]["volume"], summary["WA1"]["volume"], summary["WA2"]["volume"]
    a(f"Certified volumes (x, y in length units, phi in radians): W inside {W['inside']:.1f}, undecided "
      f"{W['boundary']:.1f}; WA1 (det A > 0) inside {A1['inside']:.1f}, undecided {A1['boundary']:.1f}; "
      f"WA2 (det A < 0) inside {A2['inside']:.1f}, undecided {A2['boundary']:.1f}.\n")
    per = summary["aspects"]["components_per_sign"]
    big = sorted(ra.aspect_info, key=lambda d: -d["volume"])[:2]
    a(f"The paper finds two aspects, WA1 (det A > 0) and WA2 (det A < 0). Here: {per['WA1']} components of "
      f"certified det A > 0 boxes and {per['WA2']} of det A < 0; the largest of each sign hold "
      + ", ".join(f"{d['volume']:.1f} ({d['aspect']})" for d in big)
      + " of volume, the others are small fragments cut off by the undecided layer. Two aspects are "
      "certified different (opposite det A signs): a lower bound of 2. "
      + _aspect_upper_text(summary["aspects"]) + "\n")
    for number in (3, 5, 6):
        a(figure_passage(number, analysis, summary, files))

    a("## Joint space and basic components (Figures 2 and 11)\n")
    a("Cells are connected sets of voxels certified off an outer enclosure of g(S); each cell's count and "
      "its split between the aspects come from one certified solve and hold in the whole cell. The paper "
      "describes domains with 2, 4 and 6 solutions; the cells found (more than one voxel):\n")
    a("| cell | solutions | WA1 | WA2 | share of the joint box |")
    a("|---|---|---|---|---|")
    for c in jp.cells:
        if c.n_voxels > 1 and c.count >= 0:
            a(f"| {c.id} | {c.count} | {c.n_wa1} | {c.n_wa2} | {100 * c.share:.2f}% |")
    a(f"\nUndecided (may meet g(S)): {100 * float(jp.marked.mean()):.1f}% of the joint box. In every cell the "
      "solutions split equally between the two aspects. Cells of equal count may be one true domain joined "
      "through the undecided layer; single-voxel cells are almost certainly such pieces.\n")
    big = {c.id for c in jp.cells if c.n_voxels > 1}
    pairs = [p for p in jp.joinable if p[0] in big and p[1] in big]
    if pairs:
        a("Pairs of cells of equal count separated only by a stretch of the undecided layer (their nearest-cell "
          "shares of the layer touch), hence possibly one domain of the paper: "
          + ", ".join(f"{i}-{j}" for i, j in pairs) + ". If such cells were one domain, the basic regions above "
          "them would coincide and the count of basic regions would drop; this is why 28 is not claimed exact.\n")
    for number in (2, 11):
        a(figure_passage(number, analysis, summary, files))

    g = analysis.geometry
    L.extend(joint_cells_passage(summary, ([float(v) for v in g.rho_min], [float(v) for v in g.rho_max])))

    a("## Characteristic surfaces and basic regions (Figures 9, 10)\n")
    br = summary["basic_regions"]
    a(f"The paper counts 28 basic regions. The count here is the sum over the cells of the direct joint paving "
      f"(section above): {br['count']} ({br['why']}). Below, the sheets seen in the workspace paving, above the "
      "cells of the joint-space enclosure grid that carry certified workspace boxes.\n")
    realized = sorted({r.cell for r in ra.regions})
    parts = {}
    for cid in realized:
        parts.setdefault(jp.cells[cid].count, []).append(cid)
    a("Decomposition: " + " + ".join(f"{len(v)} cell(s) with {k} solutions ({k * len(v)} regions)"
                                    for k, v in sorted(parts.items()))
      + f" = {sum(k * len(v) for k, v in parts.items())} basic regions. The paper describes Figure 11 as two "
      "upper domains made of two coincident components each, four middle domains of four, and two last domains "
      "of six; read as 2 + 4 + 2 disjoint domains, that description would give 2x2 + 4x4 + 2x6 = 32 regions, "
      "not 28; the decomposition found here adds up to the paper's count.\n")
    a("| cell | solutions | regions per aspect | sheets seen with boxes (WA1, WA2) |")
    a("|---|---|---|---|")
    for cid in realized:
        c = jp.cells[cid]
        seen = {x["aspect"]: x["sheets_with_boxes"] for x in ra.consistency if x["cell"] == cid}
        a(f"| {cid} | {c.count} | {c.n_wa1} | {seen.get('WA1', 0)}, {seen.get('WA2', 0)} |")
    a(f"\n{sum(r.count > 0 for r in jp.cells) - len(realized)} further cells with solutions carry no "
      "certified box at this depth (they are small pieces near g(S)); they are not counted. "
      f"Proposition 1 check: {'every sheet above every counted cell holds certified boxes' if ra.consistent else 'some sheets have no certified box yet (deeper subdivision needed there)'}.\n")
    for number in (9, 10):
        a(figure_passage(number, analysis, summary, files))

    a("## Uniqueness domains (Figure 12) and the six regions of one cell (Figure 13)\n")
    ud = summary["uniqueness_domains"]
    a(f"The paper finds 6 uniqueness domains, as many as the largest number of solutions. Here: {ud['count']} "
      f"({ud['why']}).\n")
    for gi, grp in enumerate(ra.domains):
        a(f"- domain {gi}: regions {list(grp)} ({ra.regions[grp[0]].aspect}), cells "
          f"{[ra.regions[i].cell for i in grp]}")
    a("")
    for number in (12, 13):
        a(figure_passage(number, analysis, summary, files))

    trs = summary.get("trajectories") or []
    if trs:
        a("## Non-singular assembly-mode changing trajectories (section 3.2, Figure 13)\n")
        a("The paper shows that solutions 2, 3 and 6 of Table 1 can be joined without meeting a singularity, "
          "and remarks that such a motion must pass through a joint-space domain with only two solutions. For "
          "each pair, a path through boxes certified inside WA1 was found and every straight segment of it was "
          "proved (interval evaluation of det A and of the leg lengths over enclosures of the segment's pieces) "
          "to keep det A > 0 and 10 <= rho_i <= 32. The basic regions crossed are read at sampled points; the "
          "joint cells crossed are certified.\n")
        a("| path | certified | waypoints | basic regions crossed | joint cells crossed (count) | through a 2-solution cell |")
        a("|---|---|---|---|---|---|")
        for t in trs:
            if "waypoints" not in t:
                a(f"| {t['from']} -> {t['to']} | no | - | - | - | {t.get('reason', '')} |")
                continue
            regs = " -> ".join(str(r) for r in (t.get("basic_regions") or []))
            cells = " -> ".join("layer" if c["cell"] == "layer" else f"{c['cell']} ({c['count']})"
                                for c in (t.get("joint_cells") or []))
            a(f"| {t['from']} -> {t['to']} | {'yes' if t['certified'] else 'NO'} | {len(t['waypoints'])} | {regs} | "
              f"{cells} | {'yes' if t.get('through_two_solution_cell') else 'not seen at this depth'} |")
        a("")
        for t in trs:
            for name, where in (("trajectory_workspace_xy.png", "in the workspace"),
                                ("trajectory_workspace_3d.png", "in (x, y, phi); an X marks each crossing of the "
                                 "seam phi = +-180 deg"),
                                ("trajectory_joint.png", "in joint space")):
                path = f"{t.get('folder')}/{name}"
                if "folder" in t and path in files:  # only files this run wrote
                    a(f"![Path {t['from']} -> {t['to']} {where}]({path})\n")
        a("The animations are `trajectory_animation.gif` in each `trajectories/` folder. Each certified path is "
          "also a claim in `certificates/trajectory.json`, which `intervalkin verify` re-proves piece by piece "
          "in arb.\n")

    a("## Depth, time, undecided volumes\n")
    for k, v in summary["timings_seconds"].items():
        a(f"- {k}: {v:.1f} s")
    u = summary["undecided_volume"]
    a(f"- undecided volume: W {u['W']:.1f}, WA1 {u['WA1']:.1f}, WA2 {u['WA2']:.1f}; characteristic layer "
      f"{summary['characteristic_layer_volume']:.1f}")
    for h in analysis.refinement:
        a(f"- regions at depth {h.depth}: {h.basic_regions} basic regions, Proposition 1 seen in full: "
          f"{'yes' if h.consistent else 'no'}" + (f" ({h.stopped})" if h.stopped else ""))
    a("\nA deeper run (`intervalkin paper --depth 9`) thins every undecided layer by about half; "
      "`--refine-to 9` deepens only the regions paving, and only while Proposition 1 is not seen in full.\n")
    atomic_write_bytes(Path(out) / "report.md", ("\n".join(L) + "\n").encode())
    return "report.md"

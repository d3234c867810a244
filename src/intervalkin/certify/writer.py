"""The certificate folder: each claim intervalkin makes, with the evidence a sceptic needs.

:func:`write_certificates` turns the library's results into JSON files (the
claims are built by :mod:`~intervalkin.certify.solve_claims` and
:mod:`~intervalkin.certify.workspace_claims`); the independent checker
(:mod:`intervalkin.checker`, ``intervalkin verify DIR``) re-proves them from the
files alone with arb, without the paving, region or solver code.  This module
holds the specification of the format.

Schema (format ``"intervalkin-certificate"``, version 1)
-------------------------------------------------------
A certificate folder holds ``index.json`` and one file per claim type::

    index.json   {"format": "intervalkin-certificate", "version": 1, "kind": "index",
                  "geometry_toml": "<Geometry.to_toml()>", "files": ["dkp.json", ...],
                  "tool": {"name": "intervalkin", "version": "..."},
                  "omitted": [{"what": "...", "why": "..."}]}
    <kind>.json  {"format": ..., "version": 1, "kind": "<kind>",
                  "geometry_toml": "<the same text as the index>", "precision": 128,
                  "claims": [{"id": "...", ...}, ...]}

Conventions for every file:

* ``geometry_toml``: the manipulator as the exact decimal strings that were read
  (:meth:`~intervalkin.core.geometry.Geometry.to_toml`); the checker re-reads it with
  :func:`~intervalkin.core.geometry.parse_geometry` and requires every file to carry
  the index's text.
* Joint vectors are exact: decimal strings ``"14.98"`` when the value is a finite
  decimal, else ``"p/q"`` (never JSON numbers).
* A box is ``[[xlo, xhi], [ylo, yhi], [philo, phihi]]`` of binary64 numbers written
  in shortest round-trip form (Python ``repr``), phi in radians; the box is the
  set of reals between those binary64 values.
* ``precision``: arb working precision (bits) of the checker for the claim
  (a claim's own ``precision`` overrides the file's).
* ``statement``: human text; the checker never trusts it.

Claim fields by kind (``id`` is unique within its file):

``dkp``
    ``rho`` (3 exact strings), ``complete`` (bool), ``count``, ``phi0`` (binary64
    shift of t = tan((phi - phi0)/2), used when complete), ``solutions``:
    ``[{"box", "det_sign": 1 | -1}]``.  Proves: each box holds exactly one
    solution, with that sign of det A; with ``complete``, there are no others.
``joint_cell``
    ``cell`` (id in the joint paving), ``witness`` (3 exact strings), ``count``,
    ``n_wa1``, ``n_wa2``, ``phi0``, ``solutions`` as for dkp (always complete).
    Proves the witness's count and aspect split.  That the whole cell shares
    them rests on the library's enclosure of g(S) (not re-checked).
``aspect_distinct``
    ``boxes``: ``[{"box", "aspect": "WA1" | "WA2", "paving_index"}]``.  Proves
    each box inside W with that sign of det A on the whole box: two aspects.
``region_distinct``
    ``rho``, ``cell``, ``aspect``, ``solutions``: ``[{"box", "det_sign", "piece",
    "region", "paving_box": {"index", "box", "labels": {"W", "det_positive",
    "off_Sc"}}}]``.  Proves k distinct solutions of q in the aspect, each inside
    its paving box, whose W and det labels are re-proved; the off-S_c label and
    the piece / region ids are the library's (see the claim statement).
``box_labels``
    ``seed``, ``population`` (boxes in the paving), ``sample_size``, ``boxes``:
    ``[{"index", "box", "labels": {"W": 1|2|3, "det_positive": 1|2|3}}]``; the
    indices are :func:`intervalkin.checker.sample_indices` (seed, population,
    sample_size).  Labels: 1 OUTSIDE, 2 INSIDE, 3 BOUNDARY (claims nothing).
``trajectory``
    one claim per path (id ``"I-J"``): ``rho`` (3 exact strings), ``from``,
    ``to`` (solution numbers, 1-based in increasing phi, as ``intervalkin dkp``
    lists them), ``aspect``, ``det_sign``, ``phi0`` and ``solutions`` (the
    complete solution list of rho, as for dkp: it fixes the numbering),
    ``start_box``, ``goal_box`` (enclosures of the two end solutions, phi in
    [-pi, pi]), ``phi_turns`` (the path reaches the goal at its phi plus
    2 pi phi_turns: phi is unwrapped along the path), ``waypoints`` (m rows
    [x, y, phi] as hex strings, for the reader) and ``segments``:
    ``[{"start", "end", "pieces"}]`` exactly as
    :meth:`~intervalkin.space.trajectory_result.Trajectory.certificate` gives them: end point
    enclosures ``[[lo, hi]] * 3`` and pieces ``[[t0, t1], ...]``, every number a
    binary64 written EXACTLY as a hex string (``float.hex``).  Proves: the
    straight segments, each from any point of its start enclosure to any point
    of its end enclosure, keep det A of the aspect's sign and every leg within
    its limits; they join end to end from the exact start solution to the
    exact goal solution.
``aspect_connected``
    one claim per sign of det A (id and ``aspect`` "WA1" or "WA2"): ``domain``
    (hex floats), ``phi_divisor``, ``directions`` ([a, b, c] integers: e = (a, b,
    c / phi_divisor)) and ``boxes``: rows ``[level, i, j, k, code]`` of octree
    coordinates, code -1 OUT, -2 SINK, d >= 0 retracting along directions[d],
    OUT and SINK rows first, then retracting rows so that every box across an
    exit face comes earlier (:mod:`intervalkin.certify.aspect_claims`).  Proves:
    the aspect's part of W is nonempty and connected (checker.aspects).
``joint_fold_model``
    one claim per fold box (id ``"fold-<leaf>"``): ``box`` (the joint box, three
    ``[lo, hi]`` pairs of exact strings), ``axis`` (k, 0-based: the sheet is a graph
    q_k = h(q_i, q_j)), ``pose`` (the pose box X, binary64 as for dkp boxes),
    ``criterion`` (``{"name": "height_inside" | "normal_signs"}`` or ``{"name":
    "edge_heights", "along": b}``) and ``witnesses`` (``{"below": q, "above": q}``, exact
    joint vectors, either optional).  Proves: X holds every singular pose whose joint vector
    is in the box (up to 2 pi in phi), the parametric Krawczyk image of X over the box's
    (r_i, r_j) lies in its interior, and the criterion holds: g(S) meets the box in one
    graph sheet cutting it into two connected pieces; each witness lies on its side
    (:mod:`intervalkin.certify.joint_claims`, :mod:`intervalkin.checker.joint_models`).
``joint_join``
    ``cells`` (the library's cell ids of the two ends, for the reader), ``ends`` (two
    objects ``{"witness", "count", "n_wa1", "n_wa2", "phi0", "solutions"}`` as in a
    joint_cell claim), ``nodes`` (``{"clear": joint box}`` or ``{"fold": "<id of a
    joint_fold_model claim>", "side": -1 | 1}``, below or above its sheet) and ``links``
    (one exact joint vector between consecutive nodes).  Proves: both witnesses have the
    declared count and split and lie in one component of the open joint box minus g(S):
    each clear node is re-proved off g(S), each link lies in both its nodes
    (:mod:`intervalkin.checker.joint_join`).
``joint_separation.json`` and ``joint_separation.npz`` (beside the index, not listed in its
    ``files``: the arb checker does not read them; ``intervalkin verify`` re-proves them with
    :mod:`intervalkin.recheck.separation_file`)
    one claim per count barrier (:mod:`intervalkin.certify.separation_claims`): ``cell``,
    ``signature``, ``witness`` and ``others`` (witness objects as in a joint_cell claim),
    ``region`` (the claim's number: the npz rows ``region_lo/hi`` and ``barrier_lo/hi`` whose
    ``region_claim`` / ``barrier_claim`` equal it).  Proves: the cell's witness and the others
    lie in different components of the joint box minus g(S).
``counts``
    one claim per count: ``name`` (``aspects``, ``basic_regions``,
    ``uniqueness_domains``), ``lower_bound``, ``upper_bound`` (null: none
    declared), ``found`` (the library's number), ``exact`` (true only when the
    two bounds meet), ``support`` (references ``"file#id"`` to the claims that
    prove the bounds).

Writers build each solve claim, then run the checker on it before writing; a
claim the checker refuses is left out and listed under ``omitted`` in the index
with the reason (it is never written as if it held).
"""

from __future__ import annotations

import contextlib
import dataclasses
from pathlib import Path
from typing import Sequence

from intervalkin.certify.aspect_claims import aspect_connected_claims
from intervalkin.certify.joint_claims import joint_claims
from intervalkin.certify.separation_claims import PATTERN_BUDGET, pattern_barriers, separation_claims
from intervalkin.certify.solve_claims import (
    dkp_claim,
    joint_cell_claims,
    trajectory_claims,
)
from intervalkin.certify.workspace_claims import (
    aspect_distinct_claims,
    box_labels_claim,
    counts_claims,
    region_distinct_claims,
)
from intervalkin.checker import FORMAT, INDEX, KINDS, VERSION
from intervalkin.core.errors import InputError
from intervalkin.core.files import atomic_write, write_json, write_npz_columns
from intervalkin.core.geometry import Geometry
from intervalkin.core.workers import Beside
from intervalkin.core.version import __version__

#: The count barriers (:mod:`intervalkin.certify.separation_claims`), written beside the claim files.
SEPARATION_JSON, SEPARATION_NPZ = "joint_separation.json", "joint_separation.npz"

__all__ = ['write_certificates']


def write_certificates(
    out_dir: str | Path,
    geometry: Geometry,
    *,
    dkp_results: Sequence = (),
    joint=None,
    regions=None,
    paving=None,
    box_sample: int = 200,
    seed: int = 0,
    precision: int = 128,
    trajectories: Sequence = (),
    counts=None,
    aspect_topology=None,
    joint_cells=None,
    separations: bool = True,
    barrier_faces: int | None = None,
) -> list[Path]:
    """Write the certificate folder of the given results; return the paths written (index last).

    Parameters
    ----------
    out_dir : folder, created if needed.
    geometry : the manipulator the results are about.
    dkp_results : :class:`~intervalkin.solve.solutions.DkpResult` objects -> ``dkp.json``.
    joint : :class:`~intervalkin.space.joint_space.JointPaving` -> ``joint_cell.json`` (each
        certified cell's witness is re-solved).
    regions : :class:`~intervalkin.space.basic_region.RegionAnalysis` -> ``aspect_distinct``,
        ``region_distinct``, ``box_labels`` (on its paving) and ``counts``.
    paving : a workspace paving used for ``aspect_distinct`` and ``box_labels``
        when ``regions`` is None.
    box_sample : number of boxes in the ``box_labels`` sample (0: no sample).
    seed : seed of the sample (:func:`intervalkin.checker.sample_indices`).
    trajectories : :class:`~intervalkin.space.trajectory_result.Trajectory` objects ->
        ``trajectory.json`` (uncertified ones are omitted).
    precision : arb bits the checker starts with (raised per claim when needed).
    counts : the :class:`~intervalkin.space.basic_region.RegionCounts` to declare (default:
        ``regions.counts()``); the pipeline passes its own, whose basic regions are counted
        over the cells of the direct joint paving.
    aspect_topology : :class:`~intervalkin.space.aspect_topology.AspectTopology` ->
        ``aspect_connected.json`` (one claim per sign whose cover closed).  These claims are
        large (tens of thousands of boxes, several seconds of arb) and are written without the
        pre-check: ``intervalkin verify`` re-proves them.
    joint_cells : :class:`~intervalkin.space.joint_paving.JointSpacePaving` -> ``joint_fold_model.json``
        and ``joint_join.json`` when it has fold pieces (a capped selection, each claim checked
        first: :mod:`~intervalkin.certify.joint_claims`); with ``separations`` also the count barriers
        ``joint_separation.json`` and ``.npz`` beside the claim files (:mod:`~intervalkin.certify.separation_claims`:
        tens of seconds on the default paving; ``intervalkin verify`` re-proves them).
    barrier_faces : faces the pattern barriers may range in all (``--barrier-faces``; None: PATTERN_BUDGET):
        more certifies more separations, at about 5 ms a face.

    Every solve claim is re-checked with :mod:`intervalkin.checker` before it
    is written; refused ones are listed under ``omitted`` in ``index.json``.
    Each file is written atomically; ``index.json`` is written last.
    """
    if isinstance(box_sample, bool) or not isinstance(box_sample, int) or box_sample < 0:
        raise InputError(f"box_sample: expected an integer >= 0, got {box_sample!r}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    toml = geometry.to_toml()
    files: dict[str, list[dict]] = {}
    omitted: list[dict] = []

    wanted = joint_cells is not None and separations
    # the pattern floods are serial: a second process runs them while this one proves the other claims
    budget = PATTERN_BUDGET if barrier_faces is None else barrier_faces
    floods = Beside(pattern_barriers, joint_cells, geometry, precision, budget) if wanted else contextlib.nullcontext()
    with floods as side:
        dkp_list = []
        for k, res in enumerate(dkp_results):
            got, why = dkp_claim(geometry, res, f"q-{k}", precision)
            (dkp_list.append(got) if got else omitted.append({"what": f"dkp q-{k}", "why": why}))
        if dkp_list:
            files["dkp"] = dkp_list
        if joint is not None:
            cells, om = joint_cell_claims(geometry, joint, precision)
            omitted += om
            files["joint_cell"] = cells
        pav = regions.paving if regions is not None else paving
        if pav is not None:
            asp, om = aspect_distinct_claims(geometry, pav, precision)
            omitted += om
            files["aspect_distinct"] = asp
        if regions is not None:
            reg, om = region_distinct_claims(geometry, regions, joint, precision)
            omitted += om
            files["region_distinct"] = reg
        if pav is not None and box_sample > 0:
            files["box_labels"] = [box_labels_claim(pav, box_sample, seed, precision)]
        if trajectories:
            trj, om = trajectory_claims(geometry, trajectories, precision)
            omitted += om
            files["trajectory"] = trj
        if aspect_topology is not None:
            conn, om = aspect_connected_claims(aspect_topology)
            omitted += om
            files["aspect_connected"] = conn
        if joint_cells is not None:
            models, joins, om = joint_claims(geometry, joint_cells, precision)
            omitted += om
            if models:
                files["joint_fold_model"] = models
            if joins:
                files["joint_join"] = joins
        if regions is not None:
            aspect_refs = [f"aspect_distinct.json#{c['id']}" for c in files.get("aspect_distinct", [])]
            aspect_refs += [f"aspect_connected.json#{c['id']}" for c in files.get("aspect_connected", [])]
            # the counts lean on exactly the solves the library counted from (the joint cells' witnesses): an
            # extra solve (Table 1's) could prove a larger bound than the count printed beside it
            solve_refs = [f"joint_cell.json#{c['id']}" for c in files.get("joint_cell", [])]
            if counts is None and aspect_topology is not None:
                counts = regions.counts()
                counts = dataclasses.replace(counts, aspects=aspect_topology.count(counts.aspects))
            files["counts"] = counts_claims(regions, aspect_refs, solve_refs, counts)

        barriers = separation_claims(geometry, joint_cells, precision, patterned=side) if wanted else None
    if barriers is not None:
        omitted += barriers[2]

    written = []
    for kind in KINDS:
        if kind not in files:
            continue
        written.append(write_json(out / f"{kind}.json", {
            "format": FORMAT, "version": VERSION, "kind": kind, "geometry_toml": toml,
            "precision": precision, "claims": files[kind]}, indent=1))
    beside = []
    if barriers is not None and barriers[0]:
        beside = [write_json(out / SEPARATION_JSON, {
            "format": FORMAT, "version": VERSION, "kind": "joint_separation", "geometry_toml": toml,
            "claims": barriers[0]}, indent=1),
            atomic_write(out / SEPARATION_NPZ, lambda fh: write_npz_columns(fh, barriers[1]))]
    index = {
        "format": FORMAT,
        "version": VERSION,
        "kind": "index",
        "geometry_toml": toml,
        "files": [p.name for p in written],
        "tool": {"name": "intervalkin", "version": __version__},
        "omitted": omitted,
        "beside": [p.name for p in beside],
        "how_to_check": "intervalkin verify DIR (or intervalkin.checker.verify_directory(DIR))",
    }
    written.append(write_json(out / INDEX, index, indent=1))
    return written + beside

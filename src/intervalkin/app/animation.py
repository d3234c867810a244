"""A trajectory written out: ``trajectory.json``, its figures and the animation of the platform.

:func:`write_trajectory` writes the ``--json`` object of a
:class:`~intervalkin.space.trajectory_result.Trajectory` together with its
certificate (the evidence the checker re-proves), then
:func:`render_trajectory` draws

* the path in the workspace (x, y, phi in degrees; phi wrapped, so the path is
  cut where it crosses the seam phi = +-180 deg, and each crossing is marked at
  both ends) over the undecided singular layer of the paving, and its projection
  on the x-y plane with the base points, the solutions numbered as
  ``intervalkin dkp`` lists them;
* its image g(path) in joint space, a closed loop through the start joint vector,
  coloured by the certified solution count of the joint cell each piece maps
  into, and that count along the path (paper section 5.2, Fig. 13);
* the platform and legs moving along the path (a GIF with Pillow, PNG frames
  otherwise).

Every file is written atomically (:mod:`intervalkin.core.files`).  The figures
illustrate a certified motion; the certificate is in the JSON, not in them.
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg

from intervalkin.app.palette import colour_of
from intervalkin.app.plotting import base_points, draw_base_points, legend_outside, new_figure, pyplot, save_png
from intervalkin.app.units import JOINT_AXES, WORKSPACE_AXES
from intervalkin.core.files import atomic_write_bytes, write_json
from intervalkin.core.geometry import Geometry
from intervalkin.paving.tree import Paving
from intervalkin.space.joint_space import JointPaving
from intervalkin.space.path_search import metric_length, path_distance, wrap_phi
from intervalkin.space.singular_surface import may_be_singular
from intervalkin.space.trajectory_result import Trajectory

__all__ = ['render_trajectory', 'write_trajectory']

#: Resolution of the trajectory figures and frames.
_DPI = 110
#: Resolution and frame rate of the animation.
_GIF_DPI = 80
_FPS = 12


def _platform(geometry: Geometry, pose: np.ndarray):
    """Base points (3, 2) and platform points (3, 2) of a float pose (for drawing)."""
    base = np.array([[float(c) for c in a] for a in geometry.base])
    x, y, phi = pose
    c, s = math.cos(phi), math.sin(phi)
    pts = []
    for i in range(3):
        px, py = (float(v) for v in geometry.platform_point(i))
        pts.append((x + c * px - s * py, y + s * px + c * py))
    return base, np.array(pts)


def _segments_3d(samples: np.ndarray):
    """Split a path at the phi seam: list of (k, 3) arrays with wrapped phi (radians)."""
    w = samples.copy()
    w[:, 2] = wrap_phi(w[:, 2])
    jumps = np.flatnonzero(np.abs(np.diff(w[:, 2])) > math.pi) + 1
    return np.split(w, jumps)


def seam_crossings(samples: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Where a path crosses phi = +-pi: for each crossing, the point (x, y, phi) on each side of the seam.

    The two points share (x, y) (interpolated between the samples around the jump) and
    have phi = +pi and -pi in the order the path meets them, so a drawing can join the
    two ends of the cut.
    """
    out = []
    parts = _segments_3d(samples)
    for a, b in zip(parts[:-1], parts[1:]):
        p, q = a[-1], b[0]
        side = math.copysign(math.pi, p[2])
        # unwrap q next to p, then find where the straight piece reaches the seam
        q2 = q[2] + (2 * math.pi if side > 0 else -2 * math.pi)
        t = (side - p[2]) / (q2 - p[2]) if q2 != p[2] else 0.5
        xy = p[:2] + t * (q[:2] - p[:2])
        out.append((np.array([xy[0], xy[1], side]), np.array([xy[0], xy[1], -side])))
    return out


def render_trajectory(traj: Trajectory, geometry: Geometry, out: str | Path, paving: Paving | None = None,
                      joint: JointPaving | None = None, frames: int = 48) -> list[Path]:
    """Write the figures of a trajectory into folder ``out`` (atomically); returns the paths.

    * ``trajectory_workspace_3d.png``: the path in (x, y, phi), phi wrapped, over
      the singular layer of the paving (grey, subsampled) with the solutions numbered;
    * ``trajectory_workspace_xy.png``: its projection on the (x, y) plane;
    * ``trajectory_joint.png``: its image g(path) in joint space over the marked
      layer of the joint paving, coloured by the certified count of the cell, and
      the count along the path;
    * ``trajectory_animation.gif`` (Pillow) or ``trajectory_frames/frame_NNN.png``:
      the platform and legs moving.
    """
    plt = pyplot()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    rng = np.random.default_rng(0)
    sols = np.array([s.midpoint for s in traj.solutions]) if traj.solutions else np.zeros((0, 3))
    colour = "#1f77b4" if traj.sign > 0 else "#d62728"
    layer = None
    if paving is not None:
        sel = np.flatnonzero(may_be_singular(paving.labels))
        if sel.size > 6000:
            sel = np.sort(rng.choice(sel, 6000, replace=False))
        layer = 0.5 * (paving.lo[sel] + paving.hi[sel])
    title = (f"rho = ({', '.join(f'{float(v):g}' for v in traj.rho)}): solution {traj.i_from} -> {traj.i_to} "
             f"in {traj.aspect}, {'certified' if traj.certified else 'NOT certified'}")

    # 3-D workspace (phi in degrees)
    deg = 180.0 / math.pi
    fig = new_figure(8.8, 6.2)
    ax = fig.add_subplot(projection="3d")
    if layer is not None:
        ax.scatter(layer[:, 0], layer[:, 1], layer[:, 2] * deg, s=2, c=colour_of("state", "undecided"), alpha=0.5,
                   label="det A = 0 may occur (singular layer)")
    for k, part in enumerate(_segments_3d(traj.samples)):
        ax.plot(part[:, 0], part[:, 1], part[:, 2] * deg, color=colour, lw=2.5, label="path" if k == 0 else None)
    for k, (a, b) in enumerate(seam_crossings(traj.samples)):
        ax.plot(*[[a[i], b[i]] for i in range(2)], [a[2] * deg, b[2] * deg], color=colour, lw=0.8, ls=":",
                label="the two ends of a cut (same pose)" if k == 0 else None)
        ax.scatter([a[0], b[0]], [a[1], b[1]], [a[2] * deg, b[2] * deg], marker="X", s=45, color="k",
                   label="path crosses the seam φ = ±180°" if k == 0 else None)
    for i, s in enumerate(sols, 1):
        ax.scatter([s[0]], [s[1]], [s[2] * deg], color="k", s=18, label="solutions (numbered)" if i == 1 else None)
        ax.text(s[0], s[1], s[2] * deg, f" {i}", fontsize=9)
    ax.set_xlabel(WORKSPACE_AXES[0], fontsize=8)
    ax.set_ylabel(WORKSPACE_AXES[1], fontsize=8)
    ax.set_zlabel(WORKSPACE_AXES[2], fontsize=8)
    ax.set_zlim(-180, 180)
    ax.set_zticks([-180, -90, 0, 90, 180])
    ax.tick_params(labelsize=7)
    fig.suptitle(title, fontsize=9)
    legend_outside(fig, ax.get_legend_handles_labels()[0], markerscale=2)
    written.append(save_png(fig, out / "trajectory_workspace_3d.png", dpi=_DPI))
    plt.close(fig)

    # x-y projection
    fig = new_figure(8.6, 6.2)
    ax = fig.add_subplot()
    if layer is not None:
        ax.scatter(layer[:, 0], layer[:, 1], s=1, c=colour_of("state", "undecided"), alpha=0.5,
                   label="det A = 0 may occur (singular layer)")
    ax.plot(traj.samples[:, 0], traj.samples[:, 1], color=colour, lw=2, label="path")
    ax.plot(traj.waypoints[:, 0], traj.waypoints[:, 1], "o", color=colour, ms=3, label="waypoints")
    for k, (a, _) in enumerate(seam_crossings(traj.samples)):
        ax.plot(a[0], a[1], "X", color="k", ms=7, label="path crosses the seam φ = ±180°" if k == 0 else None)
    for i, s in enumerate(sols, 1):
        ax.plot(s[0], s[1], "k*", ms=8, label="solutions (numbered)" if i == 1 else None)
        ax.annotate(str(i), (s[0], s[1]), textcoords="offset points", xytext=(4, 4)).set_in_layout(False)
    draw_base_points(ax, base_points(geometry))
    # "datalim": the constrained layout misplaces a shrunk equal-aspect box next to a wide outside legend
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(WORKSPACE_AXES[0])
    ax.set_ylabel(WORKSPACE_AXES[1])
    fig.suptitle(title, fontsize=9)
    legend_outside(fig, ax.get_legend_handles_labels()[0])
    written.append(save_png(fig, out / "trajectory_workspace_xy.png", dpi=_DPI))
    plt.close(fig)

    # joint space
    fig = new_figure(14, 5.5)
    fig.get_layout_engine().set(wspace=0.1)  # room for the vertical label of the 3-D axes
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    if joint is not None:
        idx = np.argwhere(joint.marked)
        if idx.shape[0] > 8000:
            idx = idx[rng.choice(idx.shape[0], 8000, replace=False)]
        r0, h = joint.approx_grid()
        vox = r0 + (idx + 0.5) * h
        ax.scatter(vox[:, 0], vox[:, 1], vox[:, 2], s=2, c="0.6", alpha=0.2, label="enclosure of g(S)")
    counts = traj.sample_count if traj.sample_count is not None else np.full(len(traj.samples), -1)
    r = traj.sample_rho
    for c in sorted(set(counts.tolist())):
        m = counts == c
        ax.scatter(r[m, 0], r[m, 1], r[m, 2], s=4,
                   color=colour_of("count", c) if c >= 0 else colour_of("state", "singular"),
                   label=f"path in a cell of {c} solutions" if c >= 0 else "path where g may meet g(S)")
    ax.scatter(*[[float(v)] for v in traj.rho], color="k", s=40, marker="*", label="rho (start = end)")
    ax.set_xlabel(JOINT_AXES[0], fontsize=8)
    ax.set_ylabel(JOINT_AXES[1], fontsize=8)
    ax.set_zlabel(JOINT_AXES[2], fontsize=8)
    ax.tick_params(labelsize=7)
    ax.set_title("image g(path): a closed loop in joint space", fontsize=9)
    ax2 = fig.add_subplot(1, 2, 2)
    s_along = np.concatenate([[0.0], np.cumsum(path_distance(traj.samples[:-1], traj.samples[1:], metric_length(geometry)))])
    ax2.step(s_along, np.where(counts >= 0, counts, np.nan), where="post", color="k")
    ax2.scatter(s_along[counts < 0], np.full(np.count_nonzero(counts < 0), 0.5), s=3,
                color=colour_of("state", "singular"))
    ax2.set_yticks([0, 2, 4, 6])
    ax2.set_xlabel(f"length along the path (length units; a turn of dφ counts as {metric_length(geometry):.1f}·dφ, "
                   "the platform's rms radius)", fontsize=8)
    ax2.set_ylabel("certified number of solutions of g(X)")
    ax2.set_title("solution count along the path (joint cells)", fontsize=9)
    handles = ax.get_legend_handles_labels()[0]
    legend_outside(fig, handles, markerscale=3)
    written.append(save_png(fig, out / "trajectory_joint.png", dpi=_DPI))
    plt.close(fig)

    written += _render_animation(traj, geometry, out, frames)
    return written


def _render_animation(traj: Trajectory, geometry: Geometry, out: Path, frames: int) -> list[Path]:
    plt = pyplot()
    s = traj.samples
    L = metric_length(geometry)
    arc = np.concatenate([[0.0], np.cumsum(path_distance(s[:-1], s[1:], L))])
    targets = np.linspace(0.0, arc[-1], frames)
    poses = np.stack([np.interp(targets, arc, s[:, j]) for j in range(3)], axis=1)
    allpts = np.vstack([_platform(geometry, p)[1] for p in poses] + [_platform(geometry, poses[0])[0]])
    pad = 3.0
    xl = (allpts[:, 0].min() - pad, allpts[:, 0].max() + pad)
    yl = (allpts[:, 1].min() - pad, allpts[:, 1].max() + pad)

    fig, ax = plt.subplots(figsize=(6, 6))
    # the static parts are drawn once and the moving artists updated in place: clearing and redrawing the
    # axes for each frame cost about three times as much
    base = _platform(geometry, poses[0])[0]
    ax.plot(s[:, 0], s[:, 1], color="0.7", lw=1)
    ax.plot(base[:, 0], base[:, 1], "ks", ms=6)
    legs = [ax.plot([], [], color="0.3", lw=2)[0] for _ in range(3)]
    body = ax.fill([0, 0, 0], [0, 0, 0], color="#1f77b4" if traj.sign > 0 else "#d62728", alpha=0.5)[0]
    edge = ax.plot([], [], color="k", lw=1)[0]
    ax.set_xlim(*xl)
    ax.set_ylim(*yl)
    ax.set_aspect("equal")
    ax.set_xlabel(WORKSPACE_AXES[0], fontsize=8)
    ax.set_ylabel(WORKSPACE_AXES[1], fontsize=8)
    title = ax.set_title("", fontsize=9)

    def draw(k):
        plat = _platform(geometry, poses[k])[1]
        for i, leg in enumerate(legs):
            leg.set_data([base[i, 0], plat[i, 0]], [base[i, 1], plat[i, 1]])
        tri = np.vstack([plat, plat[:1]])
        body.set_xy(tri)
        edge.set_data(tri[:, 0], tri[:, 1])
        title.set_text(f"solution {traj.i_from} -> {traj.i_to} ({traj.aspect}), frame {k + 1}/{len(poses)}")
        return [*legs, body, edge, title]

    written: list[Path] = []
    try:
        from PIL import Image
    except ImportError:  # pragma: no cover - Pillow ships with matplotlib in practice
        Image = None
    if Image is not None:
        # blitting: the static background is rendered once, each frame redraws only the moving artists on it
        # (matplotlib's animation writers render every frame twice, in full)
        canvas = FigureCanvasAgg(fig)
        fig.set_dpi(_GIF_DPI)
        canvas.draw()
        background = canvas.copy_from_bbox(fig.bbox)
        images = []
        for k in range(len(poses)):
            canvas.restore_region(background)
            for artist in draw(k):
                ax.draw_artist(artist)
            images.append(Image.fromarray(np.asarray(canvas.buffer_rgba())[..., :3].copy()))
        gif = io.BytesIO()
        images[0].save(gif, format="GIF", save_all=True, append_images=images[1:], duration=1000 // _FPS, loop=0)
        written.append(atomic_write_bytes(out / "trajectory_animation.gif", gif.getvalue()))
    else:
        folder = out / "trajectory_frames"
        folder.mkdir(exist_ok=True)
        for k in range(len(poses)):
            draw(k)
            written.append(save_png(fig, folder / f"frame_{k:03d}.png", dpi=_DPI))
    plt.close(fig)
    return written


def write_trajectory(traj: Trajectory, geometry: Geometry, out: str | Path, paving: Paving | None = None,
                     joint: JointPaving | None = None) -> list[Path]:
    """``trajectory.json`` (the --json object plus the certificate) and the figures, atomically."""
    out = Path(out)
    doc = traj.to_json()
    doc["certificate"] = traj.certificate()
    doc["seconds"] = traj.seconds
    paths = [write_json(out / "trajectory.json", doc)]
    paths += render_trajectory(traj, geometry, out, paving=paving, joint=joint)
    return paths

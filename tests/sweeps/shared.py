"""The sweep file shared by the sweep tests: twelve designs around the paper's manipulator at depth 4.

The joint limits rho_max 34..40 are where the analysis is cheapest (about 2 s a design, against up to
15 s for rho_max 28 or 30, whose aspect covers are larger): the sweep tests check the sweep, not the
analysis, and the engine's killed-worker sweep computes all twelve."""

GRID = """
name = "scale x rho_max"
[analysis]
depth = 4
[vary]
"platform.scale" = { start = 0.8, stop = 1.2, step = 0.2 }
"limits.rho_max" = [34, 36, 38, 40]
"""

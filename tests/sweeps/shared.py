"""The sweep file shared by the sweep tests: twelve designs around the paper's manipulator at depth 4."""

GRID = """
name = "scale x rho_max"
[analysis]
depth = 4
[vary]
"platform.scale" = { start = 0.8, stop = 1.2, step = 0.2 }
"limits.rho_max" = [28, 30, 32, 36]
"""

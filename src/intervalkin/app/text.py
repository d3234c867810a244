"""Human-readable output of the direct kinematics: the table ``intervalkin dkp`` prints.

One row per certified solution, numbered from 1 in increasing phi: the box
midpoint (approximate), the largest enclosure width, the proved sign of det A,
the aspect and the status; then whether completeness ("no other solutions")
was proved.  The certified content is in the result, not in the rounding of
the printed digits.
"""

from __future__ import annotations

from intervalkin.core.exact import exact_text
from intervalkin.solve.dkp import DkpResult

__all__ = ['format_dkp_table']


# --------------------------------------------------------------------------------------
# Human output
# --------------------------------------------------------------------------------------
def format_dkp_table(result: DkpResult) -> str:
    """A human table: solutions numbered from 1 in increasing phi.

    Columns: x, y, phi (box midpoints, 12 decimals), the largest enclosure
    width, sign of det A, aspect, status; then whether completeness was proved.
    """
    rho = ", ".join(exact_text(r) for r in result.rho)
    lines = [f"rho = ({rho}): {result.count} solution(s)"]
    head = f"{'#':>2}  {'x':>18}  {'y':>18}  {'phi (rad)':>16}  {'width':>8}  {'det A':>5}  {'aspect':>6}  status"
    lines.append(head)
    lines.append("-" * len(head))
    for i, s in enumerate(result.solutions, 1):
        x, y, phi = s.midpoint
        sign = {1: "+", -1: "-"}.get(s.det_sign, "?")
        line = (f"{i:>2}  {x:>18.12f}  {y:>18.12f}  {phi:>16.12f}  {s.width:>8.1e}  {sign:>5}  "
                f"{s.aspect or '-':>6}  {s.status}")
        if s.status != "unique":
            line += f" ({s.reason})"
        lines.append(line)
    if result.complete:
        lines.append(f"completeness PROVED: no other solutions ({result.completeness_reason})")
    else:
        lines.append(f"completeness NOT proved: {result.completeness_reason}")
    return "\n".join(lines)

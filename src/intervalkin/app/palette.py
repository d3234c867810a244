"""One colour per thing, the same in every figure, in report.html and in the legends.

A reader who follows basic region 7 from the phi-slices to the 3-D view and to the
interactive report must see the same colour each time, so every drawing asks
:func:`colour_of` and none picks colours of its own.  Colours are hex strings,
which matplotlib and plotly both read, so this module imports neither.

Kinds of keys:

``"region"``  basic region id (0, 1, ...)
``"domain"``  uniqueness domain id (0, 1, ...)
``"count"``   certified number of solutions of a joint cell (0, 2, 4, 6; -1 unsolved)
``"aspect"``  ``"WA1"`` (det A > 0) or ``"WA2"`` (det A < 0)
``"state"``   a named set: ``"workspace"``, ``"undecided"``, ``"singular"``,
              ``"characteristic"``, ``"joint_space"``, ``"path"``

>>> colour_of("region", 3) == colour_of("region", 3 + len(REGION_COLOURS))
True
>>> colour_of("aspect", "WA1")
'#1f5fbf'
"""

from __future__ import annotations

__all__ = ["REGION_COLOURS", "DOMAIN_COLOURS", "COUNT_COLOURS", "ASPECT_COLOURS", "STATE_COLOURS", "colour_of"]

#: Basic regions: 32 colours far apart in hue and lightness (the first colours of Glasbey's
#: maximally distinct sequence, the palest replaced by darker ones so that thin pieces show on
#: white); no grey, which reads as "undecided".
REGION_COLOURS: tuple[str, ...] = (
    "#d60000", "#8c3bff", "#018700", "#00acc6", "#97ff00", "#ff7ed1", "#6b004f", "#ffa52f",
    "#573b00", "#005659", "#0000dd", "#00fdcf", "#a17569", "#7a6fd6", "#95b577", "#bf03b8",
    "#645474", "#790000", "#0774d8", "#c9a300", "#004b00", "#8e7900", "#ff7266", "#b85c5c",
    "#5d7e66", "#5fa8d3", "#eb0077", "#a57bb8", "#5900a3", "#03c600", "#9e4b00", "#9c3b4f",
)

#: Uniqueness domains: the Okabe-Ito set (distinct for colour-blind readers), then more.
DOMAIN_COLOURS: tuple[str, ...] = (
    "#e69f00", "#56b4e9", "#009e73", "#d55e00", "#0072b2", "#cc79a7", "#f0e442", "#7f3c8d",
    "#11a579", "#e73f74", "#3969ac", "#80ba5a",
)

#: Joint cells by certified number of solutions (-1: the cell's solve was not completed).
COUNT_COLOURS: dict[int, str] = {-1: "#7f7f7f", 0: "#efe3c2", 2: "#4aa3df", 4: "#f2a900", 6: "#c0262d"}

#: The two aspects (det A > 0, det A < 0).
ASPECT_COLOURS: dict[str, str] = {"WA1": "#1f5fbf", "WA2": "#d1495b"}

#: Named sets that are not numbered.
STATE_COLOURS: dict[str, str] = {
    "workspace": "#2e8b57",
    "joint_space": "#5b8bd0",
    "undecided": "#d9d9d9",
    "singular": "#565b70",
    "characteristic": "#ff9f1c",
    "path": "#111111",
}


def colour_of(kind: str, key) -> str:
    """The colour of ``key`` among the things of ``kind`` (see the module docstring).

    Numbered kinds wrap around their palette (region 32 has the colour of region 0);
    an unknown kind or key raises ``KeyError`` rather than inventing a colour.
    """
    if kind == "region":
        return REGION_COLOURS[int(key) % len(REGION_COLOURS)]
    if kind == "domain":
        return DOMAIN_COLOURS[int(key) % len(DOMAIN_COLOURS)]
    if kind == "count":
        return COUNT_COLOURS.get(int(key), "#9467bd")  # an odd count (never expected) still gets a colour
    if kind == "aspect":
        return ASPECT_COLOURS[str(key)]
    if kind == "state":
        return STATE_COLOURS[str(key)]
    raise KeyError(f"colour_of: unknown kind {kind!r}")

"""The one unit rule of motion files: metres per file unit, guessed from a body's height in file units.

Both readers of capture files use it: :func:`generation.formats.bvh.read_bvh` (the posed body's largest extent,
median over the frames) and the importer (:mod:`generation.mocap.importer`: the posed body's height along the up
axis, median over the frames). A caller that knows the unit passes it instead (``scale`` / ``--scale``).
"""
from __future__ import annotations

from generation.core.motion import MotionFormatError

#: (lowest height, highest height, metres per unit, name) of the units recognised from a body's height.
UNIT_BANDS = ((0.5, 3.0, 1.0, "metres"), (50.0, 300.0, 0.01, "centimetres"), (500.0, 3000.0, 0.001, "millimetres"))
#: The body height a file in no recognised unit is normalised to, metres.
NORMALISED_HEIGHT_M = 1.7


def guess_unit(height: float) -> tuple[float, str]:
    """(metres per file unit, how it was chosen) for a body ``height`` file units tall: 0.5..3 metres, 50..300
    centimetres, 500..3000 millimetres, else normalised to a 1.7 m body. MotionFormatError when the body has no
    height."""
    for low, high, scale, name in UNIT_BANDS:
        if low <= height <= high:
            return scale, name
    if not height > 0:
        raise MotionFormatError("the body has no vertical extent; cannot guess units (give the scale)")
    return NORMALISED_HEIGHT_M / height, f"unknown unit, normalised to a {NORMALISED_HEIGHT_M:g} m body"

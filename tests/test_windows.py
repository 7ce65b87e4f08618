"""generation.core.windows: the one window slicer, in the three ways its callers use it."""
from __future__ import annotations

from generation.core.windows import windows


def test_windows_reach_the_end_or_not_and_short_clips():
    assert windows(10, 4, 3) == [slice(0, 4), slice(3, 7), slice(6, 10)]
    assert windows(11, 4, 3) == [slice(0, 4), slice(3, 7), slice(6, 10), slice(7, 11)]     # one more to the end
    assert windows(11, 4, 3, to_end=False) == [slice(0, 4), slice(3, 7), slice(6, 10)]
    assert windows(3, 4, 3) == [] and windows(3, 4, 3, whole_if_short=True) == [slice(0, 3)]
    assert windows(4, 4, 0) == [slice(0, 4)]                                               # hop at least 1

"""The one window slicer: frame windows of a fixed length every ``hop`` frames, used by the real-capture observer
(:mod:`generation.quality.real_observer`), the real-capture training windows (:mod:`generation.gait.real_data`)
and the realism measures (:mod:`generation.quality.realism`)."""
from __future__ import annotations


def windows(num_frames: int, length: int, hop: int, *, to_end: bool = True, whole_if_short: bool = False
            ) -> list[slice]:
    """Slices of ``length`` frames starting every ``hop`` frames (at least 1) from frame 0.

    ``to_end``: one more window ending at the last frame when the hops do not land there. A clip shorter than
    ``length`` gives no window, or with ``whole_if_short`` one window of the whole clip."""
    if num_frames < length:
        return [slice(0, num_frames)] if whole_if_short and num_frames > 0 else []
    starts = list(range(0, num_frames - length + 1, max(1, hop)))
    if to_end and starts[-1] != num_frames - length:
        starts.append(num_frames - length)
    return [slice(a, a + length) for a in starts]

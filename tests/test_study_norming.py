"""The cyclic balanced incomplete design of a norming study (protocol.norming, no Django)."""
from collections import Counter

import pytest

from protocol.norming import (
    clip_order,
    cyclic_block,
    design_errors,
    min_ratings,
    ratings_per_clip,
    required_participants,
)


@pytest.mark.parametrize("c, m", [(14, 7), (22, 8), (71, 8), (16, 4), (8, 8), (5, 3)])
def test_balanced_over_participants_and_positions(c, m):
    n = c * m
    per_clip, per_position = Counter(), Counter()
    for i in range(n):
        block = cyclic_block(c, m, i)
        assert len(block) == len(set(block)) == m              # no clip twice for one participant
        per_clip.update(block)
        per_position.update((clip, p) for p, clip in enumerate(block))
    assert set(per_clip.values()) == {m * m}
    assert max(abs(k - m) for k in per_position.values()) <= 2 and len(per_position) == c * m
    for n_part in range(1, 3 * c):
        counts = Counter(x for i in range(n_part) for x in cyclic_block(c, m, i))
        low = min(counts.get(x, 0) for x in range(c))
        assert low == min_ratings(c, m, n_part) and max(counts.values()) - low <= 1


def test_needed_participants_and_errors():
    assert required_participants(22, 20, 8) == 55 and min_ratings(22, 8, 55) == 20 and min_ratings(22, 8, 54) == 19
    assert required_participants(6, 20, 8) == 20          # M capped at C: everyone sees every clip
    assert design_errors(22, 20, 8, 55) == []
    assert "plan at least 55 participants" in design_errors(22, 20, 8, 54)[0]
    assert "set the participant limit" in design_errors(22, 20, 8, 0)[0]
    assert design_errors(0, 20, 8, 10) == ["the pool matches no clip"]
    assert ratings_per_clip({"norming": {"ratings_per_clip": 12}}) == 12 and ratings_per_clip({}) is None
    assert clip_order(["b", "a", "c"], "s1") == clip_order(["c", "b", "a"], "s1")    # fixed, whatever the input order

"""The library as a Python caller (a script or a notebook) uses it: inputs left as they were,
errors that say what is wrong."""

from __future__ import annotations

import numpy as np
import pytest

from mdframework import Skeleton


def test_skeleton_leaves_the_callers_arrays_writeable() -> None:
    t = np.arange(0.0, 1.0, 0.01)
    pos = np.zeros((t.size, 1, 3))
    pos[:, 0, 0] = 10.0
    valid = np.ones((t.size, 1), dtype=bool)
    sk = Skeleton(t, pos, ("p",), valid)
    resampled = Skeleton.resampled(t, pos, ("p",))
    # the caller's arrays stay theirs to change ...
    assert t.flags.writeable and pos.flags.writeable and valid.flags.writeable
    t += 0.0
    pos[0, 0, 0] = 10.0
    # ... while the skeleton's own arrays are read-only (stages share skeletons)
    for skeleton in (sk, resampled):
        with pytest.raises(ValueError, match="read-only"):
            skeleton.positions[0, 0, 0] = 1.0
        with pytest.raises(ValueError, match="read-only"):
            skeleton.time[0] = 1.0
    with pytest.raises(ValueError, match="read-only"):
        sk.valid[0, 0] = False

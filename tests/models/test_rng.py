"""The counter-based normals: one compiled signature whatever the ids array's flags (a cold start loads one kernel)."""

import numpy as np

from ddmm.models.rng import _fill, normals, stream_key


def test_read_only_ids_draw_the_same_normals_through_one_signature():
    frozen = np.arange(6)
    frozen.flags.writeable = False  # as a pipeline's afferent ids are
    key = stream_key(1, 0, 0)
    assert np.array_equal(normals(key, frozen[:3], 3, 4), normals(key, [0, 1, 2], 3, 4))
    assert all(sig[1].mutable for sig in _fill.signatures)
    assert normals(key, 7, 0, 2).shape == (1, 2)

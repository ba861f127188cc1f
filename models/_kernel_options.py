"""Numba options of the kernels whose loops divide: under them the loops vectorise.

Under numba's default error model ("python") every float division checks its divisor so that it can raise
`ZeroDivisionError`, a branch in the loop's body that keeps LLVM from vectorising the loop.  Under
``error_model="numpy"`` a division by zero gives inf or nan, as IEEE 754 says, and the loop vectorises: the
same instructions on several afferents at once, so no bit changes.  The kernels that take `VECTOR_KERNEL`
divide only by what cannot be zero (a validated positive constant, a shear magnitude tested > 0) or select a
quotient away when its divisor is zero (the profile's two pieces, `ddmm.models.nap.boundary_radius`).

Measured (one core of a 2-core AVX-512 host, one-off): the profile AF of 12,584 afferents took 2.0 ns an
afferent against 14.7 ns under the default model; the hand's streaming front pass at contact onset, where the
shear direction moves each sample, 0.19 ms a push against 0.28-0.31 ms (three alternated pairs).  ``tests/models/test_kernel_options.py``
holds the vector division in the compiled code, and the pinned digests the bits.
"""

from __future__ import annotations

__all__ = ["VECTOR_KERNEL"]

#: ``nb.njit(**VECTOR_KERNEL)``: cached, GIL released, numpy's error model (module docstring).
VECTOR_KERNEL = {"cache": True, "nogil": True, "error_model": "numpy"}

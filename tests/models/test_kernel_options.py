"""The kernels whose loops divide compile under `VECTOR_KERNEL`, and their divisions vectorise.

Numba's default error model checks every divisor for zero, a branch that keeps a loop scalar; the kernels
below take numpy's model instead (`ddmm.models._kernel_options`).  The bits are the pinned digests'
(``tests/population/test_regression.py``); here, that the options are the ones named and that they make
the profile's divisions vector instructions.
"""

import re

import numba as nb
import numpy as np
import pytest

from ddmm.models import _fused_passes, _transducer_kernels, attenuation
from ddmm.models._kernel_options import VECTOR_KERNEL
from ddmm.models.currents import CurrentParams
from ddmm.models.fused import AfferentColumns, FusedPipeline
from ddmm.models.nap import get_profile, tip_radius

KERNELS = {
    "the front pass (profile AF, F_A, filters)": _fused_passes._front_range,
    "the profile AF of many directions": attenuation._af_kernel,
    "the transducers' first pass": _transducer_kernels.transduce_pre,
    "the transducers' middle pass": _transducer_kernels.transduce_mid,
    "the fused transducers' scaling": _transducer_kernels._scale_rows,
}
_VECTOR_DIVISION = re.compile(r"fdiv (?:\w+ )*<\d+ x double>")


@pytest.mark.parametrize("what", KERNELS)
def test_each_dividing_kernel_takes_the_vector_options(what):
    options = KERNELS[what].targetoptions  # the compiler's options (caching is the dispatcher's own)
    assert (options.get("error_model"), options.get("nogil")) == ("numpy", True), what
    assert VECTOR_KERNEL == {"cache": True, "nogil": True, "error_model": "numpy"}


def _profile_arguments(n=64):
    """Arguments of `_af_kernel`: two directions, ``n`` selective afferents at spread tuning angles."""
    prof = get_profile("selective")
    theta = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    coeffs = tuple(np.full(n, p) for p in (prof.p1, prof.p2, prof.p3, prof.p4, prof.p5))
    return (np.array([1.0, 0.0]), np.array([0.0, 1.0]), np.cos(theta), np.sin(theta), np.full(n, 3.0), coeffs,
            np.full(n, tip_radius("selective")))


def _compiled_ir(options, args) -> str:
    """LLVM IR of `_af_kernel` compiled afresh (the shipped one is cached, and cached code has no IR)."""
    fresh = nb.njit(**{k: v for k, v in options.items() if k != "cache"})(attenuation._af_kernel.py_func)
    fresh(*args)
    return "".join(fresh.inspect_llvm().values())


def test_the_profile_divisions_vectorise_under_the_options_and_not_under_the_default():
    args = _profile_arguments()
    shipped = _compiled_ir(attenuation._af_kernel.targetoptions, args)
    assert _VECTOR_DIVISION.search(shipped), "the profile's divisions are scalar"
    # The yardstick: numba's default model leaves the same loop scalar (so the check above can fail).
    assert not _VECTOR_DIVISION.search(_compiled_ir({"nogil": True}, args))


@pytest.mark.parametrize("f_th", [0.0, -0.1, float("nan")])
def test_the_pipeline_refuses_a_shear_threshold_it_would_divide_by(f_th):
    columns = AfferentColumns.filled(["SAI"], nap=["selective"], theta_t=[0.0], k=[3.0])
    FusedPipeline(columns, CurrentParams(), 1000.0, f_th=0.1)  # the yardstick: a positive threshold is taken
    with pytest.raises(ValueError, match="f_th"):
        FusedPipeline(columns, CurrentParams(), 1000.0, f_th=f_th)

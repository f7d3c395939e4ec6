"""Drivers compiled once per kernel-data type, with the block generator as a first-class
function.

A compiled driver that takes a kernel *dispatcher* as an argument cannot be cached by
numba, and it links (and re-optimises) the kernel's whole code into itself. Typed instead
with the kernel as a first-class function ``none(data, int64[::1], int64[::1],
float64[:, ::1])`` -- the signature of every block generator (the kernel drivers'
``traction_block``, the example kernels) -- the driver is compiled once per type of the
kernel's data, cached on disk, and calls the kernel through a pointer. The H-matrix build
(assembly.py), the one-shot product (product.py), the ACA entry points (aca.py) and the
kernel drivers' self-block maxima are compiled this way.
"""
from types import FunctionType

import numba
from numba import njit, types

#: Floating-point flags (numba's ``fastmath``) of the loops that are vectorised: LLVM may
#: reassociate sums (dot products, Gauss sums) while NaN and inf keep their meaning, so
#: finiteness checks stay meaningful. Used by the H-matrix engine's ACA, recompression and
#: matvec, and by the half-space point source's Gauss sum (:mod:`hmatddm.layered.okada_point3d`).
FAST = {"reassoc", "contract", "nsz", "arcp"}

#: Element indices, as the block generators take them.
INDEX = types.int64[::1]

_COMPILED = {}


def kernel_type(data_type):
    """The first-class function type of a block generator for kernel data ``data_type``."""
    return types.FunctionType(types.none(data_type, INDEX, INDEX, types.float64[:, ::1]))


def compiled_for_data(function, data, argument_types, result_type=None):
    """``function`` (a plain Python function in njit style, called as ``function(kernel,
    data, *arguments)``) compiled for the type of ``data``: the kernel as a first-class
    function, then ``data``, then arguments of ``argument_types``; ``result_type`` None
    lets numba infer it. Compiled (or loaded from numba's disk cache) once per process
    and data type."""
    data_type = numba.typeof(data)
    key = (function, data_type)
    compiled = _COMPILED.get(key)
    if compiled is None:
        arguments = (kernel_type(data_type), data_type) + tuple(argument_types)
        signature = arguments if result_type is None else result_type(*arguments)
        compiled = njit(signature, cache=True, nogil=True)(function)
        _COMPILED[key] = compiled
    return compiled


def serial_twin(dispatcher, **options):
    """The Python function of the ``parallel=True`` ``dispatcher`` compiled again without
    parallel launches (``njit(**options)``), under its own name ``<name>_serial``: the
    one-thread path of an operation skips the threading layer's fork and join.

    The twin must not be the same Python function: numba keys its on-disk cache by the
    function's qualified name, line and signature, not by the ``parallel`` flag, so a
    twin of the same function shares the parallel one's cache entries, and whichever
    compiles first is loaded for both. That made every H-matrix product serial once a
    small (serial) product had been compiled first (issue 40); a renamed copy has a cache
    of its own."""
    function = dispatcher.py_func
    twin = FunctionType(function.__code__, function.__globals__, function.__name__ + "_serial",
                        function.__defaults__, function.__closure__)
    twin.__qualname__ = function.__qualname__ + "_serial"
    twin.__doc__ = f"The serial twin of :func:`{function.__name__}` (:func:`hmatddm.compiled.serial_twin`)."
    return njit(**options)(twin)

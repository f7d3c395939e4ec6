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
import numba
from numba import njit, types

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

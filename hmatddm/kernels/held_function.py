"""A compiled function held in a kernel record and called through a pointer, so that it is
compiled once for all its callers (issue 32: the cold compile of the 3D layered kernel).

numba links every njit function a compiled function calls into the caller's library, and
LLVM optimises and generates machine code for all of it again there: a large per-pair
function called from the operator's block driver, from the stress at points and from the
drivers' typing of the per-kind functions is compiled once per caller. Called through a
first-class function value it is not linked: the caller calls its address (as
:mod:`hmatddm.compiled` hands the block generator to the H-matrix build). A kernel record
(``typing.NamedTuple``) holds such a value in a field (:class:`HeldFunction`); numba types
it as ``FunctionType(signature)`` and fetches the function's address when the record is
passed in from Python (the function compiled for that signature, or loaded from numba's
disk cache, once per process). A record type cannot contain a function of itself, so the
held function takes the record with its function fields set to None
(:func:`without_functions`), through a pointer (:func:`address_of`, :func:`dereference`;
both at once: :func:`held_record`) as its first argument; large tuples (a workspace) are
best passed the same way.

A call whose argument types differ from the held signature does not compile (numba's
check of first-class function calls): no call can reach the function with other types.
"""
import numba
from numba import types
from numba.core import cgutils
from numba.core.types import WrapperAddressProtocol
from numba.experimental.function_type import _get_wrapper_address
from numba.extending import intrinsic

from .drivers import _without_reference_count

#: Addresses of compiled functions, per (function, signature), in this process.
_ADDRESSES = {}


class HeldFunction(WrapperAddressProtocol):
    """``function`` (an njit dispatcher, ``cache=True``) as a value for a field of
    ``record`` (a kernel record whose function fields are None): called as
    ``function(address_of(without_functions(record)), *arguments)``, ``types_of(record)`` (a
    module-level function, evaluated once, when numba first types the record) giving the
    numba types ``(result, arguments)`` after the record's pointer. Pickles without its
    address."""

    def __init__(self, function, record, types_of):
        self.function = function
        self.record = record
        self.types_of = types_of
        self._signature = None

    def signature(self):
        if self._signature is None:
            result, arguments = self.types_of(self.record)
            self._signature = result(types.CPointer(numba.typeof(self.record)), *arguments)
        return self._signature

    def __wrapper_address__(self):
        key = (self.function, self.signature())
        address = _ADDRESSES.get(key)
        if address is None:
            address = _ADDRESSES[key] = _get_wrapper_address(self.function, key[1])
        return address

    def __reduce__(self):
        return HeldFunction, (self.function, self.record, self.types_of)


def _strip_functions(record):
    """The numba type of ``record`` (a NamedTuple type) with its first-class function
    fields as None."""
    fields = [types.none if isinstance(kind, types.FunctionType) else kind for kind in record.types]
    return types.NamedTuple(fields, record.instance_class)


def _stripped_value(context, builder, record, stripped, value):
    """The code of ``value`` (a ``record``) as its ``stripped`` type: the function fields
    None, the arrays borrowed."""
    out = cgutils.get_null_value(context.get_value_type(stripped))
    for k, kind in enumerate(record.types):
        if not isinstance(kind, types.FunctionType):
            item = _without_reference_count(context, builder, kind, builder.extract_value(value, k))
            out = builder.insert_value(out, item, k)
    return out


@intrinsic
def without_functions(typingctx, record):
    """``record`` (a kernel record) with its first-class function fields (:class:`HeldFunction`)
    set to None: the first argument of those functions. Its arrays are borrowed
    (:func:`hmatddm.kernels.drivers.borrowed`: no reference counts), so only for a call
    while ``record`` is alive."""
    stripped = _strip_functions(record)

    def codegen(context, builder, signature, args):
        return _stripped_value(context, builder, record, stripped, args[0])

    return stripped(record), codegen


@intrinsic
def address_of(typingctx, value):
    """A pointer (``CPointer``) to a copy of ``value`` on the caller's stack, its arrays
    borrowed (no reference counts): for a call while ``value`` is alive. A held function
    takes its large arguments so (:func:`dereference` inside): by value, the call passes
    every array's fields one by one, and compiling that marshalling cost about as much as
    the small callers' own code."""
    def codegen(context, builder, signature, args):
        model = context.data_model_manager[value]
        slot = cgutils.alloca_once(builder, model.get_data_type())
        builder.store(model.as_data(builder, _without_reference_count(context, builder, value, args[0])), slot)
        return slot

    return types.CPointer(value)(value), codegen


@intrinsic
def held_record(typingctx, record):
    """``address_of(without_functions(record))`` in one step: no stripped record between
    them, whose arrays numba would release one by one (code that LLVM optimises in every
    caller of a held function)."""
    stripped = _strip_functions(record)

    def codegen(context, builder, signature, args):
        value = _stripped_value(context, builder, record, stripped, args[0])
        model = context.data_model_manager[stripped]
        slot = cgutils.alloca_once(builder, model.get_data_type())
        builder.store(model.as_data(builder, value), slot)
        return slot

    return types.CPointer(stripped)(record), codegen


@intrinsic
def dereference(typingctx, pointer):
    """The value :func:`address_of` points to (borrowed, as it was stored)."""
    def codegen(context, builder, signature, args):
        return context.data_model_manager[pointer.dtype].load_from_data_pointer(builder, args[0])

    return pointer.dtype(pointer), codegen


__all__ = ["HeldFunction", "without_functions", "address_of", "held_record", "dereference"]

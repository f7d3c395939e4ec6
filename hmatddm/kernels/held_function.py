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
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.core.types import WrapperAddressProtocol
from numba.experimental.function_type import _get_wrapper_address
from numba.extending import intrinsic, typeof_impl
from numba.np.arrayobj import make_array, populate_array

from .drivers import _without_reference_count

#: Addresses of compiled functions, per (function, signature), in this process.
_ADDRESSES = {}
#: Signatures of held functions, per (``types_of``, the record's numba type), in this process.
_SIGNATURES = {}


def held_signature(types_of, record):
    """The signature ``result(CPointer(typeof(record)), *arguments)`` of a held function whose
    :class:`HeldFunction` takes ``types_of``, made once per record type: ``types_of`` types
    the workspace and the state (the layered 3D kernel's make their arrays in Python to type
    them), and a growing simulation makes a new record at every operator build (13 builds
    of ``shallow-sill``: 0.39 -> 0.26 s of CPU a run on an Intel Xeon at dgemm 73 GFLOP/s,
    1 thread; benchmarks/RESULTS.md, issue 32, twelfth session)."""
    record_type = numba.typeof(record)
    key = (types_of, record_type)
    found = _SIGNATURES.get(key)
    if found is None:
        result, arguments = types_of(record)
        found = _SIGNATURES[key] = result(types.CPointer(record_type), *arguments)
    return found


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
        self._type = None
        self._address = None

    def signature(self):
        if self._signature is None:
            self._signature = held_signature(self.types_of, self.record)
        return self._signature

    def numba_type(self):
        """``FunctionType(signature())``, made once: numba types the record's fields at
        every call from Python, and making the type again hashes the whole record type
        it holds (~150 us a held function a call on an Intel Xeon at dgemm ~73 GFLOP/s, 1
        thread; benchmarks/RESULTS.md, twelfth session)."""
        if self._type is None:
            self._type = types.FunctionType(self.signature())
        return self._type

    def __wrapper_address__(self):
        if self._address is None:  # per instance too: the key's hash is the signature's, deep
            key = (self.function, self.signature())
            address = _ADDRESSES.get(key)
            if address is None:
                address = _ADDRESSES[key] = _get_wrapper_address(self.function, key[1])
            self._address = address
        return self._address

    def __reduce__(self):
        return HeldFunction, (self.function, self.record, self.types_of)


@typeof_impl.register(HeldFunction)
def _typeof_held(value, context):
    """The held function's :meth:`HeldFunction.numba_type` (numba's own typeof of a
    wrapper-address object makes it anew at every call)."""
    return value.numba_type()


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


@intrinsic
def data_pointer(typingctx, array):
    """The address of a C-contiguous array's first element (``CPointer`` of its dtype),
    indexed as the flat array: no reference counts (numba calls ``NRT_incref`` and
    ``NRT_decref``, functions it never inlines, for each array an inlined function takes or a
    record's field it reads, ~10 calls a near-table lookup of the layered 3D kernel) and no
    check for a negative index. Valid while the array lives; for hot loops over arrays held
    elsewhere (a record, a workspace). A boolean array's pointer is of ``uint8`` (numba loads
    a boolean through a pointer as the byte it stores)."""
    if not isinstance(array, types.Array) or array.layout != "C":
        return None
    dtype = types.uint8 if isinstance(array.dtype, types.Boolean) else array.dtype

    def codegen(context, builder, signature, args):
        data = make_array(array)(context, builder, args[0]).data
        return builder.bitcast(data, context.get_value_type(signature.return_type))

    return types.CPointer(dtype)(array), codegen


def _array_leaves(kind, path=()):
    """``(path, array type)`` of every array in ``kind`` (an array, or tuples of them)."""
    if isinstance(kind, types.Array):
        return [(path, kind)]
    if isinstance(kind, types.BaseTuple):
        return [leaf for k, item in enumerate(kind.types) for leaf in _array_leaves(item, path + (k,))]
    return []


def _stash_dtor(module):
    """The destructor of a :func:`stash`'s buffer: releases the ``n`` meminfos stored after
    ``n`` at its start."""
    void_p = cgutils.voidptr_t
    fn = cgutils.get_or_insert_function(module, ir.FunctionType(ir.VoidType(), [void_p, cgutils.intp_t, void_p]),
                                        "_hmatddm_stash_dtor")
    if fn.is_declaration:
        fn.linkage = "linkonce_odr"
        builder = ir.IRBuilder(fn.append_basic_block())
        words = builder.bitcast(fn.args[0], cgutils.intp_t.as_pointer())
        decref = cgutils.get_or_insert_function(module, ir.FunctionType(ir.VoidType(), [void_p]), "NRT_decref")
        owners = builder.bitcast(builder.gep(words, [cgutils.intp_t(1)]), void_p.as_pointer())
        with cgutils.for_range(builder, builder.load(words)) as loop:
            builder.call(decref, [builder.load(builder.gep(owners, [loop.index]))])
        builder.ret_void()
    return fn


@intrinsic
def stash(typingctx, value):
    """``(buffer, pointer)``: ``value`` (a tuple of arrays, nested tuples of them) stored
    in a new uint8 array ``buffer`` with every array borrowed (no reference counts),
    ``pointer`` (``CPointer``) to it (:func:`dereference`, :func:`item`); the buffer holds a
    reference to each array and releases them when it is freed. A copy of ``(buffer,
    pointer)`` takes one reference, not one per array: numba takes and drops a reference
    on every array of an aggregate each time it copies it or passes it to an inlined
    function, and LLVM optimised those counts of a 69-array workspace in every caller
    (benchmarks/RESULTS.md, issue 32, twelfth session). The arrays are the same arrays,
    not copies."""
    leaves = _array_leaves(value)
    buffer_type = types.Array(types.uint8, 1, "C")
    result = types.Tuple((buffer_type, types.CPointer(value)))

    def codegen(context, builder, signature, args):
        model = context.data_model_manager[value]
        data_type = model.get_data_type()
        word = context.get_abi_sizeof(cgutils.intp_t)
        header = -(-(word * (1 + len(leaves))) // 16) * 16  # n, then the n owners
        size = header + context.get_abi_sizeof(data_type)
        meminfo = context.nrt.meminfo_alloc_dtor(builder, cgutils.intp_t(size), _stash_dtor(builder.module))
        data = context.nrt.meminfo_data(builder, meminfo)
        words = builder.bitcast(data, cgutils.intp_t.as_pointer())
        builder.store(cgutils.intp_t(len(leaves)), words)
        owners = builder.bitcast(builder.gep(words, [cgutils.intp_t(1)]), cgutils.voidptr_t.as_pointer())
        out = args[0]
        for n, (path, kind) in enumerate(leaves):
            leaf = args[0]
            for k in path:
                leaf = builder.extract_value(leaf, k)
            context.nrt.incref(builder, kind, leaf)  # the buffer's reference
            array = make_array(kind)(context, builder, value=leaf)
            builder.store(builder.bitcast(array.meminfo, cgutils.voidptr_t), builder.gep(owners, [cgutils.intp_t(n)]))
            array.meminfo = cgutils.get_null_value(array.meminfo.type)
            out = _insert_at(builder, out, path, array._getvalue())
        slot = builder.bitcast(builder.gep(data, [cgutils.intp_t(header)]), data_type.as_pointer())
        builder.store(model.as_data(builder, out), slot)
        buffer = make_array(buffer_type)(context, builder)
        populate_array(buffer, data=data, shape=cgutils.pack_array(builder, [cgutils.intp_t(size)]),
                       strides=cgutils.pack_array(builder, [cgutils.intp_t(1)]), itemsize=cgutils.intp_t(1),
                       meminfo=meminfo)
        return context.make_tuple(builder, result, [buffer._getvalue(), slot])

    return result(value), codegen


def _insert_at(builder, value, path, item):
    """``value`` with ``item`` at ``path`` (nested tuple indices)."""
    if len(path) == 1:
        return builder.insert_value(value, item, path[0])
    inner = _insert_at(builder, builder.extract_value(value, path[0]), path[1:], item)
    return builder.insert_value(value, inner, path[0])


@intrinsic
def item(typingctx, pointer, index):
    """``dereference(pointer)[index]`` (``index`` a constant) without loading the rest of
    the tuple (numba would release each of its arrays at the end of the loaded value's
    life: code for LLVM, though :func:`stash`'s arrays count no references)."""
    if not isinstance(index, types.IntegerLiteral):
        return None
    k = index.literal_value
    kind = pointer.dtype.types[k]

    def codegen(context, builder, signature, args):
        slot = builder.gep(args[0], [ir.Constant(ir.IntType(32), 0), ir.Constant(ir.IntType(32), k)])
        return context.data_model_manager[kind].load_from_data_pointer(builder, slot)

    return kind(pointer, index), codegen


__all__ = ["HeldFunction", "without_functions", "address_of", "held_record", "dereference", "stash", "item",
           "data_pointer"]

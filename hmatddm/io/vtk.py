"""VTK XML files for ParaView: meshes with per-element fields and time collections.

The ``.vtu`` files are written directly as XML (VTK file format 1.0, inline base64
binary, little endian, 64-bit headers), so writing needs neither VTK nor pyvista:

* a :class:`~hmatddm.mesh.Mesh3D` becomes one ``VTK_QUAD`` cell per rectangle (its four
  corners, counter-clockwise about the element normal);
* a :class:`~hmatddm.mesh.Mesh2D` becomes one ``VTK_LINE`` cell per segment, embedded in
  the plane ``z = 0``.

Each element keeps its own corner points (points are not shared between cells), so
the per-element (constant-DD) fields show as the piecewise-constant values they are.
Fields are cell data of shape ``(N,)`` or ``(N, k)``; in 2D, vectors of 2 components
are padded to 3 (``z = 0``) so that ParaView treats them as vectors.
The element's ``fracture_id`` is always written unless a field of that name is given.

Every file is written atomically (a temporary file in the same folder, then
``os.replace``), so a running ParaView or a crash never sees a half-written file.
"""
import base64
import os
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from .._validation import finite_scalar
from ..errors import InputError
from ..mesh import Mesh2D, Mesh3D
from .atomic import atomic_output

VTK_LINE = 3
VTK_QUAD = 9

_VTK_TYPE_NAMES = {
    np.dtype("<f8"): "Float64",
    np.dtype("<i8"): "Int64",
    np.dtype("u1"): "UInt8",
}


# ---------------------------------------------------------------------------------
# Input checks
# ---------------------------------------------------------------------------------

def _check_mesh(mesh):
    if not isinstance(mesh, (Mesh2D, Mesh3D)):
        raise InputError(f"mesh must be a Mesh2D or Mesh3D, got {type(mesh).__name__}")
    return mesh


def cell_field(name, values, n_elements, pad_to_3d=False):
    """One per-element field as a little-endian array ready for VTK.

    Parameters
    ----------
    name : str
        Field name (used in error messages and as the VTK array name).
    values : array_like, shape (N,) or (N, k)
        Floats, integers or booleans.
    n_elements : int
        Expected number of elements N.
    pad_to_3d : bool
        Pad 2-component vectors with a zero ``z`` component (2D meshes).

    Raises
    ------
    InputError
        Wrong type, wrong shape (the message gives the expected shape) or non-finite
        values (the message names the field).
    """
    if not isinstance(name, str) or not name.strip():
        raise InputError(f"cell_data names must be non-empty strings, got {name!r}")
    array = np.asarray(values)
    if array.dtype == object or not (np.issubdtype(array.dtype, np.number) or array.dtype == bool):
        raise InputError(f"cell_data[{name!r}] must be an array of numbers, got dtype {array.dtype}")
    if np.iscomplexobj(array):
        raise InputError(f"cell_data[{name!r}] must be real, got dtype {array.dtype}")
    if array.ndim not in (1, 2) or array.shape[0] != n_elements or (array.ndim == 2 and array.shape[1] < 1):
        raise InputError(f"cell_data[{name!r}] must have shape ({n_elements},) or ({n_elements}, k), "
                         f"one value per element, got {array.shape}")
    if array.dtype == bool:
        array = array.astype("u1")
    elif np.issubdtype(array.dtype, np.integer):
        array = array.astype("<i8")
    else:
        array = array.astype("<f8")
        bad = np.flatnonzero(~np.isfinite(array.reshape(n_elements, -1)).all(axis=1))
        if bad.size:
            raise InputError(f"cell_data[{name!r}] must contain only finite numbers; "
                             f"element {int(bad[0])} holds NaN or inf")
    if pad_to_3d and array.ndim == 2 and array.shape[1] == 2:
        array = np.column_stack([array, np.zeros(n_elements, dtype=array.dtype)])
    return np.ascontiguousarray(array)


# ---------------------------------------------------------------------------------
# Geometry as VTK cells
# ---------------------------------------------------------------------------------

def cells_of(mesh):
    """``(points (P, 3), connectivity (N, k), cell_type)`` of a mesh.

    3D: ``k = 4`` corners per ``VTK_QUAD``; 2D: ``k = 2`` end points per ``VTK_LINE``
    at ``z = 0``. Points are not shared between elements.
    """
    _check_mesh(mesh)
    n = mesh.n_elements
    if isinstance(mesh, Mesh3D):
        points = mesh.corners().reshape(-1, 3)
        return points, np.arange(4 * n, dtype=np.int64).reshape(n, 4), VTK_QUAD
    start, end = mesh.endpoints
    planar = np.stack([start, end], axis=1).reshape(-1, 2)
    points = np.column_stack([planar, np.zeros(len(planar))])
    return points, np.arange(2 * n, dtype=np.int64).reshape(n, 2), VTK_LINE


# ---------------------------------------------------------------------------------
# XML writing
# ---------------------------------------------------------------------------------

def _encoded(array):
    """Inline binary payload: base64 of a UInt64 byte count followed by the raw data."""
    data = np.ascontiguousarray(array).tobytes()
    header = np.array([len(data)], dtype="<u8").tobytes()
    return base64.b64encode(header + data).decode("ascii")


def _data_array(array, name=None, indent="        "):
    array = np.asarray(array)
    if array.dtype not in _VTK_TYPE_NAMES:
        array = array.astype("<f8" if np.issubdtype(array.dtype, np.floating) else "<i8")
    components = 1 if array.ndim == 1 else array.shape[1]
    attributes = f'type="{_VTK_TYPE_NAMES[array.dtype]}"'
    if name is not None:
        attributes += f" Name={quoteattr(name)}"
    attributes += f' NumberOfComponents="{components}" format="binary"'
    return f"{indent}<DataArray {attributes}>\n{indent}  {_encoded(array)}\n{indent}</DataArray>\n"


def _cell_data_attributes(fields):
    """The ``Scalars``/``Vectors`` hints ParaView uses to pick a default array."""
    scalars = next((name for name, values in fields.items() if values.ndim == 1), None)
    vectors = next((name for name, values in fields.items() if values.ndim == 2 and values.shape[1] == 3), None)
    attributes = ""
    if scalars is not None:
        attributes += f" Scalars={quoteattr(scalars)}"
    if vectors is not None:
        attributes += f" Vectors={quoteattr(vectors)}"
    return attributes


def _vtu_text(points, connectivity, cell_type, fields):
    n_cells, nodes_per_cell = connectivity.shape
    offsets = np.arange(1, n_cells + 1, dtype="<i8") * nodes_per_cell
    types = np.full(n_cells, cell_type, dtype="u1")
    parts = [
        '<?xml version="1.0"?>\n',
        '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n',
        "  <UnstructuredGrid>\n",
        f'    <Piece NumberOfPoints="{len(points)}" NumberOfCells="{n_cells}">\n',
        "      <Points>\n",
        _data_array(points.astype("<f8"), name="Points"),
        "      </Points>\n",
        "      <Cells>\n",
        _data_array(connectivity.reshape(-1).astype("<i8"), name="connectivity"),
        _data_array(offsets, name="offsets"),
        _data_array(types, name="types"),
        "      </Cells>\n",
        f"      <CellData{_cell_data_attributes(fields)}>\n",
        *(_data_array(values, name=name) for name, values in fields.items()),
        "      </CellData>\n",
        "    </Piece>\n",
        "  </UnstructuredGrid>\n",
        "</VTKFile>\n",
    ]
    return "".join(parts)


def write_vtu(path, mesh, cell_data=None):
    """Write ``mesh`` and its per-element fields as a VTK unstructured grid (``.vtu``).

    Parameters
    ----------
    path : str or Path
        Output file (conventionally ending in ``.vtu``); its folder is created if
        missing. Written atomically.
    mesh : Mesh2D or Mesh3D
    cell_data : dict[str, array_like], optional
        Per-element fields, each ``(N,)`` or ``(N, k)`` (e.g. ``opening`` (N,),
        ``dd`` (N, d)). Units are the caller's; SI is the convention.

    Returns
    -------
    Path
        The written file.

    Raises
    ------
    InputError
        A field of the wrong length or with NaN/inf (the message names the field and
        the expected shape), or a mesh of the wrong type.
    """
    _check_mesh(mesh)
    cell_data = {} if cell_data is None else cell_data
    if not hasattr(cell_data, "items"):
        raise InputError(f"cell_data must be a dict of name -> array, got {type(cell_data).__name__}")
    n = mesh.n_elements
    pad = isinstance(mesh, Mesh2D)
    fields = {name: cell_field(name, values, n, pad_to_3d=pad) for name, values in cell_data.items()}
    if "fracture_id" not in fields:
        fields["fracture_id"] = cell_field("fracture_id", mesh.fracture_id, n)
    points, connectivity, cell_type = cells_of(mesh)
    text = _vtu_text(points, connectivity, cell_type, fields)
    path = Path(path)
    with atomic_output(path) as temporary:
        temporary.write_text(text, encoding="ascii")
    return path


def _collection_file_name(folder, file_name):
    """A data-set file name as the ``.pvd`` stores it: relative to the ``.pvd`` folder
    when possible, with forward slashes."""
    file_name = Path(file_name)
    if file_name.is_absolute():
        try:
            file_name = Path(os.path.relpath(file_name, folder.resolve()))
        except ValueError:  # another drive on Windows: keep the absolute name
            pass
    return file_name.as_posix()


def write_pvd(path, entries):
    """Write a ParaView collection (``.pvd``) listing data sets over time.

    Parameters
    ----------
    path : str or Path
        Output file (conventionally ending in ``.pvd``). Written atomically.
    entries : list of (time, file_name)
        ``time`` in seconds (finite); ``file_name`` relative to the folder of ``path``
        (an absolute name is made relative when possible).

    Returns
    -------
    Path
    """
    path = Path(path)
    lines = ['<?xml version="1.0"?>\n',
             '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n',
             "  <Collection>\n"]
    for index, entry in enumerate(entries):
        try:
            time, file_name = entry
        except (TypeError, ValueError):
            raise InputError(f"entries[{index}] must be a pair (time, file_name), got {entry!r}") from None
        time = finite_scalar(f"entries[{index}] time", time)
        if not isinstance(file_name, (str, os.PathLike)) or not str(file_name):
            raise InputError(f"entries[{index}] file_name must be a non-empty path, got {file_name!r}")
        relative = _collection_file_name(path.parent, file_name)
        lines.append(f'    <DataSet timestep="{time!r}" group="" part="0" file={quoteattr(relative)}/>\n')
    lines += ["  </Collection>\n", "</VTKFile>\n"]
    with atomic_output(path) as temporary:
        temporary.write_text("".join(lines), encoding="utf-8")
    return path


# ---------------------------------------------------------------------------------
# Reading back
# ---------------------------------------------------------------------------------

def read_vtu(path):
    """Read a ``.vtu`` file: ``(points (P, 3), cells (N, k), cell_data dict)``.

    ``cells`` holds the point indices of each cell (all cells must have the same
    number of points, as in the files :func:`write_vtu` writes). Uses pyvista (VTK's
    own reader), so a file that reads here also reads in ParaView.
    """
    import pyvista

    path = Path(path)
    if not path.is_file():
        raise InputError(f"path must be an existing .vtu file, got {path}")
    grid = pyvista.read(path)
    cells_by_type = grid.cells_dict
    if len(cells_by_type) > 1:
        raise InputError(f"{path.name} mixes cell types {sorted(cells_by_type)}; read it with pyvista")
    cells = next(iter(cells_by_type.values())) if cells_by_type else np.empty((0, 0), dtype=np.int64)
    cell_data = {name: np.asarray(grid.cell_data[name]) for name in grid.cell_data.keys()}
    return np.asarray(grid.points, dtype=float), np.asarray(cells), cell_data


def read_pvd(path):
    """Read a ``.pvd`` collection: a list of ``(time, file_name)`` in file order."""
    import xml.etree.ElementTree as ElementTree

    root = ElementTree.parse(path).getroot()
    return [(float(node.get("timestep")), node.get("file")) for node in root.iter("DataSet")]


__all__ = ["write_vtu", "write_pvd", "read_vtu", "read_pvd", "cell_field", "cells_of", "VTK_LINE", "VTK_QUAD"]

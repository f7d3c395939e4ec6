"""VTU/PVD output: round trips through VTK's own reader, input checks, atomic writes."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.io import atomic_output, read_pvd, read_vtu, write_pvd, write_vtu
from hmatddm.io.vtk import VTK_LINE, VTK_QUAD


@pytest.fixture(scope="module")
def mesh3d():
    """A vertical 4 m x 2 m fracture (8 x 4) crossed by a perpendicular one (4 x 4)."""
    hydraulic = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 0, 1], 4, 2, 8, 4)
    natural = hd.mesh.rectangle([1, 0.5, 0], [0, 1, 0], [0, 0, 1], 2, 2, 4, 4, fracture_id=1)
    return hd.mesh.concatenate([hydraulic, natural])


@pytest.fixture(scope="module")
def mesh2d():
    crossing = hd.mesh.line([0.5, -0.5], [0.5, 0.5], 3, fracture_id=1)
    return hd.mesh.concatenate([hd.mesh.line([-1, 0], [1, 0], 6), crossing])


def _fields(mesh, seed=0):
    rng = np.random.default_rng(seed)
    n = mesh.n_elements
    return {"opening": rng.uniform(0, 1e-3, n), "dd": rng.normal(size=(n, mesh.dim)),
            "state": rng.integers(0, 3, n), "active": rng.random(n) < 0.5}


def test_vtu_3d_round_trip_keeps_cells_and_values(tmp_path, mesh3d):
    fields = _fields(mesh3d)
    path = write_vtu(tmp_path / "step.vtu", mesh3d, fields)
    points, cells, cell_data = read_vtu(path)
    n = mesh3d.n_elements
    assert cells.shape == (n, 4)
    np.testing.assert_allclose(points[cells], mesh3d.corners(), rtol=0, atol=1e-14)
    np.testing.assert_array_equal(cell_data["opening"], fields["opening"])
    np.testing.assert_array_equal(cell_data["dd"], fields["dd"])
    np.testing.assert_array_equal(cell_data["state"], fields["state"])
    np.testing.assert_array_equal(cell_data["active"], fields["active"].astype(np.uint8))
    np.testing.assert_array_equal(cell_data["fracture_id"], mesh3d.fracture_id)


def test_vtu_cell_types_are_quads_in_3d_and_lines_in_2d(tmp_path, mesh3d, mesh2d):
    import pyvista

    quads = pyvista.read(write_vtu(tmp_path / "a.vtu", mesh3d, {}))
    lines = pyvista.read(write_vtu(tmp_path / "b.vtu", mesh2d, {}))
    assert set(np.asarray(quads.celltypes)) == {VTK_QUAD}
    assert set(np.asarray(lines.celltypes)) == {VTK_LINE}


def test_vtu_2d_lies_at_z0_with_vectors_padded_to_3_components(tmp_path, mesh2d):
    fields = _fields(mesh2d)
    points, cells, cell_data = read_vtu(write_vtu(tmp_path / "crack.vtu", mesh2d, fields))
    start, end = mesh2d.endpoints
    assert cells.shape == (mesh2d.n_elements, 2)
    np.testing.assert_array_equal(points[:, 2], 0.0)
    np.testing.assert_allclose(points[cells[:, 0], :2], start, atol=1e-15)
    np.testing.assert_allclose(points[cells[:, 1], :2], end, atol=1e-15)
    assert cell_data["dd"].shape == (mesh2d.n_elements, 3)
    np.testing.assert_array_equal(cell_data["dd"][:, :2], fields["dd"])
    np.testing.assert_array_equal(cell_data["dd"][:, 2], 0.0)
    np.testing.assert_array_equal(cell_data["opening"], fields["opening"])


def test_user_fracture_id_field_wins_over_the_mesh_one(tmp_path, mesh2d):
    labels = np.arange(mesh2d.n_elements)
    _, _, cell_data = read_vtu(write_vtu(tmp_path / "a.vtu", mesh2d, {"fracture_id": labels}))
    np.testing.assert_array_equal(cell_data["fracture_id"], labels)


@pytest.mark.parametrize("values", [np.zeros(5), np.zeros((7, 3, 2)), np.zeros((0,))])
def test_field_of_wrong_shape_names_field_and_expected_shape(tmp_path, mesh3d, values):
    n = mesh3d.n_elements
    with pytest.raises(hd.InputError, match=rf"'opening'.*\({n},\)"):
        write_vtu(tmp_path / "a.vtu", mesh3d, {"opening": values})
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_field_is_refused_with_its_name(tmp_path, mesh2d, bad):
    values = np.ones((mesh2d.n_elements, 2))
    values[4, 1] = bad
    with pytest.raises(hd.InputError, match=r"'slip'.*element 4"):
        write_vtu(tmp_path / "a.vtu", mesh2d, {"slip": values})


def test_other_bad_inputs_raise_input_error(tmp_path, mesh2d):
    n = mesh2d.n_elements
    with pytest.raises(hd.InputError, match="mesh"):
        write_vtu(tmp_path / "a.vtu", "not a mesh", {})
    with pytest.raises(hd.InputError, match="names"):
        write_vtu(tmp_path / "a.vtu", mesh2d, {"": np.zeros(n)})
    with pytest.raises(hd.InputError, match="'label'"):
        write_vtu(tmp_path / "a.vtu", mesh2d, {"label": np.array(["a"] * n)})
    with pytest.raises(hd.InputError, match="cell_data"):
        write_vtu(tmp_path / "a.vtu", mesh2d, [np.zeros(n)])


def test_rewrite_replaces_the_file_and_leaves_no_temporary(tmp_path, mesh3d):
    path = tmp_path / "out" / "step.vtu"
    write_vtu(path, mesh3d, {"opening": np.zeros(mesh3d.n_elements)})
    write_vtu(path, mesh3d, {"opening": np.ones(mesh3d.n_elements)})
    assert [p.name for p in path.parent.iterdir()] == ["step.vtu"]
    np.testing.assert_array_equal(read_vtu(path)[2]["opening"], 1.0)


def test_atomic_output_keeps_the_old_file_when_writing_fails(tmp_path):
    path = tmp_path / "summary.json"
    path.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_output(path) as temporary:
            temporary.write_text("half")
            raise RuntimeError("crash while writing")
    assert path.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["summary.json"]


def test_pvd_lists_times_and_relative_names_readable_by_vtk(tmp_path, mesh3d):
    import pyvista

    names = []
    for step in range(3):
        path = write_vtu(tmp_path / f"step_{step:04d}.vtu", mesh3d, {"opening": np.full(mesh3d.n_elements, step)})
        names.append(path.name)
    times = [0.0, 0.5, 1.25]
    entries = [(times[0], names[0]), (times[1], tmp_path / names[1]), (times[2], names[2])]  # absolute made relative
    pvd = write_pvd(tmp_path / "series.pvd", entries)
    assert read_pvd(pvd) == list(zip(times, names))
    reader = pyvista.get_reader(pvd)
    np.testing.assert_allclose(reader.time_values, times)
    reader.set_active_time_value(1.25)
    grid = reader.read()[0]
    assert grid.n_cells == mesh3d.n_elements
    np.testing.assert_array_equal(grid.cell_data["opening"], 2.0)


@pytest.mark.parametrize("entries, message", [
    ([(float("nan"), "a.vtu")], "time must be a finite number, got nan"),
    ([("soon", "a.vtu")], "time must be a finite number, got 'soon'"),
    ([(0.0, "")], "file_name"),
    ([(0.0,)], r"entries\[0\] must be a pair"),
])
def test_pvd_bad_entries_raise_input_error(tmp_path, entries, message):
    with pytest.raises(hd.InputError, match=message):
        write_pvd(tmp_path / "series.pvd", entries)
    assert not (tmp_path / "series.pvd").exists()

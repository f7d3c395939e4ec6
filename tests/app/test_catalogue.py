"""The catalogue of a run (ref. Sec. 7.4): a small run whose natural fracture slips gives
events.csv and a map through `hmatddm run` and `hmatddm microseismic DIR`; the
[microseismic] scene section refuses bad input naming the key."""
import shutil

import numpy as np
import pytest

from hmatddm.app import cli
from hmatddm.errors import InputError
from hmatddm.app.catalogue import EVENTS_CSV, MAP_PNG, read_events_csv
from hmatddm.scene import load_scene, parse_scene

# a pressurised crack next to a critically stressed natural fracture (as tests/coupled/test_contact.py):
# its four elements fail remotely in the first step and slip
SLIP_SCENE = """
dimension = 2
height = 2.0
[material]
shear_modulus = 10e9
poisson_ratio = 0.25
[fluid]
viscosity = 1e-3
compressibility = 1e-9
[stress]
s_hmin = 9e6
s_hmax = 14e6
[[cluster]]
position = [0.0, 0.0]
rate = 1e-3
[[initial_fracture]]
shape = "line"
p0 = [-2.0, 0.0]
p1 = [2.0, 0.0]
element_size = 0.5
[leak_off]
pore_pressure = 5e6
[network]
friction_coefficient = 0.3
element_size = 0.5
[[natural_fracture]]
p0 = [2.133974596215561, 0.1]
p1 = [3.866025403784439, 1.1]
[numerics]
time_step = 1.0
end_time = 2.0
backend = "dense"
initial_pressure = 9.5e6
initial_opening = 1e-4
singular_correction = "average"
alpha = 1.0
[output]
snapshots = false
history_plot = false
"""
MICROSEISMIC = """
[microseismic]
wells = [[20.0, 0.0], [0.0, 20.0]]
"""


def _png_is_not_blank(path):
    from matplotlib.image import imread

    image = imread(path)
    return image.shape[0] > 100 and float(np.std(image[..., :3])) > 0.01


@pytest.fixture(scope="module")
def run_folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("slip")
    scene = folder / "slip.toml"
    scene.write_text(SLIP_SCENE + MICROSEISMIC)
    out = folder / "out"
    assert cli.main(["run", str(scene), "--out", str(out), "--quiet"]) == cli.EXIT_OK
    return folder, out


def test_run_writes_a_catalogue_with_exact_noise_free_locations(run_folder):
    _, out = run_folder
    columns = read_events_csv(out / EVENTS_CSV)
    assert len(columns["event"]) == 4  # the natural fracture's four elements
    np.testing.assert_array_equal(columns["time_s"], 1.0)  # they fail and slip in the first step
    np.testing.assert_allclose(columns["located_x_m"], columns["x_m"], atol=1e-6)
    np.testing.assert_allclose(columns["located_y_m"], columns["y_m"], atol=1e-6)
    assert np.all(columns["location_error_m"] < 1e-5)
    np.testing.assert_allclose(columns["area_m2"], 0.5 * 2.0)  # element length times the flow height
    assert np.all(columns["dc"] > 0.99)  # closed and slipping: shear events
    mu = 3000.0 * 2350.0 ** 2
    np.testing.assert_allclose(columns["M0_Nm"], mu * columns["potency_m3"], rtol=1e-5)
    np.testing.assert_allclose(columns["Mw"], 2 / 3 * np.log10(columns["M0_Nm"]) - 6.0, atol=1e-5)
    assert _png_is_not_blank(out / MAP_PNG)


def test_microseismic_command_on_a_finished_run(run_folder, tmp_path, capsys):
    # on a copy of the run: this test rewrites the catalogue that the test above reads
    folder, out = tmp_path, tmp_path / "out"
    shutil.copytree(run_folder[1], out)
    (out / EVENTS_CSV).unlink()
    (out / MAP_PNG).unlink()
    assert cli.main(["microseismic", str(out)]) == cli.EXIT_OK
    assert "4 microseismic events" in capsys.readouterr().out
    assert (out / EVENTS_CSV).is_file() and _png_is_not_blank(out / MAP_PNG)
    # another monitoring set-up from a scene file: one well with noise
    noisy = folder / "noisy.toml"
    noisy.write_text(SLIP_SCENE + "[microseismic]\nwells = [[20.0, 0.0]]\nrotation_noise_deg = 10.0\n"
                     "travel_time_noise = 2e-3\nseed = 3\n")
    assert cli.main(["microseismic", str(out), "--scene", str(noisy), "--quiet"]) == cli.EXIT_OK
    columns = read_events_csv(out / EVENTS_CSV)
    assert len(columns["event"]) == 4 and np.all(columns["location_error_m"] > 1e-3)
    # a well through an event: refused, naming the field
    x, y = float(columns["x_m"][0]), float(columns["y_m"][0])
    on_source = folder / "on_source.toml"
    on_source.write_text(SLIP_SCENE + f"[microseismic]\nwells = [[{x!r}, {y!r}]]\n")
    assert cli.main(["microseismic", str(out), "--scene", str(on_source)]) == cli.EXIT_BAD_INPUT
    assert "microseismic.wells: receiver" in capsys.readouterr().err
    # a scene without the section
    assert cli.main(["microseismic", str(out), "--scene", "kgd"]) == cli.EXIT_BAD_INPUT
    assert "has no [microseismic] section" in capsys.readouterr().err


@pytest.mark.parametrize("section, message", [
    ("wells = []", "microseismic.wells must hold at least one"),
    ("receiver_spacing = 5.0", r"microseismic.wells \(m\) is required"),
    ("wells = [[1.0, 2.0]]\nreceiver_spacing = 0.0", "microseismic.receiver_spacing must be > 0"),
    ("wells = [[1.0, 2.0]]\np_wave_speed = -4000.0", "microseismic.p_wave_speed must be > 0"),
    ("wells = [[1.0, 2.0]]\ns_wave_speed = 4000.0", "microseismic.s_wave_speed must be < sqrt"),
    ("wells = [[1.0, 2.0]]\nreceiver_bottom = 30.0", "microseismic.receiver_bottom must be <="),
    ("wells = [[1.0]]", r"microseismic.wells\[0\] must be a list of 2"),
    ("wells = [[1.0, 2.0]]\nwave_speed = 1.0", "unknown key 'microseismic.wave_speed'"),
])
def test_bad_microseismic_sections_name_the_key(section, message):
    with pytest.raises(InputError, match=message):
        parse_scene(SLIP_SCENE + "[microseismic]\n" + section + "\n")


def test_dfn_3cluster_has_a_microseismic_section():
    section = load_scene("dfn-3cluster").data["microseismic"]
    assert len(section["wells"]) == 2 and section["p_wave_speed"] == 4000.0


def test_events_of_a_simulation_object_match_those_of_its_run_folder(run_folder):
    from hmatddm.app.catalogue import events_from_run, onset_recorder, read_run, run_state_from_simulation
    from hmatddm.microseismic.sources import Medium, SlipOnset
    from hmatddm.scene import build_simulation

    folder, out = run_folder
    scene = load_scene(str(folder / "slip.toml"))
    simulation = build_simulation(scene.data)
    onset = SlipOnset()
    simulation.run(scene.numerics["end_time"], callback=onset_recorder(onset))
    medium = Medium()
    direct = events_from_run(run_state_from_simulation(simulation, onset, height=2.0), medium)
    from_folder = events_from_run(read_run(out), medium)
    assert len(direct) == len(from_folder) == 4
    np.testing.assert_allclose(direct.position, from_folder.position, atol=1e-9)
    np.testing.assert_allclose(direct.moment_tensor, from_folder.moment_tensor, rtol=1e-6,
                               atol=1e-6 * np.abs(direct.moment_tensor).max())
    np.testing.assert_array_equal(direct.time, from_folder.time)


def test_a_3d_run_folder_gives_the_events_of_its_elements(tmp_path):
    """The .vtu path in 3D (quads rebuilt into rectangles): two saved states, the second
    with one more slipping element, give the onsets and the moment tensors of the DDs."""
    import hmatddm as hd
    from hmatddm.io import write_pvd, write_vtu
    from hmatddm.app.catalogue import events_from_run, read_run
    from hmatddm.microseismic.sources import Medium, moment_tensor
    from hmatddm.app.runner import cell_fields

    mesh = hd.mesh.rectangle([0, 0, 0], [1, 1, 0], [0, 0, 1], 4.0, 2.0, 4, 2, fracture_id=3)
    tangent = mesh.frames[:, 0, :]
    dd = 1e-3 * tangent + 1e-4 * mesh.normals  # slip with a small opening: passes Eq. 7.29
    state = np.full(mesh.n_elements, 2)
    first = np.where(np.arange(mesh.n_elements) < 3, 1.0, 0.0)[:, None]
    stress = np.zeros((3, 3))
    write_vtu(tmp_path / "vtu/step-000001.vtu", mesh, cell_fields(mesh, dd * first, np.zeros(mesh.n_elements),
                                                                    stress, np.where(first[:, 0] > 0, 2, 1)))
    write_vtu(tmp_path / "vtu/step-000002.vtu", mesh, cell_fields(mesh, dd, np.zeros(mesh.n_elements), stress, state))
    write_pvd(tmp_path / "fractures.pvd", [(1.0, "vtu/step-000001.vtu"), (2.0, "vtu/step-000002.vtu")])
    medium = Medium()
    events = events_from_run(read_run(tmp_path), medium)
    assert len(events) == mesh.n_elements
    order = np.lexsort(events.position.T[::-1])
    expected_order = np.lexsort(mesh.centers.T[::-1])
    np.testing.assert_allclose(events.position[order], mesh.centers[expected_order], atol=1e-12)
    np.testing.assert_allclose(events.moment_tensor[order],
                               moment_tensor(dd, mesh.normals, mesh.areas, medium)[expected_order], rtol=1e-9,
                               atol=1e-9 * medium.shear_modulus * 1e-3)
    assert np.all(events.decomposition()[0] > 0)  # the opening part: positive ISO
    np.testing.assert_array_equal(np.sort(events.time), [1.0] * 3 + [2.0] * (mesh.n_elements - 3))

"""Checks of a scene before the engine starts (hmatddm.scene.preflight): the size
estimate and its refusals, and collocation points on element edges found in numpy
exactly where the kernels find them."""
import numpy as np
import pytest

import hmatddm as hd
import hmatddm.scene as hs
from hmatddm.elasticity import operator as operators
from hmatddm.errors import InputError
from hmatddm.scene import preflight
from scene_texts import KGD_2D_HEAD, RADIAL_3D_BODY

KGD = KGD_2D_HEAD + 'end_time = 2.0\nbackend = "dense"\n'


def test_near_singular_fraction_is_the_operators():
    assert preflight.NEAR_SINGULAR_FRACTION == operators.NEAR_SINGULAR_FRACTION


def _kernel_pairs(mesh):
    return operators.singular_pairs(mesh, operators.influence_data(mesh, hd.Elastic(10e9, 0.25)))


def _meshes_with_junctions():
    """T junctions, near misses at several gaps and clean crossings, in 2D and 3D."""
    main2 = hd.mesh.line([-2.0, 0.0], [2.0, 0.0], 4)  # centres at -1.5, -0.5, 0.5, 1.5
    for gap in (0.0, 0.1, 0.2, 0.3, 0.6):
        branch = hd.mesh.line([0.5, gap], [0.5, gap + 1.0], 2, fracture_id=1)  # ends `gap` above a centre
        yield hd.mesh.concatenate([main2, branch])
    yield hd.mesh.concatenate([main2, hd.mesh.line([1.0, -1.0], [1.0, 1.0], 2, fracture_id=1)])  # end on an end
    main3 = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 4.0, 4.0, 4, 4)
    for gap in (0.0, 0.15, 0.3, 0.8):
        wall = hd.mesh.rectangle([0.5, 0.0, gap + 1.0], [0, 1, 0], [0, 0, 1], 4.0, 2.0, 4, 2, fracture_id=1)
        yield hd.mesh.concatenate([main3, wall])
    tilted = hd.mesh.rectangle([0.3, 0.2, 0.4], [1, 0, 1], [0, 1, 0], 2.0, 2.0, 3, 3, fracture_id=1)
    yield hd.mesh.concatenate([main3, tilted])


def test_near_edge_pairs_match_the_kernels():
    found_some = False
    for mesh in _meshes_with_junctions():
        receivers, sources, gaps = preflight.near_edge_pairs(mesh)
        kernel_receivers, kernel_sources = _kernel_pairs(mesh)
        assert np.array_equal(receivers, kernel_receivers) and np.array_equal(sources, kernel_sources)
        assert np.all(gaps >= 0.0)
        found_some |= len(receivers) > 0
    assert found_some


def _scene(text, *overrides):
    return hs.parse_scene(text, overrides=list(overrides)).data


def test_a_t_junction_scene_is_refused_before_the_engine_with_the_fix():
    t_scene = KGD + '[[initial_fracture]]\nshape = "line"\np0 = [0.0, 0.0]\np1 = [0.0, 0.5]\nelement_size = 0.25\n'
    with pytest.raises(InputError, match=r"centre of element \d+ of initial_fracture\[0\].* is on an edge of element "
                                         r"\d+ of initial_fracture\[1\].*numerics.singular_correction = \"average\""):
        preflight.check_scene(_scene(t_scene))
    preflight.check_scene(_scene(t_scene, 'numerics.singular_correction="average"'))  # averaged: allowed


def test_estimate_counts_elements_from_the_numbers():
    size = preflight.estimate(_scene("dimension = 3\n" + RADIAL_3D_BODY))
    assert size.elements == 9 and size.natural_elements == 0 and size.unknowns == 4 * 9
    assert size.dense_bytes == 2 * 8.0 * 27 ** 2 and size.steps == 2 and size.backend == "dense"
    penny = _scene("dimension = 3\n" + RADIAL_3D_BODY.replace(
        "center = [0.0, 0.0, 0.0]\ne1 = [1.0, 0.0, 0.0]\ne2 = [0.0, 1.0, 0.0]\nlength = 3.0\nheight = 3.0",
        'shape = "penny"\nnormal = [0.0, 0.0, 1.0]\nradius = 5.0'))
    built = hd.mesh.penny([0, 0, 0], [0, 0, 1], 5.0, 1.0)
    assert abs(preflight.estimate(penny).elements - built.n_elements) <= 0.1 * built.n_elements
    text = "\n".join(preflight.estimate(penny).lines())
    assert "elements:" in text and "memory at the start: dense" in text and "per step" in text


def test_a_huge_scene_is_refused_naming_the_estimate_and_the_setting():
    huge = _scene("dimension = 3\n" + RADIAL_3D_BODY.replace("length = 3.0\nheight = 3.0\nelement_size = 1.0",
                                                             "length = 100.0\nheight = 100.0\nelement_size = 1e-4"))
    with pytest.raises(InputError, match=r"about 1,000,000,000,000 elements \(initial_fracture\[0\].*more than "
                                         r"numerics.max_elements = 200,000.*initial_fracture\[0\].element_size"):
        preflight.check_scene(huge)
    two_d = _scene(KGD.replace("element_size = 0.25", "element_size = 0.75e-6"), "numerics.max_elements=10000000")
    size = preflight.estimate(two_d)
    assert size.elements == 1_000_000
    if size.available_bytes is not None and size.memory_bytes > size.available_bytes:  # dense 2D at 1e6: 32 TB
        with pytest.raises(InputError, match=r"about 1,000,000 elements .* more than the .* available on this "
                                             r"machine; use a larger element_size \(initial_fracture\[0\]"):
            preflight.refuse_too_large(two_d, size)


def test_natural_elements_count_towards_the_limit_not_the_starting_operator():
    network = KGD + "[network]\nelement_size = 0.5\n[[natural_fracture]]\np0 = [2.0, -5.0]\np1 = [2.0, 5.0]\n"
    size = preflight.estimate(_scene(network))
    assert size.elements == 3 and size.natural_elements == 20 and size.total_elements == 23
    assert size.dense_bytes == 2 * 8.0 * 6 ** 2 and size.joined_bytes > size.memory_bytes
    assert "if every natural element joined the operator" in "\n".join(size.lines())
    with pytest.raises(InputError, match=r"about 23 elements .*3 elements\), 20 natural\), more than "
                                         r"numerics.max_elements = 10.*network.element_size"):
        preflight.check_scene(_scene(network, "numerics.max_elements=10"))

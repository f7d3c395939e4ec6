"""A dense operator whose matrix leads a grown mesh's (``ElasticityOperator(leading=)``):
the new elements' rows and columns from the kernels, the rest copied; the same matrix as a
full build, bit for bit (every entry is one pair's), and a growing run's grown meshes
bordered instead of assembled again; and ``dense_view``, the matrix read without a copy."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.elasticity.operator import leads
from hmatddm.simulation.growing_operator import GrowingOperator
from hmatddm.simulation.settings import OperatorSettings, RebuildSettings

ROCK = hd.Elastic(1e10, 0.25)


def _network_2d():
    """A crack and a branch meeting it at a near-miss junction, then two more elements."""
    main = hd.mesh.line([-1.0, 0.0], [1.0, 0.0], 10)
    branch = hd.mesh.line([0.3, 0.002], [0.9, 0.6], 4, fracture_id=1)
    more = hd.mesh.line([1.0, 0.0], [1.3, 0.0], 2, fracture_id=0)
    return hd.mesh.concatenate([main, branch]), hd.mesh.concatenate([main, branch, more])


def _network_3d():
    first = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 0, 1], 2.0, 1.0, 4, 2)
    crossing = hd.mesh.rectangle([0.5, 0.6, 0], [0.6, 0.8, 0], [0, 0, 1], 1.0, 1.0, 2, 2, fracture_id=1)
    grown = hd.mesh.rectangle([1.25, 0, 0], [1, 0, 0], [0, 0, 1], 0.5, 1.0, 1, 2)
    old = hd.mesh.concatenate([first, crossing])
    return old, hd.mesh.concatenate([first, crossing, grown])


@pytest.mark.parametrize("network", [_network_2d, _network_3d])
@pytest.mark.parametrize("options", [dict(singular_correction="average"),
                                     dict(singular_correction="average", alpha=2.0)])
def test_bordered_matrix_is_the_full_build_bit_for_bit(network, options):
    old, new = network()
    assert leads(old, new) and not leads(new, old)
    base = hd.ElasticityOperator(old, ROCK, **options)
    bordered = hd.ElasticityOperator(new, ROCK, leading=base, **options)
    full = hd.ElasticityOperator(new, ROCK, **options)
    assert np.array_equal(bordered.to_dense(), full.to_dense())
    # the same mesh again: the whole matrix copied
    assert np.array_equal(hd.ElasticityOperator(new, ROCK, leading=full, **options).to_dense(), full.to_dense())


def test_leading_is_refused_for_the_hmatrix_backend():
    old, new = _network_3d()
    with pytest.raises(hd.InputError, match="leading is for backend='dense' only"):
        hd.ElasticityOperator(new, ROCK, backend="hmatrix", leading=hd.ElasticityOperator(old, ROCK))


@pytest.mark.parametrize("change", ["material", "alpha", "mesh", "backend"])
def test_a_leading_operator_that_does_not_lead_is_refused(change):
    old, new = _network_2d()
    base = hd.ElasticityOperator(old, ROCK, singular_correction="average")
    if change == "material":
        arguments = dict(material=hd.Elastic(2e10, 0.25))
    elif change == "alpha":
        arguments = dict(alpha=2.0)
    elif change == "mesh":
        arguments = dict(mesh=hd.mesh.line([-1.0, 0.1], [1.0, 0.1], 12))
    else:
        base = hd.ElasticityOperator(old, ROCK, backend="hmatrix", singular_correction="average")
        arguments = {}
    arguments = dict(dict(mesh=new, material=ROCK, singular_correction="average"), **arguments)
    with pytest.raises(hd.InputError, match="leading must be a dense ElasticityOperator"):
        hd.ElasticityOperator(arguments.pop("mesh"), arguments.pop("material"), leading=base, **arguments)


def test_a_growing_dense_run_borders_its_operator(monkeypatch):
    from hmatddm.kernels import drivers

    assembled = []
    whole = drivers.traction_matrix

    def counting(data, out):
        assembled.append(out.shape[0])
        whole(data, out)

    monkeypatch.setattr(drivers, "traction_matrix", counting)
    old, new = _network_3d()
    operators = GrowingOperator(ROCK, OperatorSettings(backend="dense"), RebuildSettings())
    first = operators(old)
    grown = operators(new)
    assert operators.builds == 1 and assembled == [3 * old.n_elements]  # the grown one bordered
    assert operators.base is grown and grown is not first
    assert np.array_equal(grown.to_dense(), hd.ElasticityOperator(new, ROCK).to_dense())


def test_dense_view_is_the_matrix_read_only():
    old, _ = _network_3d()
    dense = hd.ElasticityOperator(old, ROCK)
    view = dense.dense_view()
    assert np.array_equal(view, dense.to_dense()) and not view.flags.writeable
    with pytest.raises(ValueError):
        view[0, 0] = 1.0
    compressed = hd.ElasticityOperator(old, ROCK, backend="hmatrix")
    assert np.array_equal(compressed.dense_view(), compressed.to_dense())

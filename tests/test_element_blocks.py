"""hmatddm.element_blocks: the compiled block-diagonal products against numpy's einsum."""
import numpy as np
import pytest

from hmatddm.element_blocks import apply_blocks, join_frame, split_frame


@pytest.mark.parametrize("d", [1, 2, 3])
def test_apply_blocks_is_einsum(d):
    rng = np.random.default_rng(d)
    blocks = rng.normal(size=(50, d, d))
    x = rng.normal(size=50 * d)
    expected = np.einsum("eij,ej->ei", blocks, x.reshape(50, d)).ravel()
    np.testing.assert_allclose(apply_blocks(blocks, x), expected, rtol=1e-14, atol=1e-14)
    # a strided view of the blocks (ContactRows.subset) is copied, not misread
    np.testing.assert_allclose(apply_blocks(blocks[::2], x[:25 * d]),
                               np.einsum("eij,ej->ei", blocks[::2], x[:25 * d].reshape(25, d)).ravel(), rtol=1e-14)
    with pytest.raises(ValueError, match="entries"):
        apply_blocks(blocks, x[:-1])


def test_split_and_join_frames_are_the_projections():
    rng = np.random.default_rng(9)
    frames = np.linalg.qr(rng.normal(size=(40, 3, 3)))[0].transpose(0, 2, 1)  # rows: e1, e2, n
    normals, axes = np.ascontiguousarray(frames[:, 2]), np.ascontiguousarray(frames[:, :2])
    x = rng.normal(size=120)
    opening, shear, largest_shear, largest = split_frame(x, normals, axes)
    vectors = x.reshape(40, 3)
    np.testing.assert_allclose(opening, np.einsum("ek,ek->e", vectors, normals), rtol=1e-13, atol=1e-14)
    np.testing.assert_allclose(shear, np.einsum("eak,ek->ea", axes, vectors).ravel(), rtol=1e-13, atol=1e-14)
    assert largest == np.abs(x).max() and largest_shear == pytest.approx(np.abs(shear).max(), rel=1e-15)
    np.testing.assert_allclose(join_frame(opening, shear, normals, axes), x, rtol=0, atol=1e-13)
    np.testing.assert_allclose(join_frame(opening, None, normals, axes), (opening[:, None] * normals).ravel(), rtol=1e-15)

"""The octahedral view atlas of baked impostors."""

import numpy as np
import pytest
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.impostors import octahedral as oc


@pytest.mark.parametrize("hemi", [False, True])
def test_encode_and_decode_are_inverse(hemi):
    rng = np.random.default_rng(0)
    d = rng.normal(size=(500, 3))
    if hemi:
        d[:, 2] = np.abs(d[:, 2])
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    uv = oc.encode(d, hemi)
    assert uv.min() >= 0 and uv.max() <= 1
    assert np.allclose(oc.decode(uv, hemi), d, atol=1e-12)


@pytest.mark.parametrize("hemi", [False, True])
def test_each_cell_shows_its_own_direction(hemi):
    views = oc.view_directions(8, hemi)
    assert np.allclose(np.linalg.norm(views, axis=-1), 1)
    cells = oc.cell_of(views.reshape(-1, 3), 8, hemi)
    j, i = np.divmod(np.arange(64), 8)
    assert np.array_equal(cells, np.stack([i, j], 1))
    if hemi:
        assert (views[..., 2] >= 0).all()
    else:
        assert (views[..., 2] < 0).any() and (views[..., 2] > 0).any()
    with pytest.raises(InvalidInputError):
        oc.view_directions(0)

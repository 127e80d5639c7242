"""Row gathers and scatters (`kernels.common.rows`): the same values as plain fancy indexing, whichever way
`put_blocks` writes."""

import numpy as np
import pytest
from tessera.kernels.common import rows


def naive_blocks(target, starts, blocks, offsets):
    out = target.copy()
    for i, s in enumerate(starts):
        block = blocks if blocks.ndim == 2 else blocks[i]
        value = block if offsets is None else block + offsets[i]
        out[s : s + block.shape[0]] = value
    return out


@pytest.mark.parametrize("n_rows", [1, 7, rows.BLOCK_ROWS - 1, rows.BLOCK_ROWS, 3 * rows.BLOCK_ROWS])
@pytest.mark.parametrize("shared", [True, False])
@pytest.mark.parametrize("dtype", [np.int32, np.int64, np.float64])
def test_put_blocks_writes_what_indexing_writes(n_rows, shared, dtype):
    """Short blocks (scattered row by row) and long ones (one slice each) give the rows fancy indexing gives:
    shared or per-owner blocks, index offsets on integer targets, gaps between the blocks left alone."""
    rng = np.random.default_rng(n_rows)
    k, width = 5, 3
    gaps = rng.integers(0, 4, k)
    starts = np.cumsum(gaps + n_rows) - n_rows  # the blocks in order, with gaps
    target = np.full((int(starts[-1]) + n_rows + 2, width), -7, dtype)
    shape = (n_rows, width) if shared else (k, n_rows, width)
    integer = np.issubdtype(dtype, np.integer)
    blocks = rng.integers(0, 1000, shape) if integer else rng.normal(size=shape)
    offsets = rng.integers(0, 10**6, k) if integer else None
    want = naive_blocks(target, starts, blocks.astype(dtype), offsets)
    rows.put_blocks(target, starts, blocks, offsets)
    assert target.dtype == dtype and np.array_equal(target, want)


def test_put_blocks_refuses_a_strided_target():
    target = np.zeros((10, 4), np.int32)[:, :3]
    with pytest.raises(ValueError):
        rows.put_blocks(target, np.array([0]), np.zeros((rows.BLOCK_ROWS, 3), np.int32))

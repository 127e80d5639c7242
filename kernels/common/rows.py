"""Whole-row gathers and scatters of 2-D arrays: each row is moved as one opaque item, which numpy copies several
times faster than element-wise fancy indexing of the same rows; `put_blocks` writes runs of consecutive rows (one
template block per owner) as slices."""

import numpy as np


def _row_view(a):
    row = np.dtype((np.void, a.dtype.itemsize * a.shape[1]))
    return np.ascontiguousarray(a).view(row).reshape(len(a))


def take_rows(table, index):
    """``table[index]`` for an (N, C) table and an integer index array (...). Returns (..., C), table's dtype."""
    index = np.asarray(index)
    return np.take(_row_view(table), index).view(table.dtype).reshape(index.shape + table.shape[1:])


def put_rows(target, rows, block):
    """``target[rows] = block`` for a C-contiguous (N, C) target, rows (k,) int and a (k, C) block of the same
    dtype (rows of another dtype or width are refused, never converted)."""
    if block.dtype != target.dtype or block.shape[1:] != target.shape[1:]:
        raise TypeError(f"rows of {block.dtype}{block.shape[1:]} into {target.dtype}{target.shape[1:]}")
    if not target.flags.c_contiguous:
        raise ValueError("put_rows needs a C-contiguous target")
    row = np.dtype((np.void, target.dtype.itemsize * target.shape[1]))
    target.view(row).reshape(len(target))[rows] = _row_view(block)


#: Rows per block from which `put_blocks` writes each block as one slice (a short Python loop over the owners)
#: instead of scattering every row by index (one vectorised pass, which pays per row).
BLOCK_ROWS = 256


def put_blocks(target, starts, blocks, offsets=None):
    """Write one block of R consecutive rows per owner: ``target[starts[i] + r] = blocks[i, r] + offsets[i]``.

    target: (N, C) C-contiguous; starts: (k,) int first row of each owner's block (the blocks do not overlap);
    blocks: (k, R, C), or (R, C) one block shared by every owner; offsets: (k,) integers added to an integer
    block, or None. The values are converted to target's dtype (index blocks: exact where the results fit, which
    the caller sizes target's dtype for). Long blocks are written slice by slice, short ones scattered row by row;
    both write the same values.
    """
    starts = np.asarray(starts, np.int64)
    blocks = np.asarray(blocks)
    n_rows = blocks.shape[-2]
    if len(starts) == 0 or n_rows == 0:
        return
    if not target.flags.c_contiguous:
        raise ValueError("put_blocks needs a C-contiguous target")
    shared = blocks.ndim == 2
    if n_rows >= BLOCK_ROWS:
        block = blocks.astype(target.dtype, copy=False)
        for i, s in enumerate(starts.tolist()):
            out = target[s : s + n_rows]
            source = block if shared else block[i]
            if offsets is None:
                out[...] = source
            else:
                np.add(source, target.dtype.type(offsets[i]), out=out)
        return
    rows = (starts[:, None] + np.arange(n_rows)).ravel()
    values = blocks[None] if shared else blocks
    if offsets is not None:
        values = np.asarray(offsets, np.int64)[:, None, None] + values
    values = np.broadcast_to(values, (len(starts),) + blocks.shape[-2:])
    put_rows(target, rows, np.ascontiguousarray(values, dtype=target.dtype).reshape(len(rows), -1))

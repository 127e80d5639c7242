"""Worker threads for array work that numpy runs without the GIL, and one BLAS thread while they run.

`kernels.tessellation.tessellate` evaluates positions, shading normals and attributes side by side once the
refinement exists. Each part writes its own arrays, so the result does not depend on the scheduling.
OpenBLAS would start its own threads inside every matrix product on top of ours; while the workers run
it is held to one thread (threadpoolctl, when installed; without it the results are the same, a little
slower).
"""

import threading
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager

try:
    from threadpoolctl import ThreadpoolController
except ImportError:  # optional: only the speed depends on it
    ThreadpoolController = None

#: Worker threads (the parts that run beside the caller's thread).
WORKERS = 2
_pool = []
_blas = []


def in_worker():
    """True on one of our worker threads (work it would hand to the pool and wait for runs in place instead: the
    pool may have no free thread)."""
    return threading.current_thread().name.startswith("tessera")


def submit(fn, *args):
    """Run ``fn(*args)`` on a worker thread; returns a `concurrent.futures.Future`."""
    if not _pool:
        _pool.append(ThreadPoolExecutor(max_workers=WORKERS, thread_name_prefix="tessera"))
    return _pool[0].submit(fn, *args)


@contextmanager
def parallel_section():
    """While inside, matrix products use one BLAS thread each (our own threads do the parallel work)."""
    if ThreadpoolController is None:
        yield
        return
    if not _blas:
        _blas.append(ThreadpoolController())
    with _blas[0].limit(limits=1, user_api="blas"):
        yield

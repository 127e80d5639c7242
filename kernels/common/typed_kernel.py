"""OpenCL kernels whose scalar arguments are packed by type, not converted one by one at each launch.

A pyopencl ``Kernel`` called with numpy scalars sets each through the buffer protocol, one Python round trip a
scalar argument, far more than the driver's own ``clSetKernelArg``: a displacement dab's dozen scalars then cost
many times the launch itself. With the types declared (``Kernel.set_scalar_arg_dtypes``) pyopencl packs them all
in one step. What a dab costs is measured by ``bench/displacement.py`` (``dab``) and kept in
``docs/performance.md``.

`TypedKernel` declares them from the call: each distinct signature (the numpy dtype of every scalar argument, None
for buffers and anything else) gets its own kernel object with those types. A scalar is packed as its own dtype,
so the bytes the device receives are the ones the untyped call passed.

A launch sets the kernel object's arguments and then enqueues it; OpenCL lets any call be made from any thread except
setting the arguments of one kernel object from two at once (``clSetKernelArg``), so each launch holds the object's
lock from the first argument to the enqueue.
"""

import threading

import numpy as np


class TypedKernel:
    """Called like a pyopencl kernel, ``kernel(queue, global_size, local_size, *args, **kwargs)``."""

    def __init__(self, cl, program, name):
        self._cl = cl
        self._program = program
        self.function_name = name
        self._kernels = {}  # signature -> kernel object with those scalar types
        self._lock = threading.Lock()  # held from setting a launch's arguments to its enqueue

    def for_signature(self, args):
        """The kernel object typed for ``args``."""
        signature = tuple(a.dtype if isinstance(a, np.generic) else None for a in args)
        kernel = self._kernels.get(signature)
        if kernel is None:
            kernel = self._cl.Kernel(self._program, self.function_name)
            kernel.set_scalar_arg_dtypes(list(signature))
            self._kernels[signature] = kernel
        return kernel

    def __call__(self, queue, global_size, local_size, *args, **kwargs):
        with self._lock:
            return self.for_signature(args)(queue, global_size, local_size, *args, **kwargs)

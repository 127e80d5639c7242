"""`typed_kernel.TypedKernel`: scalar arguments packed by their own dtype give the untyped call's bytes."""

import numpy as np
import pytest

pytestmark = pytest.mark.opencl


def test_a_typed_kernel_gives_the_untyped_calls_bytes(opencl):
    from tessera.kernels.common.typed_kernel import TypedKernel
    from tessera.kernels.displacement.map_dabs import MAP_PROGRAM
    from tessera.kernels.displacement.map_edit import _f2, _f4

    cl = opencl.cl
    program = opencl.program(MAP_PROGRAM)
    rng = np.random.default_rng(1)
    base = rng.normal(size=(40, 50, 4)).astype(np.float32)
    outs = []
    for kernel in (cl.Kernel(program, "draw"), TypedKernel(cl, program, "draw")):
        m = base.copy()
        buf = cl.Buffer(opencl.context, cl.mem_flags.READ_WRITE | cl.mem_flags.COPY_HOST_PTR, hostbuf=m)
        for pos, radius in (((20.25, 11.5), 9.0), ((3.0, 30.75), 14.5)):  # float2 / float4 structs, ints, floats
            kernel(opencl.queue, (50, 40), None, buf, np.int64(0), np.int32(50), np.int32(4), np.int32(0),
                   np.int32(0), np.int32(50), np.int32(40), _f2(pos), np.float32(radius), np.float32(0.3),
                   np.int32(2), _f4((0.5, -1.0, 2.0, 0.25)))
        cl.enqueue_copy(opencl.queue, m, buf)
        outs.append(m)
    assert outs[0].tobytes() == outs[1].tobytes() != base.tobytes()


def test_each_signature_gets_its_own_kernel_object(opencl):
    from tessera.kernels.common.typed_kernel import TypedKernel
    from tessera.kernels.displacement.map_dabs import MAP_PROGRAM

    kernel = TypedKernel(opencl.cl, opencl.program(MAP_PROGRAM), "morphing")
    buf = opencl.cl.Buffer(opencl.context, opencl.cl.mem_flags.READ_WRITE, 16)
    first = kernel.for_signature((buf, buf, buf, np.int64(4), np.float32(0.5)))
    assert kernel.for_signature((buf, buf, buf, np.int64(9), np.float32(0.1))) is first
    assert kernel.for_signature((buf, buf, buf, np.int32(4), np.float32(0.5))) is not first
    assert opencl.kernel(MAP_PROGRAM, "morphing") is opencl.kernel(MAP_PROGRAM, "morphing")

"""Kernel pieces several capabilities share: errors and tolerances, worker threads, the OpenCL runtime, mesh arrays and
topology, the camera, the tessellator's edge partition, curve and patch geometry, image I/O, the memory budget.
The module map: ``docs/architecture.md``."""

"""Displacement maps and the brushes that edit them ([Andrade 2012, ch. 5]: dabs, brushes, custom kernels), on the
OpenCL device or in the numpy reference, with tile undo. The module map: ``docs/architecture.md``."""

"""GLSL sources and the Python that declares, compiles (lazily, cached) and draws them: what the capabilities share
here, one subpackage per capability with its ``*.glsl`` beside its `draw` module."""

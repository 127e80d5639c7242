"""GLSL sources (files) and the Python that declares, compiles (lazily, cached) and draws them."""

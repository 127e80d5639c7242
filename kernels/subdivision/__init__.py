"""Loop subdivision of triangle meshes ([Concheiro et al.], Part A) and the compressed colours of its baked light.
The module map: ``docs/architecture.md``."""

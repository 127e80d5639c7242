"""PN-triangle, Phong and linear tessellation with adaptive, crack-free edge levels (seeds 000 and 001). The module
map: ``docs/architecture.md``."""

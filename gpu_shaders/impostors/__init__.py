"""Nailboards drawn on the GPU (seed 003 §B.4.1): the board's quad, a dependent lookup through the offset map, and
per-texel depth (`draw`)."""

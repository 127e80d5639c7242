"""Surfaces and curves generated where they are needed ([Nunes 2011, §2.3–2.4]): one-point parametric surfaces,
adaptive rational Bézier patches and adaptive curves. The module map: ``docs/architecture.md``."""

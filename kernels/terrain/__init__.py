"""Adaptive terrain level of detail from height maps and elevation data ([Nunes 2011, §5]), crack-free and
screen-space error bounded, read out of core. The module map: ``docs/architecture.md``."""

"""Ready-made models."""

from ._voussoir import benchmark_wall

__all__ = ["benchmark_wall"]

"""The reference arch's benchmarks (Pulatsu, Gonen & Lourenço 2021): each returns the dict of
its ``summary.json`` entry (see ``docs/benchmarks/``)."""

from ._voussoir import arch_impact, arch_static, impact_setups

__all__ = ["arch_impact", "arch_static", "impact_setups"]

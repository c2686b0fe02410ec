"""Generators: walls (running bond, multi-leaf, rubble), arches, vaults. Each returns a list of ``voussoir.Block``; add them with
``Model.add_blocks``."""

from ._voussoir import arch, barrel_vault, dome, multi_leaf_wall, rubble_wall, running_bond_wall

__all__ = ["arch", "barrel_vault", "dome", "multi_leaf_wall", "rubble_wall", "running_bond_wall"]

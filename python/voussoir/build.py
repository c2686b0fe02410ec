"""Generators: walls (running bond, multi-leaf, rubble), arches, vaults. Each returns a list of ``voussoir.Block``; add them with
``Model.add_blocks``. ``arch_joints`` gives the joints of ``arch``'s arch for
``voussoir.classify_joints``."""

from ._voussoir import arch, arch_joints, barrel_vault, dome, multi_leaf_wall, rubble_wall, running_bond_wall

__all__ = ["arch", "arch_joints", "barrel_vault", "dome", "multi_leaf_wall", "rubble_wall", "running_bond_wall"]

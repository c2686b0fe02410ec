"""Type stubs of the native module ``voussoir._voussoir`` (re-exported by ``voussoir``)."""

from os import PathLike
from typing import Any, Callable, Dict, Iterable, List, Literal, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

Vec3 = Union[Sequence[float], npt.ArrayLike]
Points = Union[Sequence[Sequence[float]], npt.ArrayLike]
Dof = Union[Literal["free", "fixed"], float]
FixitySpec = Union[bool, None, Literal["fixed", "free"], Dict[str, Sequence[Dof]]]
Path = Union[str, "PathLike[str]"]
Progress = Callable[[int, float], Optional[bool]]
JointSpec = Dict[str, Any]
FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

class VoussoirError(ValueError):
    """Bad input (block indices out of range name the argument), divergence, no convergence,
    a corrupt scene or checkpoint. Sizes beyond the library's limits raise MemoryError."""

class LimitInfeasibleError(VoussoirError):
    """Limit analysis with a live load: the dead loads are not carried (the dead-load question
    alone answers False instead of raising)."""

class LimitUnboundedError(VoussoirError):
    """Limit analysis: the live load's multiplier has no upper bound."""

class LimitSolverError(VoussoirError):
    """Limit analysis: the conic solver stopped without an answer or a certificate."""

class VoussoirIOError(OSError):
    """Reading or writing a file failed."""

class CoulombSlip:
    def __init__(
        self,
        kn: float,
        ks: float,
        friction_deg: float,
        residual_friction_deg: Optional[float] = None,
        cohesion: float = 0.0,
        tensile_strength: float = 0.0,
    ) -> None: ...
    @staticmethod
    def dry(kn: float, ks: float, friction_deg: float) -> "CoulombSlip": ...
    @property
    def kn(self) -> float: ...
    @property
    def ks(self) -> float: ...
    @property
    def friction_deg(self) -> float: ...
    @property
    def residual_friction_deg(self) -> float: ...
    @property
    def cohesion(self) -> float: ...
    @property
    def tensile_strength(self) -> float: ...

class MortarJoint:
    """A mortared joint that cracks in tension and shear and softens by its fracture energies
    (J/m²) per unit area, whatever the sub-contact count; each fracture energy is required with
    its strength (0: brittle). With ``cap_strength`` (Pa) and ``cap_fracture_energy`` (J/m²) it
    crushes on Lourenço–Rots' compression cap ``σ² + C_ss τ² ≤ σ_c²`` (``cap_shear_factor``
    ``C_ss``, ``cap_peak_closure`` the plastic closure at the peak in m). The fracture energy
    consumed, crushing included, is ``Model.energies()["fracture"]``."""
    def __init__(
        self,
        kn: float,
        ks: float,
        friction_deg: float,
        residual_friction_deg: Optional[float] = None,
        tensile_strength: float = 0.0,
        mode_i_fracture_energy: Optional[float] = None,
        cohesion: float = 0.0,
        mode_ii_fracture_energy: Optional[float] = None,
        dilatancy_deg: float = 0.0,
        softening: Literal["exponential", "linear"] = "exponential",
        cap_strength: Optional[float] = None,
        cap_fracture_energy: Optional[float] = None,
        cap_shear_factor: float = 9.0,
        cap_peak_closure: float = 0.0,
    ) -> None: ...
    @property
    def kn(self) -> float: ...
    @property
    def ks(self) -> float: ...
    @property
    def friction_deg(self) -> float: ...
    @property
    def residual_friction_deg(self) -> float: ...
    @property
    def dilatancy_deg(self) -> float: ...
    @property
    def tensile_strength(self) -> float: ...
    @property
    def mode_i_fracture_energy(self) -> float: ...
    @property
    def cohesion(self) -> float: ...
    @property
    def mode_ii_fracture_energy(self) -> float: ...
    @property
    def softening(self) -> Literal["exponential", "linear"]: ...
    @property
    def cap_strength(self) -> Optional[float]: ...
    @property
    def cap_fracture_energy(self) -> Optional[float]: ...
    @property
    def cap_shear_factor(self) -> Optional[float]: ...
    @property
    def cap_peak_closure(self) -> Optional[float]: ...

class LinearElastic:
    def __init__(self, kn: float, ks: float) -> None: ...
    @property
    def kn(self) -> float: ...
    @property
    def ks(self) -> float: ...

JointLaw = Union[CoulombSlip, MortarJoint, LinearElastic]

class Block:
    @staticmethod
    def cuboid(
        name: str,
        min: Vec3,
        max: Vec3,
        density: float,
        *,
        material: int = 0,
        fixed: FixitySpec = None,
        velocity: Optional[Vec3] = None,
        angular_velocity: Optional[Vec3] = None,
    ) -> "Block": ...
    @staticmethod
    def from_vertices(
        name: str,
        vertices: Points,
        density: float,
        *,
        faces: Optional[Sequence[Sequence[int]]] = None,
        material: int = 0,
        fixed: FixitySpec = None,
        velocity: Optional[Vec3] = None,
        angular_velocity: Optional[Vec3] = None,
    ) -> "Block": ...
    def with_material(self, material: int) -> "Block": ...
    def with_fixity(self, fixity: FixitySpec) -> "Block": ...
    def with_velocity(self, velocity: Vec3, angular_velocity: Optional[Vec3] = None) -> "Block": ...
    @property
    def name(self) -> str: ...
    @property
    def material(self) -> int: ...
    @property
    def density(self) -> float: ...
    @property
    def mass(self) -> float: ...
    @property
    def volume(self) -> float: ...
    @property
    def centroid(self) -> FloatArray: ...
    @property
    def vertices(self) -> FloatArray: ...
    # Each face as the indices of its vertices, counter-clockwise seen from outside.
    @property
    def faces(self) -> List[List[int]]: ...
    @property
    def fixity(self) -> Dict[str, List[Dof]]: ...
    @property
    def is_fixed(self) -> bool: ...

class Model:
    def __init__(
        self,
        *,
        gravity: Optional[Vec3] = None,
        contact_tolerance: float = 1e-3,
        subcontacts_per_edge: int = 15,
        subcontact_spacing: Optional[float] = None,
        time_step: Optional[float] = None,
        safety: float = 0.5,
        mode: Literal["large", "small"] = "large",
        max_speed: float = 1000.0,
        impact_step: Optional[float] = 0.1,
        node_rule: Literal["point", "integrated"] = "point",
    ) -> None: ...
    # The constructor's defaults above, as the library has them (the stub's are checked against it).
    @staticmethod
    def defaults() -> Dict[str, Any]: ...
    # building
    def set_joint_law(self, a: int, b: int, law: JointLaw) -> None: ...
    def joint_law(self, a: int, b: int) -> Optional[JointLaw]: ...
    def set_interface_law(self, a: int, b: int, law: JointLaw) -> None: ...
    def interface_law(self, a: int, b: int) -> Optional[JointLaw]: ...
    def set_damping(
        self,
        kind: Literal["none", "local", "rayleigh", "rayleigh_mass", "rayleigh_stiffness"],
        *,
        alpha: float = 0.8,
        ratio: Optional[float] = None,
        frequency: Optional[float] = None,
        mass: Optional[float] = None,
        stiffness: Optional[float] = None,
    ) -> None: ...
    @property
    def damping(self) -> Dict[str, Any]: ...
    @property
    def gravity(self) -> FloatArray: ...
    @gravity.setter
    def gravity(self, g: Vec3) -> None: ...
    def add_block(self, block: Block) -> int: ...
    # All or nothing: when one block is refused, none is added.
    def add_blocks(self, blocks: Iterable[Block]) -> List[int]: ...
    def add_cuboid(
        self,
        name: str,
        min: Vec3,
        max: Vec3,
        density: float,
        *,
        material: int = 0,
        fixed: FixitySpec = None,
        velocity: Optional[Vec3] = None,
        angular_velocity: Optional[Vec3] = None,
    ) -> int: ...
    def add_polyhedron(
        self,
        name: str,
        vertices: Points,
        density: float,
        *,
        faces: Optional[Sequence[Sequence[int]]] = None,
        material: int = 0,
        fixed: FixitySpec = None,
        velocity: Optional[Vec3] = None,
        angular_velocity: Optional[Vec3] = None,
    ) -> int: ...
    def set_fixity(self, block: int, fixity: FixitySpec) -> None: ...
    # The block's translations follow the histories from now on (kind "acceleration" from
    # rest, "velocity", or "displacement" from 0); no history removes the motion.
    # Push-over to the capacity under servo control (no loading rate); returns peak_load,
    # travel_at_peak, raw_peak_load, stop and curve (time, step, travel, load, smoothed_load).
    def push_over(
        self,
        block: int,
        direction: Sequence[float],
        increment: float,
        *,
        max_unbalanced_ratio: float = 1e-3,
        max_travel: float = 0.01,
        stop_fraction: float = 0.5,
        fallen_travel: Optional[float] = None,
        sample_travel: Optional[float] = None,
        smoothing_window: float = 0.0,
        max_steps: int = 100_000_000,
        progress: bool = False,
    ) -> Dict[str, Any]: ...
    def set_base_motion(
        self,
        block: int,
        x: Optional[TimeHistory] = None,
        y: Optional[TimeHistory] = None,
        z: Optional[TimeHistory] = None,
        *,
        kind: Literal["acceleration", "velocity", "displacement"] = "acceleration",
    ) -> None: ...
    def set_load(self, block: int, force: Optional[Vec3] = None, moment: Optional[Vec3] = None) -> None: ...
    def set_load_history(
        self,
        block: int,
        history: Optional[TimeHistory],
        force: Optional[Vec3] = None,
        moment: Optional[Vec3] = None,
    ) -> None: ...
    def load(self, block: int) -> Dict[str, FloatArray]: ...
    def set_velocity(self, block: int, velocity: Vec3, angular_velocity: Optional[Vec3] = None) -> None: ...
    def set_prescribed_velocity(self, block: int, velocity: Vec3) -> None: ...
    # running
    def step(self) -> None: ...
    def run_steps(
        self, n: int, callback: Optional[Progress] = None, every: int = 1000, *, progress: bool = False
    ) -> bool: ...
    def run_until_time(
        self, t: float, callback: Optional[Progress] = None, every: int = 1000, *, progress: bool = False
    ) -> bool: ...
    def run_to_equilibrium(
        self,
        ratio: float = 1e-5,
        max_steps: int = 1_000_000,
        callback: Optional[Progress] = None,
        every: int = 1000,
        *,
        progress: bool = False,
    ) -> int: ...
    # state
    def __len__(self) -> int: ...
    @property
    def block_count(self) -> int: ...
    @property
    def time(self) -> float: ...
    @property
    def step_count(self) -> int: ...
    @property
    def dt(self) -> float: ...
    @property
    def critical_step(self) -> Optional[float]: ...
    @property
    def unbalanced_force_ratio(self) -> float: ...
    @property
    def contact_count(self) -> int: ...
    @property
    def subcontact_count(self) -> int: ...
    def set_joint_stepping(self, stepping: Literal["whole", "cells"]) -> None: ...
    # How a closed, sticking joint is stepped: "whole" (default) or "cells"; the same answers
    # to round-off.
    @property
    def joint_stepping(self) -> Literal["whole", "cells"]: ...
    def whole_joint_count(self) -> int: ...
    def block(self, i: int) -> Block: ...
    def block_names(self) -> List[str]: ...
    def positions(self) -> FloatArray: ...
    def displacements(self) -> FloatArray: ...
    def rotations(self) -> FloatArray: ...
    # Rotation vectors (axis × angle, rad) of each block since its initial pose.
    def rotations_from_initial(self) -> FloatArray: ...
    def rotation_matrices(self) -> FloatArray: ...
    def velocities(self) -> FloatArray: ...
    def angular_velocities(self) -> FloatArray: ...
    # keys: blocks, normal, normal_force, force, moment_a, moment_b, shear_force,
    # application_point, tangent1, tangent2, tangent_force, kind ("face" or "nodes"), polygon,
    # subcontact_count (one row or item per contact).
    def contacts(self) -> Dict[str, Any]: ...
    def subcontacts(self) -> Dict[str, Any]: ...
    # kinetic, initial_kinetic, elastic, gravity_work, load_work, boundary_work, friction,
    # fracture, damping, joint_work, input, accounted, balance_error (J).
    def energies(self) -> Dict[str, float]: ...
    def reaction(self, block: int) -> Dict[str, FloatArray]: ...
    def contact_wrench(self, block: int) -> Dict[str, FloatArray]: ...
    # monitors
    def add_monitor(
        self,
        name: str,
        kind: Literal[
            "displacement",
            "velocity",
            "reaction",
            "contact_force",
            "contact_resultant",
            "energy",
            "unbalanced_ratio",
        ],
        *,
        block: Optional[int] = None,
        point: Optional[Vec3] = None,
        component: Literal["x", "y", "z", "magnitude"] = "z",
        a: Optional[int] = None,
        b: Optional[int] = None,
        term: Optional[str] = None,
    ) -> None: ...
    @property
    def monitor_interval(self) -> int: ...
    @monitor_interval.setter
    def monitor_interval(self, n: int) -> None: ...
    def monitor_names(self) -> List[str]: ...
    def history(self) -> Dict[str, npt.NDArray[Any]]: ...
    def history_units(self) -> Dict[str, str]: ...
    def clear_history(self) -> None: ...
    # files
    def write_history_csv(self, path: Path) -> None: ...
    # cells="surfaces": one polygon per face (ParaView and meshio read it; as ParaviewSeries
    # writes blocks); "polyhedra": one polyhedron cell per block (ParaView).
    def write_vtk_blocks(self, path: Path, *, cells: Literal["surfaces", "polyhedra"] = "surfaces") -> None: ...
    def write_vtk_subcontacts(self, path: Path) -> None: ...
    def to_scene_json(self) -> str: ...
    # Atomic: a temporary file beside the target, renamed over it; a symbolic link is written
    # through.
    def save_scene(self, path: Path) -> None: ...
    @staticmethod
    def from_scene_json(text: str) -> "Model": ...
    @staticmethod
    def load_scene(path: Path) -> "Model": ...
    def to_checkpoint_string(self) -> str: ...
    def save_checkpoint(self, path: Path) -> None: ...
    @staticmethod
    def from_checkpoint_string(text: str) -> "Model": ...
    @staticmethod
    def load_checkpoint(path: Path) -> "Model": ...

# One series per name and folder at a time (lock file); VoussoirIOError otherwise, or when the
# folder was deleted mid-run.
class TimeHistory:
    """A sampled history h(t), linear between samples (accelerogram, velocity, displacement)."""
    def __init__(self, times: Sequence[float], values: Sequence[float]) -> None: ...
    @staticmethod
    def sine(amplitude: float, frequency: float, duration: float, samples_per_period: int = 50) -> "TimeHistory": ...
    # Two columns of a CSV file (0-based), values times scale (9.81 for a record in g).
    @staticmethod
    def from_csv(path: Path, time_column: int = 0, value_column: int = 1, scale: float = 1.0) -> "TimeHistory": ...
    @property
    def times(self) -> FloatArray: ...
    @property
    def values(self) -> FloatArray: ...
    @property
    def end(self) -> float: ...
    def value_at(self, t: float) -> float: ...
    def __len__(self) -> int: ...

class ParaviewSeries:
    # subcontacts_every: sub-contacts on every n-th frame only (blocks on every frame).
    # time_from_first_frame: the .pvd times count from the first frame, not the model's time.
    def __init__(
        self, folder: Path, name: str = "model", *, subcontacts_every: int = 1, time_from_first_frame: bool = False
    ) -> None: ...
    def write_frame(self, model: Model) -> None: ...
    @property
    def blocks_pvd(self) -> str: ...
    def __len__(self) -> int: ...

class Viewer:
    # A run in one self-contained HTML page (blocks in 3-D over time, fields, joints, forces,
    # curves); shows itself inline in Jupyter.
    def __init__(self, title: str = "voussoir", *, contacts: bool = True, time_from_first_frame: bool = False) -> None: ...
    def record(self, model: Model) -> None: ...
    def add_curve(
        self,
        name: str,
        x: Sequence[float],
        y: Sequence[float],
        *,
        x_label: str = "time (s)",
        y_label: str = "",
        time_axis: bool = True,
    ) -> None: ...
    def html(self) -> str: ...
    def write(self, path: Union[str, Path]) -> Path: ...
    def _repr_html_(self) -> str: ...
    @property
    def times(self) -> List[float]: ...
    def __len__(self) -> int: ...

# voussoir.build
def arch(
    *,
    span: float = 1.2,
    rise: float = 0.4,
    thickness: float = 0.2,
    width: float = 0.15,
    voussoirs: int = 13,
    density: float = 2446.4831804281343,
    abutment_outer_width: float = 0.20,
    abutment_depth: float = 0.30,
    voussoir_material: int = 0,
    abutment_material: int = 0,
) -> List[Block]: ...
def arch_joints(
    *,
    span: float = 1.2,
    rise: float = 0.4,
    thickness: float = 0.2,
    width: float = 0.15,
    voussoirs: int = 13,
    density: float = 2446.4831804281343,
    abutment_outer_width: float = 0.20,
    abutment_depth: float = 0.30,
    voussoir_material: int = 0,
    abutment_material: int = 0,
    first_block: int = 0,
) -> List[Dict[str, Any]]:
    """The joints of ``arch(...)``'s arch for ``classify_joints``: ``index``, ``blocks``,
    ``intrados``, ``extrados`` (mid-width edge points) and ``points`` (the joint face's corners)."""
    ...
def running_bond_wall(
    *,
    bricks_per_course: int = 10,
    courses: int = 10,
    brick: Optional[Vec3] = None,
    density: float = 2000.0,
    material: int = 0,
    base_material: int = 0,
) -> List[Block]: ...
def multi_leaf_wall(
    *,
    length: float = 2.0,
    height: float = 1.0,
    leaves: Optional[Points] = None,
    density: float = 2000.0,
    material: int = 0,
) -> List[Block]: ...
def rubble_wall(
    *,
    length: float = 2.0,
    thickness: float = 0.5,
    height: float = 1.2,
    stone_size: float = 0.2,
    leaves: int = 2,
    jitter: float = 0.3,
    through_stones: float = 0.1,
    seed: int = 1,
    density: float = 2200.0,
    material: int = 0,
    base_material: int = 0,
) -> List[Block]: ...
def barrel_vault(
    *,
    radius: float = 2.0,
    thickness: float = 0.3,
    ring_length: float = 0.25,
    rings: int = 10,
    voussoirs: int = 25,
    density: float = 2200.0,
    material: int = 0,
) -> List[Block]: ...
def dome(
    *,
    blocks: Optional[int] = None,
    radius: Optional[float] = None,
    thickness: Optional[float] = None,
    per_course: Optional[Sequence[int]] = None,
    oculus_angle: Optional[float] = None,
    density: Optional[float] = None,
    material: int = 0,
) -> List[Block]: ...

# voussoir.scenes
# MemoryError above voussoir's MAX_GENERATED_BLOCKS (10 million blocks), as the generators.
def benchmark_wall(blocks: int, *, spacing: Optional[float] = None) -> Model: ...

# voussoir.scenarios
def arch_static(
    *,
    friction_deg: float = 30.5,
    kn: float = 4e9,
    ks: Optional[float] = None,
    width: float = 0.15,
    mode: Literal["large", "small"] = "large",
    per_edge: int = 15,
    servo_increment: float = 2e-5,
    servo_ratio: float = 1e-3,
    rate: Optional[float] = None,
    max_displacement: float = 0.012,
    stop_fraction: float = 0.5,
    local_damping: float = 0.8,
    convergence_check: bool = False,
    label: Optional[str] = None,
    plate: Literal["rolling", "held"] = "rolling",
    joint_friction: Optional[Mapping[int, float]] = None,
) -> Dict[str, Any]: ...
def arch_impact(
    setup: str = "M60H20",
    *,
    kn: float = 4e9,
    damping: float = 0.01,
    width: float = 0.15,
    duration: float = 1.0,
    friction_deg: float = 30.5,
    per_edge: int = 15,
    guide: Literal["frame", "seat"] = "frame",
    base: Literal["sloped", "flat"] = "sloped",
    release: Literal["above", "full"] = "above",
    offsets_mm: Sequence[float] = (0.0,),
    settled_states: int = 1,
    node_rule: Literal["point", "integrated"] = "integrated",
) -> Dict[str, Any]: ...
def impact_setups() -> List[Dict[str, Any]]: ...

def check_density_convergence(
    run: Callable[..., float],
    *,
    subcontacts_per_edge: int = 15,
    subcontact_spacing: Optional[float] = None,
) -> Dict[str, Any]:
    """Run ``run`` at a sub-contact density and at the density with the joints' cells halved
    (``2 n - 1`` per edge, or half the spacing), passing the density as ``Model``'s keyword
    argument; return ``value``, ``refined``, ``relative_change``, ``density`` and
    ``refined_density``."""
    ...

def check_servo_convergence(
    run: Callable[..., float], *, increment: float, max_unbalanced_ratio: float = 1e-3
) -> Dict[str, Any]:
    """Run ``run(increment=..., max_unbalanced_ratio=...)`` and again with both halved; return
    ``value``, ``refined``, ``relative_change``, ``servo`` and ``refined_servo``."""
    ...

LiveLoad = Union[Dict[str, Any], Tuple[int, Sequence[float], Sequence[float]]]

def limit(
    model: Model,
    live_loads: Sequence[LiveLoad],
    *,
    fixity: Optional[Dict[int, FixitySpec]] = None,
    friction: Literal["cone", "pyramid"] = "cone",
    facets: int = 16,
    check_dead_load: bool = True,
    max_iterations: int = 200,
    joints: Optional[Sequence[JointSpec]] = None,
    mechanism_tolerance: float = 1e-3,
) -> Dict[str, Any]:
    """The collapse multiplier of ``live_loads`` (``{"block", "point", "force"}``: the force
    ``multiplier * force`` at ``point``) for the model's rigid blocks as they stand, no-tension
    Coulomb joints, by limit analysis (a second-order cone programme); the model must have been
    stepped once. Returns ``multiplier``, ``status``, ``iterations``, ``carries_dead_load``,
    ``reason``, ``blocks`` (``centroid``, ``velocity``, ``angular_velocity``: the mechanism) and
    ``contacts`` (per contact: ``blocks``, ``normal``, ``points``, ``normal_force``,
    ``shear_force``, ``opening``, ``sliding``, ``resultant``, ``application_point``); with
    ``joints`` (as ``classify_joints`` takes them) also ``joints`` (per joint: opening rates,
    sliding, ``hinge``, ``is_sliding``) and ``mechanism`` (e.g. ``"hinges 4e 8i"``).

    No live load (``[]``, or forces all zero): the dead-load question alone, an answer either
    way: ``multiplier`` None, ``carries_dead_load`` True (``contacts`` with the forces of an
    admissible state) or False (``status`` ``"PrimalInfeasible"``, ``reason``, ``blocks`` the
    solver's certificate: which blocks fall; zero forces); ``joints``/``mechanism`` None.

    With a live load raises ``voussoir.LimitInfeasibleError`` (dead load not carried),
    ``voussoir.LimitUnboundedError`` (no bound), ``voussoir.LimitSolverError`` (no answer):
    subclasses of ``VoussoirError``."""
    ...

def classify_joints(
    model: Model,
    joints: Sequence[JointSpec],
    *,
    open_fraction: float = 0.5,
    edge_band: float = 0.25,
    slip: float = 5e-4,
) -> Dict[str, Any]:
    """Measure ``joints`` (``{"blocks": (a, b), "intrados", "extrados", "index"?}``) and name the
    mechanism: ``joint``, ``open_fraction``, ``compression_position``, ``slip``,
    ``normal_force``, ``hinge`` (None/"intrados"/"extrados"), ``sliding``, ``hinges``,
    ``sliding_joints``, ``description``."""
    ...

"""Type stubs of the package lacuna (the extension lacuna._lacuna). Lengths are millimetres."""

import os
from typing import Any, Dict, List, Literal, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

_Path = Union[str, os.PathLike[str]]
_Points = npt.ArrayLike  # N x 3 (mm)
_Vec3 = Sequence[float]
_Recipe = Union[_Path, str, Mapping[str, Any]]

class LacunaError(Exception):
    """Every error Lacuna raises on purpose; the message says what to change."""

class InvalidInputError(LacunaError, ValueError):
    """Bad arguments, recipes or input meshes, with the message the command line prints."""

class FileError(LacunaError, OSError, ValueError):
    """A file that cannot be opened, read or written."""

class ResourceLimitError(LacunaError):
    """The job would exceed the memory budget; refused before allocating. Names a voxel size that fits."""

class CheckFailedError(LacunaError):
    """A result failed its validity checks; nothing was written."""
    report: Optional[Dict[str, Any]]

class InternalError(LacunaError, RuntimeError):
    """A broken invariant inside Lacuna: a bug."""

class CancelledError(LacunaError):
    """The call was cancelled; nothing was left behind."""

class Mesh:
    """An immutable triangle mesh (mm), counter-clockwise seen from outside."""
    def __init__(self, vertices: _Points, faces: npt.ArrayLike) -> None:
        """Copied from N x 3 positions (mm) and M x 3 vertex indices."""
    @property
    def vertices(self) -> npt.NDArray[np.float64]:
        """N x 3 positions (mm), a read-only view of the mesh's memory."""
    @property
    def faces(self) -> npt.NDArray[np.uint32]:
        """M x 3 vertex indices, a read-only view of the mesh's memory."""
    @property
    def volume_mm3(self) -> float:
        """Enclosed volume (mm^3), positive for an outward-oriented solid."""
    @property
    def volume(self) -> float:
        """The same as volume_mm3 (mm^3)."""
    @property
    def area_mm2(self) -> float:
        """Surface area (mm^2)."""
    @property
    def area(self) -> float:
        """The same as area_mm2 (mm^2)."""
    @property
    def genus(self) -> int:
        """Sum over components of (2 - Euler characteristic) / 2."""
    @property
    def components(self) -> int:
        """Connected components."""
    @property
    def bounding_box(self) -> npt.NDArray[np.float64]:
        """2 x 3: the smallest and the largest corner (mm)."""
    def check(
        self,
        printability: bool = False,
        min_wall_mm: float = 0.0,
        min_hole_mm: float = 0.0,
        build_direction: _Vec3 = (0.0, 0.0, 1.0),
        critical_angle_deg: float = 45.0,
        voxel_size_mm: Optional[float] = None,
    ) -> Dict[str, Any]:
        """The report `lacuna check --json` prints, plus "valid"."""
    def save(
        self,
        path: _Path,
        name: str = "",
        *,
        max_tet_volume_mm3: float = ...,
        quality: float = ...,
        min_dihedral_deg: float = ...,
        preserve_surface: bool = ...,
        msh_version: Literal["4.1", "2.2"] = ...,
        element: Literal["C3D4", "C3D10"] = ...,
        time_limit_s: float = ...,
        quantize_mm: float = ...,
    ) -> Optional[Dict[str, Any]]:
        """Writes .stl, .3mf, .drc (Draco within quantize_mm; returns its check and compression), or tetrahedra
        (.msh, .inp, .vtu, .mesh; returns their report). All or nothing."""
    def simplify(self, max_deviation_mm: float) -> "Mesh":
        """A copy simplified with every collapse guarded, within max_deviation_mm (mm)."""

class Grid:
    """A narrow-band level set (signed distance, negative inside)."""
    @property
    def voxel_size_mm(self) -> float: ...
    @property
    def band_voxels(self) -> float: ...
    @property
    def active_voxels(self) -> int: ...
    @property
    def memory_bytes(self) -> int: ...
    @property
    def voxel_volume_mm3(self) -> float:
        """Volume counted voxel by voxel (mm^3; about a voxel layer accurate)."""
    @property
    def bounding_box(self) -> npt.NDArray[np.float64]: ...
    def distance(self, points: _Points) -> npt.NDArray[np.float64]:
        """Signed distance (mm) at N x 3 points."""
    def mesh(self, simplify_mm: Optional[float] = None, max_memory_gb: Optional[float] = None) -> Mesh:
        """The surface, simplified to simplify_mm (mm; None: a fifth of the voxel, 0: not simplified)."""

class Solid:
    """A recipe fragment: inputs, CSG and offsets. Nothing is computed until mesh() or voxelize()."""
    @property
    def type(self) -> str: ...
    @property
    def name(self) -> str: ...
    def __or__(self, other: "Solid") -> "Solid": ...
    def __sub__(self, other: "Solid") -> "Solid": ...
    def __and__(self, other: "Solid") -> "Solid": ...
    def offset(self, distance_mm: float) -> "Solid":
        """Euclidean offset (mm, not 0): > 0 grows, < 0 shrinks."""
    def shell(self, thickness_mm: float) -> "Solid":
        """Walls of thickness_mm (mm) inward, cavity sealed."""
    def infill(self, structure: "Solid", skin_mm: float, fuse_mm: Optional[float] = None) -> "Solid":
        """This hull with a skin of skin_mm (mm) and the structure inside, fused fuse_mm (mm) into the skin."""
    def mesh(
        self,
        voxel_size_mm: float = 0.1,
        simplify_mm: Optional[float] = None,
        band_voxels: float = 3.0,
        seed: int = 0,
        max_memory_gb: Optional[float] = None,
        threads: Optional[int] = None,
    ) -> Mesh:
        """Voxelized at voxel_size_mm (mm) and meshed in memory; simplify_mm (mm; None: a fifth of the voxel)."""
    def voxelize(
        self,
        voxel_size_mm: float = 0.1,
        band_voxels: float = 3.0,
        seed: int = 0,
        max_memory_gb: Optional[float] = None,
        threads: Optional[int] = None,
    ) -> Grid:
        """The level set at voxel_size_mm (mm)."""
    def to_recipe(
        self,
        name: str = "solid",
        voxel_size_mm: float = 0.1,
        simplify_mm: Optional[float] = None,
        band_voxels: float = 3.0,
        seed: int = 0,
    ) -> Dict[str, Any]:
        """The solid as a recipe dict with one output, <name>.stl."""

class RunResult:
    """What run() did."""
    @property
    def report(self) -> Dict[str, Any]:
        """What report.json holds, plus "valid" and "written"."""
    @property
    def files(self) -> List[str]: ...
    @property
    def meshes(self) -> Dict[str, Mesh]:
        """The STL, 3MF and Draco outputs by file name, read back when first asked for."""

def run(
    recipe: _Recipe,
    output_dir: Optional[_Path] = None,
    voxel_size_mm: Optional[float] = None,
    max_memory_gb: Optional[float] = None,
    threads: Optional[int] = None,
    simplify_mm: Optional[float] = None,
    write_report: bool = True,
) -> RunResult:
    """Runs a recipe (path, JSON text or dict) as `lacuna run`: checked files, all or nothing."""

def slice(
    recipe: _Recipe,
    output: _Path,
    object: str = "",
    layer_mm: Optional[float] = None,
    pixel_mm: Optional[float] = None,
    tolerance_mm: Optional[float] = None,
    binary: bool = False,
    slab_mm: Optional[float] = None,
    voxel_size_mm: Optional[float] = None,
    max_memory_gb: Optional[float] = None,
    threads: Optional[int] = None,
) -> Dict[str, Any]:
    """Layers for printers (PNG folder, .zip, .sl1, .cli) as `lacuna slice`: checked, all or nothing."""

def stream(
    recipe: _Recipe,
    output_dir: Optional[_Path] = None,
    slab_mm: Optional[float] = None,
    voxel_size_mm: Optional[float] = None,
    max_memory_gb: Optional[float] = None,
    threads: Optional[int] = None,
    simplify_mm: Optional[float] = None,
    write_report: bool = True,
) -> Dict[str, Any]:
    """STL outputs streamed slab by slab as `lacuna run --stream`: the run's files, checked chunk by chunk."""

def voxelize(
    recipe: _Recipe,
    object: str = "",
    voxel_size_mm: Optional[float] = None,
    max_memory_gb: Optional[float] = None,
    threads: Optional[int] = None,
) -> Grid:
    """The level set of one object of a recipe (default: its first output's)."""

def read_mesh(path: _Path) -> Mesh:
    """Reads STL, OBJ, PLY, 3MF or Draco (.drc)."""

def input_types() -> List[str]: ...
def solid(type: str, **keys: Any) -> Solid:
    """An input of any recipe type with its keys as keyword arguments."""

# Inputs: the keyword arguments are the recipe's keys for that input type (README.md, Inputs).
def sphere(*, center_mm: _Vec3 = ..., radius_mm: float) -> Solid: ...
def spheres(
    centers: Optional[_Points] = None,
    radii: Union[float, npt.ArrayLike, None] = None,
    *,
    centers_mm: _Points = ...,
    radius_mm: float = ...,
    radii_mm: npt.ArrayLike = ...,
) -> Solid: ...
def capsule(*, a_mm: _Vec3, b_mm: _Vec3, radius_mm: float, radius_b_mm: float = ...) -> Solid: ...
def tubes(
    points: Union[_Points, Sequence[_Points], None] = None,
    radii: Union[float, npt.ArrayLike, Sequence[Union[float, npt.ArrayLike]], None] = None,
    *,
    polylines: Sequence[Mapping[str, Any]] = ...,
) -> Solid: ...
def box(
    *, center_mm: _Vec3 = ..., size_mm: _Vec3 = ..., min_mm: _Vec3 = ..., max_mm: _Vec3 = ...
) -> Solid: ...
def cylinder(*, center_mm: _Vec3 = ..., axis: _Vec3 = ..., radius_mm: float, height_mm: float) -> Solid: ...
def torus(
    *, center_mm: _Vec3 = ..., axis: _Vec3 = ..., major_radius_mm: float, minor_radius_mm: float
) -> Solid: ...
def region(
    *,
    loops_mm: Sequence[npt.ArrayLike],
    height_mm: float,
    origin_mm: _Vec3 = ...,
    axis_u: _Vec3 = ...,
    axis_v: _Vec3 = ...,
) -> Solid: ...
def mesh(
    vertices: Union[_Points, Mesh, None] = None,
    faces: Optional[npt.ArrayLike] = None,
    *,
    file: _Path = ...,
    positions_mm: _Points = ...,
    triangles: npt.ArrayLike = ...,
    scale: float = ...,
    translate_mm: _Vec3 = ...,
    repair: Mapping[str, Any] = ...,
) -> Solid: ...
def surface(
    vertices: Union[_Points, Mesh, None] = None,
    faces: Optional[npt.ArrayLike] = None,
    *,
    thickness_mm: float,
    file: _Path = ...,
    positions_mm: _Points = ...,
    triangles: npt.ArrayLike = ...,
    scale: float = ...,
    translate_mm: _Vec3 = ...,
) -> Solid: ...
def lattice(
    *,
    cell: Literal["cubic", "bcc"] = ...,
    period_mm: float = ...,
    strut_radius_mm: float = ...,
    min_mm: _Vec3 = ...,
    max_mm: _Vec3 = ...,
    fit_to: Solid = ...,
    grade: Mapping[str, Any] = ...,
    layout: Literal["tiled", "scaled", "conforming"] = ...,
    inset_mm: float = ...,
) -> Solid: ...
def cifs(
    *,
    system: Union[str, Mapping[str, Any]],
    level: int = ...,
    radius_mm: float = ...,
    thickness_mm: float = ...,
    fit_to: Solid = ...,
    **keys: Any,
) -> Solid:
    """Also takes `as` (tubes, shell, cells, edges): cifs(system=..., **{"as": "edges"}), and support."""
def cifs_support(
    *,
    system: Union[str, Mapping[str, Any]],
    base_mm: Sequence[float],
    level: int = ...,
    thickness_mm: float = ...,
    fit_to: Solid = ...,
    base_size_mm: float = ...,
    fork: float = ...,
    shrink: float = ...,
) -> Solid:
    """A cifs shell (a tensor surface) stood on its own fractal tree, rooted at base_mm on the plate."""
def curve(
    *,
    kind: Literal["hilbert", "sierpinski", "hilbert3d"] = ...,
    orders: Union[str, Sequence[int]] = ...,
    radius_mm: Union[float, Sequence[float]] = ...,
    scale_mm: float = ...,
    surface: str = ...,
    patch: Mapping[str, Any] = ...,
    mesh: _Path = ...,
    center_mm: _Vec3 = ...,
    offset_mm: float = ...,
    tolerance_mm: float = ...,
    base_mm: float = ...,
) -> Solid: ...
def fill_motifs(
    *,
    motif: Union[str, Mapping[str, Any]],
    region: Mapping[str, Any] = ...,
    wallpaper: Mapping[str, Any] = ...,
    c: float = ...,
    N: float = ...,
    count: int = ...,
    min_area_mm2: float = ...,
    max_trials: int = ...,
    gap_mm: float = ...,
    boundary_gap_mm: float = ...,
    seed: int = ...,
    random_rotation: bool = ...,
    height_mm: float,
    base_z_mm: float = ...,
    wrap: Mapping[str, Any] = ...,
) -> Solid: ...
def fill_spheres(
    *,
    fit_to: Solid = ...,
    box: Mapping[str, Any] = ...,
    sphere: Mapping[str, Any] = ...,
    motif: Literal["sphere", "cube", "tetrahedron", "octahedron"] = ...,
    random_rotation: bool = ...,
    c: float = ...,
    N: float = ...,
    count: int = ...,
    min_radius_mm: float = ...,
    max_trials: int = ...,
    gap_mm: float = ...,
    boundary_gap_mm: float = ...,
    seed: int = ...,
) -> Solid: ...
def voronoi_spheres(
    *,
    dimension: int = ...,
    d: int = ...,
    points: npt.ArrayLike = ...,
    random: int = ...,
    seed: int = ...,
    level: int = ...,
    period_mm: float = ...,
    origin_mm: _Vec3 = ...,
    radius_mm: float,
    colours: Sequence[int] = ...,
    tiles: Sequence[int] = ...,
) -> Solid: ...
def voronoi_tiles(
    *,
    dimension: int = ...,
    d: int = ...,
    points: npt.ArrayLike = ...,
    random: int = ...,
    seed: int = ...,
    level: int = ...,
    period_mm: float = ...,
    origin_mm: _Vec3 = ...,
    colours: Sequence[int] = ...,
    clearance_mm: float = ...,
    thickness_mm: float = ...,
) -> Solid: ...
def voronoi_foam(
    *,
    dimension: int = ...,
    d: int = ...,
    points: npt.ArrayLike = ...,
    random: int = ...,
    seed: int = ...,
    level: int = ...,
    period_mm: float = ...,
    origin_mm: _Vec3 = ...,
    wall_mm: float,
    tiles: Sequence[int] = ...,
    cover: Solid = ...,
    thickness_mm: float = ...,
    refine: Mapping[str, Any] = ...,
) -> Solid: ...
def bcifs_plate(
    *,
    face: Mapping[str, Any] = ...,
    faces: Sequence[Mapping[str, Any]] = ...,
    shared: Sequence[Mapping[str, int]] = ...,
    level: int = ...,
    thickness_mm: float = ...,
    radius_mm: float = ...,
    gap_fraction: float = ...,
    lacuna_scale: float = ...,
    notch_depth: float = ...,
    realization: Literal["default", "paper"] = ...,
    origin_mm: _Vec3 = ...,
) -> Solid: ...
def bcifs_cell(
    *,
    cell: Literal["hexahedron", "truncated_tetrahedron", "tetrahedron", "prism"] = ...,
    edge_mm: float = ...,
    thickness_mm: float = ...,
    center_mm: _Vec3 = ...,
    edge: str = ...,
    params: str = ...,
    algorithm: str = ...,
    level: int = ...,
    gap_fraction: float = ...,
    lacuna_scale: float = ...,
    notch_depth: float = ...,
    realization: Literal["default", "paper"] = ...,
) -> Solid: ...
def bcifs_volume(
    *,
    cell: Literal["hexahedron", "truncated_tetrahedron", "tetrahedron", "prism"] = ...,
    edge_mm: float = ...,
    center_mm: _Vec3 = ...,
    delay: int = ...,
    corners_mm: Sequence[_Vec3] = ...,
    faces: Sequence[Sequence[int]] = ...,
    cells: Sequence[Mapping[str, Any]] = ...,
    walls: Literal["lacunar", "plain"] = ...,
    edge: str = ...,
    params: str = ...,
    algorithm: str = ...,
    interior: Literal["lacunar", "plain"] = ...,
    radial: str = ...,
    interior_params: str = ...,
    interior_algorithm: str = ...,
    level: int = ...,
    lacuna_scale: float = ...,
    face_lacuna_scale: float = ...,
    gap_fraction: float = ...,
    notch_depth: float = ...,
    realization: Literal["default", "paper"] = ...,
) -> Solid: ...
def bcifs_infill(
    *,
    hull: Solid,
    skin_mm: float = ...,
    cell_mm: float = ...,
    level: int = ...,
    equal_lacunas: bool = ...,
    grade: Mapping[str, Any] = ...,
    cell_grade: Mapping[str, Any] = ...,
    walls: Literal["lacunar", "plain"] = ...,
    edge: str = ...,
    params: str = ...,
    algorithm: str = ...,
    interior: Literal["lacunar", "plain"] = ...,
    radial: str = ...,
    interior_params: str = ...,
    interior_algorithm: str = ...,
    lacuna_scale: float = ...,
    face_lacuna_scale: float = ...,
    gap_fraction: float = ...,
    notch_depth: float = ...,
    realization: Literal["default", "paper"] = ...,
) -> Solid: ...

# Generators.
def cifs_library() -> List[str]: ...
def cifs_info(system: Union[str, _Path, Mapping[str, Any]]) -> Dict[str, Any]: ...
def cifs_tessellate(system: Union[str, _Path, Mapping[str, Any]], level: int = 3) -> Dict[str, Any]:
    """points (N x 3, mm) and polylines, triangles (M x 3) or cells (with faces); pieces, dimension."""
def nurbs_automaton(degree: int, knots: Sequence[float]) -> Dict[str, Any]: ...
def nurbs_tessellate(
    degree: int, knots: Sequence[float], control_points: npt.ArrayLike, level: int = 4
) -> Dict[str, npt.NDArray[np.float64]]:
    """points (2^level + 1 x 3, mm) and parameters."""
def curve_points(
    kind: str = "hilbert", orders: Union[str, Sequence[int]] = "1..3", surface: str = "plane", tolerance: float = 0.01
) -> Dict[str, Any]: ...
def curve_fill_rate(
    kind: str = "hilbert", orders: Union[str, Sequence[int]] = "1..3", width: float = 0.02
) -> Dict[str, Any]: ...
def curve_fill_rate_series(
    kind: str = "hilbert", orders: Union[str, Sequence[int]] = "1..5", width: float = 0.02
) -> Dict[str, Any]: ...
def curve_surface_fill_rate(
    kind: str = "hilbert",
    orders: Union[str, Sequence[int]] = "1..3",
    width: float = 0.02,
    surface: str = "plane",
    patch: Optional[Dict[str, Any]] = None,
    mesh: Union[None, Mesh, str, os.PathLike] = None,
    samples: int = 0,
    tolerance: float = 0.01,
) -> Dict[str, Any]: ...
def fill_pattern(
    group: str = "p1",
    lattice: npt.ArrayLike = ((10.0, 0.0), (0.0, 10.0)),
    c: float = 1.3,
    N: float = 2.0,
    motif: Union[str, int, os.PathLike, npt.ArrayLike] = "circle",
    count: int = 1000,
    max_trials: int = 100000,
    gap_mm: float = 0.0,
    seed: int = 1,
    policy: Literal["allow", "reject", "snap"] = "reject",
    random_rotation: bool = False,
    cells: int = 0,
    colors: Optional[Literal["size", "orbit", "random"]] = None,
    palette: Union[None, str, Sequence[str]] = None,
) -> Dict[str, Any]: ...
def voronoi_rules(
    dimension: int = 2,
    d: int = 2,
    points: Optional[npt.ArrayLike] = None,
    random: int = 0,
    seed: int = 1,
    children: Literal["scaled", "shifted"] = "scaled",
) -> Dict[str, Any]: ...
def voronoi_cells(
    dimension: int = 2,
    d: int = 2,
    points: Optional[npt.ArrayLike] = None,
    random: int = 0,
    seed: int = 1,
    children: Literal["scaled", "shifted"] = "scaled",
    level: int = 2,
) -> Dict[str, Any]: ...
def voronoi_walls(
    dimension: int = 2,
    d: int = 2,
    points: Optional[npt.ArrayLike] = None,
    random: int = 0,
    seed: int = 1,
    level: int = 2,
) -> Dict[str, Any]: ...
def bcifs_rules(boundary: str, params: str = "C2 B2 B2", algorithm: str = "A1", delay: int = 1) -> Dict[str, Any]: ...
def bcifs_measure(levels: Tuple[int, int] = (0, 4), **plate: Any) -> Dict[str, Any]:
    """The keys of a bcifs_plate input; per face N^C_i, N^L_i, R_i, R; areas, perimeters, box counting."""
def bcifs_volume_measure(last: int = 3, **volume: Any) -> Dict[str, Any]:
    """The keys of a bcifs_volume input; per cell N^C_i, N^L_i, R_i, R; volumes, surfaces, tunnels, genus;
    3D box counting and the three middle sections (1024 x 1024 uint8 masks)."""

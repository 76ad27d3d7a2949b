"""Type stubs of seam's extension module (the docstrings are on the objects themselves)."""

from os import PathLike
from typing import Callable, Literal, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt
import scipy.sparse

__version__: str

ArrayLike = npt.ArrayLike
Vec3 = Tuple[float, float, float]
Topology = Literal["hex8", "tet4", "wedge6", "pyramid5"]
ModelName = Literal["conductance", "gap_conductance", "tied_nitsche", "tied_mortar"]
ConductanceAnswer = Union[float, Tuple[float, float, float]]

class SeamError(Exception):
    """Any failure reported by seam; ``code`` is the C API's status for it."""

    code: int
    message: str
    help: str

class MeshError(SeamError): ...  # code 2
class DeckError(SeamError):  # code 3
    diagnostic_codes: list[str]

class ArgumentError(SeamError): ...  # code 4
class OrderError(SeamError): ...  # code 5
class EnforcementError(SeamError): ...  # code 6
class InternalError(SeamError): ...  # code 7
class PluginError(SeamError): ...  # code 8
class CutbackError(SeamError):  # code 9
    factor: float

class NothingPairedError(SeamError): ...  # code 10
class OtherRankError(SeamError): ...  # code 11

class PointState:
    """A contact point as a conductance function sees it (SI units)."""

    gap: float
    pressure: float
    temp_a: float
    temp_b: float
    x: Vec3
    time: float
    @property
    def mean_temperature(self) -> float: ...

class Heat:
    """W leaving side A and leaving side B (their sum is 0 to round-off)."""

    side_a: float
    side_b: float

class Rectangular:
    offset: Vec3
    def __init__(self, offset: Vec3) -> None: ...

class Cylindrical:
    axis: Vec3
    center: Vec3
    angle: float
    def __init__(self, axis: Vec3, center: Vec3, angle: float) -> None: ...

class AlignSurface:
    invert_normals: bool
    def __init__(self, invert_normals: bool = True) -> None: ...

class Mapped:
    x: str
    y: str
    z: Optional[str]
    def __init__(self, x: str, y: str, z: Optional[str] = None) -> None: ...

PeriodicMap = Union[Rectangular, Cylindrical, AlignSurface, Mapped]

class Builder:
    def __init__(self, coords: ArrayLike) -> None: ...
    def block(self, name: str, topology: Topology, connectivity: ArrayLike, conductivity: float) -> Builder: ...
    def side_set(self, name: str, elements: ArrayLike, sides: Optional[ArrayLike] = None) -> Builder: ...
    def face_set(self, name: str, faces: ArrayLike) -> Builder: ...
    def dofs(self, dofs: ArrayLike) -> Builder: ...
    def fixed_nodes(self, nodes: ArrayLike) -> Builder: ...
    def integration(self, kind: Literal["segments", "quadrature"], order: int = 5) -> Builder: ...
    def build(self) -> Embedding: ...

class Contributions:
    jacobian: scipy.sparse.csr_matrix
    residual: npt.NDArray[np.float64]
    load: npt.NDArray[np.float64]
    heat: list[Optional[Heat]]

class Evaluation:
    jacobian: scipy.sparse.csr_matrix
    residual: npt.NDArray[np.float64]
    load: npt.NDArray[np.float64]
    heat: list[Optional[Heat]]
    pattern: int

class Coverage:
    points: int
    paired_points: int
    area: float
    paired_area: float
    unpaired_points: npt.NDArray[np.int64]
    unpaired_x: npt.NDArray[np.float64]
    unpaired_reasons: list[Literal["no_face", "too_far", "normals_not_opposed", "outside_subdomain"]]
    gap_range: Optional[Tuple[float, float]]

class PointFields:
    x: npt.NDArray[np.float64]
    weight: npt.NDArray[np.float64]
    paired: npt.NDArray[np.bool_]
    side_a_element: npt.NDArray[np.int64]
    side_a_side: npt.NDArray[np.int64]
    side_b_element: npt.NDArray[np.int64]
    side_b_side: npt.NDArray[np.int64]
    gap: npt.NDArray[np.float64]
    flux: npt.NDArray[np.float64]
    temp_a: npt.NDArray[np.float64]
    temp_b: npt.NDArray[np.float64]
    multiplier: npt.NDArray[np.float64]

class FaceFields:
    element: npt.NDArray[np.int64]
    side: npt.NDArray[np.int64]
    surface: npt.NDArray[np.int64]
    area: npt.NDArray[np.float64]
    paired_area: npt.NDArray[np.float64]
    fraction: npt.NDArray[np.float64]
    gap: npt.NDArray[np.float64]
    flux: npt.NDArray[np.float64]

class TieConstraints:
    @property
    def interaction(self) -> int: ...
    @property
    def multipliers(self) -> Literal["standard", "dual"]: ...
    @property
    def multiplier_dofs(self) -> npt.NDArray[np.int64]: ...
    @property
    def rhs(self) -> npt.NDArray[np.float64]: ...
    @property
    def crosspoints(self) -> npt.NDArray[np.int64]: ...
    def matrix(self, n: int) -> scipy.sparse.csr_matrix: ...
    def condensed(
        self, n: int
    ) -> Tuple[npt.NDArray[np.int64], npt.NDArray[np.float64], scipy.sparse.csr_matrix]: ...
    def heat(self, lam: ArrayLike) -> Heat: ...
    def dual_multipliers(self, residual: ArrayLike) -> npt.NDArray[np.float64]: ...

class Embedding:
    time: float
    def __len__(self) -> int: ...
    def add_interaction(
        self,
        side_a: str,
        side_b: str,
        model: ModelName,
        *,
        h: float = 0.0,
        multipliers: Literal["standard", "dual"] = "standard",
        conductance: Optional[Callable[[PointState], ConductanceAnswer]] = None,
        depends_on_temperature: bool = True,
        offset: float = 0.0,
        penalty_factor: Optional[float] = None,
        periodic: Optional[PeriodicMap] = None,
        search: Optional[dict[str, Union[float, bool, None]]] = None,
        allow_unpaired: bool = False,
        quarantine: bool = False,
    ) -> int: ...
    def add_deck(self, text: str, name: str = "deck") -> list[int]: ...
    def add_deck_file(self, path: Union[str, PathLike[str]]) -> list[int]: ...
    def search(self) -> None: ...
    def move_nodes(self, coords: ArrayLike) -> None: ...
    def surfaces(self, i: int) -> Tuple[str, str]: ...
    def allow_unpaired(self, i: Optional[int], allow: bool = True) -> None: ...
    def set_active(self, i: int, on: bool) -> None: ...
    def is_active(self, i: int) -> bool: ...
    def set_point_pressures(self, i: int, pressures: Optional[ArrayLike]) -> None: ...
    def set_quarantine(self, i: int, on: bool) -> None: ...
    def quarantined(self, i: int) -> list[Tuple[Vec3, str]]: ...
    def is_linear(self) -> bool: ...
    def contributions(self, u: ArrayLike) -> Contributions: ...
    def evaluate(self, u: ArrayLike) -> Evaluation: ...
    def heat(self, u: ArrayLike) -> list[Optional[Heat]]: ...
    def heat_of(self, i: int, u: ArrayLike) -> Optional[Heat]: ...
    def coverage(self, i: int) -> Coverage: ...
    def point_fields(self, i: int, u: ArrayLike) -> PointFields: ...
    def face_fields(self, i: int, u: ArrayLike, side_b: bool = False) -> FaceFields: ...
    def constraints(self) -> list[TieConstraints]: ...
    def tie_point_fields(self, tie: TieConstraints, lam: ArrayLike) -> PointFields: ...
    def tie_face_fields(self, tie: TieConstraints, lam: ArrayLike, side_b: bool = False) -> FaceFields: ...


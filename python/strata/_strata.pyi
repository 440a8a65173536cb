"""Type stubs of strata._strata, the C++ bindings (python/src/module.cpp). Use the package
strata: it re-exports the classes below and wraps the private functions (leading underscore)
with keyword arguments, defaults and documentation."""

import os
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

class InvalidInput(ValueError):
    """Bad input: a parameter out of range, a malformed scene, a file whose content is wrong.
    The message names the function or file, the field or position, and the value."""

class IoError(OSError):
    """A file could not be read or written (missing, unreadable, disk full ...)."""

class Cancelled(RuntimeError):
    """The operation was cancelled; its input is unchanged."""

class Layer:
    """One layer: a polyline, open or closed, with its parameters. Lengths in scene units."""

    def __init__(
        self,
        points: npt.ArrayLike,
        *,
        name: str = "",
        closed: bool = False,
        thickness: float = 0.0,
        weight: float = 1.0,
        alpha: Optional[float] = None,
        beta: Optional[float] = None,
        outer: Optional[Sequence[str]] = None,
    ) -> None:
        """``points``: (n, 2) array, >= 2 points (3 if closed); ``name`` unique in a scene
        (empty: ``layer_<index>`` in files); ``thickness`` >= 0 (scene units); ``weight`` > 0
        (heavier moves less); ``alpha``, ``beta`` in [0, 1] (None: the algorithm's 0.8, 0.9);
        ``outer``: names of the layers directly outside (None in every layer: the scene's
        order is one stack, innermost first). Validated when the Scene is made."""
    @property
    def name(self) -> str: ...
    @property
    def points(self) -> npt.NDArray[np.float64]:
        """(n, 2) float64 array, a copy."""
    @property
    def closed(self) -> bool: ...
    @property
    def thickness(self) -> float: ...
    @property
    def weight(self) -> float: ...
    @property
    def alpha(self) -> Optional[float]: ...
    @property
    def beta(self) -> Optional[float]: ...
    @property
    def outer(self) -> Optional[List[str]]: ...
    @property
    def length(self) -> float:
        """Total length of the segments, scene units."""
    def __len__(self) -> int: ...

class Scene:
    """Layers plus their nesting, validated on construction (InvalidInput naming the layer,
    the point or field, and the value); exact consecutive duplicate points are removed."""

    def __init__(self, layers: Sequence[Layer], *, units: str = "") -> None: ...
    def __len__(self) -> int: ...
    def __getitem__(self, key: Union[int, str]) -> Layer: ...
    @property
    def layers(self) -> List[Layer]: ...
    @property
    def names(self) -> List[str]: ...
    @property
    def units(self) -> str:
        """Length unit of the coordinates ("m", "dm" ...); may be empty."""
    @property
    def notes(self) -> List[str]:
        """What validation changed or noticed (removed duplicates, unknown keys kept ...)."""
    @property
    def removed_duplicates(self) -> int: ...
    @property
    def vertex_count(self) -> int: ...
    @property
    def is_implicit_stack(self) -> bool:
        """No layer has ``outer``: the layers are one stack in order, innermost first."""
    @property
    def bounds(self) -> Tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax), scene units."""
    def required_separation(self, a: int, b: int) -> float:
        """Required distance between layers a and b, scene units."""
    def relation(self, a: int, b: int) -> str:
        """"same", "under", "over" or "side-by-side": placement of layer a with respect to b."""
    def with_points(self, layer: int, points: npt.ArrayLike) -> Scene:
        """A copy with the points of one layer replaced (validated)."""

class LayerReport:
    """Per-layer outcome of simplify()."""

    name: str
    before: int  #: Vertex count of the input layer.
    after: int  #: Vertex count of the result.
    target: int  #: Vertex count asked for.
    refused: int  #: Removals rolled back (their vertex kept).
    untangled: int  #: Removals that needed a local untangling.
    hausdorff: float  #: Symmetric Hausdorff distance to the input layer, scene units.
    max_displacement: float  #: Largest move of a kept vertex, scene units.

class SimplifyReport:
    """What simplify() did."""

    layers: List[LayerReport]
    removed: int
    untangle_calls: int
    refused: int
    gave_up: int
    chord_shifts: int
    shape_refused: int
    deferred: int
    batches: int
    targets_met: bool
    raised_separations: int
    rolled_vertices: int  #: Output vertices kept on a rolled side, as in the input.
    restored: int  #: Input vertices put back by the last resort (the whole-result check failed).
    trimmed_ends: int  #: End vertices of open layers taken out to meet a target (``trim_ends``).
    crossings: int  #: Final exact check of the output: crossings between layers.
    self_crossings: int
    nesting_violations: int
    min_separation_ratio: float  #: inf when nothing is required.
    collision_free: bool
    seconds_total: float  #: Seconds (also seconds_decimate, _fields, _untangle, _finish, _check).
    seconds_decimate: float
    seconds_fields: float
    seconds_untangle: float
    seconds_finish: float
    seconds_check: float
    @property
    def hausdorff(self) -> float:
        """Largest per-layer Hausdorff distance, scene units."""
    def to_dict(self) -> Dict[str, Any]:
        """The report as ``strata simplify --report`` writes it."""

class UntangleReport:
    tries: int  #: Untanglings from the input; passes, rounds and seconds count them all.
    passes: int
    rounds: int
    converged: bool
    collision_free: bool
    moved_vertices: int
    max_displacement: float  #: Scene units.
    crossings_before: int
    crossings_after: int
    self_crossings_after: int
    nesting_violations_after: int
    min_separation_ratio_after: float
    inferred_sides: bool  #: The input's rolled regions kept (sides inferred per region).
    gave_up: bool  #: The result's try ended early, stalled (give_up_when_stalled).
    input_kept: bool  #: Every try failed, none less tangled than the input: kept unchanged.
    @property
    def seconds(self) -> float: ...

def read_scene(path: Union[str, os.PathLike[str]]) -> Scene: ...
def write_scene(scene: Scene, path: Union[str, os.PathLike[str]]) -> None: ...
def _simplify(
    scene: Scene, options: Dict[str, Any], progress: Optional[Callable[[str, float], bool]]
) -> Tuple[Scene, SimplifyReport, Optional[SimplifyReport], Optional[Dict[str, Any]]]: ...
def _untangle(
    scene: Scene, options: Dict[str, Any], progress: Optional[Callable[[str, float], bool]]
) -> Tuple[Scene, UntangleReport]: ...
def _check(
    scene: Scene,
    reference: Optional[Scene],
    near_distance: float,
    separation_tolerance: float,
    hausdorff_tolerance: float,
) -> Dict[str, Any]: ...
def _slice(
    meshes: List[Any],
    axis: str,
    heights: List[float],
    split_components: bool,
    order: List[str],
    thickness: float,
    mesh_thickness: Dict[str, float],
    units: str,
    weld: bool,
    weld_tolerance: float,
) -> List[Optional[Scene]]: ...
def _sample_field(
    scene: Scene,
    layer: int,
    spacing: float,
    box: Optional[List[float]],
    backend: str,
    voxel_size: float,
    band_width: float,
    margin: float,
) -> Dict[str, Any]: ...
def _expand_inputs(inputs: List[str]) -> List[str]: ...
def _batch_output(folder: str, input: str) -> str: ...
def _batch_header() -> str: ...
def _batch_slice(input: str, output: str, options: Dict[str, Any]) -> Dict[str, Any]: ...
def _validate_options(options: Dict[str, Any]) -> None: ...
def _batch_footer(
    slices: int, failed: int, skipped: int, untangled: int, tangled: int, peak: float
) -> str: ...
def _peak_memory_mib() -> float: ...

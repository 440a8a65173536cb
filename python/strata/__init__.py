"""strata: collision-free simplification of 2D multi-layered shapes.

Python bindings of the strata C++ library (Gong, Parakkat & Rohmer 2023, on top of Buffet et
al. 2019). A scene is a list of layers, innermost first; a layer is a polyline (an (n, 2)
float64 array) with a name, ``closed``, a ``thickness`` (scene units, >= 0), a ``weight``
(> 0) and optionally ``outer`` (the names of the layers directly outside it).

Lengths are in scene units (the units of the points) throughout. Every function that computes
releases the GIL. Errors are :class:`InvalidInput` (a ``ValueError``: bad parameters or a bad
scene or file content), :class:`IoError` (an ``OSError``: a file that cannot be read or written)
and :class:`Cancelled`, carrying the message ``strata`` (the CLI) prints after
``strata: error:``, e.g. ``suit.json: layer 'b': thickness must be in [0, 1.79769e+308] (got
-0.5)``.

>>> import numpy as np, strata
>>> scene = strata.read_scene("tests/data/slices/cipc_multilayer_y+0.00.json")
>>> simplified, report = strata.simplify(scene, remove=0.9)
>>> report.collision_free, report.layers[0].before, report.layers[0].after
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _strata
from ._strata import (
    Cancelled,
    InvalidInput,
    IoError,
    Layer,
    LayerReport,
    Scene,
    SimplifyReport,
    UntangleReport,
)

__all__ = [
    "Cancelled",
    "CheckReport",
    "FieldGrid",
    "InvalidInput",
    "IoError",
    "Layer",
    "LayerReport",
    "Scene",
    "SimplifyReport",
    "UntangleReport",
    "check",
    "read_scene",
    "sample_field",
    "scene_from_arrays",
    "simplify",
    "slice",
    "untangle",
    "write_scene",
]

__version__ = "0.1.0"

PathLike = Union[str, "os.PathLike[str]"]


def read_scene(path: PathLike) -> Scene:
    """Reads a scene from a ``.json`` (strata's format) or ``.svg`` file (by extension).

    The scene is validated as ``strata`` validates it (finite coordinates, enough points,
    unique names, ``outer`` names that exist and form no cycle, parameters in range); exact
    consecutive duplicate points are removed and counted (``scene.removed_duplicates``,
    ``scene.notes``). Raises :class:`IoError` (missing or unreadable file) or
    :class:`InvalidInput` (the message names the file, the line and column or the layer and
    point, and the value).
    """
    return _strata.read_scene(os.fspath(path))


def write_scene(scene: Scene, path: PathLike) -> None:
    """Writes ``scene`` to ``path`` (``.json`` or ``.svg``, by extension), atomically: a
    temporary file beside it, then a rename. ``read_scene(p)`` after ``write_scene(s, p)``
    gives ``s`` back exactly (both formats)."""
    _strata.write_scene(scene, os.fspath(path))


def scene_from_arrays(
    arrays: Sequence[np.ndarray],
    *,
    names: Optional[Sequence[str]] = None,
    closed: Union[bool, Sequence[bool]] = False,
    thickness: Union[float, Sequence[float]] = 0.0,
    weight: Union[float, Sequence[float]] = 1.0,
    outer: Optional[Sequence[Optional[Sequence[str]]]] = None,
    units: str = "",
) -> Scene:
    """A scene from one (n, 2) float64 array per layer, innermost first.

    ``names`` default to ``layer_<index>``; ``closed`` (default False), ``thickness`` (scene
    units, default 0) and ``weight`` (default 1) are one value for every layer or one per
    layer; ``outer`` (default: none, the layers are then one stack in the given order) is one
    list of names per layer. Raises :class:`InvalidInput` naming the layer, the point and the
    value.
    """
    n = len(arrays)

    def per_layer(value, what):
        if isinstance(value, (str, bytes)) or not isinstance(value, Iterable):
            return [value] * n
        values = list(value)
        if len(values) != n:
            raise InvalidInput(f"scene_from_arrays: {what} has {len(values)} values for {n} layers")
        return values

    names = list(names) if names is not None else [f"layer_{i}" for i in range(n)]
    if len(names) != n:
        raise InvalidInput(f"scene_from_arrays: names has {len(names)} values for {n} layers")
    closed_l = per_layer(closed, "closed")
    thickness_l = per_layer(thickness, "thickness")
    weight_l = per_layer(weight, "weight")
    outer_l = list(outer) if outer is not None else [None] * n
    if len(outer_l) != n:
        raise InvalidInput(f"scene_from_arrays: outer has {len(outer_l)} values for {n} layers")
    layers = [
        Layer(
            np.asarray(a, dtype=np.float64),
            name=names[i],
            closed=bool(closed_l[i]),
            thickness=float(thickness_l[i]),
            weight=float(weight_l[i]),
            outer=None if outer_l[i] is None else list(outer_l[i]),
        )
        for i, a in enumerate(arrays)
    ]
    return Scene(layers, units=units)


def simplify(
    scene: Scene,
    remove: float = 0.9,
    *,
    keep: int = 0,
    decimator: str = "visvalingam",
    max_error: float = 0.0,
    seed: int = 1,
    untangle: bool = True,
    schedule: str = "deferred",
    untangle_batch: int = 16,
    n_out: int = 7,
    keep_gaps: float = 0.9,
    trim_ends: bool = True,
    thickness: float = 0.0,
    backend: str = "indexed",
    alpha: Optional[float] = None,
    beta: Optional[float] = None,
    gradient_steps: Optional[int] = None,
    tolerance: Optional[float] = None,
    max_rounds: Optional[int] = None,
    global_untangle: bool = False,
    shape_matching: bool = True,
    finish: bool = True,
    input_crossings: str = "untangle",
    progress: Optional[Callable[[str, float], bool]] = None,
) -> Tuple[Scene, SimplifyReport]:
    """Collision-free simplification, as ``strata simplify IN -o OUT`` (same defaults).

    Returns ``(simplified scene, report)``; ``scene`` itself is not changed. The report has
    per-layer counts (``report.layers[i].before / after / target / refused / untangled``),
    the per-layer symmetric Hausdorff distance to the input (scene units), the final exact
    check (``crossings``, ``nesting_violations``, ``collision_free``), timings in seconds
    (``seconds_total`` ...) and ``report.to_dict()`` (the CLI's ``--report`` JSON).

    Parameters (the CLI option in brackets):
      remove: fraction of each layer's vertices to remove, [0, 1] (``--remove``, 0.9).
      keep: vertices to keep per layer, 0 = use ``remove`` (``--keep``).
      decimator: "random" (the paper's), "visvalingam" or "max-error" (``--decimator``).
      max_error: > 0: never leave an input vertex farther than this, scene units.
      seed: seed of the random decimator.
      untangle: False = naive decimation (``--no-untangle``).
      schedule: "deferred" (default, fast) or "immediate" (the paper's Algorithm 1).
      untangle_batch: untanglings run side by side, >= 1 (``--untangle-batch``, 16).
      n_out: N_out, fixed collar vertices around each piece (7).
      keep_gaps: share of the smallest input gap kept by pairs of layers whose thicknesses
        require nothing, [0, 1], 0 = off (``--keep-gaps``, 0.9).
      trim_ends: a layer left above its target by refused removals may lose end vertices of
        its open pieces, where the exact check passes (``report.trimmed_ends``); False keeps
        every end (``--no-trim-ends``).
      thickness: thickness given to layers of thickness 0, scene units (0: none).
      backend: field evaluation, "indexed" (default), "exact" or "grid".
      alpha, beta: shape-matching stiffness and quadratic share, [0, 1] (0.8, 0.9).
      gradient_steps: N_gd, projection steps per round (10). tolerance: epsilon (1e-6,
        relative to the scene diagonal). max_rounds: rounds per pass (1).
      global_untangle: untangle the whole scene after each tangling removal (``--global``).
      shape_matching: False = pure projection (``--no-shape-matching``).
      finish: False = no finishing stage (``--no-finish``).
      input_crossings: an input that already crosses is untangled first ("untangle",
        default) or refused ("fail": :class:`InvalidInput` naming the first crossing).
      progress: called as progress("simplify", fraction of the removals done) from the
        computing thread (with the GIL), and as progress("untangle", fraction of its rounds)
        while an input that crosses is untangled first; returning False cancels
        (:class:`Cancelled`, nothing returned); an exception it raises, or Ctrl-C, stops the
        work and is raised.

    Raises :class:`InvalidInput` (a parameter out of range, with the CLI's message).
    """
    result, report, _naive, _untangled = _strata._simplify(
        scene,
        dict(
            remove=remove,
            keep=keep,
            decimator=decimator,
            max_error=max_error,
            seed=seed,
            untangle=untangle,
            schedule=schedule,
            untangle_batch=untangle_batch,
            n_out=n_out,
            keep_gaps=keep_gaps,
            trim_ends=trim_ends,
            thickness=thickness,
            backend=backend,
            alpha=alpha,
            beta=beta,
            gradient_steps=gradient_steps,
            tolerance=tolerance,
            max_rounds=max_rounds,
            global_untangle=global_untangle,
            shape_matching=shape_matching,
            finish=finish,
            input_crossings=input_crossings,
        ),
        progress,
    )
    return result, report


def untangle(
    scene: Scene,
    *,
    backend: str = "indexed",
    alpha: Optional[float] = None,
    beta: Optional[float] = None,
    gradient_steps: Optional[int] = None,
    tolerance: Optional[float] = None,
    max_rounds: Optional[int] = None,
    max_passes: Optional[int] = None,
    shape_matching: bool = True,
    finish: bool = True,
    global_order: bool = False,
    give_up_when_stalled: bool = False,
    progress: Optional[Callable[[str, float], bool]] = None,
) -> Tuple[Scene, UntangleReport]:
    """Untangles a scene that already crosses (the global mode of ``strata untangle``, without
    an original): every vertex may move; where the input has a part rolled over an open layer,
    by the sides inferred per region of it (``report.inferred_sides``) when that comes out
    clean, else by the global order. Returns ``(untangled scene, report)``;
    ``report.collision_free`` tells whether the result is clean (no crossing, nesting kept,
    gaps >= 0.9 x required); when it is not, the result is the least tangled of the tries and
    the input (``report.input_kept``: the input, unchanged).
    Parameters (``strata untangle``'s options; None: the library's default): ``backend``
    "indexed" (default), "exact" or "grid"; ``alpha`` 0.8 and ``beta`` 0.9 (shape matching,
    [0, 1]); ``gradient_steps`` 10; ``tolerance`` 1e-6 (relative to the scene diagonal);
    ``max_rounds`` 1 per pass; ``max_passes`` 64; ``shape_matching`` (default True; False =
    pure projection); ``finish`` (default True; False = no finishing stage, the paper's
    untangling alone); ``global_order`` (default False; True = the global order alone, as
    ``strata untangle --global-order``); ``give_up_when_stalled`` (default False; True = end each
    try early when its violation, extrapolated, would not fall enough by the pass cap, as
    ``strata untangle --give-up-when-stalled``: faster failures, fewer successes;
    ``report.gave_up``). ``progress``: as in
    :func:`simplify`, called once per round ("untangle", fraction; from the second try on,
    "untangle, try N")."""
    return _strata._untangle(
        scene,
        dict(
            backend=backend,
            alpha=alpha,
            beta=beta,
            gradient_steps=gradient_steps,
            tolerance=tolerance,
            max_rounds=max_rounds,
            max_passes=max_passes,
            shape_matching=shape_matching,
            finish=finish,
            global_order=global_order,
            give_up_when_stalled=give_up_when_stalled,
        ),
        progress,
    )


@dataclass
class CheckReport:
    """What :func:`check` found (``strata check``)."""

    collision_free: bool  #: No crossing or touch between layers, no self-crossing, nesting kept.
    crossings: int  #: Contacts between layers (proper crossings and touches).
    touches: int  #: Of which touches or overlaps.
    self_crossings: List[int]  #: Per layer.
    nesting_violations: int  #: Vertices on the wrong side of another layer.
    separation_violations: int  #: Vertices closer to another layer than required.
    min_separation_ratio: float  #: Smallest gap / required over the near pairs (inf: none).
    near_distance: float  #: Pairs closer than this were measured, scene units.
    #: (layer a, segment a, layer b, segment b, (x, y), is_touch) per listed crossing.
    crossing_list: List[tuple] = field(default_factory=list)
    #: (layer a, layer b, gap, required) per near pair, scene units.
    pairs: List[tuple] = field(default_factory=list)
    #: Symmetric Hausdorff distance to the reference's layer of the same name, scene units.
    hausdorff: Dict[str, float] = field(default_factory=dict)
    #: One line naming the first culprit ("" when collision-free).
    summary: str = ""


def check(
    scene: Scene,
    reference: Optional[Scene] = None,
    *,
    near: float = 0.0,
    separation_tolerance: float = 0.0,
    hausdorff_tolerance: float = 1e-9,
) -> CheckReport:
    """Exact checks of ``strata check``: crossings, self-crossings, separations of the layers
    closer than ``near`` (scene units, 0 = automatic: max(5% of the diagonal, 2 x the largest
    required separation)), nesting; with ``reference``, the symmetric Hausdorff distance of
    each layer to the reference's layer of the same name (to within ``hausdorff_tolerance`` x
    the reference's diagonal), and nesting is judged against the reference's sides as in
    ``strata check --reference`` (open layers take their outside side from it, and each vertex
    the side of the nearest vertex of its layer there: a rolled part keeps its side; a
    reference with none of the scene's layer names raises InvalidInput).
    ``separation_tolerance``: a gap passes when gap >= required x (1 - tol), [0, 1)."""
    d = _strata._check(scene, reference, near, separation_tolerance, hausdorff_tolerance)
    return CheckReport(**d)


def slice(  # noqa: A001 - the verb's name
    meshes: Sequence[
        Union[PathLike, Tuple[str, PathLike], Tuple[str, np.ndarray, np.ndarray]]
    ],
    at: Union[float, Sequence[float]],
    *,
    axis: str = "y",
    components: bool = False,
    order: Sequence[str] = (),
    thickness: float = 0.0,
    mesh_thickness: Optional[Mapping[str, float]] = None,
    units: str = "",
    weld: bool = True,
    weld_tolerance: float = 0.0,
) -> List[Optional[Scene]]:
    """Planar slices of garment meshes with their nesting (``strata slice``).

    ``meshes``: paths (OBJ/OFF/PLY/STL, read through OpenMesh; the layer names start with the
    file stem), tuples ``(name, path)`` (the CLI's ``name=path``) or tuples ``(name, vertices, faces)`` with vertices an (n, 3) float array and
    faces an (m, k >= 3) integer array of vertex indices. ``at``: one height or several, mesh
    units along ``axis`` ("x", "y" or "z"). Returns one scene per height (None where the plane
    misses every mesh). ``components``: name layers after their connected component;
    ``order``: mesh names innermost first; ``thickness`` (mesh units) for every layer,
    ``mesh_thickness`` per mesh name; ``weld`` (default True) joins open pieces that meet at a
    seam within ``weld_tolerance`` (mesh units; 0 = automatic, 5% of the median edge)."""
    heights = [float(at)] if np.isscalar(at) else [float(h) for h in at]
    items = [
        (m[0], os.fspath(m[1])) if isinstance(m, tuple) and len(m) == 2
        else m if isinstance(m, tuple) else os.fspath(m)
        for m in meshes
    ]
    return _strata._slice(
        items,
        axis,
        heights,
        components,
        list(order),
        float(thickness),
        dict(mesh_thickness or {}),
        units,
        weld,
        float(weld_tolerance),
    )


@dataclass
class FieldGrid:
    """A layer's signed distance field sampled on a regular grid (:func:`sample_field`).

    Row ``j`` (from the top) and column ``i`` (from the left) sample the point
    ``(xmin + (i + 0.5) h, ymax - (j + 0.5) h)`` with ``h`` the spacing, the orientation of an
    image (``strata grid --png``)."""

    value: np.ndarray  #: f, scene units: negative inside (under), positive outside; clamped to +-band_width.
    gradient_x: np.ndarray  #: d f / d x.
    gradient_y: np.ndarray  #: d f / d y.
    border: np.ndarray  #: Border field b of open layers, scene units (inf for closed layers).
    in_band: np.ndarray  #: bool: the sample lies in the narrow band.
    bounds: Tuple[float, float, float, float]  #: (xmin, ymin, xmax, ymax) of the grid, scene units.
    spacing: float  #: h, scene units.
    band_width: float  #: Half-width of the narrow band, scene units.
    voxel_size: float  #: OpenVDB voxel size (grid backend), else 0.


def sample_field(
    scene: Scene,
    layer: Union[int, str],
    *,
    spacing: Optional[float] = None,
    bounds: Optional[Tuple[float, float, float, float]] = None,
    backend: str = "grid",
    voxel_size: float = 0.0,
    band_width: float = 0.0,
    margin: Optional[float] = None,
) -> FieldGrid:
    """Samples the field of one layer (index or name) on a grid, for inspection
    (``strata grid``). ``backend``: "grid" (OpenVDB narrow band, default, as ``strata grid``),
    "indexed" or "exact". ``spacing`` (scene units; default: 1/400 of the larger side of the
    area), ``bounds`` (xmin, ymin, xmax, ymax; default: the layer's box inflated by ``margin``,
    default 2 x the band width). ``voxel_size`` and ``band_width``: scene units, 0 =
    automatic."""
    index = layer
    if isinstance(layer, str):
        names = scene.names
        if layer not in names:
            raise InvalidInput(f"sample_field: no layer named '{layer}'")
        index = names.index(layer)
    if spacing is None:
        if bounds is not None:
            xmin, ymin, xmax, ymax = bounds
        else:
            pts = scene[index].points
            xmin, ymin = pts.min(axis=0)
            xmax, ymax = pts.max(axis=0)
        spacing = max(xmax - xmin, ymax - ymin, 1e-300) / 400.0
    d = _strata._sample_field(
        scene,
        int(index),
        float(spacing),
        None if bounds is None else [float(b) for b in bounds],
        backend,
        float(voxel_size),
        float(band_width),
        -1.0 if margin is None else float(margin),
    )
    return FieldGrid(spacing=float(spacing), **d)

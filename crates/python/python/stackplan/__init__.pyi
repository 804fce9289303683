"""Type stubs of the ``stackplan`` package (the compiled module ``stackplan._native``).

Lengths in millimetres, angles in degrees (arguments named ``*_deg``). Options are those of the command line
``stackplan`` without ``--`` and with ``_`` for ``-``; the defaults below are the command line's.
"""

from os import PathLike
from typing import Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, "PathLike[str]"]
_Points = npt.ArrayLike  # (n, 3) numbers

class StackplanError(ValueError):
    """An error of stackplan, with the command line's one-line message."""

class Part:
    """A rigid part: a union of convex pieces (mm)."""

    @staticmethod
    def from_file(path: _Path, units: str = "mm", triangulate: bool = False) -> "Part":
        """Reads ``.step``/``.stp``, ``.stl``, ``.obj`` or part ``.json``; ``units`` (mm, cm, m, in) for STL and OBJ.
        STEP solids and non-convex meshes are recognised as sheet metal; ``triangulate`` splits concave faces by
        plain triangulation instead of merging triangles into larger convex pieces."""
    @staticmethod
    def from_arrays(pieces: Sequence[_Points], name: str = "part", density: float = 1.0) -> "Part":
        """A part from its convex pieces, each an ``(n, 3)`` array of points whose convex hull is the piece."""
    @staticmethod
    def example(name: str, triangulate: bool = False) -> "Part":
        """A built-in example: channel, triangle, complex, cube, l-corner or block."""
    @property
    def name(self) -> str: ...
    @property
    def pieces(self) -> list[npt.NDArray[np.float64]]:
        """The vertices of each convex piece, ``(n, 3)`` arrays (mm)."""
    @property
    def triangles(self) -> list[npt.NDArray[np.int64]]:
        """The faces of each piece as ``(k, 3)`` triangles indexing ``pieces[i]``, counter-clockwise from outside."""
    @property
    def volume(self) -> float:
        """Volume (mm^3)."""
    @property
    def mass(self) -> float:
        """Density x volume."""
    @property
    def center_of_gravity(self) -> npt.NDArray[np.float64]:
        """``(3,)`` (mm)."""
    @property
    def bounds(self) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """The bounding box ``(lo, hi)`` (mm)."""
    def to_json(self) -> str:
        """Part JSON in the convex-pieces form."""

class Plan:
    """A stacking plan."""

    @property
    def poses(self) -> npt.NDArray[np.float64]:
        """``(n, 4, 4)``: world point = ``pose[:3, :3] @ p + pose[:3, 3]`` for each placed part."""
    @property
    def part(self) -> Part: ...
    @property
    def placed(self) -> int: ...
    @property
    def count(self) -> int:
        """Parts asked for."""
    @property
    def height(self) -> float:
        """Height of the stack's top (mm)."""
    @property
    def footprint(self) -> Tuple[Tuple[float, float], Tuple[float, float]]:
        """``((x_min, y_min), (x_max, y_max))`` (mm)."""
    @property
    def total_cost(self) -> float:
        """Sum of the parts' cost terms (mm^2)."""
    @property
    def stopped(self) -> Optional[str]:
        """Why the plan ended early; ``None`` when every part was placed."""
    @property
    def stack_stable(self) -> bool: ...
    @property
    def seconds(self) -> float:
        """Planning time (s)."""
    def to_json(self, timings: bool = True) -> str:
        """``plan.json`` of ``stackplan plan``; ``timings=False``: the timings 0, as ``stackplan batch`` writes it."""
    def write(self, dir: _Path) -> None:
        """Writes plan.json, stack.svg, stack.png, build.svg, build.png, stack.glb and report.html into ``dir``."""

class Report:
    """The result of :func:`check`."""

    @property
    def ok(self) -> bool: ...
    def to_json(self) -> str:
        """As ``stackplan check --json`` prints it."""
    def to_dict(self) -> dict: ...

def plan(
    part: Union[Part, _Path],
    *,
    count: int = 15,
    w: float = 0.5,
    floor: Optional[Sequence[float]] = None,
    height: Optional[float] = None,
    clearance: float = 5.0,
    dtheta_deg: float = 5.0,
    mu: float = 0.5,
    cup_diameter: float = 10.0,
    candidates: int = 8,
    triangulate: bool = False,
    search_partitions: int = 2,
    grasp_tilt_deg: float = 5.0,
    time_limit: Optional[float] = None,
    node_budget: int = ...,
) -> Plan:
    """Plans a stack of ``count`` copies of ``part`` (a :class:`Part`, a part file or ``"example:NAME"``) as
    ``stackplan plan`` does. ``floor``: ``(x0, y0, x1, y1)`` (mm); default: a square of 3 part footprints plus 2
    clearances. ``height``: default 6 part sizes. ``triangulate`` only with a path. Releases the GIL."""

def check(
    stack: Union[Plan, _Path],
    mu: Optional[float] = None,
    clearance: Optional[float] = None,
    cup_diameter: Optional[float] = None,
    grasp_tilt_deg: Optional[float] = None,
    contact_tolerance: Optional[float] = None,
    margin_directions: int = 8,
) -> Report:
    """Checks every part of a stack as ``stackplan check`` does (a plan with its own options unless given)."""

def cspace_obstacle(
    a: _Points, b: _Points, theta_deg: float = 0.0
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
    """The c-space obstacle of convex piece ``a`` turned by ``theta_deg`` about z against convex piece ``b``:
    ``(vertices (m, 3), triangles (k, 3))``."""

def place(
    part: Part,
    stack: Union[Plan, _Path],
    *,
    floor: Optional[Sequence[float]] = None,
    floor_polygon: Optional[_Path] = None,
    height: Optional[float] = None,
    w: Optional[float] = None,
    origin: Optional[Sequence[float]] = None,
    target: Optional[Sequence[float]] = None,
    dtheta_deg: float = 5.0,
    clearance: float = 0.0,
    insertion: bool = False,
    fixed_z: Optional[float] = None,
    k: int = 1,
) -> dict:
    """The best placements of ``part`` in ``stack``, as ``stackplan place --json`` prints them: ``placements`` (best
    first), ``exhausted`` and ``stats``."""

def contacts(
    moving: Part,
    fixed: Part,
    t_min: Sequence[float],
    t_max: Sequence[float],
    *,
    offset: Optional[Sequence[float]] = None,
    seed: int = 1,
    population: int = ...,
    generations: int = ...,
) -> dict:
    """The assembly contact state graph of ``moving`` against ``fixed`` within ``t_min`` .. ``t_max`` on
    ``(x, y, z, rx, ry, rz)`` (mm, degrees), as ``stackplan contacts --json`` prints it."""

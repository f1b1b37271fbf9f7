# Type stubs of the tetseg.preprocess extension (GPL; CGAL). Docstrings: help().
import os
from typing import Any, Callable, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

class InputError(ValueError):
    file: str
    detail: str

_Mesh = Union[str, os.PathLike, Tuple[Any, Any], Sequence[Any]]

def build(mesh: _Mesh, *, source: Optional[str] = ..., clusters: str = ...,
          refine_visibility: float = ..., refine_max_clusters: int = ..., refine_gain: float = ...,
          refine_merge: bool = ..., alpha: float = ..., beta_divisor: float = ...,
          equalization: str = ..., growth_bound: float = ..., grow_through_marked: bool = ...,
          min_cluster_triangles: int = ..., detector: str = ..., min_visibility: float = ...,
          solver: str = ...,
          tolerance: float = ..., cell_size: float = ..., facet_size: float = ...,
          facet_distance: float = ..., optimize: bool = ..., threads: int = ...,
          repair: str = ..., wrap_alpha: float = ..., wrap_offset: float = ...,
          wrap_sheet_offset: float = ...,
          keep_largest_component: bool = ..., max_deviation: float = ...,
          time_limit: float = ...,
          rest_positions: bool = ..., body: str = ..., detectors: Optional[str] = ...,
          on_stage: Optional[Callable[[str, float, str], Any]] = ...) -> Tuple[bytes, dict]: ...
def charge(mesh: _Mesh, *, source: Optional[str] = ..., solver: str = ...,
           tolerance: float = ..., max_iterations: int = ..., theta: float = ...,
           order: int = ..., relaxed_products: bool = ..., equalize: str = ...,
           bins: int = ...) -> dict: ...
def generate(shape: str, *, size: float = ..., radius: float = ...,
             axes: Tuple[float, float, float] = ..., cell_size: float = ...,
             facet_size: float = ..., facet_distance: float = ..., facet_angle: float = ...,
             radius_edge_ratio: float = ..., optimize: bool = ...,
             threads: int = ...) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32]]: ...

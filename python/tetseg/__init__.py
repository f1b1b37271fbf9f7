"""tetseg: continuous self-collision detection for deformable tetrahedral objects.

The runtime part (this package) loads assets and answers per-step collision queries on NumPy
arrays; it links the tetseg runtime only. Building assets is in the separate, GPL-licensed
``tetseg.preprocess`` module (CGAL), which this package never imports. See docs/python.md.
"""

from ._runtime import (  # noqa: F401
    CONTACT_DTYPE,
    EDGE_EDGE,
    MODES,
    VERTEX_FACE,
    Asset,
    AssetError,
    BodyShape,
    Collider,
    ColliderError,
    FramesError,
    Scene,
    __version__,
    gather_node_positions,
    load_asset,
    read_frames,
    skinned_detector_positions,
)

__all__ = [
    "Asset",
    "AssetError",
    "BodyShape",
    "CONTACT_DTYPE",
    "Collider",
    "ColliderError",
    "EDGE_EDGE",
    "FramesError",
    "MODES",
    "Scene",
    "VERTEX_FACE",
    "gather_node_positions",
    "load_asset",
    "read_frames",
    "skinned_detector_positions",
]

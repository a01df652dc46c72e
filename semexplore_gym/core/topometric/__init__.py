"""Semantic topometric segmentation of occupancy grids (see :func:`segment_map` and
:class:`TopometricSegmenter`)."""

from semexplore_gym.core.topometric.params import SegmentationParams
from semexplore_gym.core.topometric.segmentation import TopometricSegmenter, segment_map
from semexplore_gym.core.topometric.types import (
    Area,
    AreaType,
    Frontier,
    GraphEdge,
    Opening,
    TopometricMap,
)

__all__ = [
    "Area",
    "AreaType",
    "Frontier",
    "GraphEdge",
    "Opening",
    "SegmentationParams",
    "TopometricMap",
    "TopometricSegmenter",
    "segment_map",
]

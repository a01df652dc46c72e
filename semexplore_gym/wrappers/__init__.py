"""Observation and action wrappers over SemanticExplore-v0 (variants of the canonical env)."""

from semexplore_gym.wrappers.egocentric import (
    EgocentricObservation,
    EgocentricParams,
    egocentric_features,
)
from semexplore_gym.wrappers.fixed_size import FixedSizeMap

__all__ = ["EgocentricObservation", "EgocentricParams", "FixedSizeMap", "egocentric_features"]

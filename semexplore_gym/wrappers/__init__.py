"""Observation and action wrappers over SemanticExplore-v0 (variants of the canonical env)."""

from semexplore_gym.wrappers.egocentric import (
    EgocentricObservation,
    EgocentricParams,
    egocentric_features,
)

__all__ = ["EgocentricObservation", "EgocentricParams", "egocentric_features"]

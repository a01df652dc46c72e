"""Semantic topometric segmentation of occupancy grids (see segment_map)."""

"""Worlds: wall geometry, bounds, start pose and ground-truth free space."""

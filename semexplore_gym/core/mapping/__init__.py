"""Mapping: LiDAR ray casting, log-odds occupancy grids and the odometry drift model."""

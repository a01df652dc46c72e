"""Frontiers: wavefront detection (WFD), the nearest reachable frontier for a disc robot, and
path distance to the nearest frontier."""

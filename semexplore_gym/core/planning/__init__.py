"""Planning: the paper's Algorithm 1 over the topometric graph, grid search (costmaps, Dijkstra,
Navfn-like), line of sight, the LiDAR potential field and the DWA local planner."""

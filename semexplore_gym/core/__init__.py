"""Pure algorithms (numpy / scipy / numba only; never gymnasium or pymunk).

Grid convention, said once here and used everywhere: a grid is indexed ``(row, col)``;
``col`` grows with world ``x`` and ``row`` grows with world ``y`` (row 0 is the *lowest* y,
as in a ROS ``nav_msgs/OccupancyGrid``). Cell ``(r, c)`` covers
``[origin_x + c*res, origin_x + (c+1)*res) x [origin_y + r*res, origin_y + (r+1)*res)``.
Images for people are flipped vertically when drawn (see ``semexplore_gym.rendering``).
"""

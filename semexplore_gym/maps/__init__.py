"""Maps and worlds from files, and the one entry point for every world spec.

- :func:`make_world` (:mod:`.world_specs`): ``"maze1"``, ``"office:seed=3"``, a ROS map
  ``.yaml``, a HouseExpo ``.json`` or ``"map:NAME"`` to a :class:`~semexplore_gym.core.worlds.World`.
- :mod:`.ros_map` and :mod:`.houseexpo`: the two map file formats.
- :mod:`.catalogue`: public maps of real places, pinned with checksums, and where they are
  looked for; :mod:`.download` fetches them into the map cache (``semexplore maps get``).

The worlds made by code and the geometry on arrays stay in :mod:`semexplore_gym.core.worlds`.
"""

from semexplore_gym.maps.houseexpo import load_houseexpo_world
from semexplore_gym.maps.ros_map import load_ros_map, load_ros_map_world
from semexplore_gym.maps.world_specs import make_world

__all__ = ["load_houseexpo_world", "load_ros_map", "load_ros_map_world", "make_world"]

"""Configuration and file input, one layer above the pure algorithms of ``core``.

- :mod:`~semexplore_gym.config.builder`: the one config path, :func:`build_params` (preset ->
  YAML -> mapping -> ``a.b=value`` overrides into a frozen dataclass), :func:`from_dict`,
  :func:`to_dict`, :func:`merge_overrides` and :class:`ConfigError`.
- :mod:`~semexplore_gym.config.loading`: bounded YAML / JSON reading (size, depth, aliases).
- :mod:`~semexplore_gym.config.output_paths`: output file checks made before any work is done.
"""

from semexplore_gym.config.builder import (
    ConfigError,
    build_params,
    from_dict,
    load_yaml,
    merge_overrides,
    nest_dotted,
    parse_override,
    to_dict,
)
from semexplore_gym.config.loading import UnsafeInputError, load_json_file, load_yaml_file
from semexplore_gym.config.output_paths import check_output_file

__all__ = [
    "ConfigError",
    "UnsafeInputError",
    "build_params",
    "check_output_file",
    "from_dict",
    "load_json_file",
    "load_yaml",
    "load_yaml_file",
    "merge_overrides",
    "nest_dotted",
    "parse_override",
    "to_dict",
]

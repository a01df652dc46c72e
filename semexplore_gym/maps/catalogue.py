"""The map catalogue: public ROS maps of real places, pinned to a commit, with checksums.

It also lists a documented sample of the DungeonMaps (``dungeon-*``, PNG world files read by
:mod:`.dungeon_maps`; the names and checksums are in :mod:`.dungeon_catalogue`).

``world="map:NAME"`` (see :func:`~semexplore_gym.maps.world_specs.make_world`) loads a
catalogue map from disk; this module knows what the maps are and where they live, and does no
network I/O. Fetching them is ``semexplore maps get NAME`` (:mod:`semexplore_gym.maps.download`).

Every file has a sha256 and a size. Upstream files are fetched from
``raw.githubusercontent.com/OWNER/REPO/COMMIT/PATH`` at the full commit hash given (checked
once against each repository: every upstream file exists at its commit with the catalogue's
sha256). Maps whose source has no map_server yaml (a bare image plus a scale in a Stage world
file) get a sidecar yaml written by us: this package generates it from the fields recorded
below, since there is nothing upstream to download, and checksums it like the rest.

Where maps are looked for, in order:

1. each directory in ``$SEMEXPLORE_MAPS_DIR`` (``os.pathsep``-separated), laid out either as
   the cache (``DIR/NAME/FILE``) or as the shared collection the catalogue was made from
   (``DIR/turtlebot3/world/map.yaml``, see :attr:`CatalogueMap.shared_subdir`);
2. the cache, :func:`maps_cache_dir`: ``$SEMEXPLORE_CACHE/maps``, else
   ``$XDG_CACHE_HOME/semexplore/maps``, else ``~/.cache/semexplore/maps``.
"""

from __future__ import annotations

import hashlib
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from semexplore_gym.maps import dungeon_catalogue as _dm

#: Where upstream files are fetched from; ``OWNER/REPO/COMMIT/PATH`` follows.
RAW_GITHUB_BASE = "https://raw.githubusercontent.com"
_NAME_RE = re.compile(r"^[a-z0-9][a-z0-9-]*$")


@dataclass(frozen=True)
class MapFile:
    """One file of a catalogue map.

    Attributes:
        filename: File name inside the map's directory (the yaml's ``image:`` refers to it).
        sha256: Hex sha256 of the file's bytes.
        size_bytes: File size.
        upstream_path: Path in the source repository at the pinned commit; ``None`` for a
            sidecar yaml shipped in this package (the source has none).
    """

    filename: str
    sha256: str
    size_bytes: int
    upstream_path: str | None


@dataclass(frozen=True)
class CatalogueMap:
    """A catalogue entry.

    Attributes:
        name: Catalogue name, as in ``map:NAME``.
        description: One line on what the map shows.
        licence: Licence of the map data (of the source repository or package).
        repo: Source repository, ``OWNER/NAME`` on GitHub.
        commit: The pinned commit of ``repo``.
        shared_subdir: Directory of the files in the shared collection layout.
        files: The map's files; the world file (``.yaml``, ``.json`` or DungeonMaps ``.png``)
            comes last.
    """

    name: str
    description: str
    licence: str
    repo: str
    commit: str
    shared_subdir: str
    files: tuple[MapFile, ...]

    @property
    def world_file(self) -> MapFile:
        """The file ``make_world`` loads (map_server ``.yaml``, HouseExpo ``.json``, DungeonMaps
        ``.png``)."""
        return self.files[-1]

    @property
    def size_bytes(self) -> int:
        return sum(f.size_bytes for f in self.files)

    @property
    def source(self) -> str:
        return f"github.com/{self.repo}@{self.commit}"

    def url(self, file: MapFile, base_url: str = RAW_GITHUB_BASE) -> str | None:
        """Download URL of ``file`` at the pinned commit (``None`` for a packaged sidecar)."""
        if file.upstream_path is None:
            return None
        return f"{base_url.rstrip('/')}/{self.repo}/{self.commit}/{file.upstream_path}"


def _up(directory: str, filename: str, sha256: str, size_bytes: int) -> MapFile:
    return MapFile(filename, sha256, size_bytes, f"{directory}/{filename}")


#: map_server fields of the sidecar yamls we write for sources that have none (our reading of
#: each source: scale from its world file or paper, thresholds fitted to its grey levels).
_SIDECAR_FIELDS: dict[str, dict[str, object]] = {
    "08d4ecc49835d0bd677138765d90a035.yaml": {
        "image": "08d4ecc49835d0bd677138765d90a035.png",
        "resolution": 0.01,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    },
    "15ded3a168cd9513b876ab36600b5650.yaml": {
        "image": "15ded3a168cd9513b876ab36600b5650.png",
        "resolution": 0.01,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    },
    "1dfb7bd5d9a447175a9719096fbacea7.yaml": {
        "image": "1dfb7bd5d9a447175a9719096fbacea7.png",
        "resolution": 0.01,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    },
    "1eb932a28c3b80449c06b59a35fbf549.yaml": {
        "image": "1eb932a28c3b80449c06b59a35fbf549.png",
        "resolution": 0.01,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    },
    "20ec9ec7f8783ee18b3c9da7bff12b0e.yaml": {
        "image": "20ec9ec7f8783ee18b3c9da7bff12b0e.png",
        "resolution": 0.01,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    },
    "237f80139e1659ec0232b6c7e6bd3e21.yaml": {
        "image": "237f80139e1659ec0232b6c7e6bd3e21.png",
        "resolution": 0.01,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    },
    "9cea230f67d0a5a2fb1dd857e1f4393d.yaml": {
        "image": "9cea230f67d0a5a2fb1dd857e1f4393d.png",
        "resolution": 0.01,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    },
    "Freiburg79_scan.yaml": {
        "image": "Freiburg79_scan.png",
        "resolution": 0.05,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    },
    "SFU_1200x615.yaml": {
        "image": "SFU_1200x615.png",
        "resolution": 1.0,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    },
    "c4513f5dfd084681ed2d0c24e85b9cf7.yaml": {
        "image": "c4513f5dfd084681ed2d0c24e85b9cf7.png",
        "resolution": 0.01,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    },
    "cave.yaml": {
        "image": "cave.png",
        "resolution": 0.032,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    },
    "freiburg_building79.yaml": {
        "image": "freiburg_building79.png",
        "resolution": 0.05,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    },
    "intel_map.yaml": {
        "image": "intel_map.png",
        "resolution": 0.05,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.2,
        "free_thresh": 0.05,
    },
    "willow-full.yaml": {
        "image": "willow-full.pgm",
        "resolution": 0.1,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.1,
    },
}


def _sidecar_text(filename: str) -> str:
    """The sidecar yaml we write for ``filename`` (map_server fields, one per line)."""
    f = _SIDECAR_FIELDS[filename]
    out = [
        "# map_server metadata written by semexplore: the source ships the image without one.",
        *(f"{k}: {list(v) if isinstance(v, tuple) else v}" for k, v in f.items()),
    ]
    return "\n".join(out) + "\n"


def _ours(filename: str, *_legacy: object) -> MapFile:
    data = _sidecar_text(filename).encode()
    return MapFile(filename, hashlib.sha256(data).hexdigest(), len(data), None)


_TB3 = ("ROBOTIS-GIT/turtlebot3", "Apache-2.0")
_NAV2 = ("ros-navigation/navigation2", "Apache-2.0")
_F1T = ("f1tenth/f1tenth_gym", "MIT")
_IPA = ("ipa320/ipa_coverage_planning", "LGPL, academic/non-commercial use only")
_STAGE = ("rtv/Stage", "GPL-2.0")
_IPA_DIR = "ipa_room_segmentation/common/files/test_maps"
_F1T_DIR = "gym/f110_gym/envs/maps"
_HOUSEEXPO_PNGS = (
    ("1dfb7bd5d9a447175a9719096fbacea7", "small 4-room flat, 7.1x5.7 m",
     "8a2bf1178d9e20ce7643660a66327db39dc68a529ad5c2f32eb4314c909c7911", 6284,
     "192cb31a0539c37f2f318d69d4509ad5a29947212b79640eefada875bc198314"),
    ("08d4ecc49835d0bd677138765d90a035", "L-shaped flat, 5-6 rooms, 9.5x9.0 m",
     "97b9a56619825bdf77373a7601fe710a7f85b3a071bdab4d6c0e4d66879fb629", 9546,
     "f28e0f480111754d6dd2986306a99afe411a57cc48ef8fceeef1d44487606ecc"),
    ("237f80139e1659ec0232b6c7e6bd3e21", "irregular outline, central hall, 12.5x12.5 m",
     "a5feaa1edd91df23d87ebb7c22951f8f8796a4d91aa1c6e1ce89bd36142fa262", 12169,
     "f3bc0d3b854a50eca68f050658643039dc57ea19d79c315c329cf26d5312ffd3"),
    ("9cea230f67d0a5a2fb1dd857e1f4393d", "two wings, strongly non-convex, 17.0x15.4 m",
     "7fa8371edb154a8b18d01e3584cdc1d640ce36a5e9a5bc965920946223877a3a", 17773,
     "26b29ac541784edb68af64cc3be4d8ac1b747654af4ae9bbc000df97fd204e17"),
    ("20ec9ec7f8783ee18b3c9da7bff12b0e", "long and narrow row of rooms, 29.1x8.8 m",
     "9493a68dd15954a6fd424ce3497690ee97dfb84a46eda9b991191f7c187a119a", 14551,
     "221c4633688ed9ad9729745498aac13fd7416898ee0007ed9ebd424a5f749331"),
    ("15ded3a168cd9513b876ab36600b5650", "many small rooms, two corridors, 15.3x18.1 m",
     "870d403e703a5e8134f1ae65294b2e13a6918db4bb4abbf561bd98b6994eb688", 34909,
     "452f0c1309625e6b5c6cce50febace56a2496b3124698ad50c3ac62b46aba85d"),
    ("1eb932a28c3b80449c06b59a35fbf549", "large house, central corridor, 23.3x31.1 m",
     "6079356978fe779d5a3fd7f1659b1b3e8b076602a4e3482e9efef2b187c8c472", 39103,
     "0ce4cfe244656eb02d76e01bc6f910e8b6f62211bd7ca24df9c7b11a64578825"),
    ("c4513f5dfd084681ed2d0c24e85b9cf7", "very large, big open rooms, 33.2x26.1 m",
     "1293f551d5da7d4da2eafc518d2a6603fbe35cade773191152f46b37466b0b85", 34863,
     "81a2e163fd857d0b9c13fa24c77face9a8e292e6036e635336a7d83790bdc9cc"),
)  # fmt: skip

_ENTRIES: tuple[CatalogueMap, ...] = (
    CatalogueMap(
        "tb3-world", "TurtleBot3 World: Gazebo hexagonal arena with 3x3 pillars (SLAM map)",
        _TB3[1], _TB3[0], "da785b7201d317e6e2a662e41bb3d3fd50ebd503", "turtlebot3/world",
        (_up("turtlebot3_navigation2/map", "map.pgm",
             "57eaad9291fcf02e068cbcd1874990694838a74a3304755bae1bd7b726c4522f", 147508),
         _up("turtlebot3_navigation2/map", "map.yaml",
             "964566f958dbee800d2e9961cb438476218526f4363b5fe550b9ea962efe584b", 131)),
    ),
    CatalogueMap(
        "tb3-office", "real office with desks, gmapping on a TurtleBot3 (RPLidar A3)",
        _TB3[1], _TB3[0], "5315fa67213f1052af57b8abe35105546cc0dcb8", "turtlebot3/office",
        (_up("maps", "map_office_raw.pgm",
             "32db1e9e5d9f27b5349def932165143d18f4f8cdc741c9e1c67dc34e6b1ad0af", 147508),
         _up("maps", "map_office_raw.yaml",
             "95479b1c49a6bb1de9641dbb2a723a4bfae1dec3b9f5f21ff39719d50a838582", 174)),
    ),
    CatalogueMap(
        "nav2-depot", "Nav2 demo depot: small warehouse floor with shelves, 30x15 m",
        _NAV2[1], _NAV2[0], "a3a97043ee93d92fe8d70ec56d183933169beb1c", "navigation2",
        (_up("nav2_bringup/maps", "depot.pgm",
             "71bbac79cfc2f5db89095182bfa86b29d96b07d4ed3b7726e513ed57afffc851", 185443),
         _up("nav2_bringup/maps", "depot.yaml",
             "fc724e706bfb453a5c4bf513644f754130be27b618e59d75293ead1b7e129bf6", 120)),
    ),
    CatalogueMap(
        "nav2-warehouse", "Nav2 demo warehouse: racks and aisles, 30x50 m at 3 cm",
        _NAV2[1], _NAV2[0], "a3a97043ee93d92fe8d70ec56d183933169beb1c", "navigation2",
        (_up("nav2_bringup/maps", "warehouse.pgm",
             "934ce2ca1feacc2216b68142349c6ebb3e46cc7c76fd80a9c2d2a6fb85ba7ff7", 1684107),
         _up("nav2_bringup/maps", "warehouse.yaml",
             "ec00d3d25912028e3debed9ded3d6471f70a3bf0f0d1a3f9470458f3068cc585", 125)),
    ),
    CatalogueMap(
        "willow-garage", "Willow Garage office building: offices, corridors, 54x59 m (SLAM map)",
        "BSD", "ros-simulation/stage_ros", "c3abc19b9e9713fe450597ca33b6f5399d1691ca", "stage_ros",
        (_up("world", "willow-full.pgm",
             "6ca11ef810d13d981dca36fd6592114a1abb4225008ba7affc549243b2cc5d2f", 317018),
         _ours("willow-full.yaml",
               "32ea0a1ccd7814917b22cd76a1ca0808b44bdb2e0175d47d87219772b7269de2", 582)),
    ),
    CatalogueMap(
        "intel-lab", "Intel Research Lab Seattle: ring corridor and small rooms (SLAM benchmark)",
        _IPA[1], _IPA[0], "f8a1dae4a09693f36a84fd92b6f9772d4c6faff1", "ipa_room_segmentation",
        (_up(_IPA_DIR, "intel_map.png",
             "05a2e536c6d9d2fdb72184668372293f96cbdf21f0272116375390805369711f", 99405),
         _ours("intel_map.yaml",
               "97d129115fbbe847656635b46baf3d0ff3091d81bff416d1a6be08df5020e8f0", 545)),
    ),
    CatalogueMap(
        "freiburg79", "Freiburg building 079: corridor with offices, raw SLAM map",
        _IPA[1], _IPA[0], "f8a1dae4a09693f36a84fd92b6f9772d4c6faff1", "ipa_room_segmentation",
        (_up(_IPA_DIR, "freiburg_building79.png",
             "dc8e2abd27d9d1bfeee50207c18825bef19df3ec58c1f8f80cc5bf3d6e576c18", 12448),
         _ours("freiburg_building79.yaml",
               "bc8b3135be0350c4bcf765105496b98fb6633ac2be3814cc9cc94c53ab15d6bb", 410)),
    ),
    CatalogueMap(
        "freiburg79-scan", "Freiburg building 079, cleaned into a tidy map with straight walls",
        _IPA[1], _IPA[0], "f8a1dae4a09693f36a84fd92b6f9772d4c6faff1", "ipa_room_segmentation",
        (_up(_IPA_DIR, "Freiburg79_scan.png",
             "fb51360bce67938c2562c1a60a774ab9e1aebc558d734afc0fe453d15774ca02", 4146),
         _ours("Freiburg79_scan.yaml",
               "2bca835702d7b8fd0a62550d9f2236b9f45bc5d750dc47796095c1bbf926c635", 406)),
    ),
    CatalogueMap(
        "stata-basement", "MIT Stata Center basement corridor loops, 87x66 m (SLAM map)",
        _F1T[1], _F1T[0], "4fdb9c7e6fb7c701290f4dc18377d07c1681724f", "f1tenth_gym",
        (_up(_F1T_DIR, "stata_basement.png",
             "b0ea5bed595dc3dd68f7d3c12a8b337c476c66a09fd7bf5c818c25c461b2aa2b", 23608),
         _up(_F1T_DIR, "stata_basement.yaml",
             "1363973d0e66d0fcbaa6a8b5e9c744ab4199619428dff760d2c0fb8a90b3c105", 133)),
    ),
    CatalogueMap(
        "skirk", "indoor corridors and rooms, 22x30 m (SLAM map)",
        _F1T[1], _F1T[0], "4fdb9c7e6fb7c701290f4dc18377d07c1681724f", "f1tenth_gym",
        (_up(_F1T_DIR, "skirk.png",
             "7af605d5487fbd7bbd3d7db286aa240cc0ce5ebfb7c6e144767aad8e2fd02aea", 10705),
         _up(_F1T_DIR, "skirk.yaml",
             "e1eb3c4d5535834232911eb6428cd432898507e265ce0d9a40a7e04c986ededb", 126)),
    ),
    CatalogueMap(
        "brsu-c069", "RoboCup@Home lab C069, H-BRS: two furnished rooms (SLAM map)",
        "GPL-3.0", "b-it-bots/mas_domestic_robotics", "fac00775f00ad11849e7e98bae2e45698c349ca2", "mas_domestic_robotics/brsu-c069",
        (_up("mdr_environments/brsu-c069", "map.pgm",
             "2d9ee74a8c0e146202fe343f0183b3029795c7262f0d9764594fe7823fe4a059", 313400),
         _up("mdr_environments/brsu-c069", "map.yaml",
             "10403c379c906a0e66f636e516b327fef5da8e7efd578b598a11f8b14c8b3dd3", 129)),
    ),
    CatalogueMap(
        "stage-cave", "Player/Stage cave: unstructured blobs, no straight walls, 16x16 m",
        _STAGE[1], _STAGE[0], "281ed731ed56b23d0879a2c765d4a20824a6d58a", "stage",
        (_up("worlds/bitmaps", "cave.png",
             "ebe0bd0973e25e40299d3877483574815c1cc4c82e96eadfbb9ef6994aaa7f3f", 3138),
         _ours("cave.yaml",
               "1e89df302a0219c676993e4b8f5d4eef894a4ad87918238f81a44ae42d0a0afd", 398)),
    ),
    CatalogueMap(
        "sfu-campus", "outdoor roads of the SFU campus, 1200x615 m at 1 m (stress test)",
        _STAGE[1], _STAGE[0], "281ed731ed56b23d0879a2c765d4a20824a6d58a", "stage",
        (_up("worlds/bitmaps", "SFU_1200x615.png",
             "d30276e5d31dd42763aee2ab227b96656eea3d6393e14dbaadd936f77d15e1fd", 224435),
         _ours("SFU_1200x615.yaml",
               "df6c3528a2a27dec6b36616d3d4779ca58364bde46324f185f4daf41970f31af", 513)),
    ),
    CatalogueMap(
        "houseexpo-1451", "HouseExpo 7-room house as a vector plan (JSON), 11.3x10.8 m",
        "MIT", "ExistentialRobotics/erl_geometry", "7d53206acc335ad95e826fe7af3688e4dd594a80", "houseexpo/json",
        (_up("data", "house_expo_room_1451.json",
             "30a679b267df712356e9549f823677a092660da63c4d1ef44051b942b8f595f7", 16655),),
    ),
    *(
        CatalogueMap(
            f"houseexpo-{house_id[:8]}", f"HouseExpo floor plan at 1 cm: {what}",
            "MIT", "diesistdername/HouseExpo", "c84d5eb85c4cfb330a2af417a9ab86fb155312f7", "houseexpo/png",
            (_up("png", f"{house_id}.png", png_sha, png_size),
             _ours(f"{house_id}.yaml", yaml_sha, 782)),
        )
        for house_id, what, png_sha, png_size, yaml_sha in _HOUSEEXPO_PNGS
    ),
)  # fmt: skip

#: Catalogue names of DungeonMaps start with this (:mod:`.dungeon_catalogue`).
DUNGEON_PREFIX = "dungeon-"


def _dungeon(folder: str, stem: str, sha256: str, size_bytes: int) -> CatalogueMap:
    """A DungeonMaps PNG (its world file: :mod:`.dungeon_maps` reads it, no yaml)."""
    return CatalogueMap(
        f"{DUNGEON_PREFIX}{folder}-{stem.replace('_', '-')}",
        f"DungeonMaps (Chen et al. 2019) {folder}/{stem}.png, 28x21 m at 0.04375 m/px",
        _dm.DUNGEON_LICENCE, _dm.DUNGEON_REPO, _dm.DUNGEON_COMMIT, f"DungeonMaps/{folder}",
        (_up(f"DungeonMaps/{folder}", f"{stem}.png", sha256, size_bytes),),
    )  # fmt: skip


_DUNGEON_ENTRIES = tuple(
    _dungeon(folder, *row)
    for folder, sample in (
        ("test", _dm.TEST_SAMPLE),
        ("train", _dm.TRAIN_SAMPLE),
        ("train", _dm.VALIDATION_SAMPLE),
    )
    for row in sample
)

#: Catalogue name -> entry.
CATALOGUE: dict[str, CatalogueMap] = {m.name: m for m in _ENTRIES + _DUNGEON_ENTRIES}


def get_catalogue_map(
    name: str, catalogue: Mapping[str, CatalogueMap] | None = None
) -> CatalogueMap:
    """The catalogue entry ``name``.

    Raises:
        ValueError: ``name`` is not in the catalogue (the message lists the names).
    """
    entries = CATALOGUE if catalogue is None else catalogue
    if name not in entries:
        raise ValueError(
            f"unknown map {name!r}; catalogue maps: {', '.join(sorted(entries))} "
            "(see: semexplore maps list)"
        )
    return entries[name]


def validate_map_name(name: str) -> str:
    """``name`` if it is a valid catalogue name (lower-case letters, digits, ``-``)."""
    if not _NAME_RE.match(name):
        raise ValueError(f"map name {name!r} must be lower-case letters, digits and '-'")
    return name


def maps_cache_dir(environ: Mapping[str, str] | None = None) -> Path:
    """The map cache: ``$SEMEXPLORE_CACHE/maps``, ``$XDG_CACHE_HOME/semexplore/maps`` or
    ``~/.cache/semexplore/maps`` (the first whose variable is set and non-empty)."""
    env = os.environ if environ is None else environ
    if env.get("SEMEXPLORE_CACHE"):
        return Path(env["SEMEXPLORE_CACHE"]).expanduser() / "maps"
    if env.get("XDG_CACHE_HOME"):
        return Path(env["XDG_CACHE_HOME"]).expanduser() / "semexplore" / "maps"
    return Path("~/.cache/semexplore/maps").expanduser()


def local_maps_dirs(environ: Mapping[str, str] | None = None) -> list[Path]:
    """The directories named in ``$SEMEXPLORE_MAPS_DIR`` (``os.pathsep``-separated)."""
    env = os.environ if environ is None else environ
    return [Path(p).expanduser() for p in env.get("SEMEXPLORE_MAPS_DIR", "").split(os.pathsep) if p]


def candidate_dirs(entry: CatalogueMap, root: Path, *, flat: bool = False) -> list[Path]:
    """Where ``entry``'s files may sit under ``root``: ``root/NAME`` (cache layout),
    ``root/SHARED_SUBDIR`` (shared collection layout) and, with ``flat``, ``root`` itself."""
    return [root / entry.name, root / entry.shared_subdir, *([root] if flat else [])]


def _complete(entry: CatalogueMap, directory: Path) -> bool:
    return all((directory / f.filename).is_file() for f in entry.files)


def resolve_map_file(
    name: str,
    environ: Mapping[str, str] | None = None,
    catalogue: Mapping[str, CatalogueMap] | None = None,
) -> Path:
    """The world file of catalogue map ``name``: from ``$SEMEXPLORE_MAPS_DIR``, else the cache.

    A directory counts only if it holds every file of the map.

    Raises:
        ValueError: ``name`` is not in the catalogue.
        FileNotFoundError: the map is in neither place (the message says how to get it).
    """
    entry = get_catalogue_map(name, catalogue)
    looked = [d for root in local_maps_dirs(environ) for d in candidate_dirs(entry, root)]
    looked.append(maps_cache_dir(environ) / entry.name)
    for directory in looked:
        if _complete(entry, directory):
            return directory / entry.world_file.filename
    raise FileNotFoundError(
        f"map {name!r} is not downloaded (looked in {', '.join(map(str, looked))}); "
        f"run: semexplore maps get {name}  (offline: semexplore maps get {name} --from DIR)"
    )


def sidecar_bytes(file: MapFile) -> bytes:
    """The bytes of a sidecar yaml this package writes (the source has none)."""
    if file.upstream_path is not None:
        raise ValueError(f"{file.filename} is an upstream file, not a packaged sidecar")
    return _sidecar_text(file.filename).encode()


def sha256_file(path: Path) -> str:
    """Hex sha256 of a file, read in chunks."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            digest.update(chunk)
    return digest.hexdigest()

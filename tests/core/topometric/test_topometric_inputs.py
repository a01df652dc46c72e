"""Input checking, parameters and the JSON / networkx export of the topometric map."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from _topometric_maps import CLEARANCE_M, RES_M, T_OPEN, H

from semexplore_gym.core.grid import GridGeometry, parse_ascii_grid
from semexplore_gym.core.topometric import SegmentationParams, segment_map
from semexplore_gym.core.topometric.export import (
    FORMAT,
    area_graph_node_link,
    opening_graph_node_link,
    to_json_dict,
)


@pytest.fixture(scope="module")
def t_map():
    grid = parse_ascii_grid(T_OPEN)
    return grid, segment_map(grid, RES_M, CLEARANCE_M)


# ----------------------------------------------------------------------------------------------
# bad input
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "grid,exc,words",
    [
        (np.zeros((5, 5), dtype=np.float32), TypeError, "float32"),
        (np.zeros((5, 5), dtype=bool), TypeError, "bool"),
        (np.zeros(25, dtype=np.uint8), ValueError, "2-D"),
        (np.zeros((2, 5, 5), dtype=np.uint8), ValueError, "2-D"),
        (np.zeros((0, 5), dtype=np.uint8), ValueError, "empty"),
        (np.full((5, 5), 7, dtype=np.uint8), ValueError, "value 7"),
        (np.full((5, 5), 200, dtype=np.int16), ValueError, "200"),
        (np.full((5, 5), -2, dtype=np.int8), ValueError, "-2"),
    ],
)
def test_bad_grids_raise_clear_errors(grid, exc, words):
    with pytest.raises(exc, match=words):
        segment_map(grid, 0.05, CLEARANCE_M)


def test_encoded_value_error_names_the_position():
    grid = np.full((6, 6), 255, dtype=np.uint8)
    grid[4, 3] = 17
    with pytest.raises(ValueError, match=r"17 at \(row=4, col=3\)"):
        segment_map(grid, 0.05, CLEARANCE_M)


@pytest.mark.parametrize("res", [0.0, -0.05, float("nan"), float("inf")])
def test_non_positive_resolution(res):
    with pytest.raises(ValueError, match="resolution"):
        segment_map(np.full((5, 5), 255, dtype=np.uint8), res, CLEARANCE_M)


def test_other_bad_arguments():
    grid = np.full((5, 5), 255, dtype=np.uint8)
    with pytest.raises(TypeError, match="GridGeometry"):
        segment_map(grid, "0.05", CLEARANCE_M)
    with pytest.raises(ValueError, match="does not match"):
        segment_map(grid, GridGeometry(0.05, 0.0, 0.0, 6, 5), CLEARANCE_M)
    with pytest.raises(ValueError, match="clearance_m"):
        segment_map(grid, 0.05, -0.1)
    with pytest.raises(ValueError, match="clearance_m"):
        segment_map(grid, 0.05, float("nan"))
    with pytest.raises(TypeError, match="SegmentationParams"):
        segment_map(grid, 0.05, CLEARANCE_M, params={"spur_ratio": 0.5})
    with pytest.raises(TypeError, match="TopometricMap"):
        segment_map(grid, 0.05, CLEARANCE_M, previous="last")


def test_params_validation_and_from_dict():
    assert SegmentationParams.from_dict({"spur_ratio": 0.3}).spur_ratio == 0.3
    with pytest.raises(ValueError, match="unknown SegmentationParams key.*spur_ration"):
        SegmentationParams.from_dict({"spur_ration": 0.3})
    with pytest.raises(ValueError, match="max_hole_area_m2"):
        SegmentationParams(max_hole_area_m2=-1.0)
    with pytest.raises(ValueError, match="core_radius_ratio"):
        SegmentationParams(core_radius_ratio=0.0)
    with pytest.raises(TypeError, match="spur_ratio"):
        SegmentationParams(spur_ratio="big")
    with pytest.raises(ValueError, match="finite"):
        SegmentationParams(path_tolerance_m=float("inf"))
    with pytest.raises(ValueError, match="chord_search_deg"):
        SegmentationParams(chord_search_deg=90.0)


def test_clearance_decides_what_is_passable():
    grid = parse_ascii_grid(T_OPEN)  # 0.7 m corridors
    assert segment_map(grid, RES_M, 0.30).counts()["intersections"] == 1
    # a 0.72 m robot fits only in the junction square (0.9 m across): one area, no way out
    m = segment_map(grid, RES_M, 0.36)
    assert [(a.type, a.opening_ids) for a in m.areas.values()] == [(20, ())] and m.frontiers == []
    assert segment_map(grid, RES_M, 0.46).areas == {}


def test_zero_clearance_and_coarse_frontier_width():
    grid = parse_ascii_grid(T_OPEN)
    m = segment_map(grid, RES_M, 0.0)
    assert m.counts()["intersections"] == 1
    wide = SegmentationParams(min_frontier_width_m=1.0)  # the 0.7 m opening is too narrow now
    assert segment_map(grid, RES_M, CLEARANCE_M, params=wide).frontiers == []


# ----------------------------------------------------------------------------------------------
# export
# ----------------------------------------------------------------------------------------------


def test_json_export_is_plain_json(t_map):
    _, m = t_map
    d = to_json_dict(m)
    text = json.dumps(d)  # plain types only
    back = json.loads(text)
    assert back["format"] == FORMAT
    assert back["counts"] == m.counts()
    assert back["geometry"] == m.geometry.to_dict()
    assert back["mean_intersection_path_m"] is None  # nan -> null
    assert len(back["areas"]) == len(m.areas) and len(back["openings"]) == len(m.openings)
    inter = next(a for a in back["areas"] if a["type"] == "intersection")
    assert inter["n_openings"] == 3 and inter["n_frontier_pathways"] == 1
    (f,) = back["frontiers"]
    assert f["intersection_id"] == inter["id"] and f["path_length_m"] > 0
    for a in back["areas"]:
        assert set(a["paths_m"]) == {str(k) for k in m.areas[a["id"]].paths_m}
    slim = to_json_dict(m, include_paths=False)
    assert "paths_m" not in slim["areas"][0] and "path_m" not in slim["opening_graph"]["edges"][0]
    with pytest.raises(TypeError):
        to_json_dict({"areas": []})


def test_node_link_graphs_load_in_networkx():
    nx = pytest.importorskip("networkx")
    grid = parse_ascii_grid(H)
    m = segment_map(grid, RES_M, CLEARANCE_M)
    og = nx.node_link_graph(json.loads(json.dumps(opening_graph_node_link(m))), edges="edges")
    ag = nx.node_link_graph(json.loads(json.dumps(area_graph_node_link(m))), edges="edges")
    assert og.number_of_nodes() == len(m.openings) and og.number_of_edges() == len(m.edges)
    assert ag.number_of_nodes() == len(m.areas)
    assert ag.number_of_edges() == sum(1 for o in m.openings if min(o.area_ids) >= 0)
    assert nx.is_connected(ag)
    # the metric route between the two outer dead-end mouths runs through both intersections
    inters = [a.id for a in m.areas.values() if a.type == 0]
    mouths = [o.id for o in m.openings if any(m.areas[x].type == 20 for x in o.area_ids)]
    length = nx.shortest_path_length(og, mouths[0], mouths[-1], weight="length_m")
    assert math.isfinite(length) and length > 0
    assert {ag.nodes[i]["type"] for i in inters} == {"intersection"}

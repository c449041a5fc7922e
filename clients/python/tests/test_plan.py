"""Plans through the client: every planner, zones, battery; the path in Python form."""
import os
import pathlib
import xml.etree.ElementTree as ElementTree

import pytest

import covplan
from conftest import MAPS
from geometry import inside, moves, ring_points, samples


def test_office_plan_sweeps_every_reachable_cell(client, office_id):
    plan = client.plan(office_id, tool_width=0.5, seed=1, time_limit_s=0.5)
    stats = plan.stats
    assert plan.planner == "oarp" and plan.plan_id.startswith("p-")
    assert stats.covered_cells == stats.free_cells > 0
    assert plan.path[0].kind == "START"
    swept = {w.rank for w in plan.path if w.kind == "COVERAGE"}
    assert swept == set(range(stats.num_ranks))  # every rank driven
    assert plan.length_m("COVERAGE") == pytest.approx(stats.coverage_length_m, rel=1e-6)
    assert plan.length_m("TRANSITION") == pytest.approx(stats.transition_length_m, rel=1e-6)
    again = client.get_plan(plan.plan_id)
    assert again.response == plan.response


def test_path_array_matches_the_path(client, office_id):
    numpy = pytest.importorskip("numpy")
    plan = client.plan(office_id, tool_width=0.5, seed=1, time_limit_s=0.5)
    array = plan.path_array()
    assert array.shape == (len(plan.path), 6)
    assert numpy.allclose(array[:, :4], [(w.x, w.y, w.theta, w.time_s) for w in plan.path])
    assert numpy.all(numpy.diff(array[:, 3]) >= 0)  # times never go back
    assert array[-1, 3] == pytest.approx(plan.duration_s, rel=1e-9)


@pytest.mark.parametrize("planner,options", [
    ("boustrophedon", {"sweepAxis": "SWEEP_AXIS_HORIZONTAL"}),
    ("stc", {"tree": "STC_TREE_PRIM"}),
    ("oarp", {"partitionSolver": "MATCHING", "tourSolver": "GREEDY"}),
])
def test_every_planner_with_its_options(client, office_id, planner, options):
    plan = client.plan(office_id, tool_width=0.5, planner=planner, options=options,
                       time_limit_s=0.5)
    assert plan.planner == planner
    assert plan.stats.covered_cells == plan.stats.free_cells > 0
    if planner == "oarp":
        assert plan.stats.partition_solver.lower() == "matching"


def test_no_go_zone_is_never_entered(client):
    yard = pathlib.Path(MAPS) / "sample_yard.geojson"
    zone_file = os.path.join(MAPS, "sample_yard_no_go.geojson")
    plan = client.plan(yard, tool_width=0.5, no_go=zone_file, time_limit_s=0.5)
    [zone] = covplan.read_polygons(zone_file)
    ring = ring_points(zone.outer)
    assert plan.stats.no_go_cells > 0
    for a, b in moves(plan):
        for point in samples(a, b, 0.05):
            assert not inside(point, ring), f"move {a}->{b} enters the no-go zone at {point}"
    free = client.plan(yard, tool_width=0.5, time_limit_s=0.5)
    assert any(inside(p, ring) for a, b in moves(free, "COVERAGE") for p in samples(a, b, 0.1))


def test_region_limits_what_is_covered(client, office_id):
    whole = client.plan(office_id, tool_width=0.5, time_limit_s=0.5)
    room = [(0, 0), (6, 0), (6, 6), (0, 6)]
    part = client.plan(office_id, tool_width=0.5, regions=room, time_limit_s=0.5)
    assert 0 < part.stats.free_cells < whole.stats.free_cells
    for a, b in moves(part, "COVERAGE"):
        for x, y in (a, b):
            assert -0.5 <= x <= 6.5 and -0.5 <= y <= 6.5


def test_battery_splits_the_tour_into_cycles(client, office_id):
    battery = {"capacity": 300.0, "station": {"x": 1.0, "y": 1.0}}
    plan = client.plan(office_id, tool_width=0.5, battery=battery, time_limit_s=0.5)
    cycles = plan.response.cycles
    assert plan.stats.charge_cycles == len(cycles) > 1
    assert all(c.energy <= 300.0 + 1e-6 for c in cycles)
    kinds = {w.kind for w in plan.path}
    assert {"TO_STATION", "FROM_STATION"} <= kinds


def test_svg_draws_every_move(client, office_id, tmp_path):
    plan = client.plan(office_id, tool_width=0.5, time_limit_s=0.5)
    root = ElementTree.fromstring(plan.to_svg())
    lines = root.findall("{http://www.w3.org/2000/svg}line")
    assert len(lines) == len(plan.path) - 1

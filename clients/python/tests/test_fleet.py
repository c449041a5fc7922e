"""Fleets through the client: PlanFleet, GetMission, UpdateMission."""
import pytest


def robot(name, x, y):
    return {"id": name, "robot": {"toolWidthM": 0.5, "start": {"x": x, "y": y}}}


def test_fleet_plan_divides_the_site_and_a_stopped_robot_hands_over(client, office_id):
    fleet = client.plan_fleet(office_id, [robot("west", 1.5, 1.5), robot("east", 20.0, 1.5)],
                              time_limit_s=1.0)
    assert set(fleet.plans) == {"west", "east"}
    durations = [r.duration_s for r in fleet.response.robots]
    assert fleet.makespan_s == pytest.approx(max(durations))
    assert fleet.lower_bound_s <= fleet.makespan_s
    assert fleet.response.covered_cells == fleet.response.cover_cells
    assert sum(r.assigned_cells for r in fleet.response.robots) == fleet.response.cover_cells
    for name, plan in fleet.plans.items():
        assert client.get_plan(plan.plan_id).plan_id == plan.plan_id

    mission = client.get_mission(fleet.mission_id)
    assert {r.robot_id for r in mission.robots} == {"west", "east"}
    update = client.update_mission(fleet.mission_id, [{"robotId": "east", "stopped": True}])
    assert [r.id for r in update.robots] == ["west"]
    assert update.handed_over_cells > 0
    after = client.get_mission(fleet.mission_id)
    assert {r.robot_id: r.stopped for r in after.robots} == {"west": False, "east": True}


def test_fleet_robots_take_the_shared_model_unless_they_set_their_own(client, office_id):
    bare = [{"id": "a", "robot": {"start": {"x": 1.5, "y": 1.5}}},
            {"id": "b", "robot": {"start": {"x": 20.0, "y": 1.5}, "maxSpeedMps": 0.2}}]
    fleet = client.plan_fleet(office_id, bare, tool_width=0.5, max_speed=0.6, time_limit_s=0.5)
    assert fleet.plans["a"].grid.cell_size_m == pytest.approx(0.5)
    # b keeps its own slow speed: its coverage metres take longer per metre than a's.
    per_metre = {name: p.duration_s / (p.stats.coverage_length_m + p.stats.transition_length_m)
                 for name, p in fleet.plans.items()}
    assert per_metre["b"] > 1.5 * per_metre["a"]
    with pytest.raises(TypeError, match="own start"):
        client.plan_fleet(office_id, bare, tool_width=0.5, start=(1, 1))


def test_fleet_division_by_name(client, office_id):
    fleet = client.plan_fleet(office_id, [robot("a", 1.5, 1.5), robot("b", 20.0, 1.5)],
                              division="equal_area", time_limit_s=0.5)
    assert fleet.response.division == 1  # FLEET_DIVISION_EQUAL_AREA
    with pytest.raises(ValueError, match="makespan"):
        client.plan_fleet(office_id, [robot("a", 1.5, 1.5)], division="fastest")

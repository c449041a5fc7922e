"""Replan, Resume and Drive sessions through the client."""
import pytest

import covplan
from geometry import moves


def first_long_coverage_move(plan, after=1):
    for i in range(max(after, 1), len(plan.path)):
        a, b = plan.path[i - 1], plan.path[i]
        if b.kind == "COVERAGE" and abs(b.x - a.x) + abs(b.y - a.y) > 3.0:
            return i, ((a.x + b.x) / 2, (a.y + b.y) / 2)
    raise AssertionError("no long coverage move")


def cell_of(plan, point):
    grid = plan.grid
    return (int((point[1] - grid.origin_y_m) // grid.cell_size_m),
            int((point[0] - grid.origin_x_m) // grid.cell_size_m))


def covers_cell(plan, cell, kind="COVERAGE"):
    """Whether a move of `kind` passes through the cell (sampled every 1/200 of a move)."""
    for a, b in moves(plan, kind):
        for t in range(201):
            x = a[0] + (b[0] - a[0]) * t / 200
            y = a[1] + (b[1] - a[1]) * t / 200
            if cell_of(plan, (x, y)) == cell:
                return True
    return False


def test_replan_drives_around_a_new_obstacle(client, office_id):
    plan = client.plan(office_id, tool_width=0.5, seed=3, time_limit_s=0.5)
    index, point = first_long_coverage_move(plan, after=5)
    here = plan.path[index - 1]
    new = client.replan(plan, progress=covplan.progress(index, (here.x, here.y)),
                        obstacles=covplan.obstacles(points=[point]))
    assert new.plan_id != plan.plan_id and new.method
    assert new.replan.newly_blocked_cells >= 1
    blocked = cell_of(plan, point)
    assert not covers_cell(new, blocked, "COVERAGE")
    assert not covers_cell(new, blocked, "TRANSITION")
    assert new.replan.complete == (not new.unreachable)
    assert client.get_plan(new.plan_id).plan_id == new.plan_id


def test_replan_methods_by_name(client, office_id):
    plan = client.plan(office_id, tool_width=0.5, seed=3, time_limit_s=0.5)
    index, point = first_long_coverage_move(plan, after=5)
    here = plan.path[index - 1]
    detour = client.replan(plan.plan_id, progress=covplan.progress(index, (here.x, here.y)),
                           obstacles=covplan.obstacles(points=[point]), method="greedy_detour")
    assert "greedy" in detour.method
    with pytest.raises(ValueError, match="ilp1"):
        client.replan(plan, method="fastest")


def test_resume_from_a_pose(client, office_id):
    plan = client.plan(office_id, tool_width=0.5, seed=3, time_limit_s=0.5)
    stop = plan.path[len(plan.path) // 2]
    resumed = client.resume(plan, pose=(stop.x + 1.0, stop.y),
                            progress=covplan.progress(len(plan.path) // 2, (stop.x, stop.y)))
    assert resumed.replan.progress_source == "request"
    assert resumed.path[0].x == pytest.approx(stop.x + 1.0)
    assert 0 < resumed.stats.free_cells < plan.stats.free_cells


def test_drive_session_reports_an_obstacle_and_receives_a_replan(client, office_id):
    plan = client.plan(office_id, tool_width=0.5, seed=4, time_limit_s=0.5)
    index, point = first_long_coverage_move(plan, after=5)
    with client.drive(plan) as session:
        assert session.plan_id == plan.plan_id and session.session_id
        for waypoint in range(1, index):  # progress only: no events
            w = plan.path[waypoint - 1]
            session.report(covplan.progress(waypoint, (w.x, w.y)))
        here = plan.path[index - 1]
        sequence = session.report(covplan.progress(index, (here.x, here.y)),
                                  covplan.obstacles(points=[point]))
        event = session.next_event(timeout=30)
        assert event is not None and event.error is None
        assert event.sequence == sequence
        assert event.replan.plan_id != plan.plan_id
        assert session.plan_id == event.replan.plan_id
        assert not covers_cell(event.replan, cell_of(plan, point))
        assert session.next_event(timeout=0.5) is None  # nothing more was asked
    with pytest.raises(covplan.FailedPrecondition, match="closed"):
        session.report(covplan.progress(1, (here.x, here.y)))


def test_a_session_the_server_ended_raises_on_the_next_report(client, office_id):
    import time
    plan = client.plan(office_id, tool_width=0.5, seed=4, time_limit_s=0.5)
    w = plan.path[0]
    with client.drive(plan) as session:
        session.report(covplan.progress(1, (w.x, w.y)))
        time.sleep(4.5)  # past the test server's --session_idle_s=3
        assert session.ended
        assert isinstance(session.error, covplan.DeadlineExceeded)
        with pytest.raises(covplan.DeadlineExceeded, match="idle"):
            session.report(covplan.progress(1, (w.x, w.y)))
    with pytest.raises(covplan.DeadlineExceeded):  # how it ended, still after closing
        session.report(covplan.progress(1, (w.x, w.y)))


def test_drive_on_an_unknown_plan_raises_not_found(client):
    with pytest.raises(covplan.NotFound):
        with client.drive("p-00000000000000000000000000000000"):
            pass

#!/usr/bin/env python3
"""Drive a simulated robot along a plan through a Drive session: it reports its progress at
every waypoint, meets an obstacle the map did not show halfway, reports it, and drives the
plan the server pushes back until the end.

    python drive_robot.py --server 127.0.0.1:50051 --map maps/sample_office.yaml
"""
import argparse
import sys

import covplan


def obstacle_ahead(plan, start):
    """A point in the middle of the first coverage move at or after path[start]."""
    path = plan.path
    for i in range(max(start, 1), len(path)):
        if path[i].kind == "COVERAGE":
            a, b = path[i - 1], path[i]
            if abs(b.x - a.x) + abs(b.y - a.y) > 4 * plan.grid.cell_size_m:
                return i, ((a.x + b.x) / 2, (a.y + b.y) / 2)
    return None, None


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--server", default="127.0.0.1:50051")
    parser.add_argument("--token")
    parser.add_argument("--map", required=True)
    parser.add_argument("--tool-width", type=float, default=0.5)
    args = parser.parse_args()

    with covplan.Client(args.server, token=args.token) as client:
        try:
            plan = client.plan(client.put_map(args.map).map_id, tool_width=args.tool_width)
            run(client, plan)
        except covplan.CovplanError as e:
            sys.exit(f"covplan: {e}")


def run(client, plan):
    print(f"driving {plan!r}")
    seen = False
    with client.drive(plan) as session:
        print(f"session {session.session_id} open on {session.plan_id}")
        waypoint = 1
        while waypoint < len(plan.path):
            here = plan.path[waypoint - 1]
            if not seen and waypoint >= len(plan.path) // 2:
                index, point = obstacle_ahead(plan, waypoint)
                if point is not None:
                    seen = True
                    sequence = session.report(covplan.progress(waypoint, (here.x, here.y)),
                                              covplan.obstacles(points=[point]))
                    print(f"obstacle at ({point[0]:.2f}, {point[1]:.2f}) on waypoint {index}")
                    event = next((e for e in session.events(timeout=30)
                                  if e.sequence == sequence), None)
                    if event is None:
                        sys.exit("covplan: no replan within 30 s")
                    if event.error:
                        raise event.error
                    plan, waypoint = event.replan, 1
                    stats = event.replan.replan
                    print(f"replanned by {stats.method} in {stats.total_ms:.1f} ms: "
                          f"{stats.remaining_cells} cells left, new plan {plan.plan_id}, "
                          f"{len(plan.path)} waypoints")
                    continue
            session.report(covplan.progress(waypoint, (here.x, here.y)))
            waypoint += 1
        end = plan.path[-1]
        session.report(covplan.progress(len(plan.path) - 1, (end.x, end.y)))
    print(f"done: reached ({end.x:.2f}, {end.y:.2f}); obstacle {'met' if seen else 'never met'}")


if __name__ == "__main__":
    main()

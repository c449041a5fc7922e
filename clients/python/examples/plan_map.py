#!/usr/bin/env python3
"""Plan a map through covplan-server and save the plan as JSON, an SVG picture and the
exports a robot stack reads (GeoJSON, CSV waypoints, a nav_msgs/Path JSON).

    python plan_map.py --server 127.0.0.1:50051 --map maps/sample_office.yaml \
        --tool-width 0.5 --out plan_py
writes plan_py.json, .svg, .geojson, .csv and .nav_path.json and prints the figures.
"""
import argparse
import json
import pathlib
import sys

import covplan


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--server", default="127.0.0.1:50051")
    parser.add_argument("--token", help="bearer token (a server with --token_file)")
    parser.add_argument("--map", required=True, help=".yaml, .png/.pgm (with --resolution), "
                        ".geojson")
    parser.add_argument("--resolution", type=float, help="metres per pixel of a .png/.pgm")
    parser.add_argument("--no-go", help="GeoJSON of zones the robot must never enter")
    parser.add_argument("--tool-width", type=float, default=0.5)
    parser.add_argument("--planner", default="oarp", choices=["oarp", "boustrophedon", "stc"])
    parser.add_argument("--out", default="plan_py", help="output prefix")
    args = parser.parse_args()

    options = {"resolution": args.resolution} if args.resolution else {}
    with covplan.Client(args.server, token=args.token) as client:
        try:
            info = client.put_map(args.map, **options)
            plan = client.plan(info.map_id, tool_width=args.tool_width, planner=args.planner,
                               no_go=args.no_go)
        except covplan.CovplanError as e:
            sys.exit(f"covplan: {e}")
    stats = plan.stats
    print(f"map {info.map_id[:12]} ({info.name}, {info.free_area_m2:.1f} m² free): "
          f"{plan.planner} plan {plan.plan_id}")
    print(f"  {stats.num_ranks} ranks, {stats.num_turns} turns, "
          f"{stats.coverage_length_m:.1f} m coverage + {stats.transition_length_m:.1f} m "
          f"transitions, {plan.duration_s:.1f} s, {stats.covered_cells}/{stats.free_cells} "
          f"cells swept, planned in {stats.planning_ms:.0f} ms")
    for suffix, text in ((".json", plan.to_json()), (".svg", plan.to_svg()),
                         (".geojson", json.dumps(plan.to_geojson())), (".csv", plan.to_csv()),
                         (".nav_path.json", json.dumps(plan.to_nav_path(frame_id="map")))):
        pathlib.Path(args.out + suffix).write_text(text)
    print(f"wrote {args.out}.json, .svg, .geojson, .csv and .nav_path.json")


if __name__ == "__main__":
    main()

"""Exports (GeoJSON, CSV, nav_msgs/Path JSON) from the Python package: validated against
RFC 7946 and the plan, read back by an independent library (shapely), and equal to what
the CLI's `covplan export` writes for the same plan."""
import csv
import io
import json
import math
import os
import pathlib
import subprocess

import pytest

import covplan
import covplan.exports
from conftest import MAPS, SERVER_BINARY

# A clockwise no-go square with a clockwise hole: the exports must turn the outer ring
# counter-clockwise and the hole clockwise (RFC 7946).
ZONE = {"type": "Polygon", "coordinates": [
    [[19.0, 2.0], [19.0, 5.0], [22.6, 5.0], [22.6, 2.0], [19.0, 2.0]],
    [[20.0, 3.0], [20.0, 4.0], [21.0, 4.0], [21.0, 3.0], [20.0, 3.0]]]}


@pytest.fixture(scope="module")
def yard_plan(server):
    battery = {"capacity": 400.0, "station": {"x": 1.0, "y": 1.0}}
    with covplan.Client(server.address) as client:
        return client.plan(pathlib.Path(MAPS) / "sample_yard.geojson", tool_width=0.5,
                           no_go=ZONE,
                           battery=battery, time_limit_s=0.5)


def test_geojson_follows_rfc7946_and_lies_inside_the_lawn(yard_plan):
    shapely = pytest.importorskip("shapely.geometry")
    document = json.loads(json.dumps(yard_plan.to_geojson()))  # JSON-clean
    assert document["type"] == "FeatureCollection"
    by_kind = {}
    for feature in document["features"]:
        by_kind.setdefault(feature["properties"]["feature"], []).append(feature)
    [path] = by_kind["path"]
    line = shapely.shape(path["geometry"])
    assert len(line.coords) == len(yard_plan.path)
    assert all(len(p) == 2 for p in path["geometry"]["coordinates"])  # [x, y]
    assert path["properties"]["times_s"][-1] == pytest.approx(yard_plan.duration_s, rel=1e-9)
    with open(os.path.join(MAPS, "sample_yard.geojson")) as f:
        yard = shapely.shape(json.load(f)["features"][0]["geometry"])
    assert yard.buffer(1e-6).contains(line)
    [zone] = by_kind["no_go"]
    polygon = shapely.shape(zone["geometry"])
    assert line.distance(shapely.Polygon(polygon.exterior)) > 0  # never entered nor touched
    outer, hole = zone["geometry"]["coordinates"]
    assert outer[0] == outer[-1] and shapely.LinearRing(outer).is_ccw
    assert hole[0] == hole[-1] and not shapely.LinearRing(hole).is_ccw
    assert len(by_kind["rank"]) == yard_plan.num_ranks
    assert len(by_kind.get("cycle", [])) == len(yard_plan.response.cycles) > 1


def test_csv_reads_back_to_the_same_path(yard_plan):
    rows = list(csv.DictReader(io.StringIO(yard_plan.to_csv())))
    assert len(rows) == len(yard_plan.path)
    for row, w in zip(rows, yard_plan.path):
        assert (float(row["x"]), float(row["y"]), float(row["heading_rad"]),
                float(row["time_s"])) == (w.x, w.y, w.theta, w.time_s)
        assert (row["kind"], int(row["rank"])) == (w.kind, w.rank)


def test_nav_path_quaternions_are_unit_and_match_the_headings(yard_plan):
    path = yard_plan.to_nav_path(frame_id="odom", start_stamp_s=1700000000.75)
    assert path["header"] == {"frame_id": "odom", "stamp": {"sec": 1700000000,
                                                            "nanosec": 750000000}}
    for pose, w in zip(path["poses"], yard_plan.path):
        q = pose["pose"]["orientation"]
        assert q["x"] ** 2 + q["y"] ** 2 + q["z"] ** 2 + q["w"] ** 2 == pytest.approx(1.0)
        yaw = math.atan2(2 * q["w"] * q["z"], 1 - 2 * q["z"] ** 2)
        assert math.remainder(yaw - w.theta, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)
        stamp = pose["header"]["stamp"]
        assert stamp["sec"] + stamp["nanosec"] * 1e-9 == pytest.approx(
            1700000000.75 + w.time_s, abs=2e-6)
    with pytest.raises(ValueError):
        yard_plan.to_nav_path(frame_id="")


def test_plans_without_times_are_refused_and_a_lone_waypoint_is_a_point(yard_plan):
    untimed = covplan.v1.covplan_pb2.PlanResponse()
    untimed.CopyFrom(yard_plan.response)
    for w in untimed.path:
        w.time_s = 0.0
    for export in (covplan.exports.to_geojson, covplan.exports.to_csv,
                   covplan.exports.to_nav_path):
        with pytest.raises(ValueError, match="no times"):
            export(untimed)
    del untimed.path[1:]
    geometry = covplan.exports.to_geojson(untimed)["features"][0]["geometry"]
    assert geometry == {"type": "Point", "coordinates": [untimed.path[0].x, untimed.path[0].y]}


def test_the_cli_writes_the_same_exports(yard_plan, tmp_path):
    cli = os.path.join(os.path.dirname(SERVER_BINARY), "covplan")
    if not os.access(cli, os.X_OK):
        pytest.fail(f"no covplan CLI beside the server ({cli})")
    plan_json = tmp_path / "plan.json"
    plan_json.write_text(yard_plan.to_json())
    subprocess.run([cli, "export", "--plan", str(plan_json), "--out-geojson",
                    str(tmp_path / "plan.geojson"), "--out-csv", str(tmp_path / "plan.csv"),
                    "--out-nav-path", str(tmp_path / "path.json"), "--nav-stamp", "12.5"],
                   check=True, capture_output=True)
    assert json.loads((tmp_path / "plan.geojson").read_text()) == yard_plan.to_geojson()
    assert json.loads((tmp_path / "path.json").read_text()) == yard_plan.to_nav_path(
        start_stamp_s=12.5)
    cli_rows = list(csv.reader(open(tmp_path / "plan.csv")))
    py_rows = list(csv.reader(io.StringIO(yard_plan.to_csv())))
    assert len(cli_rows) == len(py_rows) == len(yard_plan.path) + 1
    assert cli_rows[0] == py_rows[0]
    for a, b in zip(cli_rows[1:], py_rows[1:]):
        assert [float(v) for v in a[:4]] == [float(v) for v in b[:4]] and a[4:] == b[4:]

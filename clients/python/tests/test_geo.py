"""Geographic sites in the Python package (covplan.geo, on pyproj): the shipped lawn drawn
in longitude/latitude plans like the shipped yard in metres, its route comes back in
longitude/latitude inside the lawn, exactly as the CLI's --crs export writes it."""
import json
import os
import pathlib
import subprocess

import pytest

import covplan
from conftest import MAPS, SERVER_BINARY

pytest.importorskip("pyproj")
import covplan.geo  # noqa: E402

LAWN = os.path.join(MAPS, "sample_lawn_lonlat.geojson")
LAWN_NO_GO = os.path.join(MAPS, "sample_lawn_lonlat_no_go.geojson")
GREEDY = {"tourSolver": "GREEDY"}


@pytest.fixture(scope="module")
def lawn(server):
    site = covplan.geo.load_site(LAWN, crs="EPSG:4326")
    with covplan.Client(server.address) as client:
        plan = client.plan(site.map, tool_width=0.5, no_go=site.frame.project(LAWN_NO_GO),
                           options=GREEDY, seed=1)
    return site, plan


def test_lon_lat_lawn_plans_like_the_metric_yard(client, lawn):
    site, plan = lawn
    yard = client.plan(pathlib.Path(MAPS) / "sample_yard.geojson", tool_width=0.5,
                       no_go=os.path.join(MAPS, "sample_yard_no_go.geojson"), options=GREEDY,
                       seed=1)
    assert plan.num_ranks == yard.num_ranks
    assert plan.duration_s == pytest.approx(yard.duration_s, rel=0.005)
    assert plan.stats.covered_cells == plan.stats.free_cells == yard.stats.free_cells


def test_route_comes_back_in_lon_lat_inside_the_lawn(lawn):
    shapely = pytest.importorskip("shapely.geometry")
    site, plan = lawn
    route = plan.to_geojson(frame=site.frame)
    line = shapely.shape(route["features"][0]["geometry"])
    with open(LAWN) as f:
        area = shapely.shape(json.load(f)["features"][0]["geometry"])
    with open(LAWN_NO_GO) as f:
        no_go = shapely.shape(json.load(f)["features"][0]["geometry"])
    assert area.buffer(1e-9).contains(line)
    assert not line.intersects(no_go)
    assert "crs" not in route
    assert plan.to_csv(frame=site.frame).startswith("lon,lat,")


def test_frame_round_trips_and_names_bad_positions():
    site = covplan.geo.load_site(LAWN)
    frame = site.frame
    for lon, lat in ((11.5874, 48.1557), (11.5876, 48.1559)):
        back = frame.inverse(*frame.forward(lon, lat))
        assert back == pytest.approx((lon, lat), abs=1e-10)  # ~0.01 mm
    x, y = frame.forward(11.5874, 48.1557)  # the lawn's corner: the frame's origin
    assert abs(x) < 0.01 and abs(y) < 0.01
    with pytest.raises(ValueError, match="latitude 91"):
        frame.forward(11.5, 91.0)
    with pytest.raises(ValueError, match="EPSG:123456"):
        covplan.geo.GeoFrame("EPSG:123456", site.map.polygons.polygons)


def test_the_cli_exports_the_same_lon_lat_route(lawn, tmp_path):
    site, plan = lawn
    cli = os.path.join(os.path.dirname(SERVER_BINARY), "covplan")
    (tmp_path / "plan.json").write_text(plan.to_json())
    subprocess.run([cli, "export", "--plan", str(tmp_path / "plan.json"), "--map", LAWN,
                    "--crs", "EPSG:4326", "--out-geojson", str(tmp_path / "route.geojson")],
                   check=True, capture_output=True)
    theirs = json.loads((tmp_path / "route.geojson").read_text())
    ours = plan.to_geojson(frame=site.frame)
    assert len(theirs["features"]) == len(ours["features"])
    for a, b in zip(theirs["features"], ours["features"]):
        assert a["properties"] == b["properties"]
        coords_a = json.dumps(a["geometry"]["coordinates"])
        coords_b = json.dumps(b["geometry"]["coordinates"])
        flat_a = [float(v) for v in coords_a.replace("[", " ").replace("]", " ").split(",")]
        flat_b = [float(v) for v in coords_b.replace("[", " ").replace("]", " ").split(",")]
        assert flat_a == pytest.approx(flat_b, abs=1e-12)

#!/usr/bin/env python3
"""`covplan plan --crs`: a lawn drawn in longitude/latitude plans like the same lawn in
metres, and its exports lie where they should, checked with independent libraries
(python3-pyproj makes the lon/lat lawn and measures the round trip, python3-shapely reads
the exported GeoJSON back). Bad positions and CRSs fail naming them.

  geographic_test.py --client build/bin/covplan
Exit 77 (skipped) without pyproj/shapely unless CI=true.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

try:
    import pyproj
    import shapely.geometry
except ImportError as e:
    if os.environ.get("CI") == "true":
        raise
    print(f"SKIPPED: {e} (apt-get install python3-pyproj python3-shapely)")
    sys.exit(77)

# A lawn with a notch and a flower bed (a hole), metres; its middle is (30, 20).
OUTER = [(0, 0), (60, 0), (60, 40), (35, 40), (35, 30), (25, 30), (25, 40), (0, 40), (0, 0)]
HOLE = [(10, 10), (10, 16), (18, 16), (18, 10), (10, 10)]
NO_GO = [(42.2, 5.1), (49.7, 5.1), (49.7, 11.8), (42.2, 11.8), (42.2, 5.1)]
# The ground frame: a transverse Mercator centred on the lawn (Munich), made by pyproj.
GROUND = "+proj=tmerc +lat_0=48.137 +lon_0=11.575 +k=1 +x_0=0 +y_0=0 +datum=WGS84 +units=m"
TO_LL = pyproj.Transformer.from_crs(GROUND, "EPSG:4326", always_xy=True)
FROM_LL = pyproj.Transformer.from_crs("EPSG:4326", GROUND, always_xy=True)


def collection(rings):
    return {"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon",
                                                           "coordinates": rings}}]}


def lon_lat(ring):
    return [list(TO_LL.transform(x - 30.0, y - 20.0)) for x, y in ring]


def run(client, *args, ok=True):
    result = subprocess.run([client, "plan", "--local", *args], capture_output=True, text=True,
                            timeout=300)
    if ok:
        assert result.returncode == 0, result.stderr
    return result


def figures(text):
    ranks = int(next(l for l in text.splitlines() if l.startswith("ranks")).split()[1])
    duration = float(next(l for l in text.splitlines() if l.startswith("duration")).split()[1])
    return ranks, duration


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--client", required=True)
    args = parser.parse_args()
    d = tempfile.mkdtemp(prefix="covplan-geo-")
    path = lambda name: os.path.join(d, name)  # noqa: E731
    json.dump(collection([[list(p) for p in OUTER], [list(p) for p in HOLE]]),
              open(path("lawn_m.geojson"), "w"))
    json.dump(collection([lon_lat(OUTER), lon_lat(HOLE)]), open(path("lawn_ll.geojson"), "w"))
    json.dump(collection([[list(p) for p in NO_GO]]), open(path("no_go_m.geojson"), "w"))
    json.dump(collection([lon_lat(NO_GO)]), open(path("no_go_ll.geojson"), "w"))
    common = ["--tool-width", "0.5", "--tour", "greedy", "--seed", "1"]

    # 1. The same lawn, in metres and in lon/lat: same ranks, same duration within 0.5 %.
    metric = run(args.client, "--map", path("lawn_m.geojson"), "--no-go", path("no_go_m.geojson"),
                 *common)
    geo = run(args.client, "--map", path("lawn_ll.geojson"), "--crs", "EPSG:4326", "--no-go",
              path("no_go_ll.geojson"), *common, "--out", path("plan.json"), "--out-geojson",
              path("plan.geojson"), "--out-csv", path("plan.csv"))
    (ranks_m, duration_m), (ranks_g, duration_g) = figures(metric.stdout), figures(geo.stdout)
    print(f"metres: {ranks_m} ranks {duration_m} s; lon/lat: {ranks_g} ranks {duration_g} s")
    assert ranks_m == ranks_g, (ranks_m, ranks_g)
    assert abs(duration_g - duration_m) <= 0.005 * duration_m, (duration_m, duration_g)

    # 2. The exported path, read back by shapely in lon/lat, lies inside the lawn and
    #    outside the bed and the no-go zone.
    exported = json.load(open(path("plan.geojson")))
    path_feature = next(f for f in exported["features"] if f["properties"]["feature"] == "path")
    line = shapely.geometry.shape(path_feature["geometry"])
    lawn = shapely.geometry.Polygon(lon_lat(OUTER), [lon_lat(HOLE)])
    assert lawn.buffer(1e-9).contains(line), "the path leaves the lawn"
    assert not line.intersects(shapely.geometry.Polygon(lon_lat(NO_GO))), "enters the no-go"
    for f in exported["features"]:
        if f["geometry"]["type"] == "Polygon":
            ring = f["geometry"]["coordinates"][0]
            assert ring[0] == ring[-1] and shapely.geometry.LinearRing(ring).is_ccw
    assert "crs" not in exported  # EPSG:4326 is RFC 7946's own
    rows = list(csv.DictReader(open(path("plan.csv"))))
    assert [[float(r["lon"]), float(r["lat"])] for r in rows] == \
        path_feature["geometry"]["coordinates"]

    # 3. Round trip: the exported lon/lat, taken back to the ground frame by pyproj, is the
    #    plan's local path up to the frames' offset; to well under 1 cm.
    plan = json.load(open(path("plan.json")))
    local = [(w.get("x", 0.0), w.get("y", 0.0)) for w in plan["path"]]
    ground = [FROM_LL.transform(lon, lat) for lon, lat in
              path_feature["geometry"]["coordinates"]]
    dx = ground[0][0] - local[0][0]
    dy = ground[0][1] - local[0][1]
    worst = max(math.hypot(g[0] - l[0] - dx, g[1] - l[1] - dy) for g, l in zip(ground, local))
    print(f"round trip: worst {worst * 1000:.3f} mm over {len(local)} waypoints")
    assert worst < 0.01, worst

    # 4. The shipped lawn drawn in lon/lat (two polygons sharing an edge along a parallel,
    #    which the projection curves by micrometres) plans like the shipped yard in metres.
    maps = os.path.join(os.path.dirname(__file__), "..", "..", "maps")
    yard = run(args.client, "--map", os.path.join(maps, "sample_yard.geojson"), "--no-go",
               os.path.join(maps, "sample_yard_no_go.geojson"), *common)
    lawn = run(args.client, "--map", os.path.join(maps, "sample_lawn_lonlat.geojson"), "--crs",
               "EPSG:4326", "--no-go", os.path.join(maps, "sample_lawn_lonlat_no_go.geojson"),
               *common)
    (ranks_y, duration_y), (ranks_l, duration_l) = figures(yard.stdout), figures(lawn.stdout)
    print(f"shipped yard: {ranks_y} ranks {duration_y} s; lon/lat: {ranks_l} ranks {duration_l} s")
    assert ranks_y == ranks_l and abs(duration_l - duration_y) <= 0.005 * duration_y

    # 5. Bad input fails naming what is wrong.
    bad = collection([lon_lat(OUTER)])
    bad["features"][0]["geometry"]["coordinates"][0][3][1] = 91.5
    json.dump(bad, open(path("bad.geojson"), "w"))
    result = run(args.client, "--map", path("bad.geojson"), "--crs", "EPSG:4326", ok=False)
    assert result.returncode != 0 and "points[3]: latitude 91.5" in result.stderr, result.stderr
    result = run(args.client, "--map", path("lawn_ll.geojson"), "--crs", "EPSG:123456", ok=False)
    assert result.returncode != 0 and "EPSG:123456" in result.stderr, result.stderr
    office = os.path.join(maps, "sample_office.yaml")
    result = run(args.client, "--map", office, "--crs", "EPSG:4326", ok=False)
    assert result.returncode != 0 and "GeoJSON polygon map" in result.stderr, result.stderr
    print("geographic: all checks passed")


if __name__ == "__main__":
    main()

"""Maps and polygons from files, as the server takes them.

    office = covplan.load_map("maps/sample_office.yaml")      # ROS map_server YAML + image
    scan = covplan.load_map("scan.png", resolution=0.05)      # PNG or PGM: resolution needed
    lawn = covplan.load_map("lawn.geojson")                   # GeoJSON polygons: the free space
    zones = covplan.read_polygons("no_go.geojson")            # regions or no-go zones

GeoJSON is read as covplan's C++ reader does: RFC 7946 structure (Polygon, MultiPolygon,
Feature, FeatureCollection, GeometryCollection), coordinates [x, y] in metres in the map
frame. The server parses and checks the content: a bad image or YAML key is its
INVALID_ARGUMENT, with its message.
"""
import json
import os
import re

from covplan.v1 import covplan_pb2 as pb

_RASTER = (".png", ".pgm")
_GEOJSON = (".geojson", ".json")


def load_map(path, *, resolution=None, origin=None, negate=None, occupied_thresh=None,
             free_thresh=None, polygon_resolution=0.0):
    """A covplan.v1.Map from a file: .yaml (ROS map_server, its `image:` read relative to
    it), .png/.pgm (with `resolution` in metres per pixel) or .geojson (the free space's
    polygons; `polygon_resolution`: the raster used to check drive lines, 0 = server default).
    The keyword overrides win over the YAML's keys; `origin` is (x, y) of the bottom-left
    pixel corner."""
    path = os.fspath(path)
    ext = os.path.splitext(path)[1].lower()
    if ext in _GEOJSON:
        polygons = read_polygons(path)
        return pb.Map(polygons=pb.PolygonMap(polygons=polygons, resolution=polygon_resolution))
    raster = pb.RasterMap()
    if ext in (".yaml", ".yml"):
        with open(path, encoding="utf-8") as f:
            raster.yaml = f.read()
        image = _yaml_image(raster.yaml, path)
        with open(os.path.join(os.path.dirname(path), image), "rb") as f:
            raster.image = f.read()
    elif ext in _RASTER:
        if resolution is None:
            raise ValueError(f"{path}: a PNG or PGM map needs resolution= (metres per pixel)")
        with open(path, "rb") as f:
            raster.image = f.read()
    else:
        raise ValueError(f"{path}: unknown map format {ext!r} (expected .yaml, .png, .pgm, "
                         ".geojson)")
    if resolution is not None:
        raster.resolution = float(resolution)
    if origin is not None:
        raster.origin_x_m, raster.origin_y_m = (float(v) for v in origin)
    if negate is not None:
        raster.negate = bool(negate)
    if occupied_thresh is not None:
        raster.occupied_thresh = float(occupied_thresh)
    if free_thresh is not None:
        raster.free_thresh = float(free_thresh)
    return pb.Map(raster=raster)


def _yaml_image(text, path):
    try:
        import yaml  # python3-yaml, when present
        image = (yaml.safe_load(text) or {}).get("image")
    except ImportError:
        match = re.search(r"^image\s*:\s*(.+?)\s*$", text, re.MULTILINE)
        image = match and match.group(1).strip("'\"")
    if not image:
        raise ValueError(f"{path}: no `image:` key")
    return str(image)


def read_polygons(source):
    """Every polygon of a GeoJSON document (a path, a JSON text or a parsed dict), in
    document order, as covplan.v1.Polygon messages."""
    if isinstance(source, (str, os.PathLike)) and not str(source).lstrip().startswith("{"):
        with open(source, encoding="utf-8") as f:
            document, name = json.load(f), os.fspath(source)
    elif isinstance(source, str):
        document, name = json.loads(source), "geojson"
    else:
        document, name = source, "geojson"
    found = []
    _collect(document, name, found)
    if not found:
        raise ValueError(f"{name}: no Polygon or MultiPolygon found")
    return found


def _collect(node, where, out):
    if node is None:
        return
    if not isinstance(node, dict) or "type" not in node:
        raise ValueError(f"{where}: expected a GeoJSON object with a type")
    kind = node["type"]
    if kind == "FeatureCollection":
        for i, feature in enumerate(node.get("features", [])):
            _collect(feature, f"{where}: features[{i}]", out)
    elif kind == "Feature":
        _collect(node.get("geometry"), f"{where}.geometry", out)
    elif kind == "GeometryCollection":
        for i, geometry in enumerate(node.get("geometries", [])):
            _collect(geometry, f"{where}.geometries[{i}]", out)
    elif kind == "Polygon":
        out.append(polygon(*_rings(node.get("coordinates"), f"{where}.coordinates")))
    elif kind == "MultiPolygon":
        for i, rings in enumerate(node.get("coordinates") or []):
            out.append(polygon(*_rings(rings, f"{where}.coordinates[{i}]")))
    else:
        raise ValueError(f"{where}: a {kind} is not a polygon")


def _rings(rings, where):
    if not isinstance(rings, list) or not rings:
        raise ValueError(f"{where}: expected a list of rings")
    for i, ring in enumerate(rings):
        for j, position in enumerate(ring):
            if (not isinstance(position, list) or len(position) < 2 or
                    not all(isinstance(v, (int, float)) for v in position[:2])):
                raise ValueError(f"{where}[{i}][{j}]: expected a position [x, y] of numbers")
    return rings[0], rings[1:]


def polygon(outer, holes=()):
    """A covplan.v1.Polygon from an outer ring and holes, each a sequence of (x, y) in
    metres (closed or not: the first point is repeated when missing)."""
    return pb.Polygon(outer=_ring(outer), holes=[_ring(h) for h in holes])


def _ring(points):
    points = [(float(p[0]), float(p[1])) for p in points]
    if points and points[0] != points[-1]:
        points.append(points[0])
    return pb.Ring(points=[pb.Point2(x=x, y=y) for x, y in points])


def polygons(value):
    """Zones in any accepted form as covplan.v1.Polygon messages: None, a GeoJSON path or
    dict, a Polygon message, a ring of (x, y) points, or a list of those."""
    if value is None:
        return []
    if isinstance(value, pb.Polygon):
        return [value]
    if isinstance(value, (str, os.PathLike, dict)):
        return read_polygons(value)
    value = list(value)
    if value and _is_point(value[0]):
        return [polygon(value)]
    return [p for item in value for p in polygons(item)]


def _is_point(item):
    return (isinstance(item, (tuple, list)) and len(item) in (2, 3) and
            all(isinstance(v, (int, float)) for v in item))

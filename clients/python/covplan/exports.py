"""A plan in the formats robot stacks read, as `covplan export` and `covplan plan --out-*`
write them (api/plan_export.h is the reference; docs/clients.md shows them):

    geojson = covplan.exports.to_geojson(plan)     # dict: a GeoJSON FeatureCollection
    csv_text = covplan.exports.to_csv(plan)        # x,y,heading_rad,time_s,kind,rank
    path = covplan.exports.to_nav_path(plan, frame_id="map", start_stamp_s=time.time())

Coordinates are the map frame's metres. Rings are closed and follow RFC 7946's right-hand
rule (exteriors counter-clockwise, holes clockwise).
"""
import math

from covplan.v1 import covplan_pb2 as pb


def _response(plan):
    return getattr(plan, "response", plan)


def _xy(frame, x, y):
    """A map-frame position in the export's CRS (a covplan.geo.GeoFrame), or as it is."""
    return list(frame.inverse(x, y)) if frame is not None else [x, y]


def _ring(ring, exterior, frame=None):
    points = [_xy(frame, p.x, p.y) for p in ring.points]
    if points and points[0] != points[-1]:
        points.append(list(points[0]))
    twice_area = sum(a[0] * b[1] - b[0] * a[1] for a, b in zip(points, points[1:]))
    if (twice_area > 0) != exterior:
        points.reverse()
    return points


def _polygon(polygon, frame=None):
    return {"type": "Polygon",
            "coordinates": [_ring(polygon.outer, True, frame)] +
                           [_ring(h, False, frame) for h in polygon.holes]}


def _feature(name, geometry, **properties):
    properties["feature"] = name
    return {"type": "Feature", "geometry": geometry, "properties": properties}


def _cell_centre(grid, cell, frame=None):
    return _xy(frame, grid.origin_x_m + (cell.col + 0.5) * grid.cell_size_m,
               grid.origin_y_m + (cell.row + 0.5) * grid.cell_size_m)


def _check(r):
    """Refuses what cannot be exported honestly (as api/plan_export.cc does)."""
    if not r.path:
        raise ValueError("the plan has no path")
    if len(r.path) > 1 and r.path[-1].time_s <= 0 and r.stats.estimated_duration_s > 0:
        raise ValueError("the plan's waypoints carry no times (time_s): it was written before "
                         "they did; fetch it again with get_plan or plan again")


def to_geojson(plan, frame=None):
    """The plan as a GeoJSON FeatureCollection (a dict; json.dump it): the path with per-vertex
    times_s, headings_rad, kinds and ranks (a Point for a one-waypoint path: an idle fleet
    robot); each OARP rank; each charge cycle; the zones. `frame` (covplan.geo.GeoFrame):
    positions back in the site's CRS."""
    r = _response(plan)
    _check(r)
    path = r.path
    geometry = ({"type": "Point", "coordinates": _xy(frame, path[0].x, path[0].y)}
                if len(path) == 1 else
                {"type": "LineString", "coordinates": [_xy(frame, w.x, w.y) for w in path]})
    features = [_feature(
        "path", geometry,
        plan_id=r.plan_id, planner=r.planner, duration_s=r.stats.estimated_duration_s,
        times_s=[w.time_s for w in path], headings_rad=[w.theta for w in path],
        kinds=[pb.SegmentKind.Name(w.kind) for w in path], ranks=[w.rank for w in path])]
    for i, rank in enumerate(r.ranks):
        features.append(_feature(
            "rank", {"type": "LineString",
                     "coordinates": [_cell_centre(r.grid, rank.first_cell, frame),
                                     _cell_centre(r.grid, rank.last_cell, frame)]},
            index=i, orientation=pb.Orientation.Name(rank.orientation)))
    for i, cycle in enumerate(r.cycles):
        points = [_xy(frame, w.x, w.y)
                  for w in path[max(0, cycle.first_waypoint):cycle.last_waypoint + 1]]
        if len(points) >= 2:
            features.append(_feature("cycle", {"type": "LineString", "coordinates": points},
                                     index=i, energy=cycle.energy))
    features += [_feature("region", _polygon(z, frame)) for z in r.regions]
    features += [_feature("no_go", _polygon(z, frame)) for z in r.no_go]
    collection = {"type": "FeatureCollection", "features": features}
    if frame is not None and frame.crs not in ("EPSG:4326", "OGC:CRS84"):
        collection["crs"] = {"type": "name", "properties": {"name": frame.crs}}
    return collection


def to_csv(plan, frame=None):
    """One line per waypoint after a header: x,y,heading_rad,time_s,kind,rank (repr floats:
    they read back exactly); with a geographic `frame`, lon,lat in its CRS."""
    r = _response(plan)
    _check(r)
    lines = [("lon,lat" if frame is not None and frame.geographic else "x,y") +
             ",heading_rad,time_s,kind,rank"]
    for w in r.path:
        x, y = _xy(frame, w.x, w.y)
        lines.append(f"{x!r},{y!r},{w.theta!r},{w.time_s!r},"
                     f"{pb.SegmentKind.Name(w.kind)},{w.rank}")
    return "\n".join(lines) + "\n"


def _stamp(start_s, offset_s):
    """start + offset as a ROS stamp, each split into whole seconds and nanoseconds first
    (no precision lost adding large doubles); all 0 without a start."""
    if start_s == 0:
        return {"sec": 0, "nanosec": 0}
    start_sec, offset_sec = math.floor(start_s), math.floor(offset_s)
    nanosec = (math.floor((start_s - start_sec) * 1e9 + 0.5) +
               math.floor((offset_s - offset_sec) * 1e9 + 0.5))
    return {"sec": int(start_sec + offset_sec + nanosec // 1_000_000_000),
            "nanosec": int(nanosec % 1_000_000_000)}


def to_nav_path(plan, frame_id="map", start_stamp_s=0.0):
    """The plan as a nav_msgs/Path in the ROS 2 message's JSON form (a dict): each pose
    stamped start_stamp_s + its waypoint's time_s (all stamps 0 without a start: "unset"),
    its orientation the yaw quaternion."""
    if not frame_id:
        raise ValueError("frame_id must not be empty")
    if not math.isfinite(start_stamp_s) or start_stamp_s < 0:
        raise ValueError("start_stamp_s must be Unix seconds >= 0")
    r = _response(plan)
    _check(r)

    def header(t):
        return {"frame_id": frame_id, "stamp": _stamp(start_stamp_s, t)}

    poses = [{"header": header(w.time_s),
              "pose": {"position": {"x": w.x, "y": w.y, "z": 0.0},
                       "orientation": {"x": 0.0, "y": 0.0, "z": math.sin(w.theta / 2),
                                       "w": math.cos(w.theta / 2)}}}
             for w in r.path]
    return {"header": header(0.0), "poses": poses}

"""Request pieces from plain Python values: poses as (x, y[, theta]), points as (x, y),
cells as (row, col), dicts in the proto's JSON form. Every function also takes the message
itself and returns it unchanged."""
from google.protobuf import json_format

from covplan import maps
from covplan.v1 import covplan_pb2 as pb

_PLANNER_OPTIONS = {"oarp": ("oarp", pb.OarpOptions),
                    "boustrophedon": ("boustrophedon", pb.BoustrophedonOptions),
                    "stc": ("stc", pb.StcOptions)}


def pose(value):
    """A covplan.v1.Pose from (x, y) or (x, y, theta radians)."""
    if value is None or isinstance(value, pb.Pose):
        return value
    x, y, *rest = value
    return pb.Pose(x=float(x), y=float(y), theta=float(rest[0]) if rest else 0.0)


def robot_model(tool_width, max_speed=None, acceleration=None, turn_rate_deg_s=None,
                start=None, end=None):
    """A covplan.v1.RobotModel; unset speeds are the server's defaults, an unset start is
    the first rank, an unset end the start."""
    robot = pb.RobotModel(tool_width_m=float(tool_width))
    if max_speed is not None:
        robot.max_speed_mps = float(max_speed)
    if acceleration is not None:
        robot.acceleration_mps2 = float(acceleration)
    if turn_rate_deg_s is not None:
        robot.turn_rate_deg_s = float(turn_rate_deg_s)
    if start is not None:
        robot.start.CopyFrom(pose(start))
    if end is not None:
        robot.end.CopyFrom(pose(end))
    return robot


def progress(waypoint=0, position=None, distance_m=None, tolerance_m=None):
    """Where the robot is on its plan: driving the segment that ends at path[waypoint] and
    standing at `position` (x, y), or `distance_m` driven along the path."""
    if isinstance(waypoint, pb.RobotProgress):
        return waypoint
    if isinstance(waypoint, dict):
        return json_format.ParseDict(waypoint, pb.RobotProgress())
    message = pb.RobotProgress(waypoint=int(waypoint))
    if position is not None:
        message.position.x, message.position.y = (float(v) for v in position[:2])
    if distance_m is not None:
        message.distance_m = float(distance_m)
    if tolerance_m is not None:
        message.tolerance_m = float(tolerance_m)
    return message


def obstacles(cells=(), points=(), polygons=None):
    """Newly seen obstacles: grid cells (row, col), map points (x, y) (their cells are
    blocked) and polygons (every cell they overlap is blocked)."""
    return pb.Obstacles(cells=[pb.CellRef(row=int(r), col=int(c)) for r, c in cells],
                        points=[pb.Point2(x=float(p[0]), y=float(p[1])) for p in points],
                        polygons=maps.polygons(polygons))


def from_dict(value, message_type):
    """`value` as a `message_type`: the message itself, None, or a dict in the proto's JSON
    form (e.g. {"capacity": 500, "station": {"x": 1, "y": 1}} for a Battery)."""
    if value is None or isinstance(value, message_type):
        return value
    return json_format.ParseDict(value, message_type())


def set_planner_options(request, planner, options):
    """Puts a planner's options (its message or a dict) into a PlanRequest."""
    if options is None:
        return
    name = planner or "oarp"
    if name not in _PLANNER_OPTIONS:
        raise ValueError(f"planner {name!r} has no options (oarp, boustrophedon, stc do)")
    field, message_type = _PLANNER_OPTIONS[name]
    getattr(request, field).CopyFrom(from_dict(options, message_type))


def enum_value(enum_type, value, prefixes=("",)):
    """An enum number from its number or name, case-insensitive, with or without the
    enum's prefix (ReplanMethod "ilp2", FleetDivision "equal_area")."""
    if value is None:
        return 0
    if isinstance(value, int):
        return value
    names = enum_type.keys()
    for prefix in prefixes:
        name = (prefix + str(value)).upper()
        if name in names:
            return enum_type.Value(name)
    raise ValueError(f"{value!r} is not one of {', '.join(n.lower() for n in names)}")

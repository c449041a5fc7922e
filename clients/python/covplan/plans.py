"""What the planning calls return: thin, read-only views over the response messages with
the figures and the path in Python form. `.response` is always the message itself."""
import collections
import functools

from google.protobuf import json_format

from covplan import exports
from covplan.v1 import covplan_pb2 as pb

try:
    import numpy
except ImportError:  # numpy is optional: path_array() says so
    numpy = None

Waypoint = collections.namedtuple("Waypoint", "x y theta time_s kind rank")
Waypoint.__doc__ = ("One path vertex: position (m), heading (rad), the kind of the segment "
                    "when the robot reaches it (s from the plan's start), the kind of the segment "
                    "ending here (\"START\", \"COVERAGE\", \"TRANSITION\", \"TO_STATION\", "
                    "\"FROM_STATION\") and the rank (or cell) it sweeps, else -1.")


def _kind_name(number):
    """A SegmentKind's name; the number as text for a kind newer than this client."""
    try:
        return pb.SegmentKind.Name(number)
    except ValueError:
        return str(number)


class Plan:
    """A coverage plan (covplan.v1.PlanResponse): plan_id for GetPlan, Replan, Resume and
    Drive; stats (covplan.v1.PlanStats); the path."""

    def __init__(self, response):
        self.response = response

    plan_id = property(lambda self: self.response.plan_id)
    map_id = property(lambda self: self.response.map_id)
    planner = property(lambda self: self.response.planner)
    stats = property(lambda self: self.response.stats)
    grid = property(lambda self: self.response.grid)
    num_ranks = property(lambda self: self.response.stats.num_ranks)
    duration_s = property(lambda self: self.response.stats.estimated_duration_s)
    cut_short = property(lambda self: self.response.stats.tour_cut_short)

    @functools.cached_property
    def path(self):
        """The path as a list of Waypoint(x, y, theta, time_s, kind, rank)."""
        return [Waypoint(w.x, w.y, w.theta, w.time_s, _kind_name(w.kind), w.rank)
                for w in self.response.path]

    def path_array(self):
        """The path as a numpy array of rows (x, y, theta, time_s, kind number, rank)."""
        if numpy is None:
            raise RuntimeError("path_array() needs numpy (Debian: python3-numpy)")
        return numpy.array([(w.x, w.y, w.theta, w.time_s, w.kind, w.rank)
                            for w in self.response.path], dtype=float).reshape(-1, 6)

    def length_m(self, kind=None):
        """Length of the path's segments (of one kind, e.g. "COVERAGE", when given)."""
        total, path = 0.0, self.response.path
        for a, b in zip(path, path[1:]):
            if kind is None or _kind_name(b.kind) == kind:
                total += ((b.x - a.x) ** 2 + (b.y - a.y) ** 2) ** 0.5
        return total

    def to_svg(self, width=900):
        """The plan drawn as SVG text (covplan.svg.plan_svg)."""
        from covplan.svg import plan_svg
        return plan_svg(self, width)

    def to_geojson(self, frame=None):
        """The plan as a GeoJSON FeatureCollection dict (covplan.exports.to_geojson); with a
        covplan.geo.GeoFrame, in its site's CRS."""
        return exports.to_geojson(self, frame)

    def to_csv(self, frame=None):
        """CSV waypoints: x,y,heading_rad,time_s,kind,rank (covplan.exports.to_csv)."""
        return exports.to_csv(self, frame)

    def to_nav_path(self, frame_id="map", start_stamp_s=0.0):
        """A nav_msgs/Path as a dict in the ROS 2 message's form (covplan.exports)."""
        return exports.to_nav_path(self, frame_id, start_stamp_s)

    def to_json(self):
        """The plan in the proto's JSON form, as the CLI's plan.json (snake_case names,
        defaults printed)."""
        return json_format.MessageToJson(self.response, preserving_proto_field_name=True,
                                         including_default_value_fields=True)

    def __repr__(self):
        return (f"Plan({self.plan_id!r}, planner={self.planner!r}, ranks={self.num_ranks}, "
                f"duration_s={self.duration_s:.1f}, waypoints={len(self.response.path)})")


class Replan(Plan):
    """A replanned or resumed plan (covplan.v1.ReplanResponse): the new Plan's fields, plus
    `replan` (covplan.v1.ReplanStats) and the cells the new obstacles cut off."""

    def __init__(self, response):
        super().__init__(response.plan)
        self.replan_response = response

    replan = property(lambda self: self.replan_response.replan)
    method = property(lambda self: self.replan_response.replan.method)

    @property
    def unreachable(self):
        return [(c.row, c.col) for c in self.replan_response.unreachable]


class FleetPlan:
    """A fleet plan (covplan.v1.PlanFleetResponse): mission_id, the makespan and its lower
    bound, and per robot id its Plan."""

    def __init__(self, response):
        self.response = response
        self.plans = {r.id: Plan(r.plan) for r in response.robots}

    mission_id = property(lambda self: self.response.mission_id)
    makespan_s = property(lambda self: self.response.makespan_s)
    lower_bound_s = property(lambda self: self.response.lower_bound_s)
    gap = property(lambda self: self.response.gap)

    def __repr__(self):
        return (f"FleetPlan({self.mission_id!r}, robots={list(self.plans)}, "
                f"makespan_s={self.makespan_s:.1f}, gap={self.gap:.3f})")

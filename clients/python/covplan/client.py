"""covplan.Client: every CoveragePlanner method with Python values in and out, a deadline on
every call, a bearer token and TLS when the server asks for them, and errors as exceptions
(covplan.errors) that keep the server's code and message."""
import os

import grpc

from covplan import errors, maps, messages
from covplan.drive import DriveSession
from covplan.plans import FleetPlan, Plan, Replan
from covplan.v1 import covplan_pb2 as pb
from covplan.v1 import covplan_pb2_grpc as pb_grpc

_MAX_MESSAGE = 512 << 20  # plans of 50,000 ranks are tens of MiB


class Client:
    """A connection to covplan-server.

    address: "host:port" of its gRPC port. token: the tenant's bearer token (a server with
    --token_file). tls: True for a TLS port; root_certificates: the CA's PEM (bytes or a
    path) when the server's certificate is not signed by a system CA. timeout: the default
    deadline of each call in seconds (a Plan's tour search stops before it: the budget is
    min(time_limit_s, deadline))."""

    def __init__(self, address="127.0.0.1:50051", *, token=None, tls=False,
                 root_certificates=None, timeout=60.0):
        options = [("grpc.max_receive_message_length", _MAX_MESSAGE),
                   ("grpc.max_send_message_length", _MAX_MESSAGE),
                   # A Drive stream over a dead link fails within ~30 s instead of hanging
                   # (covplan-server accepts pings every 10 s during calls).
                   ("grpc.keepalive_time_ms", 20000), ("grpc.keepalive_timeout_ms", 10000),
                   ("grpc.keepalive_permit_without_calls", 0)]
        if tls or root_certificates is not None:
            if isinstance(root_certificates, (str, os.PathLike)):
                with open(root_certificates, "rb") as f:
                    root_certificates = f.read()
            credentials = grpc.ssl_channel_credentials(root_certificates=root_certificates)
            self._channel = grpc.secure_channel(address, credentials, options)
        else:
            self._channel = grpc.insecure_channel(address, options)
        self._stub = pb_grpc.CoveragePlannerStub(self._channel)
        self._metadata = (("authorization", f"Bearer {token}"),) if token else ()
        self.address = address
        self.timeout = timeout

    def close(self):
        self._channel.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def _call(self, method, request, timeout):
        try:
            return getattr(self._stub, method)(
                request, timeout=self.timeout if timeout is None else timeout,
                metadata=self._metadata)
        except grpc.RpcError as e:
            raise errors.from_rpc_error(e, method) from None

    # ------------------------------------------------------------------ maps

    def put_map(self, map, *, name="", timeout=None, **load_options):
        """Stores a map (a path, as covplan.load_map takes it with **load_options, or a
        covplan.v1.Map) and returns its covplan.v1.MapInfo; map_id is derived from the
        content, so putting the same map again returns the same id."""
        if not isinstance(map, pb.Map):
            if not name:
                name = os.path.basename(os.fspath(map))
            map = maps.load_map(map, **load_options)
        return self._call("PutMap", pb.PutMapRequest(map=map, name=name), timeout).info

    def get_map(self, map_id, *, include_content=False, timeout=None):
        """covplan.v1.GetMapResponse: info, and the map itself with include_content."""
        return self._call("GetMap", pb.GetMapRequest(map_id=map_id,
                                                     include_content=include_content), timeout)

    def list_maps(self, *, page_size=0, timeout=None):
        """Every stored map's covplan.v1.MapInfo, all pages."""
        found, token = [], ""
        while True:
            page = self._call("ListMaps", pb.ListMapsRequest(page_size=page_size,
                                                             page_token=token), timeout)
            found.extend(page.maps)
            token = page.next_page_token
            if not token:
                return found

    def delete_map(self, map_id, *, timeout=None):
        """True when the map existed and is deleted."""
        return self._call("DeleteMap", pb.DeleteMapRequest(map_id=map_id), timeout).deleted

    # ------------------------------------------------------------------ planning

    def plan_request(self, map, *, tool_width, planner="", options=None, max_speed=None,
                     acceleration=None, turn_rate_deg_s=None, start=None, end=None,
                     regions=None, no_go=None, battery=None, time_limit_s=0.0, seed=0,
                     min_free_fraction=0.0, improve_remembered=False, map_options=None):
        """The covplan.v1.PlanRequest that plan() sends (see there)."""
        request = pb.PlanRequest(
            robot=messages.robot_model(tool_width, max_speed, acceleration, turn_rate_deg_s,
                                       start, end),
            planner=planner, time_limit_s=float(time_limit_s), seed=int(seed),
            min_free_fraction=float(min_free_fraction), regions=maps.polygons(regions),
            no_go=maps.polygons(no_go), improve_remembered=improve_remembered)
        if isinstance(map, pb.Map):
            request.map.CopyFrom(map)
        elif isinstance(map, os.PathLike) or (isinstance(map, str) and os.path.isfile(map)):
            request.map.CopyFrom(maps.load_map(map, **(map_options or {})))
        elif isinstance(map, str):
            request.map_id = map
        else:
            raise TypeError("map: a map_id (str), a map file's path, or a covplan.v1.Map")
        messages.set_planner_options(request, planner, options)
        if battery is not None:
            request.battery.CopyFrom(messages.from_dict(battery, pb.Battery))
        return request

    def plan(self, map, *, tool_width, timeout=None, **kwargs):
        """Plans a coverage path; returns a covplan.Plan.

        map: a map_id (str, from put_map), a map file's path (str or pathlib.Path, sent
        inline; map_options: covplan.load_map's keywords, e.g. {"resolution": 0.05}) or a
        covplan.v1.Map.
        tool_width (m, also the grid's cell size); max_speed (m/s), acceleration (m/s²),
        turn_rate_deg_s; start, end: (x, y[, theta]). planner: "oarp" (default),
        "boustrophedon" or "stc", and options: its OarpOptions / BoustrophedonOptions /
        StcOptions (a message or a dict such as {"tree": "STC_TREE_PRIM"}). regions: cover
        only these; no_go: never enter these (polygons in any form covplan.maps.polygons
        takes). battery: covplan.v1.Battery or its dict. time_limit_s: the tour search's
        budget (0: the server's default); seed; min_free_fraction; improve_remembered."""
        return Plan(self._call("Plan", self.plan_request(map, tool_width=tool_width, **kwargs),
                               timeout))

    def get_plan(self, plan_id, *, timeout=None):
        """A retained plan (NotFound once the server's --plan_ttl_s passed)."""
        return Plan(self._call("GetPlan", pb.GetPlanRequest(plan_id=plan_id), timeout))

    def replan(self, plan, *, progress=None, obstacles=None, method=None, seed=0,
               timeout=None):
        """OARP-Replan: a new plan for what is left, from where the robot is (`progress`:
        covplan.progress(...)), around newly seen `obstacles` (covplan.obstacles(...)).
        plan: a plan_id or a Plan. method: "auto", "ilp1", "ilp2", "greedy_detour", "full".
        Returns a covplan.Replan."""
        request = pb.ReplanRequest(plan_id=_plan_id(plan), seed=int(seed),
                                   method=messages.enum_value(pb.ReplanMethod, method))
        _observe(request, progress, obstacles)
        return Replan(self._call("Replan", request, timeout))

    def resume(self, plan, *, pose, progress=None, obstacles=None, method=None, seed=0,
               timeout=None):
        """Continues an interrupted plan from `pose` (x, y[, theta]), where the robot stands
        now; it drives back to where it stopped (`progress`, else the last progress the
        server recorded). Returns a covplan.Replan."""
        request = pb.ResumeRequest(plan_id=_plan_id(plan), pose=messages.pose(pose),
                                   seed=int(seed),
                                   method=messages.enum_value(pb.ReplanMethod, method))
        _observe(request, progress, obstacles)
        return Replan(self._call("Resume", request, timeout))

    def drive(self, plan, *, method=None, seed=0, timeout=None, open_timeout=30.0):
        """Opens a Drive session on a plan (a plan_id or a Plan); use it as a context
        manager (covplan.drive.DriveSession). timeout: the whole session's deadline (None:
        none; the server ends idle sessions); open_timeout: how long to wait for it to
        open (DeadlineExceeded beyond)."""
        return DriveSession(self._stub.Drive, _plan_id(plan), self._metadata, method, seed,
                            timeout, open_timeout)

    # ------------------------------------------------------------------ fleets

    def plan_fleet(self, map, robots, *, division="makespan", clearance_m=0.0, timeout=None,
                   **kwargs):
        """Plans one site for several robots; returns a covplan.FleetPlan.

        robots: covplan.v1.FleetRobot messages or dicts in their JSON form, e.g.
        {"id": "west", "robot": {"toolWidthM": 0.5, "start": {"x": 1, "y": 1}}}.
        division: "makespan" or "equal_area". **kwargs: what plan() takes for the site
        (planner, options, regions, no_go, time_limit_s, seed, ...) and the robot model
        every robot shares unless it sets its own (tool_width, max_speed, acceleration,
        turn_rate_deg_s, end, battery). Each robot's start is its own."""
        if "start" in kwargs:
            raise TypeError("plan_fleet: each robot brings its own start")
        shared_robot = {k: kwargs.pop(k) for k in ("tool_width", "max_speed", "acceleration",
                                                   "turn_rate_deg_s", "end") if k in kwargs}
        battery = kwargs.pop("battery", None)
        fleet = [_with_shared(messages.from_dict(r, pb.FleetRobot), shared_robot, battery)
                 for r in robots]
        request = pb.PlanFleetRequest(
            plan=self.plan_request(map, tool_width=fleet[0].robot.tool_width_m if fleet else 0,
                                   **kwargs),
            robots=fleet,
            division=messages.enum_value(pb.FleetDivision, division, ("FLEET_DIVISION_", "")),
            clearance_m=float(clearance_m))
        return FleetPlan(self._call("PlanFleet", request, timeout))

    def update_mission(self, mission_id, robots, *, timeout=None):
        """Redivides a mission (robots: covplan.v1.MissionRobotUpdate messages or dicts,
        e.g. {"robotId": "east", "stopped": True}); covplan.v1.UpdateMissionResponse."""
        request = pb.UpdateMissionRequest(
            mission_id=mission_id,
            robots=[messages.from_dict(r, pb.MissionRobotUpdate) for r in robots])
        return self._call("UpdateMission", request, timeout)

    def get_mission(self, mission_id, *, timeout=None):
        """A mission's robots and account (covplan.v1.GetMissionResponse)."""
        return self._call("GetMission", pb.GetMissionRequest(mission_id=mission_id), timeout)


def _observe(request, progress, obstacles):
    """Puts where the robot is and what it saw into a Replan or Resume request."""
    if progress is not None:
        request.progress.CopyFrom(messages.progress(progress))
    if obstacles is not None:
        request.obstacles.CopyFrom(obstacles)


def _plan_id(plan):
    return plan if isinstance(plan, str) else plan.plan_id


def _with_shared(robot, shared, battery):
    """A FleetRobot (a copy) with the fleet's shared model fields where it sets none."""
    out = pb.FleetRobot()
    out.CopyFrom(robot)
    model = out.robot
    if "tool_width" in shared and model.tool_width_m == 0:
        model.tool_width_m = float(shared["tool_width"])
    for name, field in (("max_speed", "max_speed_mps"), ("acceleration", "acceleration_mps2"),
                        ("turn_rate_deg_s", "turn_rate_deg_s")):
        if name in shared and not model.HasField(field):
            setattr(model, field, float(shared[name]))
    if "end" in shared and not model.HasField("end"):
        model.end.CopyFrom(messages.pose(shared["end"]))
    if battery is not None and not out.HasField("battery"):
        out.battery.CopyFrom(messages.from_dict(battery, pb.Battery))
    return out

"""covplan: the Python client of the covplan coverage planning service.

    import covplan
    with covplan.Client("127.0.0.1:50051") as client:
        info = client.put_map("maps/sample_office.yaml")
        plan = client.plan(info.map_id, tool_width=0.5)
        print(plan.num_ranks, plan.duration_s, plan.path[:3])

docs/clients.md describes the API; covplan.v1 holds the raw gRPC stubs.
"""
from covplan.client import Client
from covplan.drive import DriveEvent, DriveSession
from covplan.errors import (Cancelled, CovplanError, DeadlineExceeded, FailedPrecondition,
                            InvalidArgument, NotFound, PermissionDenied, ResourceExhausted,
                            Unauthenticated, Unavailable)
from covplan.maps import load_map, polygon, polygons, read_polygons
from covplan.messages import obstacles, pose, progress, robot_model
from covplan.plans import FleetPlan, Plan, Replan, Waypoint

__version__ = "0.1.0"
__all__ = [
    "Client", "DriveEvent", "DriveSession", "Cancelled", "CovplanError", "DeadlineExceeded",
    "FailedPrecondition", "InvalidArgument", "NotFound", "PermissionDenied",
    "ResourceExhausted", "Unauthenticated", "Unavailable", "load_map", "polygon", "polygons",
    "read_polygons", "obstacles", "pose", "progress", "robot_model", "FleetPlan", "Plan",
    "Replan", "Waypoint",
]

"""Errors of covplan calls: one exception class per gRPC status code that a caller may want
to handle apart, each keeping the server's code and message.

    try:
        client.plan(map_id, tool_width=0.5)
    except covplan.InvalidArgument as e:
        print(e.code, e.message)     # StatusCode.INVALID_ARGUMENT, the server's reason
"""
import grpc


class CovplanError(Exception):
    """A failed covplan call: `code` (grpc.StatusCode), `message` (the server's text) and
    `method` (the RPC's name)."""

    def __init__(self, code, message, method=""):
        self.code = code
        self.message = message
        self.method = method
        where = f"{method}: " if method else ""
        super().__init__(f"{where}{code.name}: {message}")


class InvalidArgument(CovplanError):
    """The request is malformed or impossible (bad map, zone, robot, plan id form...)."""


class NotFound(CovplanError):
    """No such map, plan, mission or session (plans expire: the server's --plan_ttl_s)."""


class DeadlineExceeded(CovplanError):
    """Not even a first answer was ready before the call's deadline."""


class Unauthenticated(CovplanError):
    """No token or an unknown one (a server with --token_file)."""


class PermissionDenied(CovplanError):
    """The token's tenant may not see this map or plan."""


class ResourceExhausted(CovplanError):
    """The server sheds load (queue full, too many sessions) or the input is too large."""


class FailedPrecondition(CovplanError):
    """The state does not allow it (e.g. a mission robot that already stopped)."""


class Unavailable(CovplanError):
    """The server cannot be reached or is draining; retrying later may work."""


class Cancelled(CovplanError):
    """The call was cancelled (by the client, or the server shutting down)."""


_BY_CODE = {
    grpc.StatusCode.INVALID_ARGUMENT: InvalidArgument,
    grpc.StatusCode.NOT_FOUND: NotFound,
    grpc.StatusCode.DEADLINE_EXCEEDED: DeadlineExceeded,
    grpc.StatusCode.UNAUTHENTICATED: Unauthenticated,
    grpc.StatusCode.PERMISSION_DENIED: PermissionDenied,
    grpc.StatusCode.RESOURCE_EXHAUSTED: ResourceExhausted,
    grpc.StatusCode.FAILED_PRECONDITION: FailedPrecondition,
    grpc.StatusCode.UNAVAILABLE: Unavailable,
    grpc.StatusCode.CANCELLED: Cancelled,
}


def error_for(code, message, method=""):
    """The exception for a status: its class by `code` (CovplanError for the others)."""
    return _BY_CODE.get(code, CovplanError)(code, message, method)


def from_rpc_error(error, method=""):
    """The exception for a grpc.RpcError raised by a stub call."""
    return error_for(error.code(), error.details() or "", method)

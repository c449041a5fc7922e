"""A Drive session: the robot reports where it is and what it sees, the server pushes a new
plan whenever one is ready (its own replans, or a fleet mission's).

    with client.drive(plan) as session:
        session.report(covplan.progress(3, position=(2.0, 1.5)),
                       obstacles=covplan.obstacles(points=[(2.6, 1.5)]))
        for event in session.events(timeout=10):
            if event.replan:                      # a Replan: drive it from now on
                drive(event.replan)
                break

Messages are sent in order by gRPC's request iterator; events are read by a thread into a
queue, so the caller never blocks the stream. A session may be shared by threads (reports
are numbered and queued under a lock). Once the server ends the session (an error, or
idle past its --session_idle_s), report() raises that error and `ended` is true. Leaving
the `with` block half-closes the stream and waits (bounded) for the server to end it.
"""
import queue
import threading

import grpc

from covplan import errors, messages
from covplan.plans import Replan
from covplan.v1 import covplan_pb2 as pb

_END = object()


class DriveEvent:
    """One pushed event: `sequence` (the report it answers; 0 for a mission's push),
    `replan` (a Replan, or None), `error` (a CovplanError for an observation that could not
    be replanned; the session goes on), `superseded` (reports folded into this replan),
    `mission` (covplan.v1.MissionNotice, when a fleet mission pushed it)."""

    def __init__(self, event):
        self.response = event
        self.sequence = event.sequence
        kind = event.WhichOneof("event")
        self.replan = Replan(event.replan) if kind == "replan" else None
        self.error = (errors.error_for(_status(event.error.code), event.error.message, "Drive")
                      if kind == "error" else None)
        self.superseded = list(event.superseded)
        self.mission = event.mission if event.HasField("mission") else None

    def __repr__(self):
        what = f"replan={self.replan!r}" if self.replan else f"error={self.error}"
        return f"DriveEvent(sequence={self.sequence}, {what})"


def _status(number):
    """The grpc.StatusCode of a google.rpc.Code number."""
    for code in grpc.StatusCode:
        if code.value[0] == number:
            return code
    return grpc.StatusCode.UNKNOWN


class DriveSession:
    """An open Drive stream. Use as a context manager (or call close())."""

    def __init__(self, stub_method, plan_ref, metadata, method=None, seed=0, timeout=None,
                 open_timeout=30.0):
        first = pb.DriveRequest(method=messages.enum_value(pb.ReplanMethod, method),
                                seed=int(seed))
        if isinstance(plan_ref, pb.InlinePlan):
            first.plan.CopyFrom(plan_ref)
        else:
            first.plan_id = plan_ref
        self._requests = queue.Queue()
        self._events = queue.Queue()
        self._lock = threading.Lock()  # the sequence, and closing against reporting
        self._sequence = 0
        self._closed = False
        self._error = None    # the status the server ended the session with, if not OK
        self._ended = threading.Event()
        self._requests.put(first)
        self._call = stub_method(iter(self._requests.get, _END), metadata=metadata,
                                 timeout=timeout)
        self._reader = threading.Thread(target=self._read, name="covplan-drive", daemon=True)
        self._reader.start()
        if timeout is not None:
            open_timeout = min(open_timeout, timeout)
        try:
            ready = self._next(timeout=open_timeout)
        except BaseException:
            self.cancel()
            raise
        if ready is None or ready.response.WhichOneof("event") != "ready":
            self.cancel()
            raise errors.error_for(grpc.StatusCode.DEADLINE_EXCEEDED,
                                   f"the session did not open within {open_timeout} s", "Drive")
        self.ready = ready.response.ready
        self.plan_id = self.ready.plan_id

    session_id = property(lambda self: self.ready.session_id)

    @property
    def ended(self):
        """Whether the server ended the session (see `error` for how)."""
        return self._ended.is_set()

    @property
    def error(self):
        """The CovplanError the server ended the session with (None: open, or ended OK)."""
        return self._error

    def _read(self):
        try:
            for event in self._call:
                self._events.put(DriveEvent(event))
            self._events.put(_END)
        except grpc.RpcError as e:
            self._error = errors.from_rpc_error(e, "Drive")
            self._events.put(self._error)
        finally:
            self._ended.set()

    def report(self, progress=None, obstacles=None, plan_id=None, method=None):
        """Sends where the robot is (covplan.progress(...)) and what it newly sees
        (covplan.obstacles(...)); returns the report's sequence number, which the events
        answering it carry. Without obstacles it is a progress report only (no event).
        `plan_id`: the plan `progress` refers to (default: the newest plan this session
        handed out, `self.plan_id`). Raises the server's error once it ended the session,
        FailedPrecondition once closed here."""
        with self._lock:
            if self._error is not None:
                raise self._error
            if self._closed or self._ended.is_set():
                raise errors.error_for(grpc.StatusCode.FAILED_PRECONDITION,
                                       "the session is closed", "Drive")
            self._sequence += 1
            request = pb.DriveRequest(sequence=self._sequence, plan_id=plan_id or self.plan_id,
                                      method=messages.enum_value(pb.ReplanMethod, method))
            if progress is not None:
                request.progress.CopyFrom(messages.progress(progress))
            if obstacles is not None:
                request.obstacles.CopyFrom(obstacles)
            self._requests.put(request)
            return self._sequence

    def _next(self, timeout):
        try:
            item = self._events.get(timeout=timeout)
        except queue.Empty:
            return None
        if item is _END:
            self._events.put(_END)  # stays ended for every later read
            return None
        if isinstance(item, errors.CovplanError):
            self._events.put(_END)
            raise item
        if item.replan is not None:
            self.plan_id = item.replan.plan_id
        return item

    def next_event(self, timeout=None):
        """The next pushed event, or None when `timeout` seconds pass or the session ended.
        A session the server ended with an error raises it (e.g. DeadlineExceeded when
        idle past the server's --session_idle_s)."""
        return self._next(timeout)

    def events(self, timeout=None):
        """Iterates over pushed events until the session ends or none comes for `timeout`
        seconds."""
        while True:
            event = self._next(timeout)
            if event is None:
                return
            yield event

    def close(self, timeout=10.0):
        """Ends the session: half-closes the stream and waits for the server's end."""
        with self._lock:
            if not self._closed:
                self._closed = True
                self._requests.put(_END)
        self._reader.join(timeout)
        if self._reader.is_alive():
            self.cancel()

    def cancel(self):
        """Drops the session at once (the server frees it)."""
        with self._lock:
            self._closed = True
            self._requests.put(_END)
        self._call.cancel()

    def __enter__(self):
        return self

    def __exit__(self, kind, value, traceback):
        if kind is None:
            self.close()
        else:
            self.cancel()
        return False

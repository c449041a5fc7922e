"""Bad input raises with the server's code and message and loses nothing; deadlines; TLS
and bearer tokens."""
import grpc
import pytest

import covplan
from conftest import TOKEN
from covplan.v1 import covplan_pb2 as pb


def test_bad_tool_width_is_invalid_argument_with_the_servers_message(client, office_id):
    with pytest.raises(covplan.InvalidArgument) as error:
        client.plan(office_id, tool_width=0.0)
    assert error.value.code == grpc.StatusCode.INVALID_ARGUMENT
    assert "tool_width" in error.value.message
    assert error.value.method == "Plan"


def test_bad_image_adds_no_map(client):
    before = {m.map_id for m in client.list_maps()}
    bad = pb.Map(raster=pb.RasterMap(image=b"not an image", resolution=0.05))
    with pytest.raises(covplan.InvalidArgument) as error:
        client.put_map(bad, name="garbage")
    assert error.value.message
    assert {m.map_id for m in client.list_maps()} == before


def test_unknown_plan_and_map_are_not_found(client):
    with pytest.raises(covplan.NotFound):
        client.get_plan("p-00000000000000000000000000000000")
    with pytest.raises((covplan.NotFound, covplan.InvalidArgument)):
        client.plan("m-does-not-exist", tool_width=0.5)


def test_a_deadline_too_short_to_plan(client, office_id):
    with pytest.raises(covplan.DeadlineExceeded):
        client.plan(office_id, tool_width=0.2, seed=99, timeout=0.001)


def test_tls_and_token(secure_server):
    with covplan.Client(secure_server.address, root_certificates=secure_server.ca) as anonymous:
        with pytest.raises(covplan.Unauthenticated):
            anonymous.list_maps()
    with covplan.Client(secure_server.address, token="wrong",
                        root_certificates=secure_server.ca) as stranger:
        with pytest.raises(covplan.Unauthenticated):
            stranger.list_maps()
    with covplan.Client(secure_server.address, token=TOKEN,
                        root_certificates=secure_server.ca) as tenant:
        square = pb.Map(polygons=pb.PolygonMap(polygons=covplan.polygons(
            [(0, 0), (5, 0), (5, 5), (0, 5)])))
        info = tenant.put_map(square, name="square")
        plan = tenant.plan(info.map_id, tool_width=0.5, time_limit_s=0.2)
        assert plan.stats.covered_cells == plan.stats.free_cells == 100
    with covplan.Client(secure_server.address, token=TOKEN, timeout=5) as plaintext:
        with pytest.raises(covplan.Unavailable):
            plaintext.list_maps()

"""Maps from files in one call, stored, listed, read back and deleted."""
import os

import pytest

import covplan
from conftest import MAPS


def test_yaml_map_is_stored_listed_read_back_and_deleted(client):
    path = os.path.join(MAPS, "small_rooms.yaml")
    info = client.put_map(path)
    assert info.name == "small_rooms.yaml"
    assert info.resolution == pytest.approx(0.05)
    assert info.free_area_m2 > 0
    again = client.put_map(path)
    assert again.map_id == info.map_id  # content-derived id
    assert info.map_id in [m.map_id for m in client.list_maps(page_size=1)]  # every page
    content = client.get_map(info.map_id, include_content=True)
    with open(os.path.join(MAPS, "small_rooms.png"), "rb") as f:
        assert content.map.raster.image == f.read()
    assert client.delete_map(info.map_id) is True
    with pytest.raises(covplan.NotFound):
        client.get_map(info.map_id)
    assert client.delete_map(info.map_id) is False


def test_png_map_takes_its_resolution_and_origin(client):
    path = os.path.join(MAPS, "small_rooms.png")
    with pytest.raises(ValueError, match="resolution"):
        covplan.load_map(path)
    info = client.put_map(path, resolution=0.1, origin=(2.0, -1.0))
    assert info.resolution == pytest.approx(0.1)
    assert (info.origin_x_m, info.origin_y_m) == pytest.approx((2.0, -1.0))
    yaml_info = client.put_map(os.path.join(MAPS, "small_rooms.yaml"))
    # Twice the pixel size: four times the free area of the same picture.
    assert info.free_area_m2 == pytest.approx(4 * yaml_info.free_area_m2, rel=1e-6)


def test_geojson_map_is_its_polygons(client):
    yard = covplan.load_map(os.path.join(MAPS, "sample_yard.geojson"))
    assert yard.WhichOneof("source") == "polygons"
    info = client.put_map(yard, name="yard")
    outer = covplan.read_polygons(os.path.join(MAPS, "sample_yard.geojson"))
    assert info.name == "yard" and len(outer) == len(yard.polygons.polygons)
    # The free area is the polygons' (shoelace), up to the 0.05 m raster's edge pixels.
    area = sum(shoelace(p.outer) - sum(shoelace(h) for h in p.holes) for p in outer)
    assert info.free_area_m2 == pytest.approx(area, rel=0.01)


def shoelace(ring):
    points = [(p.x, p.y) for p in ring.points]
    return abs(sum(x1 * y2 - x2 * y1 for (x1, y1), (x2, y2) in zip(points, points[1:]))) / 2


def test_polygons_take_rings_dicts_and_files():
    square = [(0, 0), (4, 0), (4, 4), (0, 4)]
    [from_ring] = covplan.polygons(square)
    assert len(from_ring.outer.points) == 5  # closed
    as_dict = {"type": "Polygon", "coordinates": [[list(p) for p in square + [square[0]]]]}
    assert covplan.polygons(as_dict) == [from_ring]
    assert len(covplan.polygons([square, square])) == 2
    with pytest.raises(ValueError, match=r"coordinates\[0\]\[1\]"):
        covplan.polygons({"type": "Polygon", "coordinates": [[[0, 0], ["a", 1]]]})
    with pytest.raises(ValueError, match="LineString is not a polygon"):
        covplan.polygons({"type": "LineString", "coordinates": [[0, 0], [1, 1]]})

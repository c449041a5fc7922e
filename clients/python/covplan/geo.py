"""Sites drawn in geographic or projected coordinates (a lawn on a web map: GeoJSON in
longitude/latitude, RFC 7946), planned in a local metric frame. Needs pyproj (Debian:
python3-pyproj). The frame is the CLI's (`covplan plan --crs`, api/geo_frame.h): the CRS's
own geographic coordinates onto a transverse Mercator on its ellipsoid, centred on the
middle of the site and shifted so the corner of the site's extent is (0, 0); map vertices
are rounded to the millimetre.

    site = covplan.geo.load_site("lawn.geojson", crs="EPSG:4326")
    plan = client.plan(site.map, tool_width=0.5, no_go=site.project("beds.geojson"),
                       start=site.forward(11.5874, 48.1557))
    lawn_route = plan.to_geojson(frame=site.frame)          # back in longitude/latitude
"""
import collections
import math

from covplan import maps
from covplan.v1 import covplan_pb2 as pb

try:
    import pyproj
except ImportError:  # GeoFrame says so when used
    pyproj = None

Site = collections.namedtuple("Site", "map frame")
Site.__doc__ = "A site in a CRS: `map` (covplan.v1.Map, local metres) and its GeoFrame."


def _points(polygons):
    for polygon in polygons:
        for ring in [polygon.outer, *polygon.holes]:
            yield from ring.points


class GeoFrame:
    """The local metric frame of a site whose polygons (covplan.v1.Polygon) are in `crs`."""

    def __init__(self, crs, polygons):
        if pyproj is None:
            raise RuntimeError("geographic sites need pyproj (Debian: python3-pyproj)")
        try:
            source = pyproj.CRS.from_user_input(crs)
        except pyproj.exceptions.CRSError as e:
            raise ValueError(f"crs {crs!r}: not a coordinate reference system PROJ knows "
                             f"({e})") from None
        if not (source.is_geographic or source.is_projected):
            raise ValueError(f"crs {crs!r} is neither a geographic nor a projected CRS")
        self.crs = crs
        self.geographic = source.is_geographic
        self._to_geographic = pyproj.Transformer.from_crs(source, source.geodetic_crs,
                                                          always_xy=True)
        geographic = [self._geographic(p.x, p.y) for p in _points(polygons)]
        if not geographic:
            raise ValueError("the site has no points")
        lons, lats = [g[0] for g in geographic], [g[1] for g in geographic]
        if max(lons) - min(lons) > 180:
            raise ValueError("a site must not cross the antimeridian")
        self.lon0 = 0.5 * (min(lons) + max(lons))
        self.lat0 = 0.5 * (min(lats) + max(lats))
        ellipsoid = source.ellipsoid
        self._a, self._b = ellipsoid.semi_major_metre, ellipsoid.semi_minor_metre
        self._local = self._make_local(0.0, 0.0)
        local = [self._local.transform(lon, lat) for lon, lat in geographic]
        self._local = self._make_local(-min(x for x, _ in local), -min(y for _, y in local))

    def _make_local(self, x0, y0):
        self.local_definition = (
            f"+proj=tmerc +lat_0={self.lat0:.12f} +lon_0={self.lon0:.12f} +k=1 "
            f"+x_0={x0:.9f} +y_0={y0:.9f} +a={self._a:.6f} +b={self._b:.6f} +units=m")
        return pyproj.Transformer.from_pipeline(
            "+proj=pipeline +step +proj=unitconvert +xy_in=deg +xy_out=rad +step "
            + self.local_definition)

    def _geographic(self, x, y, what="point"):
        if not (math.isfinite(x) and math.isfinite(y)):
            raise ValueError(f"{what}: not a finite position")
        if self.geographic and not -180 <= x <= 180:
            raise ValueError(f"{what}: longitude {x} is outside [-180, 180]")
        if self.geographic and not -90 <= y <= 90:
            raise ValueError(f"{what}: latitude {y} is outside [-90, 90] (GeoJSON positions "
                             "are [longitude, latitude])")
        lon, lat = self._to_geographic.transform(x, y)
        if not (math.isfinite(lon) and math.isfinite(lat)):
            raise ValueError(f"{what}: ({x}, {y}) cannot be placed in {self.crs}")
        return lon, lat

    def forward(self, x, y, what="point"):
        """A position of the CRS in the local frame (metres)."""
        return self._local.transform(*self._geographic(x, y, what))

    def inverse(self, x, y):
        """A local position back in the CRS."""
        lon, lat = self._local.transform(x, y, direction=pyproj.enums.TransformDirection.INVERSE)
        return self._to_geographic.transform(
            lon, lat, direction=pyproj.enums.TransformDirection.INVERSE)

    def project(self, zones, what="polygons"):
        """Zones in the CRS (any form covplan.polygons takes) as local polygons, vertices
        rounded to the millimetre (edges shared in the CRS stay shared)."""
        out = []
        for i, polygon in enumerate(maps.polygons(zones)):
            rings = []
            for h, ring in enumerate([polygon.outer, *polygon.holes]):
                points = []
                for j, p in enumerate(ring.points):
                    x, y = self.forward(p.x, p.y, f"{what}[{i}] ring {h} point {j}")
                    points.append(pb.Point2(x=round(x, 3), y=round(y, 3)))
                rings.append(pb.Ring(points=points))
            out.append(pb.Polygon(outer=rings[0], holes=rings[1:]))
        return out


def load_site(path, crs="EPSG:4326", polygon_resolution=0.0):
    """A GeoJSON polygon map in `crs` as a Site: the map in its local frame, and the frame."""
    polygons = maps.read_polygons(path)
    frame = GeoFrame(crs, polygons)
    local = frame.project(polygons, "map.polygons")
    return Site(pb.Map(polygons=pb.PolygonMap(polygons=local, resolution=polygon_resolution)),
                frame)

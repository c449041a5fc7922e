"""Independent geometry for the tests' checks (nothing from covplan's planner)."""


def inside(point, ring):
    """Strictly inside a closed ring (ray casting)."""
    x, y = point
    result = False
    for (x1, y1), (x2, y2) in zip(ring, ring[1:]):
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            result = not result
    return result


def samples(a, b, step):
    """Points every `step` metres from a to b, both ends included."""
    length = ((b[0] - a[0]) ** 2 + (b[1] - a[1]) ** 2) ** 0.5
    n = max(1, int(length / step))
    return [(a[0] + (b[0] - a[0]) * i / n, a[1] + (b[1] - a[1]) * i / n) for i in range(n + 1)]


def ring_points(ring):
    return [(p.x, p.y) for p in ring.points]


def moves(plan, kind=None):
    """The path's segments (from, to) ending in a waypoint of `kind` (all when None)."""
    path = plan.path
    return [((a.x, a.y), (b.x, b.y)) for a, b in zip(path, path[1:])
            if kind is None or b.kind == kind]

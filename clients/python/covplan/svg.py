"""A plan as an SVG picture: coverage moves, transitions and station trips, the zones it
honours, start and end. Map frame (metres, y up) scaled to `width` pixels.

    open("plan.svg", "w").write(covplan.svg.plan_svg(plan))
"""
from xml.sax.saxutils import quoteattr

from covplan.v1 import covplan_pb2 as pb

_STYLE = {pb.COVERAGE: 'stroke="#1f77b4" stroke-width="{w}"',
          pb.TRANSITION: 'stroke="#888" stroke-width="{t}" stroke-dasharray="{t2},{t2}"',
          pb.TO_STATION: 'stroke="#d62728" stroke-width="{t}"',
          pb.FROM_STATION: 'stroke="#2ca02c" stroke-width="{t}"'}


def plan_svg(plan, width=900):
    """The SVG text of a covplan.Plan (or a covplan.v1.PlanResponse)."""
    response = getattr(plan, "response", plan)
    grid = response.grid
    x0, y0 = grid.origin_x_m, grid.origin_y_m
    w_m, h_m = grid.cols * grid.cell_size_m, grid.rows * grid.cell_size_m
    if w_m <= 0 or h_m <= 0:
        raise ValueError("the plan has an empty grid")
    scale = width / w_m
    height = int(round(h_m * scale))

    def xy(p):
        return (p.x - x0) * scale, (y0 + h_m - p.y) * scale

    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'viewBox="0 0 {width} {height}">',
           f'<title>{quoteattr(response.plan_id)[1:-1]}</title>',
           f'<rect width="{width}" height="{height}" fill="#fafafa" stroke="#ccc"/>']
    for zone, colour in ((response.regions, "#2ca02c"), (response.no_go, "#d62728")):
        for polygon in zone:
            rings = [polygon.outer] + list(polygon.holes)
            d = " ".join("M" + " L".join("%.1f,%.1f" % xy(p) for p in ring.points) + " Z"
                         for ring in rings)
            out.append(f'<path d="{d}" fill="{colour}" fill-opacity="0.15" stroke="{colour}" '
                       'fill-rule="evenodd"/>')
    sizes = {"w": f"{grid.cell_size_m * scale * 0.8:.1f}", "t": "1.5", "t2": "4"}
    path = response.path
    for a, b in zip(path, path[1:]):
        style = _STYLE.get(b.kind, _STYLE[pb.TRANSITION]).format(**sizes)
        (ax, ay), (bx, by) = xy(a), xy(b)
        out.append(f'<line x1="{ax:.1f}" y1="{ay:.1f}" x2="{bx:.1f}" y2="{by:.1f}" {style} '
                   'stroke-opacity="0.7" stroke-linecap="round"/>')
    if path:
        for point, colour in ((path[0], "#2ca02c"), (path[-1], "#d62728")):
            cx, cy = xy(point)
            out.append(f'<circle cx="{cx:.1f}" cy="{cy:.1f}" r="5" fill="{colour}"/>')
    out.append("</svg>")
    return "\n".join(out)

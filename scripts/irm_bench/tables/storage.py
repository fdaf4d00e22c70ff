"""Table 4: the map's size per km of mapped lane, plain IPM and the full method."""
from ..configs import FULL, IPM, ablation
from ..plan import Request
from ..report import Table, fmt

TITLE = "Storage (Table 4)"
MODES = ("all",)
METHODS = (("IPM", IPM), ("Ours (+PPSR)", FULL))


def requests(ctx):
    return [Request(ctx.drive(s), ablation(config)) for s in ctx.scenarios
            for _, config in METHODS]


def tables(ctx, results):
    rows = []
    for s in ctx.scenarios:
        for label, config in METHODS:
            m = results[(s, config)]
            rows.append([s, label, fmt(m.get("map_bytes_per_km"), 0),
                         fmt(m.get("control_points_per_km"), 1)])
    return [Table("Table 4. Storage", ["scenario", "method", "map bytes / km",
                                       "control points / km"], rows)]

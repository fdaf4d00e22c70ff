"""Speed: every ablation's frames per second, front-end time and window solves; then plain IPM
and the full method side by side, CPU per frame from the same run, and their ratio."""
from . import ablations
from ..configs import ABLATIONS, FULL, IPM
from ..metrics import cpu_ms_per_frame, ratio
from ..report import Table, fmt

TITLE = "Speed"
MODES = ("all",)
requests = ablations.requests  # the same maps: every ablation on every drive


def _solve_ms(md, key):
    return fmt(1e3 * md[key], 1) if key in md else "-"


def per_ablation(ctx, results):
    rows = []
    for s in ctx.scenarios:
        for label, config in ABLATIONS:
            m = results[(s, config)]
            md = m["_metadata"]
            frames = md.get("frames_used", 0) or 0
            rows.append([s, label, fmt(frames / m["_wall_s"] if m["_wall_s"] > 0 else None, 0),
                         fmt(md.get("frontend_time_p50_ms"), 2),
                         fmt(md.get("frontend_time_p95_ms"), 2),
                         _solve_ms(md, "backend_solve_time_p50_s"),
                         _solve_ms(md, "backend_solve_time_p95_s"),
                         md.get("backend_solves", "-"), md.get("backend_results_rejected", "-")])
    # Not in the docs: the wall clock moves with the machine's load and --jobs.
    return Table("Speed (map_from_bag wall clock incl. bag reading; one core for the solver)",
                 ["scenario", "method", "frames/s", "front end p50 (ms)", "front end p95 (ms)",
                  "solve p50 (ms)", "solve p95 (ms)", "solves", "rejected"], rows, docs=False)


def side_by_side(ctx, results):
    rows = []
    for s in ctx.scenarios:
        ipm, full = (cpu_ms_per_frame(results[(s, c)]) for c in (IPM, FULL))
        rows.append([s, fmt(ipm, 2), fmt(full, 2), fmt(ratio(full, ipm), 2)])
    return Table("Speed side by side: map_from_bag process CPU (user + system) per frame used, "
                 "plain IPM and the full method, this run",
                 ["scenario", "IPM CPU (ms/frame)", "Ours (+PPSR) CPU (ms/frame)",
                  "Ours / IPM"], rows)


def tables(ctx, results):
    return [per_ablation(ctx, results), side_by_side(ctx, results)]

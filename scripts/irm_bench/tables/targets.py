"""The target rows (scripts/irm_bench/targets.yaml) of the drives' tables, each with the
figure this run measured: markings, lanes, calibration and poses."""
from .. import targets

TITLE = "Targets"
MODES = ("all",)
GROUPS = ("markings", "lanes", "calibration and poses")


def requests(ctx):
    return []  # the rows read the maps of the other tables


def tables(ctx, results):
    if not ctx.extra:
        return []
    rows = targets.load()
    out = [targets.group_table(ctx, results, rows, group, targets.FUNCTIONS,
                               "Targets: %s (config/mapper.yaml)" % group) for group in GROUPS]
    return [t for t in out if t]

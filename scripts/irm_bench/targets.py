"""The target rows of targets.yaml with their measured figures: each row's `now` template
filled from the results (see targets.yaml's header for the template's fields)."""
import os
import string

from . import drives
from .configs import FULL, TRUE_EXTRINSIC_HELD
from .metrics import false_positives, ratio, roll_after
from .report import Table, fmt
from .runners import load_yaml
from .tables.full_method import NOISE, drives_of

PATH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "targets.yaml")
HEADER = ["drive", "figure", "now", "target"]


class Scope:
    """What a row's template reads: the run, its results and the row's drive."""

    def __init__(self, ctx, results, drive):
        self.ctx, self.results, self.drive = ctx, results, drive

    def metric(self, name, drive=None, config=FULL):
        """A metric of `drive` (default: the row's) mapped with `config`; "ipm/key" reads
        the plain IPM map."""
        if "/" in name:
            config, name = name.split("/", 1)
        return self.results.get((drive or self.drive, config), {}).get(name)

    def full(self, drive=None):
        return self.results.get((drive or self.drive, FULL))


class _Template(string.Formatter):
    """str.format over a Scope: {key}, {config/key}, {@function(arguments)}, each with an
    optional decimals spec ({key:2})."""

    def __init__(self, scope, functions):
        super().__init__()
        self.scope, self.functions = scope, functions

    def get_field(self, field_name, args, kwargs):
        if not field_name.startswith("@"):
            return self.scope.metric(field_name), field_name
        name, _, arguments = field_name[1:].partition("(")
        arguments = [a.strip() for a in arguments.rstrip(")").split(",")] if arguments else []
        arguments = [a for a in arguments if a]
        if name not in self.functions:
            raise KeyError("targets.yaml: unknown function @%s" % name)
        return self.functions[name](self.scope, *arguments), field_name

    def format_field(self, value, spec):
        if value is None or isinstance(value, float):
            return fmt(value, int(spec) if spec else 3)
        return str(value)


def fill(template, scope, functions):
    """The template with its fields replaced by the scope's figures."""
    return _Template(scope, functions).format(template)


def load(path=PATH):
    """The rows of the targets file, their keys checked (unknown or missing: ValueError)."""
    rows = load_yaml(path)
    if not isinstance(rows, list):
        raise ValueError("%s: expected a list of rows" % path)
    known = {"group", "drive", "label", "figure", "now", "target", "absent"}
    for i, row in enumerate(rows):
        unknown = set(row) - known
        missing = {"group", "figure", "now", "target"} - set(row)
        if unknown or missing:
            raise ValueError("%s: row %d: unknown keys %s, missing keys %s"
                             % (path, i + 1, sorted(unknown), sorted(missing)))
    return rows


def drive_absent(ctx, drive):
    """The drive was asked for but its folder under ../shared is not there."""
    if drive == drives.REAL:
        return ctx.real_absent
    if drive == drives.FLEET:
        return ctx.fleet and not drives.fleet_passes(ctx)
    return False


def drive_mapped(results, drive):
    if drive == drives.FLEET:
        return any(d.startswith(drives.FLEET + "_") for d, _ in results)
    return (drive, FULL) in results


def group_table(ctx, results, rows, group, functions, title):
    """The table of one group's rows (None when none applies)."""
    out = []
    for row in (r for r in rows if r["group"] == group):
        drive = row.get("drive")
        scope = Scope(ctx, results, drive)
        label = fill(row.get("label", drive or ""), scope, functions)
        if drive and drive_absent(ctx, drive):
            if "absent" in row:
                out.append([label, row["absent"], "skipped: not present", ""])
            continue
        if drive and not drive_mapped(results, drive):
            continue
        out.append([label, row["figure"], fill(str(row["now"]), scope, functions),
                    row["target"]])
    return Table(title, HEADER, out) if out else None


# The functions a template calls ({@name(arguments)}): each takes the Scope and the
# arguments as text.

def ceiling_note(scope, reachable_key, total_key):
    """' (view ceiling r / n)' when the drive's view caps the figure below its total."""
    reachable, total = scope.metric(reachable_key), scope.metric(total_key)
    if reachable is None or reachable == total:
        return ""
    return " (view ceiling %s / %s)" % (reachable, total)


def lane_ceiling_note(scope):
    """' (view ceiling F1 x: r of n lines)' when the view caps the lane F1 below 1."""
    f1 = scope.metric("ceiling_lane_f1")
    if f1 is None or f1 == 1.0:
        return ""
    return " (view ceiling F1 %s: %s of %s lines)" % (
        fmt(f1, 2), scope.metric("ceiling_lanes_reachable"), scope.metric("lane_gt_total"))


def held(scope, key, what=""):
    """' (<what>with the true extrinsic held: x)': the figure a perfect calibration gives
    (Table 3c)."""
    value = scope.metric(key, config=TRUE_EXTRINSIC_HELD)
    if value is None:
        return ""
    return " (%swith the true extrinsic held: %s)" % (what + " " if what else "", fmt(value))


def seeds(scope, key, digits="3"):
    """Seeds 1-3 of the row's scenario, and their mean (a single seed's figure moves with the
    noise drawn)."""
    digits = int(digits)
    names = [scope.drive] + ["%s_seed%d" % (scope.drive, k) for k in drives.SEEDS[1:]]
    if key == "false_positives":
        return " / ".join(str(false_positives(scope.full(n))) for n in names if scope.full(n))
    values = [scope.metric(key, n) for n in names if scope.full(n)]
    text = " / ".join(fmt(v, digits) for v in values)
    known = [v for v in values if v is not None]
    if len(known) > 1:
        text += " (mean %s)" % fmt(sum(known) / len(known), digits)
    return text


def lane_order(scope):
    """Per drive: does the lane APE fall from Ours (-) through +PS and +PSR to +PPSR?"""
    order = []
    for s in scope.ctx.scenarios:
        lane = [scope.metric("lane_ape_mean_m", s, c)
                for c in ("ours_ppsr", "ours_psr", "ours_ps", "ours_minus")]
        if None not in lane:
            order.append("%s %s" % (s, "yes" if lane == sorted(lane) else "no"))
    return ", ".join(order)


def _benchmark_drives(scope):
    """The drives of the per-drive rows: scenarios and seeds, not the variants."""
    variants = set(drives.VARIANTS) | {NOISE}
    return [d for d in drives_of(scope.ctx, scope.results) if d not in variants]


def benchmark_drives(scope):
    return len(_benchmark_drives(scope))


def worse_on(scope, key, slack):
    """The drives whose refined `key` ends above its initial value + slack."""
    worse = []
    for d in _benchmark_drives(scope):
        after, before = scope.metric(key, d), scope.metric(key + "_initial", d)
        if after is None or after > before + float(slack):
            worse.append(d)
    return ", ".join(worse) or "none"


FUNCTIONS = {
    "ceiling_note": ceiling_note, "lane_ceiling_note": lane_ceiling_note, "held": held,
    "seeds": seeds, "lane_order": lane_order, "benchmark_drives": benchmark_drives,
    "worse_on": worse_on,
    "false_positives": lambda scope: false_positives(scope.full()),
    "roll_after": lambda scope: roll_after(scope.full()),
    "ratio": lambda scope, a, b: ratio(scope.metric(a), scope.metric(b)),
}

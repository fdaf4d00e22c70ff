"""The nodelet's unload after the long drive: test/ros/test_long_drive_unload.cpp run on the
long drive's bag (IRM_LONG_BAG), its unload time against the budget and whether the map was
saved, as rows of the long-drive table."""
import os
import shutil
import subprocess
import sys

from . import long_stats
from .report import fmt

TARGET = "ros_test_long_drive_unload"


def build(ctx):
    """Builds the test (it is not part of the default build); returns its path."""
    print("[benchmark] building %s" % TARGET, file=sys.stderr)
    log = os.path.join(ctx.out, TARGET + "_build.log")
    with open(log, "w") as f:
        built = subprocess.run(["make", "-C", ctx.build, "-j%d" % max(1, ctx.jobs), TARGET],
                               stdout=f, stderr=subprocess.STDOUT).returncode == 0
    binary = os.path.join(ctx.bin, TARGET)
    return binary if built and os.path.exists(binary) else None


def rows(ctx, drive):
    """Runs the unload test on the drive's bag; its rows (a row saying why not when the test
    cannot be built or prints no figure)."""
    label = "unload after the drive (%s, IRM_LONG_BAG)" % TARGET
    binary = build(ctx)
    if binary is None:
        return [[label, "not measured: %s did not build (%s)" % (
            TARGET, os.path.join(ctx.out, TARGET + "_build.log"))]]
    out = os.path.join(ctx.out, "maps", drive.name, "unload")
    shutil.rmtree(out, ignore_errors=True)
    log = os.path.join(ctx.out, "maps", drive.name, "unload.log")
    print("[benchmark] %s: the unload test on the whole drive" % drive.name, file=sys.stderr)
    env = dict(os.environ, IRM_LONG_BAG=drive.bag, IRM_LONG_OUT=out)
    with open(log, "w") as f:
        passed = subprocess.run([binary], stdout=f, stderr=subprocess.STDOUT,
                                env=env).returncode == 0
    with open(log) as f:
        unload_s, budget_s = long_stats.unload_figures(f.read())
    saved = os.path.isfile(os.path.join(out, "map.json"))
    if unload_s is None:
        return [[label, "no figure printed (%s)" % log]]
    within = budget_s is not None and unload_s <= budget_s
    return [[label, "%s s against the %s s budget (%s), map %s, test %s" % (
        fmt(unload_s, 2), fmt(budget_s, 1), "within" if within else "over",
        "saved" if saved else "NOT saved", "passed" if passed else "FAILED (%s)" % log)]]

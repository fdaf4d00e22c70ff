"""The benchmark's command line (scripts/benchmark.sh passes --repo and --bin)."""
import argparse
import fcntl
import json
import os
import subprocess
import sys
import time

from . import drives, plan, registry, report
from .context import Context
from .runners import BenchmarkError

DEFAULT_DRIVES = ",".join(drives.SYNTHETIC + [drives.REAL, drives.FLEET])
DOCS = os.path.join("docs", "benchmark.md")


def parse(argv=None):
    parser = argparse.ArgumentParser(
        prog="benchmark.sh", description="The project's benchmark: drives x configs, printed as "
        "tables (docs/benchmark.md).")
    parser.add_argument("--repo", required=True)
    parser.add_argument("--bin", required=True, help="the folder of the built tools")
    parser.add_argument("--build", default=None, help="the build folder (default: --bin/../../..)")
    parser.add_argument("--scenarios", default=DEFAULT_DRIVES,
                        help="drives, comma-separated (%s is the real-geometry drive, %s the "
                             "fleet passes; both skipped when not present)"
                             % (drives.REAL, drives.FLEET))
    parser.add_argument("--shared", default=None,
                        help="the shared data folder (default <repo>/../shared)")
    parser.add_argument("--jobs", type=int, default=2,
                        help="map_from_bag runs at a time (the Speed table is measured so)")
    parser.add_argument("--quick", action="store_true",
                        help="public_road only: no noise sweep, seeds, variant drives, fleet")
    parser.add_argument("--out", default=None, help="default <repo>/out/benchmark")
    for mode in registry.modes():
        parser.add_argument("--" + mode, action="store_true", help=registry.MODE_HELP[mode])
    parser.add_argument("--instructions", action="store_true",
                        help="with --long: also count instructions per frame of three copies of "
                             "the route under callgrind (hours: valgrind is 20-30x slower)")
    parser.add_argument("--write-docs", action="store_true",
                        help="also write the printed tables into %s (between its markers)" % DOCS)
    args = parser.parse_args(argv)
    chosen = [m for m in registry.modes() if getattr(args, m.replace("-", "_"))]
    if len(chosen) > 1:
        parser.error("one mode at a time: %s" % ", ".join("--" + m for m in chosen))
    args.mode = chosen[0] if chosen else "all"
    if args.instructions and args.mode != "long":
        parser.error("--instructions goes with --long")
    if args.write_docs and (args.quick or args.scenarios != DEFAULT_DRIVES):
        parser.error("--write-docs writes the whole run's tables: not with --quick or --scenarios")
    return args


def context(args):
    out = args.out or os.path.join(args.repo, "out", "benchmark")
    selection = drives.SYNTHETIC[0] if args.quick else args.scenarios
    return Context.from_selection(
        selection, repo=args.repo, bin=args.bin,
        build=args.build or os.path.normpath(os.path.join(args.bin, "..", "..", "..")),
        shared=args.shared or os.path.join(args.repo, "..", "shared"), out=out, jobs=args.jobs,
        extra=not args.quick, instructions=args.instructions)


def lock(out):
    """One run at a time per output folder: two runs regenerating the same cached drive would
    write one corrupt bag between them."""
    os.makedirs(out, exist_ok=True)
    handle = open(os.path.join(out, ".lock"), "w")
    try:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        raise BenchmarkError("another benchmark run is using %s (wait for it, or pass --out "
                             "<another folder>)" % out, exit_code=2)
    return handle


def save_results(ctx, mode, results):
    name = "results.json" if mode == "all" else "results_%s.json" % mode
    path = os.path.join(ctx.out, name)
    with open(path, "w") as f:
        json.dump({"%s/%s" % k: {kk: vv for kk, vv in v.items() if not kk.startswith("_")}
                   for k, v in results.items()}, f, indent=1)
    return path


def commit(repo):
    """The checkout's commit (short), with "+ changes" when the work tree differs."""
    def git(*a):
        return subprocess.run(["git", "-C", repo] + list(a), stdout=subprocess.PIPE,
                              stderr=subprocess.DEVNULL, text=True).stdout.strip()
    head = git("rev-parse", "--short", "HEAD") or "unknown"
    return head + (" + changes" if git("status", "--porcelain", "--untracked-files=no") else "")


def write_docs(ctx, args, printed):
    """Replaces each printed module's section of docs/benchmark.md with its tables."""
    path = os.path.join(ctx.repo, DOCS)
    with open(path) as f:
        document = f.read()
    flag = "" if args.mode == "all" else " --" + args.mode
    stamp = "Printed by `bash scripts/benchmark.sh%s --write-docs` at commit %s." % (
        flag, commit(ctx.repo))
    for module, tables in printed:
        body = "\n\n".join([stamp] + [report.markdown(t) for t in tables if t.docs])
        document = report.replace_section(document, module.__name__.rsplit(".", 1)[-1], body)
    with open(path, "w") as f:
        f.write(document)
    print("[benchmark] tables written into %s" % path, file=sys.stderr)


def run(args):
    start = time.time()
    ctx = context(args)
    handle = lock(ctx.out)
    if ctx.real_absent:
        print("%s: %s" % (drives.REAL, ctx.missing(os.path.join(ctx.shared, "data",
                                                                drives.REAL))))
    modules = registry.tables_of(args.mode)
    results = plan.run(ctx, [r for m in modules for r in m.requests(ctx)])
    printed = []
    for module in modules:
        tables = module.tables(ctx, results)
        for table in tables:
            print(report.text(table), flush=True)
        printed.append((module, tables))
    if results:
        print("\n[benchmark] raw results: %s" % save_results(ctx, args.mode, results))
    if args.write_docs:
        write_docs(ctx, args, printed)
    print("[benchmark] whole run: %.0f s" % (time.time() - start))
    handle.close()


def main(argv=None):
    try:
        run(parse(argv))
    except BenchmarkError as e:
        print("benchmark: error: %s" % e, file=sys.stderr)
        return e.exit_code
    return 0

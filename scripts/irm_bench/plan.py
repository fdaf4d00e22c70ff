"""A run's maps: every table's requests, deduplicated by (drive, config), each drive generated
once and each map made once, `--jobs` at a time; the results keyed (drive name, config name)."""
import dataclasses
import os
import sys

from . import configs, runners
from .drives import Drive


@dataclasses.dataclass
class Request:
    """One map a table needs: `drive` mapped with `config` (configs.Config)."""
    drive: Drive
    config: configs.Config

    @property
    def key(self):
        return (self.drive.name, self.config.name)


def unique(requests):
    """The requests in first-asked order, one per key; a config that needs another's metrics
    brings that request along."""
    by_key = {}
    for r in requests:
        if r.config.needs:
            by_key.setdefault((r.drive.name, r.config.needs),
                              Request(r.drive, configs.ablation(r.config.needs)))
        by_key.setdefault(r.key, r)
    return list(by_key.values())


def _map(ctx, request, needed):
    config_path = request.config.write(ctx, request.drive, needed)
    out = os.path.join(ctx.out, "maps", request.drive.name, request.config.name)
    return runners.map_and_evaluate(ctx.bin, request.drive, config_path, out)


def run(ctx, requests):
    """Generates the drives and makes the maps; returns {(drive, config): metrics}."""
    requests = unique(requests)
    drives = {r.drive.name: r.drive for r in requests}
    generations = runners.Jobs(ctx.jobs)
    for drive in drives.values():
        generations.submit(drive.name, drive.prepare, ctx.bin)
    generated = [d for d in drives.values() if d.scenario]
    if generated:
        print("[benchmark] generating %d drives (cached ones are reused)" % len(generated),
              file=sys.stderr)
    generations.results()

    jobs = runners.Jobs(ctx.jobs)
    # The maps that need no other map's metrics first, so those they wait for are done or
    # running when a dependent map starts.
    for r in sorted(requests, key=lambda r: r.config.needs is not None):
        if r.config.needs is None:
            jobs.submit(r.key, _map, ctx, r, None)
        else:
            dependency = jobs.futures[(r.drive.name, r.config.needs)]
            jobs.submit(r.key, lambda r=r, d=dependency: _map(ctx, r, d.result()))
    if requests:
        print("[benchmark] %d maps, %d at a time" % (len(requests), ctx.jobs), file=sys.stderr)
    return jobs.results()

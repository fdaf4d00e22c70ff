"""What one benchmark run knows: its paths and options, and the drives it selected."""
import dataclasses
import os
from typing import List

from . import drives


@dataclasses.dataclass
class Context:
    """A run. `scenarios`: the drives of the per-drive tables in table order (synthetic
    scenarios and, when asked for and present, the real-geometry drive); `extra`: the noise
    sweep, seeds 2-3 and the variant drives (off with --quick); `fleet`: the fleet passes
    were asked for (they map only when present)."""
    repo: str
    bin: str
    shared: str
    out: str
    build: str = ""
    jobs: int = 2
    scenarios: List[str] = dataclasses.field(default_factory=list)
    extra: bool = True
    fleet: bool = True
    real_absent: bool = False
    instructions: bool = False

    @classmethod
    def from_selection(cls, selection, **kwargs):
        """A context for the comma-separated drive names `selection` (drives.SYNTHETIC, REAL,
        FLEET); REAL is dropped, with real_absent set, when its folder is not there."""
        ctx = cls(**kwargs)
        names = [s for s in selection.split(",") if s]
        ctx.fleet = drives.FLEET in names
        ctx.scenarios = [s for s in names if s != drives.FLEET]
        if drives.REAL in ctx.scenarios and drives.real(ctx) is None:
            ctx.scenarios.remove(drives.REAL)
            ctx.real_absent = True
        return ctx

    def drive(self, name):
        """The drive of that name among the per-drive tables' ones."""
        if name == drives.REAL:
            return drives.real(self)
        if name in drives.VARIANTS:
            return drives.variant(self, name)
        for scenario in drives.SEED_SCENARIOS:
            for seed in drives.SEEDS[1:]:
                if name == "%s_seed%d" % (scenario, seed):
                    return drives.synthetic(self, scenario, seed)
        return drives.synthetic(self, name)

    def synthetic_scenarios(self):
        return [s for s in self.scenarios if s != drives.REAL]

    def seed_drives(self):
        """The seeds 2-3 drives of the selected seed scenarios (with `extra`)."""
        if not self.extra:
            return []
        return ["%s_seed%d" % (s, seed) for s in self.scenarios if s in drives.SEED_SCENARIOS
                for seed in drives.SEEDS[1:]]

    def variant_drives(self):
        """The variant drives of this run (with `extra`; urban's only when urban runs)."""
        if not self.extra:
            return []
        names = [drives.BLOBS, drives.CROWN]
        return names + ([drives.URBAN_LABELLED] if "urban" in self.scenarios else [])

    def missing(self, folder):
        return "skipped: not present (%s)" % os.path.normpath(folder)

"""The benchmark's drives: a name, its bag, ground truth and class table, and how it comes to be
(generated from a scenario and cached by content, or read in place from ../shared)."""
import dataclasses
import math
import os
from typing import Optional

from . import runners

SYNTHETIC = ["public_road", "port", "hilly", "urban", "curvy"]
REAL = "av2_pit_dev"  # <shared>/data/av2_pit_dev: its own bag, ground truth and class table
FLEET = "av2_pit_fleet"  # <shared>/data/av2_pit_fleet/pass_XX: one drive per pass
SEED_SCENARIOS = ["public_road", "port", "hilly"]
SEEDS = [1, 2, 3]
NOISE_LEVELS = [0.1, 0.2, 0.3, 0.4, 0.5]
LONG = "public_road_long"
# public_road with one spurious segmentation blob per frame.
BLOBS = "public_road_blobs_1.0"
# urban with the vehicles ahead labelled in the masks (a class the mapper's table does not
# know, which the front end takes for an occluder): what the unseen occluders of urban cost.
URBAN_LABELLED = "urban_occluders_labelled"
# public_road with its planar 2 % cross slope replaced by a 2 % crown whose ridge is the left
# line of the vehicle's lane (docs/synthetic_drives.md).
CROWN = "public_road_crown"
VARIANTS = {
    BLOBS: ("public_road", {"segmentation": {"spurious_blobs_per_frame": 1.0}}),
    CROWN: ("public_road", {"road": {"surface": {"cross_slope_pct": 0.0, "crown_pct": 2.0,
                                                 "crown_offset_m": 1.75}}}),
    URBAN_LABELLED: ("urban", {"segmentation": {"occluder_class_id": 30}}),
}


@dataclasses.dataclass
class Drive:
    """A drive the mapper runs on. `scenario` (with `seed`) is set for a generated drive."""
    name: str
    folder: str
    ground_truth: str
    classes: Optional[str] = None
    scenario: Optional[str] = None
    seed: int = 1

    @property
    def bag(self):
        return os.path.join(self.folder, "drive.bag")

    def prepare(self, bin_dir):
        """Generates the drive unless it is read in place or cached; True when generated."""
        if self.scenario is None:
            return False
        return runners.generate(bin_dir, self.scenario, self.folder, self.seed)


def scenario_path(repo, scenario):
    return os.path.join(repo, "config", "scenarios", scenario + ".yaml")


def generated(ctx, name, scenario_file, seed=1):
    folder = os.path.join(ctx.out, "drives", name)
    return Drive(name, folder, os.path.join(folder, "ground_truth.json"), scenario=scenario_file,
                 seed=seed)


def synthetic(ctx, scenario, seed=1):
    """A scenario of config/scenarios/ at a seed (seed 1 keeps the scenario's name)."""
    name = scenario if seed == 1 else "%s_seed%d" % (scenario, seed)
    return generated(ctx, name, scenario_path(ctx.repo, scenario), seed)


def variant(ctx, name):
    """A scenario with overrides on top (VARIANTS), its scenario file in drives/<name>."""
    base, overrides = VARIANTS[name]
    return overlay_drive(ctx, name, base, overrides)


def overlay_drive(ctx, name, base, overrides):
    folder = os.path.join(ctx.out, "drives", name)
    os.makedirs(folder, exist_ok=True)
    content = {"base": scenario_path(ctx.repo, base), "name": name}
    content.update(overrides)
    return generated(ctx, name, runners.write_yaml(os.path.join(folder, "scenario.yaml"), content))


def noise_name(level):
    return "public_road_noise_%.1f" % level


def noise(ctx, level):
    """The paper's pose protocol on public_road: random errors of mean `level` (m, 2D) and
    `level` (deg, yaw) on each pose, over an RTK-grade drift. A 2D Gaussian of per-axis sigma
    s has a mean magnitude of s sqrt(pi / 2); a 1D one, s sqrt(2 / pi)."""
    return overlay_drive(ctx, noise_name(level), "public_road", {"odometry": {
        "jitter_xy_m": round(level / math.sqrt(math.pi / 2), 4),
        "jitter_yaw_deg": round(level / math.sqrt(2 / math.pi), 4)}})


def real(ctx):
    """The real-geometry drive, or None when its folder is not complete."""
    folder = os.path.join(ctx.shared, "data", REAL)
    files = [os.path.join(folder, f) for f in ("drive.bag", "ground_truth.json", "classes.yaml")]
    if not all(os.path.isfile(f) for f in files):
        return None
    return Drive(REAL, folder, files[1], classes=files[2])


def fleet_folder(ctx):
    return os.path.join(ctx.shared, "data", FLEET)


def fleet_passes(ctx):
    """Every pass of the fleet data, each a drive scored in its own odom frame (its README:
    ground_truth_odom.json, the data's classes.yaml); [] when the folder is not there."""
    folder = fleet_folder(ctx)
    classes = os.path.join(folder, "classes.yaml")
    if not os.path.isfile(classes):
        return []
    passes = []
    for name in sorted(os.listdir(folder)):
        pass_folder = os.path.join(folder, name)
        gt = os.path.join(pass_folder, "ground_truth_odom.json")
        if name.startswith("pass_") and os.path.isfile(gt):
            passes.append(Drive("%s_%s" % (FLEET, name), pass_folder, gt, classes=classes))
    return passes


def pass_label(drive):
    """"pass_03" of a fleet pass's drive."""
    return os.path.basename(drive.folder)

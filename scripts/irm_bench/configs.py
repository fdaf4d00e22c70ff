"""The mapper configs a table asks for: the ablation rows of config/ablations/ and the configs
written per drive (with a YAML library) on top of them."""
import dataclasses
import os
from typing import Callable, Optional

from . import runners

# The paper's rows (docs/design.md section 4), label and config/ablations/<name>.yaml.
ABLATIONS = [("IPM", "ipm"), ("PGO-IPM", "pgo_ipm"), ("IPM (+PS)", "ipm_ps"),
             ("Ours (-)", "ours_minus"), ("Ours (+PS)", "ours_ps"),
             ("Ours (+PSR)", "ours_psr"), ("Ours (+PPSR)", "ours_ppsr")]
IPM = "ipm"
FULL = "ours_ppsr"  # = config/mapper.yaml
TRUE_EXTRINSIC = "true_extrinsic"
TRUE_EXTRINSIC_HELD = "true_extrinsic_held"


@dataclasses.dataclass
class Config:
    """A mapper config by name (the results' key). `write(ctx, drive, needed)` returns its
    file; `needed` is the metrics of the same drive mapped with config `needs` (or None)."""
    name: str
    write: Callable
    needs: Optional[str] = None


def ablation(name):
    """config/ablations/<name>.yaml as it is."""
    return Config(name, lambda ctx, drive, needed: os.path.join(
        ctx.repo, "config", "ablations", name + ".yaml"))


def true_extrinsic(held):
    """The full method started from the drive's true extrinsic (and with `held`, not refined
    at all): the extrinsic as evaluate_map reports the truth (`extrinsic_true_*`, the config's
    convention), taken from the drive's plain IPM map's metrics."""
    name = TRUE_EXTRINSIC_HELD if held else TRUE_EXTRINSIC

    def write(ctx, drive, needed):
        content = {"base": os.path.join(ctx.repo, "config", "mapper.yaml"),
                   "method": "ours_ppsr_" + name,
                   "input": {"extrinsic": {"xyz": needed["extrinsic_true_xyz_m"],
                                           "rpy_deg": needed["extrinsic_true_rpy_deg"]}}}
        if held:
            content["backend"] = {"optimize_extrinsic": False}
        folder = os.path.join(ctx.out, "maps", drive.name)
        os.makedirs(folder, exist_ok=True)
        return runners.write_yaml(os.path.join(folder, name + ".yaml"), content)
    return Config(name, write, needs=IPM)


def noise_told(level):
    """The full method told its odometry's noise class (the pose prior), as a user would."""
    def write(ctx, drive, needed):
        content = {"base": os.path.join(ctx.repo, "config", "ablations", FULL + ".yaml"),
                   "backend": {"pose_prior_sigma_trans_m": [round(1.5 * level, 3),
                                                            round(1.5 * level, 3), 0.02],
                               "pose_prior_sigma_rot_deg": [0.05, 0.05, round(2.0 * level, 3)]}}
        return runners.write_yaml(os.path.join(drive.folder, "mapper.yaml"), content)
    return Config(FULL, write)

"""Every table module in print order, and the modes (see the package's docstring)."""
from .tables import (ablations, extrinsic, fleet_passes, full_method, kitti, long_drive,
                     pose_noise, speed, storage, targets)

TABLES = [
    ablations,
    pose_noise,
    extrinsic,
    storage,
    speed,
    full_method,
    targets,
    fleet_passes,
    kitti,
    long_drive,
]
# The modes besides the default ("all"), each a command-line flag `--<mode>`.
MODE_HELP = {
    "long": "the long-drive benchmark alone (10 km: CPU and memory per distance, APE per "
            "sixth, the unload after the drive)",
    "fleet-passes": "the real-geometry fleet passes alone (each pass mapped with plain IPM and "
                    "the full method)",
    "kitti": "the real-image table alone (Table K: kitti_onramp segmented and mapped)",
}


def tables_of(mode):
    """The table modules a mode prints, in print order."""
    return [t for t in TABLES if mode in t.MODES]


def modes():
    return sorted({m for t in TABLES for m in t.MODES} - {"all"})

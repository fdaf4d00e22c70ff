"""Table 2: the pose update at odometry noise levels 0.1/0.1 .. 0.5/0.5 (m / deg) on
public_road, the mapper told its odometry's noise class."""
from .. import drives
from ..configs import noise_told
from ..plan import Request
from ..report import Table, fmt

TITLE = "Pose update under odometry noise (Table 2)"
MODES = ("all",)


def requests(ctx):
    if not ctx.extra:
        return []
    return [Request(drives.noise(ctx, level), noise_told(level)) for level in drives.NOISE_LEVELS]


def tables(ctx, results):
    if not ctx.extra:
        return []
    rows = []
    for level in drives.NOISE_LEVELS:
        m = results[(drives.noise_name(level), "ours_ppsr")]
        rows.append(["%.1f / %.1f" % (level, level), fmt(m.get("pose_trans_err_m_input")),
                     fmt(m.get("pose_trans_err_m")), fmt(m.get("pose_rot_err_deg_input")),
                     fmt(m.get("pose_rot_err_deg")), fmt(m.get("marking_ape_mean_m"))])
    return [Table("Table 2. Pose update (Ours +PPSR) on public_road", [
        "noise m / deg", "trans in (m)", "trans out (m)", "rot in (deg)", "rot out (deg)",
        "marking APE (m)"], rows)]

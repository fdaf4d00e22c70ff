"""Figures read from evaluate_map's metrics JSON (keys: docs/file_formats.md)."""
from .report import arrow


def false_positives(m):
    """Map markings that match no GT marking and duplicate none (evaluate_map's verdicts)."""
    return sum(1 for x in m.get("markings", []) if x.get("verdict") == "false_positive")


def roll_after(m):
    """|roll| of the refined extrinsic's error (deg), or None."""
    rpy = m.get("extrinsic_rpy_err_deg")
    return abs(rpy[0]) if rpy else None


def before_after(m, key, digits=3, input_suffix="_initial"):
    """"<key><input_suffix> -> <key>": a figure before and after the mapper."""
    return arrow(m.get(key + input_suffix), m.get(key), digits)


def ratio(numerator, denominator):
    """numerator / denominator, or None when either is missing or the denominator is 0."""
    if numerator is None or not denominator:
        return None
    return numerator / denominator


def cpu_ms_per_frame(m):
    """map_from_bag's process CPU (user + system) per frame used, in ms, or None."""
    frames = m.get("_metadata", {}).get("frames_used") or 0
    return 1e3 * m["_cpu_s"] / frames if frames and "_cpu_s" in m else None

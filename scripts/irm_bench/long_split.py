"""Splits a drive's map and ground truth by distance along the drive (the long-drive table).

Every element gets the distance driven at the true frame position nearest to it
(horizontally): a marking by its center, a lane piece by its midpoint, a pose by its stamp.
A part [d0, d1) of the drive then keeps:
- in the map: the markings inside, the Catmull-Rom segments inside (each consecutive run of
  segments becomes a spline of its own with its neighbours as phantom ends, so the curve is
  exactly the original one), the trajectory poses inside;
- in the ground truth: the markings and lane points within `margin_m` of the part (so that
  an element near the border still finds its true counterpart), the frames inside.
Pure python (no numpy): the frames are bucketed on a grid for the nearest-frame queries.
"""
import bisect
import copy
import math

CELL_M = 20.0
MAX_RING = 3  # beyond this many cells, the nearest frame is searched among all
INDEX_STEP_M = 2.0  # frames closer than this to the previous indexed one are not indexed


def equal_parts(total_m, parts):
    """`parts` equal distance ranges [d0, d1) covering [0, total_m]."""
    return [(total_m * k / parts, total_m * (k + 1) / parts) for k in range(parts)]


class DriveIndex:
    """Distance driven at each GT frame, and the nearest frame to a map point."""

    def __init__(self, frames):
        self.stamps = [f["stamp"] for f in frames]
        self.xy = [tuple(f["T_map_base_true"]["t"][:2]) for f in frames]
        self.distance_m = [0.0]
        for a, b in zip(self.xy, self.xy[1:]):
            self.distance_m.append(self.distance_m[-1] + math.hypot(b[0] - a[0], b[1] - a[1]))
        self.total_m = self.distance_m[-1]
        self.cells = {}
        last = -INDEX_STEP_M
        for i, (x, y) in enumerate(self.xy):
            if self.distance_m[i] - last >= INDEX_STEP_M or i == len(self.xy) - 1:
                self.cells.setdefault(self._cell(x, y), []).append(i)
                last = self.distance_m[i]

    @staticmethod
    def _cell(x, y):
        return (math.floor(x / CELL_M), math.floor(y / CELL_M))

    def nearest_frame(self, x, y):
        """Index of the indexed frame (one every INDEX_STEP_M) nearest to (x, y)."""
        cx, cy = self._cell(x, y)
        best, best_d2 = None, float("inf")
        for ring in range(MAX_RING + 1):
            for i in range(cx - ring, cx + ring + 1):
                for j in range(cy - ring, cy + ring + 1):
                    if max(abs(i - cx), abs(j - cy)) != ring:
                        continue
                    for k in self.cells.get((i, j), ()):
                        d2 = (self.xy[k][0] - x) ** 2 + (self.xy[k][1] - y) ** 2
                        if d2 < best_d2:
                            best, best_d2 = k, d2
            # Every frame outside the rings searched is at least `ring` cells away.
            if best is not None and math.sqrt(best_d2) <= ring * CELL_M:
                return best
        # Far from the drive: every indexed frame.
        indexed = [k for cell in self.cells.values() for k in cell]
        return min(indexed, key=lambda k: (self.xy[k][0] - x) ** 2 + (self.xy[k][1] - y) ** 2)

    def distance_at_point(self, point):
        """Distance driven at the frame nearest to a map point [x, y, ...]."""
        return self.distance_m[self.nearest_frame(point[0], point[1])]

    def distance_at_stamp(self, stamp):
        """Distance driven at a stamp (linear between frames, clamped at the ends)."""
        k = bisect.bisect_left(self.stamps, stamp)
        if k <= 0:
            return self.distance_m[0]
        if k >= len(self.stamps):
            return self.distance_m[-1]
        a = (stamp - self.stamps[k - 1]) / (self.stamps[k] - self.stamps[k - 1])
        return self.distance_m[k - 1] + a * (self.distance_m[k] - self.distance_m[k - 1])


def center(corners):
    """Mean of a marking's corners."""
    return [sum(c[i] for c in corners) / len(corners) for i in range(3)]


def piece_ranges(ranges, offset, count):
    """A lane's `unmeasured` control-point ranges for its piece of `count` points from index
    `offset` on: shifted into the piece, clipped to it."""
    out = []
    for first, last in ranges:
        a, b = max(first - offset, 0), min(last - offset, count - 1)
        if a <= b:
            out.append([a, b])
    return out


def runs(flags):
    """[begin, end) of every maximal run of True in `flags`."""
    result, begin = [], None
    for i, flag in enumerate(list(flags) + [False]):
        if flag and begin is None:
            begin = i
        elif not flag and begin is not None:
            result.append((begin, i))
            begin = None
    return result


class DriveSplit:
    """A map and its ground truth with the drive distance of every element, to crop parts."""

    def __init__(self, gt, vector_map, margin_m=30.0):
        self.gt, self.map, self.margin_m = gt, vector_map, margin_m
        self.index = DriveIndex(gt["frames"])
        at = self.index.distance_at_point
        self.gt_marking_d = [at(m.get("center") or center(m["corners"])) for m in gt["markings"]]
        self.gt_lane_d = [[at(p) for p in lane["points"]] for lane in gt["lanes"]]
        self.map_marking_d = [at(center(m["corners"])) for m in vector_map["markings"]]
        # Segment i of a spline runs from c[i] to c[i + 1], i = 1 .. n - 3; by its midpoint.
        self.map_segment_d = [
            [at([(c[i][0] + c[i + 1][0]) / 2, (c[i][1] + c[i + 1][1]) / 2])
             for i in range(1, len(c) - 2)]
            for c in (lane["control_points"] for lane in vector_map["lanes"])]

    def marking_ids_inside(self, d0, d1):
        """Ids of the GT markings whose center lies in [d0, d1) of the drive."""
        return {m["id"] for m, d in zip(self.gt["markings"], self.gt_marking_d) if d0 <= d < d1}

    def ground_truth_part(self, d0, d1):
        """The ground truth of [d0, d1): elements within margin_m of it, its frames."""
        lo, hi = d0 - self.margin_m, d1 + self.margin_m
        part = copy.copy(self.gt)
        part["markings"] = [m for m, d in zip(self.gt["markings"], self.gt_marking_d)
                            if lo <= d < hi]
        part["lanes"] = []
        for lane, distances in zip(self.gt["lanes"], self.gt_lane_d):
            for begin, end in runs([lo <= d < hi for d in distances]):
                if end - begin >= 2:
                    piece = dict(lane, points=lane["points"][begin:end])
                    piece["id"] = lane["id"] * 1000 + len(part["lanes"])
                    part["lanes"].append(piece)
        part["frames"] = [f for f, d in zip(self.gt["frames"], self.index.distance_m)
                          if d0 <= d < d1]
        return part

    def map_part(self, d0, d1):
        """The map of [d0, d1): markings, spline segments and poses inside. The lane pieces
        are renumbered, so they carry no topology (it named the whole map's lane ids)."""
        part = copy.copy(self.map)
        part["markings"] = [m for m, d in zip(self.map["markings"], self.map_marking_d)
                            if d0 <= d < d1]
        part["lanes"] = []
        for lane, distances in zip(self.map["lanes"], self.map_segment_d):
            c = lane["control_points"]
            for begin, end in runs([d0 <= d < d1 for d in distances]):
                first, last = begin + 1, end  # segments first .. last, with phantom ends
                points = c[first - 1:last + 3]
                part["lanes"].append(dict(lane, control_points=points,
                                          unmeasured=piece_ranges(lane.get("unmeasured", []),
                                                                  first - 1, len(points)),
                                          id=len(part["lanes"]) + 1, predecessors=[],
                                          successors=[]))
        part["trajectory"] = [p for p in self.map.get("trajectory", [])
                              if d0 <= self.index.distance_at_stamp(p["stamp"]) < d1]
        return part

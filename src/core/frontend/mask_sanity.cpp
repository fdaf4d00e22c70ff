#include "ipm_road_mapper/core/frontend/mask_sanity.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <opencv2/imgproc.hpp>

namespace ipm_road_mapper {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr int kMaxGroundPoints = 60;        // per piece: enough for a line fit
constexpr std::size_t kEvidenceStride = 4;  // of those, the class evidence

// One 8-connected piece of a lane instance: its pixels and its line on the ground.
struct Piece {
  std::vector<cv::Point> pixels;
  std::vector<Eigen::Vector2d> ground;  // base_link x, y of up to kMaxGroundPoints pixels
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  Eigen::Vector2d direction = Eigen::Vector2d::UnitX();
  bool has_line = false;  // at least two ground points apart
  double length_m = 0.0;  // extent along direction
};

// The 8-connected pieces of an instance's pixels.
std::vector<Piece> SplitIntoPieces(const std::vector<cv::Point>& pixels) {
  const cv::Rect box = cv::boundingRect(pixels);
  cv::Mat binary = cv::Mat::zeros(box.size(), CV_8U);
  for (const cv::Point& p : pixels) binary.at<uchar>(p - box.tl()) = 1;
  cv::Mat labels;
  const int count = cv::connectedComponents(binary, labels, 8, CV_32S);
  std::vector<Piece> pieces(std::max(0, count - 1));
  for (const cv::Point& p : pixels) {
    pieces[labels.at<int>(p - box.tl()) - 1].pixels.push_back(p);
  }
  return pieces;
}

// The piece's ground points (a spread subsample) and its principal line.
void FitGroundLine(const Ipm& ipm, Piece* piece) {
  const std::size_t step = std::max<std::size_t>(1, piece->pixels.size() / kMaxGroundPoints);
  for (std::size_t i = 0; i < piece->pixels.size(); i += step) {
    Eigen::Vector3d p_base;
    const Eigen::Vector2d uv(piece->pixels[i].x, piece->pixels[i].y);
    if (ipm.PixelToGround(uv, &p_base) == IpmStatus::kOk) piece->ground.push_back(p_base.head<2>());
  }
  if (piece->ground.size() < 2) return;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : piece->ground) mean += p;
  mean /= static_cast<double>(piece->ground.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2d& p : piece->ground) scatter += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(scatter);
  piece->center = mean;
  piece->direction = eigen.eigenvectors().col(1);
  piece->has_line = eigen.eigenvalues()(1) > 1e-6;
  double lo = 0.0, hi = 0.0;
  for (const Eigen::Vector2d& p : piece->ground) {
    lo = std::min(lo, (p - mean).dot(piece->direction));
    hi = std::max(hi, (p - mean).dot(piece->direction));
  }
  piece->length_m = hi - lo;
}

// True when the two pieces are two lines, not one: side by side (near parallel, overlapping
// along their direction, and apart across it by more than collinear_max_offset_m plus 5 % of
// the distance: two lines merged in one instance), or crossing each other at more than
// split_min_turn_deg (a line and a stripe merged). Pieces that follow each other along a
// line stay one line, however a far view bends them.
bool TwoLines(const Piece& a, const Piece& b, const MaskSanityOptions& options) {
  if (!a.has_line || !b.has_line) return false;  // too little to tell: one line
  const double cos_turn = std::abs(a.direction.dot(b.direction));
  if (cos_turn < std::cos(options.split_min_turn_deg * kDegToRad)) return true;
  if (cos_turn < std::cos(options.collinear_max_turn_deg * kDegToRad)) return false;
  const Eigen::Vector2d d = b.center - a.center;
  const Eigen::Vector2d u =
      (a.direction + (a.direction.dot(b.direction) < 0 ? -b.direction : b.direction)).normalized();
  const double across = std::abs(u.x() * d.y() - u.y() * d.x());
  const double overlap = 0.5 * (a.length_m + b.length_m) - std::abs(d.dot(u));
  return overlap > 0.0 && across > options.collinear_max_offset_m + 0.05 * d.norm();
}

// Pieces grouped into lines, largest group first: union-find over the pairs of pieces of at
// least min_line_pixels that are not TwoLines; a smaller piece (a far dash, a fragment) is too
// little to be a line of its own and goes with the largest group.
std::vector<std::vector<int>> GroupIntoLines(const std::vector<Piece>& pieces,
                                             const MaskSanityOptions& options) {
  const int n = static_cast<int>(pieces.size());
  const auto big = [&](int i) {
    return pieces[i].has_line &&
           static_cast<int>(pieces[i].pixels.size()) >= options.min_line_pixels;
  };
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&parent](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      if (!big(a) || !big(b) || !TwoLines(pieces[a], pieces[b], options)) {
        parent[root(a)] = root(b);
      }
    }
  }
  std::map<int, std::vector<int>> by_root;
  std::vector<int> small;
  for (int i = 0; i < n; ++i) {
    if (big(i)) {
      by_root[root(i)].push_back(i);
    } else {
      small.push_back(i);
    }
  }
  std::vector<std::vector<int>> groups;
  for (auto& entry : by_root) groups.push_back(std::move(entry.second));
  const auto pixels = [&pieces](const std::vector<int>& g) {
    std::size_t sum = 0;
    for (const int i : g) sum += pieces[i].pixels.size();
    return sum;
  };
  std::sort(groups.begin(), groups.end(),
            [&](const auto& x, const auto& y) { return pixels(x) > pixels(y); });
  if (groups.empty()) groups.emplace_back();
  groups.front().insert(groups.front().end(), small.begin(), small.end());
  return groups;
}

// A value of `class_id` that no instance of the frame uses (0 when all 999 are taken).
std::uint16_t FreeValue(int class_id, std::vector<bool>* used) {
  for (int index = 999; index >= 1; --index) {
    const int value = class_id * 1000 + index;
    if (value <= 65535 && !(*used)[value]) {
      (*used)[value] = true;
      return static_cast<std::uint16_t>(value);
    }
  }
  return 0;
}

}  // namespace

MaskSanityOptions LoadMaskSanityOptions(OptionsReader reader) {
  MaskSanityOptions o;
  reader.Read<std::vector<int>>("area_class_ids", &o.area_class_ids,
                                [](const std::vector<int>& v) -> std::string {
                                  for (const int id : v) {
                                    if (id < 1 || id > 65) return "ids are in 1..65";
                                  }
                                  return "";
                                });
  reader.Read<bool>("split_lanes", &o.split_lanes);
  reader.Read<int>("min_piece_pixels", &o.min_piece_pixels,
                   [](const int& v) { return v >= 0 ? std::string() : "must be >= 0"; });
  reader.Read<int>("min_line_pixels", &o.min_line_pixels, CheckPositiveInt);
  reader.Read<double>("collinear_max_turn_deg", &o.collinear_max_turn_deg, CheckPositive);
  reader.Read<double>("collinear_max_offset_m", &o.collinear_max_offset_m, CheckPositive);
  reader.Read<double>("split_min_turn_deg", &o.split_min_turn_deg, CheckPositive);
  reader.Read<int>("flicker_memory_frames", &o.flicker_memory_frames,
                   [](const int& v) { return v >= 0 ? std::string() : "must be >= 0"; });
  reader.Read<double>("flicker_radius_m", &o.flicker_radius_m, CheckPositive);
  reader.Read<double>("flicker_majority", &o.flicker_majority,
                      [](const double& v) { return v >= 1.0 ? std::string() : "must be >= 1"; });
  reader.Read<int>("flicker_min_votes", &o.flicker_min_votes, CheckPositiveInt);
  reader.RejectUnknownKeys();
  return o;
}

void MaskSanityCounters::Add(const MaskSanityCounters& other) {
  area_instances += other.area_instances;
  lane_instances_split += other.lane_instances_split;
  lane_pieces_dropped += other.lane_pieces_dropped;
  lane_class_resolved += other.lane_class_resolved;
}

cv::Mat MaskSanity::Clean(const cv::Mat& mask, const Ipm& ipm, const Eigen::Isometry3d& T_map_base,
                          MaskSanityCounters* counters) {
  // The lane instances' pixels, the area instances' pixels, every value in use.
  std::map<std::uint16_t, std::vector<cv::Point>> lanes, areas;
  std::vector<bool> used(66 * 1000, false);
  for (int v = 0; v < mask.rows; ++v) {
    const std::uint16_t* row = mask.ptr<std::uint16_t>(v);
    for (int u = 0; u < mask.cols; ++u) {
      if (row[u] < 1000) continue;
      used[row[u]] = true;
      const int class_id = row[u] / 1000;
      if (std::find(options_.area_class_ids.begin(), options_.area_class_ids.end(), class_id) !=
          options_.area_class_ids.end()) {
        areas[row[u]].emplace_back(u, v);
        continue;
      }
      const ClassInfo* info = classes_->Find(class_id);
      if (info && info->kind == ElementKind::kLane) lanes[row[u]].emplace_back(u, v);
    }
  }
  cv::Mat out = mask;
  const auto paint = [&out, &mask](const std::vector<cv::Point>& pixels, std::uint16_t value) {
    if (out.data == mask.data) out = mask.clone();
    for (const cv::Point& p : pixels) out.at<std::uint16_t>(p) = value;
  };
  for (const auto& [value, pixels] : areas) {
    ++counters->area_instances;
    paint(pixels, 0);
  }
  std::vector<Vote> votes;
  for (const auto& [value, pixels] : lanes) {
    std::vector<Piece> pieces =
        options_.split_lanes ? SplitIntoPieces(pixels) : std::vector<Piece>{};
    if (!options_.split_lanes) pieces.push_back({pixels, {}, {}, {}, false});
    std::vector<Piece> kept;
    for (Piece& piece : pieces) {
      if (options_.split_lanes &&
          static_cast<int>(piece.pixels.size()) < options_.min_piece_pixels && pieces.size() > 1) {
        ++counters->lane_pieces_dropped;
        paint(piece.pixels, 0);
        continue;
      }
      FitGroundLine(ipm, &piece);
      kept.push_back(std::move(piece));
    }
    if (kept.empty()) continue;
    const std::vector<std::vector<int>> lines = GroupIntoLines(kept, options_);
    if (lines.size() > 1) ++counters->lane_instances_split;
    for (std::size_t k = 0; k < lines.size(); ++k) {
      std::vector<Eigen::Vector2f> points_map;
      for (const int i : lines[k]) {
        // Every kEvidenceStride-th ground point is evidence (the cost stays a few
        // thousand distance checks per line).
        for (std::size_t j = 0; j < kept[i].ground.size(); j += kEvidenceStride) {
          const Eigen::Vector2d& p = kept[i].ground[j];
          points_map.push_back(
              (T_map_base * Eigen::Vector3d(p.x(), p.y(), 0.0)).head<2>().cast<float>());
        }
      }
      const int class_id = ResolveClass(points_map, value / 1000, counters);
      std::uint16_t line_value = value;
      if (k > 0 || class_id != value / 1000) line_value = FreeValue(class_id, &used);
      if (line_value == 0) {  // no free value left: the line is dropped
        for (const int i : lines[k]) paint(kept[i].pixels, 0);
        continue;
      }
      for (const int i : lines[k]) {
        if (line_value != value) paint(kept[i].pixels, line_value);
      }
      for (const Eigen::Vector2f& xy : points_map) votes.push_back({xy, class_id});
    }
  }
  if (options_.flicker_memory_frames > 0) {
    memory_.push_back(std::move(votes));
    while (static_cast<int>(memory_.size()) > options_.flicker_memory_frames) memory_.pop_front();
  }
  return out;
}

int MaskSanity::ResolveClass(const std::vector<Eigen::Vector2f>& points_map, int class_id,
                             MaskSanityCounters* counters) const {
  if (options_.flicker_memory_frames <= 0 || memory_.empty()) return class_id;
  std::map<int, int> count;  // class -> evidence points near the line
  const float radius2 = static_cast<float>(options_.flicker_radius_m * options_.flicker_radius_m);
  for (const Eigen::Vector2f& xy : points_map) {
    for (const std::vector<Vote>& frame : memory_) {
      for (const Vote& vote : frame) {
        if ((vote.xy - xy).squaredNorm() <= radius2) ++count[vote.class_id];
      }
    }
  }
  int best = class_id, best_count = 0;
  for (const auto& [other, n] : count) {
    if (other != class_id && n > best_count) {
      best = other;
      best_count = n;
    }
  }
  if (best_count < options_.flicker_min_votes ||
      best_count < options_.flicker_majority * count[class_id]) {
    return class_id;
  }
  ++counters->lane_class_resolved;
  return best;
}

}  // namespace ipm_road_mapper

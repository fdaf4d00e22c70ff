#include "ipm_road_mapper/core/io/lanelet2_export.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

#include "ipm_road_mapper/core/io/map_geodesy.h"
#include "ipm_road_mapper/core/map/lanelet_pairing.h"
#include "json_io.h"

namespace ipm_road_mapper {
namespace {

using Tags = std::vector<std::pair<std::string, std::string>>;

// Points of a line closer than this along it are one node.
constexpr double kSameNodeM = 1e-6;

// The text as an XML attribute value.
std::string Escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string Fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", decimals, value + 0.0);
  return text;
}

// Accumulates the three OSM sections; ids are one positive sequence.
class OsmWriter {
 public:
  explicit OsmWriter(const GeoOrigin& origin) : to_wgs84_(origin) {}

  // A point; `unmeasured`: on a stretch of a lane line no pixel measured (irm:measured no).
  std::uint64_t Node(const Eigen::Vector3d& p_map, bool unmeasured = false) {
    const Wgs84Point p = to_wgs84_.Convert(p_map);
    const std::uint64_t id = next_id_++;
    nodes_ << "  <node id=\"" << id << "\" visible=\"true\" version=\"1\" lat=\""
           << Fixed(p.latitude_deg, 9) << "\" lon=\"" << Fixed(p.longitude_deg, 9) << "\">\n";
    Tags tags = {{"ele", Fixed(p.altitude_m, 4)},
                 {"local_x", Fixed(p_map.x(), 4)},
                 {"local_y", Fixed(p_map.y(), 4)}};
    if (unmeasured) tags.emplace_back("irm:measured", "no");
    WriteTags(&nodes_, tags);
    nodes_ << "  </node>\n";
    ++stats_.nodes;
    return id;
  }

  std::uint64_t Way(const std::vector<std::uint64_t>& node_ids, const Tags& tags) {
    const std::uint64_t id = next_id_++;
    ways_ << "  <way id=\"" << id << "\" visible=\"true\" version=\"1\">\n";
    for (std::uint64_t n : node_ids) ways_ << "    <nd ref=\"" << n << "\"/>\n";
    WriteTags(&ways_, tags);
    ways_ << "  </way>\n";
    ++stats_.ways;
    return id;
  }

  void Lanelet(std::uint64_t left_way, std::uint64_t right_way, const Tags& tags) {
    const std::uint64_t id = next_id_++;
    relations_ << "  <relation id=\"" << id << "\" visible=\"true\" version=\"1\">\n"
               << "    <member type=\"way\" ref=\"" << left_way << "\" role=\"left\"/>\n"
               << "    <member type=\"way\" ref=\"" << right_way << "\" role=\"right\"/>\n";
    WriteTags(&relations_, tags);
    relations_ << "  </relation>\n";
    ++stats_.lanelets;
  }

  std::string Document() const {
    return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
           "<osm version=\"0.6\" generator=\"ipm_road_mapper\">\n" +
           nodes_.str() + ways_.str() + relations_.str() + "</osm>\n";
  }

  Lanelet2ExportStats& stats() { return stats_; }

 private:
  static void WriteTags(std::ostringstream* out, const Tags& tags) {
    for (const auto& [k, v] : tags) {
      *out << "    <tag k=\"" << Escaped(k) << "\" v=\"" << Escaped(v) << "\"/>\n";
    }
  }

  MapToWgs84 to_wgs84_;
  std::uint64_t next_id_ = 1;
  std::ostringstream nodes_, ways_, relations_;
  Lanelet2ExportStats stats_;
};

// Lanelet2's arrow subtype of an "arrow_<direction>" class, or "".
std::string ArrowSubtype(const std::string& class_name) {
  const std::string prefix = "arrow_";
  if (class_name.compare(0, prefix.size(), prefix) != 0) return "";
  const std::string direction = class_name.substr(prefix.size());
  for (const char* known :
       {"straight", "left", "right", "straight_left", "straight_right", "left_right"}) {
    if (direction == known) return direction;
  }
  return "";
}

Tags ElementTags(std::uint64_t id, const std::string& class_name) {
  return {{"irm:id", std::to_string(id)}, {"irm:class", class_name}};
}

void WriteMarking(const MapMarking& m, OsmWriter* osm) {
  Tags tags;
  std::vector<std::uint64_t> nodes;
  const std::array<Eigen::Vector3d, 4>& c = m.corners_map;
  if (m.class_name == "stop_line") {
    // Its center line: the midpoints of its two short sides.
    const bool side0_long = (c[1] - c[0]).head<2>().norm() >= (c[2] - c[1]).head<2>().norm();
    const Eigen::Vector3d a = side0_long ? 0.5 * (c[3] + c[0]) : 0.5 * (c[0] + c[1]);
    const Eigen::Vector3d b = side0_long ? 0.5 * (c[1] + c[2]) : 0.5 * (c[2] + c[3]);
    nodes = {osm->Node(a), osm->Node(b)};
    tags = {{"type", "stop_line"}};
  } else {
    double area2 = 0.0;
    for (int i = 0; i < 4; ++i) {
      area2 += c[i].x() * c[(i + 1) % 4].y() - c[(i + 1) % 4].x() * c[i].y();
    }
    std::array<int, 4> order{{0, 1, 2, 3}};
    if (area2 < 0.0) order = {{0, 3, 2, 1}};
    for (int i : order) nodes.push_back(osm->Node(c[i]));
    nodes.push_back(nodes.front());
    const std::string arrow = ArrowSubtype(m.class_name);
    if (!arrow.empty()) {
      tags = {{"type", "arrow"}, {"subtype", arrow}};
    } else {
      tags = {{"type", "road_marking"}, {"subtype", m.class_name}};
    }
  }
  const Tags element = ElementTags(m.id, m.class_name);
  tags.insert(tags.end(), element.begin(), element.end());
  if (!m.Complete()) tags.emplace_back("irm:complete", "no");
  osm->Way(nodes, tags);
}

// Whether the drive went along the lane whose bounds' middles are `left` and `right` (its
// pose nearest to the lane's middle lies between them): its direction is known, one way.
// Other lanes (across a center line, say) may carry traffic either way as far as the drive
// can tell.
bool Driven(const Eigen::Vector2d& left, const Eigen::Vector2d& right,
            const std::vector<StampedPose>& trajectory) {
  const Eigen::Vector2d middle = 0.5 * (left + right);
  double nearest = std::numeric_limits<double>::infinity();
  for (const StampedPose& pose : trajectory) {
    nearest = std::min(nearest, (pose.T_map_base.translation().head<2>() - middle).norm());
  }
  return nearest <= 0.5 * (left - right).norm();
}

}  // namespace

std::string VectorMapToLanelet2Osm(const VectorMap& map, const GeoOrigin& origin,
                                   Lanelet2ExportStats* stats) {
  OsmWriter osm(origin);
  // Lane lines, oriented along the drive; lanes without geometry are not written.
  std::vector<const MapLane*> lanes;
  std::vector<std::vector<Eigen::Vector3d>> lines;
  std::vector<std::vector<bool>> unmeasured;  // per line sample (LanePolyline)
  for (const MapLane& lane : map.lanes) {
    std::vector<bool> flags;
    std::vector<Eigen::Vector3d> polyline = LanePolyline(lane, kLaneSampleSpacing_m, &flags);
    if (polyline.size() < 2) continue;
    lanes.push_back(&lane);
    bool reversed = false;
    lines.push_back(LaneOrientedAlongDrive(std::move(polyline), map.trajectory, &reversed));
    if (reversed) std::reverse(flags.begin(), flags.end());
    unmeasured.push_back(std::move(flags));
  }
  const LaneletLayout layout = PairLanelets(lines);
  std::vector<std::vector<double>> arcs;
  for (const auto& line : lines) arcs.push_back(ArcLengths(line));
  // Each line's pieces: nodes at its samples and cuts, the cut nodes shared by the pieces
  // on both sides of them.
  std::vector<std::vector<std::uint64_t>> piece_ways(lines.size());
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::vector<double>& arc = arcs[i];
    const std::vector<double>& cuts = layout.cuts[i];
    Tags tags = {{"type", "line_thin"}};
    if (lanes[i]->style == "solid" || lanes[i]->style == "dashed") {
      tags.emplace_back("subtype", lanes[i]->style);
    }
    const Tags element = ElementTags(lanes[i]->id, lanes[i]->class_name);
    tags.insert(tags.end(), element.begin(), element.end());
    const std::vector<bool>& laid = unmeasured[i];
    std::vector<std::uint64_t> piece{osm.Node(lines[i].front(), laid.front())};
    double last_arc = 0.0;  // of the piece's last node
    std::size_t next_cut = 0;
    for (std::size_t k = 1; k < lines[i].size(); ++k) {
      while (next_cut < cuts.size() && cuts[next_cut] < arc[k]) {
        // A cut on a sample is that sample's node; between two, unmeasured if either is.
        if (cuts[next_cut] - last_arc > kSameNodeM) {
          piece.push_back(
              osm.Node(PointAtArcLength(lines[i], arc, cuts[next_cut]), laid[k - 1] || laid[k]));
          last_arc = cuts[next_cut];
        }
        piece_ways[i].push_back(osm.Way(piece, tags));
        piece = {piece.back()};
        ++next_cut;
      }
      if (arc[k] - last_arc > kSameNodeM) {
        piece.push_back(osm.Node(lines[i][k], laid[k]));
        last_arc = arc[k];
      }
    }
    piece_ways[i].push_back(osm.Way(piece, tags));
  }
  for (const LaneletBounds& b : layout.lanelets) {
    auto piece_middle = [&](std::size_t line, std::size_t piece) {
      const auto [from, to] = PieceRange(layout, line, piece, arcs[line].back());
      return PointAtArcLength(lines[line], arcs[line], 0.5 * (from + to)).head<2>().eval();
    };
    const bool driven = Driven(piece_middle(b.left_line, b.left_piece),
                               piece_middle(b.right_line, b.right_piece), map.trajectory);
    osm.Lanelet(piece_ways[b.left_line][b.left_piece], piece_ways[b.right_line][b.right_piece],
                {{"type", "lanelet"},
                 {"subtype", "road"},
                 {"location", "urban"},
                 {"one_way", driven ? "yes" : "no"},
                 {"participant:vehicle", "yes"}});
  }
  for (const MapMarking& m : map.markings) WriteMarking(m, &osm);
  osm.stats().lanes_left_out = layout.runs_left_out;
  if (stats) *stats = osm.stats();
  return osm.Document();
}

void SaveLanelet2Osm(const VectorMap& map, const GeoOrigin& origin, const std::string& path,
                     Lanelet2ExportStats* stats) {
  json_io::WriteFileAtomically(path, VectorMapToLanelet2Osm(map, origin, stats));
}

}  // namespace ipm_road_mapper

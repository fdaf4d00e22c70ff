// The Lanelet2 OSM export (lanelet2_export.h): nodes on WGS84 with their map-frame metres,
// lane lines as line strings cut where lanelets begin and end, lanelets with their bounds on
// the right sides, markings with Lanelet2's tags; every reference resolves.
#include <gtest/gtest.h>

#include <GeographicLib/LocalCartesian.hpp>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "ipm_road_mapper/core/io/lanelet2_export.h"

namespace ipm_road_mapper {
namespace {

// The parts of the OSM document the checks need.
struct Osm {
  struct Node {
    double lat, lon;
    std::map<std::string, std::string> tags;
  };
  struct Way {
    std::vector<std::uint64_t> nodes;
    std::map<std::string, std::string> tags;
  };
  struct Relation {
    std::uint64_t left = 0, right = 0;
    std::map<std::string, std::string> tags;
  };
  std::map<std::uint64_t, Node> nodes;
  std::map<std::uint64_t, Way> ways;
  std::map<std::uint64_t, Relation> relations;
  std::size_t duplicate_ids = 0;
};

std::map<std::string, std::string> TagsOf(const std::string& body) {
  std::map<std::string, std::string> tags;
  static const std::regex tag("<tag k=\"([^\"]*)\" v=\"([^\"]*)\"/>");
  for (std::sregex_iterator it(body.begin(), body.end(), tag), end; it != end; ++it) {
    tags[(*it)[1]] = (*it)[2];
  }
  return tags;
}

Osm Parse(const std::string& xml) {
  Osm osm;
  std::set<std::uint64_t> ids;
  auto note = [&](std::uint64_t id) {
    if (!ids.insert(id).second) ++osm.duplicate_ids;
  };
  static const std::regex node(
      "<node id=\"(\\d+)\" visible=\"true\" version=\"1\" lat=\"([-0-9.]+)\" "
      "lon=\"([-0-9.]+)\">([\\s\\S]*?)</node>");
  for (std::sregex_iterator it(xml.begin(), xml.end(), node), end; it != end; ++it) {
    const std::uint64_t id = std::stoull((*it)[1]);
    note(id);
    osm.nodes[id] = {std::stod((*it)[2]), std::stod((*it)[3]), TagsOf((*it)[4])};
  }
  static const std::regex way(
      "<way id=\"(\\d+)\" visible=\"true\" version=\"1\">([\\s\\S]*?)</way>");
  static const std::regex nd("<nd ref=\"(\\d+)\"/>");
  for (std::sregex_iterator it(xml.begin(), xml.end(), way), end; it != end; ++it) {
    const std::uint64_t id = std::stoull((*it)[1]);
    note(id);
    const std::string body = (*it)[2];
    Osm::Way w;
    for (std::sregex_iterator n(body.begin(), body.end(), nd); n != end; ++n) {
      w.nodes.push_back(std::stoull((*n)[1]));
    }
    w.tags = TagsOf(body);
    osm.ways[id] = w;
  }
  static const std::regex relation(
      "<relation id=\"(\\d+)\" visible=\"true\" version=\"1\">([\\s\\S]*?)</relation>");
  static const std::regex member("<member type=\"way\" ref=\"(\\d+)\" role=\"(left|right)\"/>");
  for (std::sregex_iterator it(xml.begin(), xml.end(), relation), end; it != end; ++it) {
    const std::uint64_t id = std::stoull((*it)[1]);
    note(id);
    const std::string body = (*it)[2];
    Osm::Relation r;
    for (std::sregex_iterator m(body.begin(), body.end(), member); m != end; ++m) {
      ((*m)[2] == "left" ? r.left : r.right) = std::stoull((*m)[1]);
    }
    r.tags = TagsOf(body);
    osm.relations[id] = r;
  }
  return osm;
}

GeoOrigin Munich() { return {48.0, 11.0, 500.0}; }

// Three lines along +x (control points every 5 m, 0-100 m): solid at y -1.75, dashed at
// +1.75, solid at +5.25 from x 50 on; the drive along y = 0; an arrow, a stop line and a
// crosswalk stripe whose far side was never seen.
VectorMap ThreeLaneMap() {
  VectorMap map;
  auto lane = [](std::uint64_t id, const char* style, double y, double x0) {
    MapLane l;
    l.id = id;
    l.class_name = std::string("lane_white_") + style;
    l.style = style;
    for (double x = x0; x <= 100.0; x += 5.0) l.control_points_map.emplace_back(x, y, 0.1);
    return l;
  };
  map.lanes = {lane(1, "solid", -1.75, 0.0), lane(2, "dashed", 1.75, 0.0),
               lane(3, "solid", 5.25, 50.0)};
  for (int k = 0; k <= 50; ++k) {
    StampedPose pose;
    pose.stamp = 0.1 * k;
    pose.T_map_base.translation() = Eigen::Vector3d(2.0 * k, 0.0, 0.0);
    map.trajectory.push_back(pose);
  }
  MapMarking arrow;
  arrow.id = 10;
  arrow.class_name = "arrow_left";
  arrow.corners_map = {Eigen::Vector3d(20, -0.6, 0), Eigen::Vector3d(25, -0.6, 0),
                       Eigen::Vector3d(25, 0.6, 0), Eigen::Vector3d(20, 0.6, 0)};
  MapMarking stop = arrow;
  stop.id = 11;
  stop.class_name = "stop_line";
  stop.corners_map = {Eigen::Vector3d(90, -1.75, 0), Eigen::Vector3d(90.4, -1.75, 0),
                      Eigen::Vector3d(90.4, 1.75, 0), Eigen::Vector3d(90, 1.75, 0)};
  MapMarking stripe = arrow;
  stripe.id = 12;
  stripe.class_name = "crosswalk_stripe & co";
  stripe.sides_measured = {true, false, true, true};
  map.markings = {arrow, stop, stripe};
  return map;
}

// Mean local_y of a way's nodes.
double MeanY(const Osm& osm, std::uint64_t way) {
  double sum = 0.0;
  for (std::uint64_t n : osm.ways.at(way).nodes)
    sum += std::stod(osm.nodes.at(n).tags.at("local_y"));
  return sum / osm.ways.at(way).nodes.size();
}

TEST(Lanelet2Export, EveryReferenceResolvesAndIdsArePositiveAndUnique) {
  Lanelet2ExportStats stats;
  const std::string xml = VectorMapToLanelet2Osm(ThreeLaneMap(), Munich(), &stats);
  ASSERT_EQ(xml.rfind("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<osm version=\"0.6\"", 0), 0u);
  const Osm osm = Parse(xml);
  EXPECT_EQ(osm.duplicate_ids, 0u);
  EXPECT_EQ(osm.nodes.size(), stats.nodes);
  EXPECT_EQ(osm.ways.size(), stats.ways);
  EXPECT_EQ(osm.relations.size(), stats.lanelets);
  EXPECT_GT(osm.nodes.begin()->first, 0u);
  for (const auto& [id, way] : osm.ways) {
    EXPECT_GE(way.nodes.size(), 2u) << id;
    for (std::uint64_t n : way.nodes) EXPECT_EQ(osm.nodes.count(n), 1u) << "way " << id;
  }
  for (const auto& [id, r] : osm.relations) {
    EXPECT_EQ(osm.ways.count(r.left), 1u) << id;
    EXPECT_EQ(osm.ways.count(r.right), 1u) << id;
  }
}

TEST(Lanelet2Export, LanesAreLaneletsWithTheirBoundsOnTheirSides) {
  Lanelet2ExportStats stats;
  const Osm osm = Parse(VectorMapToLanelet2Osm(ThreeLaneMap(), Munich(), &stats));
  // The driven lane (y -1.75 .. 1.75) cut at x 50 where the third line starts: two lanelets
  // one after the other; the lane beside it (1.75 .. 5.25) from x 50: one.
  ASSERT_EQ(osm.relations.size(), 3u);
  EXPECT_EQ(stats.lanes_left_out, 0u);
  int driven = 0, beside = 0;
  for (const auto& [id, r] : osm.relations) {
    EXPECT_EQ(r.tags.at("type"), "lanelet");
    EXPECT_EQ(r.tags.at("subtype"), "road");
    EXPECT_GT(MeanY(osm, r.left), MeanY(osm, r.right));  // left is left along the drive
    if (std::abs(MeanY(osm, r.right) + 1.75) < 0.01) {
      ++driven;
      EXPECT_EQ(r.tags.at("one_way"), "yes");
    } else {
      ++beside;
      EXPECT_NEAR(MeanY(osm, r.right), 1.75, 0.01);
      EXPECT_EQ(r.tags.at("one_way"), "no");  // not driven: its direction is unknown
    }
  }
  EXPECT_EQ(driven, 2);
  EXPECT_EQ(beside, 1);
  // The two lanelets of the driven lane follow each other: they share the cut nodes.
  std::vector<const Osm::Relation*> chain;
  for (const auto& [id, r] : osm.relations) {
    if (r.tags.at("one_way") == "yes") chain.push_back(&r);
  }
  const Osm::Way& first_right = osm.ways.at(chain[0]->right);
  const Osm::Way& second_right = osm.ways.at(chain[1]->right);
  EXPECT_EQ(first_right.nodes.back(), second_right.nodes.front());
  EXPECT_EQ(osm.ways.at(chain[0]->left).nodes.back(), osm.ways.at(chain[1]->left).nodes.front());
  // The middle line's second piece is the left bound of one lane and the right of the other.
  EXPECT_EQ(chain[1]->left, [&] {
    for (const auto& [id, r] : osm.relations) {
      if (r.tags.at("one_way") == "no") return r.right;
    }
    return std::uint64_t{0};
  }());
}

TEST(Lanelet2Export, LineAndMarkingTags) {
  const Osm osm = Parse(VectorMapToLanelet2Osm(ThreeLaneMap(), Munich()));
  std::map<std::string, int> lines;
  const Osm::Way* arrow = nullptr;
  const Osm::Way* stop = nullptr;
  const Osm::Way* stripe = nullptr;
  for (const auto& [id, w] : osm.ways) {
    if (w.tags.at("irm:id") == "10") arrow = &w;
    if (w.tags.at("irm:id") == "11") stop = &w;
    if (w.tags.at("irm:id") == "12") stripe = &w;
    if (w.tags.count("type") && w.tags.at("type") == "line_thin") {
      ++lines[w.tags.at("subtype")];
    }
  }
  EXPECT_EQ(lines["solid"], 3);   // line 1 in two pieces, line 3 in one
  EXPECT_EQ(lines["dashed"], 2);  // the middle line in two pieces
  ASSERT_NE(arrow, nullptr);
  EXPECT_EQ(arrow->tags.at("type"), "arrow");
  EXPECT_EQ(arrow->tags.at("subtype"), "left");
  EXPECT_EQ(arrow->nodes.size(), 5u);
  EXPECT_EQ(arrow->nodes.front(), arrow->nodes.back());  // closed outline
  EXPECT_EQ(arrow->tags.count("irm:complete"), 0u);
  ASSERT_NE(stop, nullptr);
  EXPECT_EQ(stop->tags.at("type"), "stop_line");
  ASSERT_EQ(stop->nodes.size(), 2u);  // its center line, across the lane
  EXPECT_NEAR(std::stod(osm.nodes.at(stop->nodes[0]).tags.at("local_x")), 90.2, 1e-4);
  EXPECT_NEAR(std::abs(std::stod(osm.nodes.at(stop->nodes[0]).tags.at("local_y"))), 1.75, 1e-4);
  ASSERT_NE(stripe, nullptr);
  EXPECT_EQ(stripe->tags.at("type"), "road_marking");
  EXPECT_EQ(stripe->tags.at("subtype"), "crosswalk_stripe &amp; co");  // escaped in the XML
  EXPECT_EQ(stripe->tags.at("irm:complete"), "no");
}

// The middle line's control points 8-10 (x 40-50 m) were laid by a join: its nodes from the
// last measured control point before them (x 35 m) to the first after (55 m) carry
// irm:measured = no, whichever way the line was stored; no other node does.
TEST(Lanelet2Export, NodesOfALaneStretchNoPixelMeasuredAreTagged) {
  for (const bool stored_backwards : {false, true}) {
    VectorMap map = ThreeLaneMap();
    MapLane& middle = map.lanes[1];
    if (stored_backwards) {
      std::reverse(middle.control_points_map.begin(), middle.control_points_map.end());
      middle.unmeasured = {{10, 12}};  // 21 points: 20 - 10 .. 20 - 8
    } else {
      middle.unmeasured = {{8, 10}};
    }
    const Osm osm = Parse(VectorMapToLanelet2Osm(map, Munich()));
    int tagged = 0;
    for (const auto& [id, w] : osm.ways) {
      if (!w.tags.count("type") || w.tags.at("type") != "line_thin") continue;
      const bool is_middle = w.tags.at("irm:id") == "2";
      for (std::uint64_t n : w.nodes) {
        const Osm::Node& node = osm.nodes.at(n);
        const double x = std::stod(node.tags.at("local_x"));
        const bool flagged = node.tags.count("irm:measured") > 0;
        if (flagged) {
          EXPECT_EQ(node.tags.at("irm:measured"), "no");
          ++tagged;
        }
        if (!is_middle || x < 34.9 || x > 55.1) {
          EXPECT_FALSE(flagged) << "line " << w.tags.at("irm:id") << " x " << x;
        } else if (x > 35.1 && x < 54.9) {
          EXPECT_TRUE(flagged) << "x " << x << " backwards " << stored_backwards;
        }
      }
    }
    EXPECT_GE(tagged, 38) << stored_backwards;  // 20 m every 0.5 m
  }
}

TEST(Lanelet2Export, NodesAreOnWgs84AtTheirMapFrameMetres) {
  const GeoOrigin origin = Munich();
  const Osm osm = Parse(VectorMapToLanelet2Osm(ThreeLaneMap(), origin));
  const GeographicLib::LocalCartesian local(origin.latitude_deg, origin.longitude_deg,
                                            origin.altitude_m);
  for (const auto& [id, n] : osm.nodes) {
    double x = 0, y = 0, z = 0;
    local.Forward(n.lat, n.lon, std::stod(n.tags.at("ele")), x, y, z);
    EXPECT_NEAR(x, std::stod(n.tags.at("local_x")), 2e-4) << id;
    EXPECT_NEAR(y, std::stod(n.tags.at("local_y")), 2e-4) << id;
  }
}

TEST(Lanelet2Export, AnEmptyMapIsAnEmptyDocumentAndTheFileIsWritten) {
  const Osm osm = Parse(VectorMapToLanelet2Osm(VectorMap(), Munich()));
  EXPECT_TRUE(osm.nodes.empty() && osm.ways.empty() && osm.relations.empty());
  const std::string dir = std::filesystem::temp_directory_path() / "irm_lanelet2_export_test";
  std::filesystem::create_directories(dir);
  SaveLanelet2Osm(ThreeLaneMap(), Munich(), dir + "/map.osm");
  std::ifstream in(dir + "/map.osm");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(Parse(text).relations.size(), 3u);
  EXPECT_THROW(SaveLanelet2Osm(ThreeLaneMap(), Munich(), dir + "/missing/map.osm"),
               std::runtime_error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ipm_road_mapper

// VectorMap <-> msg round trip, Path trimming, and the marker builder: one marker per
// element and kind, closed marking outlines, class colors, DELETE for vanished elements.
#include <gtest/gtest.h>

#include <set>

#include "ipm_road_mapper/ros/marker_builder.h"
#include "ipm_road_mapper/ros/vector_map_conversion.h"

namespace ipm_road_mapper {
namespace {

using visualization_msgs::Marker;

VectorMap SomeMap() {
  VectorMap map;
  MapMarking m;
  m.id = 11;
  m.class_id = 10;
  m.class_name = "arrow_straight";
  m.corners_map = {Eigen::Vector3d(10, -0.6, 0.1), Eigen::Vector3d(13, -0.6, 0.1),
                   Eigen::Vector3d(13, 0.6, 0.12), Eigen::Vector3d(10, 0.6, 0.12)};
  m.observations = 5;
  m.sides_measured = {true, true, false, true};  // extent not closed on one side
  m.first_seen = 1000.25;
  m.last_seen = 1001.5;
  map.markings.push_back(m);
  MapLane lane;
  lane.id = 4;
  lane.class_id = 3;
  lane.class_name = "lane_yellow_solid";
  lane.style = "solid";
  for (int i = 0; i < 6; ++i) lane.control_points_map.emplace_back(3.0 * i - 3.0, 1.7, 0.01 * i);
  lane.observations = 9;
  lane.first_seen = 1000.0;
  lane.last_seen = 1002.0;
  lane.predecessors = {2};
  lane.successors = {7, 9};    // a fork
  lane.unmeasured = {{1, 2}};  // laid by a join
  map.lanes.push_back(lane);
  map.T_base_cam.linear() = RotationFromRpy(-1.6, 0.05, -1.55);
  map.T_base_cam.translation() = Eigen::Vector3d(1.5, 0.02, 1.45);
  map.T_base_cam_covariance = Eigen::Matrix<double, 6, 6>::Identity() * 1e-4;
  map.T_base_cam_covariance(1, 5) = map.T_base_cam_covariance(5, 1) = -3e-5;  // pitch-height
  map.T_base_cam_observed = {true, true, true, false, false, true};
  for (int i = 0; i < 10; ++i) {
    StampedPose pose;
    pose.stamp = 1000.0 + 0.1 * i;
    pose.T_map_base.translation() = Eigen::Vector3d(i, 0.1 * i, 0.0);
    map.trajectory.push_back(pose);
  }
  return map;
}

TEST(VectorMapConversion, RoundTripKeepsEveryField) {
  const VectorMap map = SomeMap();
  const auto msg = ToVectorMapMsg(map, "odom", ros::Time(1002.0));
  EXPECT_EQ(msg.header.frame_id, "odom");
  EXPECT_EQ(msg.header.stamp, ros::Time(1002.0));
  ASSERT_EQ(msg.markings.size(), 1u);
  ASSERT_EQ(msg.lanes.size(), 1u);
  EXPECT_EQ(msg.lanes[0].control_points.size(), 6u);
  EXPECT_DOUBLE_EQ(msg.markings[0].corners[2].y, 0.6);

  EXPECT_DOUBLE_EQ(msg.base_to_camera_covariance[6 * 1 + 5], -3e-5);  // row-major
  EXPECT_FALSE(msg.base_to_camera_observed[3]);
  const VectorMap back = FromVectorMapMsg(msg);
  EXPECT_EQ(back.frame_id, "odom");
  EXPECT_EQ(back.T_base_cam_covariance, map.T_base_cam_covariance);
  EXPECT_EQ(back.T_base_cam_observed, map.T_base_cam_observed);
  ASSERT_EQ(back.markings.size(), 1u);
  EXPECT_EQ(back.markings[0].id, 11u);
  EXPECT_EQ(back.markings[0].class_name, "arrow_straight");
  EXPECT_EQ(back.markings[0].observations, 5);
  EXPECT_FALSE(msg.markings[0].complete);
  EXPECT_FALSE(msg.markings[0].sides_measured[2]);
  EXPECT_EQ(back.markings[0].sides_measured, map.markings[0].sides_measured);
  EXPECT_NEAR(back.markings[0].first_seen, 1000.25, 1e-9);
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(back.markings[0].corners_map[i].isApprox(map.markings[0].corners_map[i]));
  }
  ASSERT_EQ(back.lanes.size(), 1u);
  EXPECT_EQ(back.lanes[0].style, "solid");
  EXPECT_EQ(back.lanes[0].control_points_map.size(), 6u);
  EXPECT_TRUE(back.lanes[0].control_points_map[5].isApprox(map.lanes[0].control_points_map[5]));
  EXPECT_EQ(msg.lanes[0].successors, (std::vector<std::uint64_t>{7, 9}));
  EXPECT_EQ(back.lanes[0].predecessors, (std::vector<std::uint64_t>{2}));
  EXPECT_EQ(back.lanes[0].successors, (std::vector<std::uint64_t>{7, 9}));
  EXPECT_EQ(msg.lanes[0].unmeasured, (std::vector<std::uint8_t>{0, 1, 1, 0, 0, 0}));
  EXPECT_EQ(back.lanes[0].unmeasured, map.lanes[0].unmeasured);
  EXPECT_TRUE(back.T_base_cam.isApprox(map.T_base_cam, 1e-9));
  // A patch carries the flags of its own points, none when none of them is unmeasured.
  EXPECT_EQ(ToLanePatchMsg(map.lanes[0], 2).unmeasured, (std::vector<std::uint8_t>{1, 0, 0, 0}));
  EXPECT_TRUE(ToLanePatchMsg(map.lanes[0], 3).unmeasured.empty());
  VectorMap measured = map;
  measured.lanes[0].unmeasured.clear();
  EXPECT_TRUE(ToVectorMapMsg(measured, "map", ros::Time(1.0)).lanes[0].unmeasured.empty());
}

TEST(VectorMapConversion, UnknownStyleAndBadStampsAreSafe) {
  VectorMap map = SomeMap();
  map.lanes[0].style = "";
  map.markings[0].first_seen = -5.0;  // ros::Time would throw on a negative stamp
  map.markings[0].last_seen = std::nan("");
  const auto msg = ToVectorMapMsg(map, "map", ros::Time(1.0));
  EXPECT_EQ(msg.lanes[0].style, "unknown");
  EXPECT_EQ(msg.markings[0].first_seen, ros::Time(0));
  EXPECT_EQ(msg.markings[0].last_seen, ros::Time(0));
  EXPECT_EQ(FromVectorMapMsg(msg).lanes[0].style, "");
}

TEST(VectorMapConversion, PathKeepsTheNewestPoses) {
  const VectorMap map = SomeMap();
  const nav_msgs::Path all = ToPathMsg(map.trajectory, "odom", 0, ros::Time(5.0));
  ASSERT_EQ(all.poses.size(), 10u);
  EXPECT_EQ(all.header.frame_id, "odom");
  EXPECT_NEAR(all.header.stamp.toSec(), 1000.9, 1e-6);
  const nav_msgs::Path last = ToPathMsg(map.trajectory, "odom", 3, ros::Time(5.0));
  ASSERT_EQ(last.poses.size(), 3u);
  EXPECT_DOUBLE_EQ(last.poses[0].pose.position.x, 7.0);
  EXPECT_EQ(last.poses[2].header.frame_id, "odom");
  EXPECT_EQ(ToPathMsg({}, "odom", 3, ros::Time(5.0)).header.stamp, ros::Time(5.0));
}

std::set<std::string> NamespacesOf(const visualization_msgs::MarkerArray& array, int action) {
  std::set<std::string> ns;
  for (const Marker& m : array.markers) {
    if (m.action == action) ns.insert(m.ns);
  }
  return ns;
}

TEST(MarkerBuilder, OneMarkerPerElementAndKind) {
  MarkerBuilder builder;
  const auto array = builder.Build(SomeMap(), "odom", ros::Time(3.0));
  ASSERT_EQ(array.markers.size(), 4u);
  EXPECT_EQ(NamespacesOf(array, Marker::ADD),
            (std::set<std::string>{"lanes", "lane_control_points", "markings", "marking_labels"}));
  for (const Marker& m : array.markers) {
    EXPECT_EQ(m.header.frame_id, "odom");
    EXPECT_DOUBLE_EQ(m.pose.orientation.w, 1.0);
    EXPECT_GT(m.color.a, 0.0f);
    if (m.ns == "markings") {
      EXPECT_EQ(m.type, Marker::LINE_STRIP);
      ASSERT_EQ(m.points.size(), 5u);  // closed
      EXPECT_EQ(m.points.front().x, m.points.back().x);
      EXPECT_EQ(m.id, 11);
    } else if (m.ns == "lanes") {
      EXPECT_EQ(m.type, Marker::LINE_STRIP);
      // The curve runs from c_1 (x = 0) to c_4 (x = 9), a little over 9 m (z rises):
      // samples every 0.5 m, then the end point.
      EXPECT_EQ(m.points.size(), 20u);
      EXPECT_NEAR(m.points.front().x, 0.0, 1e-9);
      EXPECT_NEAR(m.points.back().x, 9.0, 1e-9);
      EXPECT_FLOAT_EQ(m.color.r, 1.0f);  // yellow
      EXPECT_LT(m.color.b, 0.5f);
    } else if (m.ns == "lane_control_points") {
      EXPECT_EQ(m.type, Marker::SPHERE_LIST);
      EXPECT_EQ(m.points.size(), 6u);
    } else {
      EXPECT_EQ(m.type, Marker::TEXT_VIEW_FACING);
      EXPECT_EQ(m.text, "arrow_straight");
      EXPECT_NEAR(m.pose.position.x, 11.5, 1e-9);
    }
  }
}

TEST(MarkerBuilder, VanishedElementsAreDeleted) {
  MarkerBuilder builder;
  VectorMap map = SomeMap();
  builder.Build(map, "odom", ros::Time(3.0));
  map.markings.clear();  // e.g. dropped as spurious
  const auto array = builder.Build(map, "odom", ros::Time(4.0));
  EXPECT_EQ(NamespacesOf(array, Marker::DELETE),
            (std::set<std::string>{"markings", "marking_labels"}));
  for (const Marker& m : array.markers) {
    if (m.action == Marker::DELETE) {
      EXPECT_EQ(m.id, 11);
    }
  }
  // Deleted once: the next build has nothing to delete.
  EXPECT_TRUE(NamespacesOf(builder.Build(map, "odom", ros::Time(5.0)), Marker::DELETE).empty());
  const auto cleared = builder.Clear();
  ASSERT_EQ(cleared.markers.size(), 1u);
  EXPECT_EQ(cleared.markers[0].action, Marker::DELETEALL);
  // After a clear, nothing is remembered.
  EXPECT_TRUE(
      NamespacesOf(builder.Build(VectorMap(), "odom", ros::Time(6.0)), Marker::DELETE).empty());
}

TEST(MarkerBuilder, ChangesModeSendsOnlyWhatChanged) {
  using Mode = MarkerBuilder::Mode;
  MarkerBuilder builder;
  VectorMap map = SomeMap();
  EXPECT_EQ(builder.Build(map, "odom", ros::Time(1.0), Mode::kChanges).markers.size(), 4u);
  // Nothing changed: nothing to send.
  EXPECT_TRUE(builder.Build(map, "odom", ros::Time(2.0), Mode::kChanges).markers.empty());
  // A moved marking and a new lane: just their markers, with stable ids.
  map.markings[0].corners_map[0].x() += 0.2;
  MapLane second = map.lanes[0];
  second.id = 5;
  map.lanes.push_back(second);
  const auto changes = builder.Build(map, "odom", ros::Time(3.0), Mode::kChanges);
  ASSERT_EQ(changes.markers.size(), 4u);
  for (const Marker& m : changes.markers) {
    EXPECT_EQ(m.action, Marker::ADD);
    EXPECT_EQ(m.id, m.ns.rfind("mark", 0) == 0 ? 11 : LaneChunkMarkerId(5, 0)) << m.ns;
  }
  // A lane's class changes (re-colored), the other lane leaves the map.
  map.lanes[1].class_id = 7;
  map.lanes.erase(map.lanes.begin());
  const auto after = builder.Build(map, "odom", ros::Time(4.0), Mode::kChanges);
  EXPECT_EQ(NamespacesOf(after, Marker::DELETE),
            (std::set<std::string>{"lanes", "lane_control_points"}));
  EXPECT_EQ(NamespacesOf(after, Marker::ADD),
            (std::set<std::string>{"lanes", "lane_control_points"}));
  for (const Marker& m : after.markers) {
    EXPECT_EQ(m.id, LaneChunkMarkerId(m.action == Marker::DELETE ? 4 : 5, 0));
  }
  // kFull re-sends every element, with no DELETE for what is still there.
  const auto full = builder.Build(map, "odom", ros::Time(5.0), Mode::kFull);
  EXPECT_EQ(full.markers.size(), 4u);
  EXPECT_TRUE(NamespacesOf(full, Marker::DELETE).empty());
}

TEST(MarkerBuilder, ColorsAreStablePerClassAndDistinct) {
  const auto a = ClassColor(10, "arrow_straight");
  const auto b = ClassColor(11, "arrow_left");
  EXPECT_EQ(a.r, ClassColor(10, "arrow_straight").r);
  EXPECT_FALSE(a.r == b.r && a.g == b.g && a.b == b.b);
  const auto white = ClassColor(1, "lane_white_solid");
  EXPECT_GT(white.r, 0.9f);
  EXPECT_GT(white.b, 0.9f);
}

}  // namespace
}  // namespace ipm_road_mapper

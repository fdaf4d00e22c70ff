// Hostile map and ground-truth files: each must fail with a one-line MapFormatError that
// names the file and the JSON path, in well under a second (json_limits.h).
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"
#include "ipm_road_mapper/core/io/ground_truth.h"
#include "ipm_road_mapper/core/io/json_limits.h"
#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {
namespace {

namespace fs = std::filesystem;

// A fresh temporary folder per test, removed afterwards.
class JsonLimitsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/irm_json_limits_XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Writes `text` to <dir>/<name> and returns the path.
  std::string Write(const std::string& name, const std::string& text) const {
    const std::string path = dir_ + "/" + name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }

  // Loading `text` as a map (or ground truth) throws a one-line MapFormatError starting with
  // the file name and containing `expected`, within a second.
  void ExpectRejected(const std::string& text, const std::string& expected,
                      bool ground_truth = false) const {
    const std::string path = Write(ground_truth ? "ground_truth.json" : "map.json", text);
    const auto start = std::chrono::steady_clock::now();
    try {
      if (ground_truth) {
        LoadGroundTruthJson(path);
      } else {
        LoadVectorMapJson(path);
      }
      ADD_FAILURE() << "accepted; expected: " << expected;
    } catch (const MapFormatError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
      EXPECT_NE(what.find(expected), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_LT(seconds, 1.0) << expected;
  }

  std::string dir_;
};

VectorMap SmallMap() {
  VectorMap map;
  MapMarking marking;
  marking.id = 1;
  marking.class_id = 10;
  marking.corners_map = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                         Eigen::Vector3d(1, 1, 0), Eigen::Vector3d(0, 1, 0)};
  map.markings.push_back(marking);
  MapLane lane;
  lane.id = 2;
  lane.class_id = 1;
  for (int k = 0; k < 6; ++k) lane.control_points_map.emplace_back(3.0 * k, 2.0, 0.0);
  map.lanes.push_back(lane);
  map.trajectory.push_back({100.0, Eigen::Isometry3d::Identity()});
  return map;
}

// The small map's JSON with `mutate` applied, as text.
template <typename Mutate>
std::string MutatedMap(Mutate mutate) {
  nlohmann::json j = VectorMapToJson(SmallMap());
  mutate(j);
  return j.dump();
}

GroundTruth SmallGroundTruth() {
  GroundTruth gt;
  gt.scenario = "tiny";
  gt.camera = {640, 480, 500.0, 500.0, 320.0, 240.0, {0, 0, 0, 0, 0}};
  GroundTruthLane lane;
  lane.id = 1;
  lane.points_map = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(10, 0, 0)};
  gt.lanes.push_back(lane);
  gt.frames.push_back({100.0, Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity()});
  return gt;
}

// The small ground truth's text (as SaveGroundTruthJson writes it) passed through `edit`.
std::string GroundTruthText(const std::string& dir) {
  const std::string path = dir + "/source_gt.json";
  SaveGroundTruthJson(SmallGroundTruth(), path);
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// `levels` nested objects {"a": {"a": ... 1 ...}} as text, built without recursion.
std::string DeepObject(int levels) {
  std::string text;
  text.reserve(6 * levels + 1);
  for (int k = 0; k < levels; ++k) text += "{\"a\":";
  text += "1";
  text.append(levels, '}');
  return text;
}

TEST_F(JsonLimitsTest, TheSmallFilesLoad) {
  const std::string map_path = Write("map.json", MutatedMap([](nlohmann::json&) {}));
  EXPECT_NO_THROW(LoadVectorMapJson(map_path));
  EXPECT_NO_THROW(LoadGroundTruthJson(Write("gt.json", GroundTruthText(dir_))));
}

TEST_F(JsonLimitsTest, DeepNestingFailsBeforeTheParse) {
  // 200,000 levels under metadata (0.5 MB+): this overflowed the stack in the recursive copy.
  std::string text = MutatedMap([](nlohmann::json& j) { j["metadata"] = 0; });
  const std::size_t at = text.find("\"metadata\":0");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 12, "\"metadata\":" + DeepObject(200000));
  ExpectRejected(text, "metadata.a.a.a");
  ExpectRejected(text, "nesting deeper than 64 levels");
  ExpectRejected(std::string(300000, '['), "[0][0][0]");  // also deep at the root
  ExpectRejected(std::string(300000, '['), "nesting deeper than 64 levels", true);
  // Within the limit it still loads.
  text = MutatedMap([](nlohmann::json& j) { j["metadata"] = 0; });
  text.replace(text.find("\"metadata\":0"), 12, "\"metadata\":" + DeepObject(40));
  EXPECT_NO_THROW(LoadVectorMapJson(Write("ok.json", text)));
}

TEST_F(JsonLimitsTest, DeepMetadataInMemoryIsRejectedToo) {
  nlohmann::json j = VectorMapToJson(SmallMap());
  nlohmann::json deep = 1;
  for (int k = 0; k < 100; ++k) deep = nlohmann::json{{"a", std::move(deep)}};
  j["metadata"] = std::move(deep);
  try {
    VectorMapFromJson(j);
    ADD_FAILURE() << "deep metadata accepted";
  } catch (const MapFormatError& e) {
    EXPECT_NE(std::string(e.what()).find("metadata: nesting deeper than"), std::string::npos)
        << e.what();
  }
}

TEST_F(JsonLimitsTest, CoordinatesBeyondTheBoundAreRejected) {
  ExpectRejected(MutatedMap([](nlohmann::json& j) {
                   j["lanes"][0]["control_points"][3] = {1e8, 0.0, 0.0};
                 }),
                 "lanes[0].control_points[3]: coordinate 1e+08 m beyond the 1e7 m bound");
  ExpectRejected(MutatedMap([](nlohmann::json& j) {
                   j["markings"][0]["corners"][2] = {0.0, -8e6, 8e6};
                 }),
                 "markings[0].corners[2]: coordinate 1.13137e+07 m beyond the 1e7 m bound");
  ExpectRejected(MutatedMap([](nlohmann::json& j) {
                   j["trajectory"][0]["t"] = {0, 0, 1e300};
                 }),
                 "trajectory[0].t: coordinate 1e+300 m");
  ExpectRejected(MutatedMap([](nlohmann::json& j) {
                   j["T_base_cam"]["t"] = {2e7, 0, 0};
                 }),
                 "T_base_cam.t: coordinate 2e+07 m");
  std::string gt = GroundTruthText(dir_);
  gt.replace(gt.find("10.0"), 4, "-1e9");  // the lane's second point
  ExpectRejected(gt, "lanes[0].points[1]: coordinate 1e+09 m beyond the 1e7 m bound", true);
  // 9.9e6 m is inside the bound.
  EXPECT_NO_THROW(LoadVectorMapJson(Write("far.json", MutatedMap([](nlohmann::json& j) {
                                            j["markings"][0]["corners"][0] = {9.9e6, 0, 0};
                                          }))));
}

TEST_F(JsonLimitsTest, NumbersBeyondDoubleAndNonFiniteNumbersAreCleanErrors) {
  std::string text = MutatedMap([](nlohmann::json& j) { j["markings"][0]["first_seen"] = 7; });
  text.replace(text.find("\"first_seen\":7"), 14, "\"first_seen\":1e999");
  ExpectRejected(text, "not valid JSON");
  ExpectRejected(text, "1e999");
  for (const char* literal : {"NaN", "nan", "Infinity", "-Infinity", "inf"}) {
    std::string bad = MutatedMap([](nlohmann::json& j) { j["markings"][0]["first_seen"] = 7; });
    bad.replace(bad.find("\"first_seen\":7"), 14, std::string("\"first_seen\":") + literal);
    ExpectRejected(bad, "not valid JSON");
  }
  // null is how nlohmann writes NaN: a clean error with the path.
  ExpectRejected(MutatedMap([](nlohmann::json& j) { j["markings"][0]["first_seen"] = nullptr; }),
                 "markings[0].first_seen: expected a finite number, got null");
  std::string gt = GroundTruthText(dir_);
  gt.replace(gt.find("\"frame_rate_hz\": 20"), 19, "\"frame_rate_hz\": -1e400");
  ExpectRejected(gt, "not valid JSON", true);
}

TEST_F(JsonLimitsTest, WrongTypesNameThePath) {
  ExpectRejected(MutatedMap([](nlohmann::json& j) {
                   j["lanes"] = {{"id", 1}};
                 }),
                 "lanes: expected an array, got a object");
  ExpectRejected(MutatedMap([](nlohmann::json& j) { j["lanes"][0]["id"] = "two"; }),
                 "lanes[0].id: expected a non-negative integer, got a string");
  ExpectRejected(MutatedMap([](nlohmann::json& j) { j["lanes"][0]["control_points"][1] = "x"; }),
                 "lanes[0].control_points[1]: expected [x, y, z]");
  ExpectRejected(MutatedMap([](nlohmann::json& j) { j["markings"][0]["class_id"] = 1.5; }),
                 "markings[0].class_id: expected an integer");
  ExpectRejected(MutatedMap([](nlohmann::json& j) { j["metadata"] = nlohmann::json::array(); }),
                 "metadata: expected an object");
  ExpectRejected(MutatedMap([](nlohmann::json& j) { j["trajectory"][0] = true; }),
                 "trajectory[0]: expected an object, got a boolean");
  std::string gt = GroundTruthText(dir_);
  gt.replace(gt.find("\"scenario\": \"tiny\""), 18, "\"scenario\": [1]");
  ExpectRejected(gt, "scenario: expected a string, got a array", true);
}

TEST_F(JsonLimitsTest, MissingKeysAndTruncatedFilesNameThePath) {
  ExpectRejected(MutatedMap([](nlohmann::json& j) { j.erase("lanes"); }), "lanes: missing");
  ExpectRejected(MutatedMap([](nlohmann::json& j) { j["markings"][0].erase("corners"); }),
                 "markings[0].corners: missing");
  const std::string gt = GroundTruthText(dir_);
  nlohmann::json gt_json = nlohmann::json::parse(gt);
  gt_json.erase("frames");
  ExpectRejected(gt_json.dump(), "frames: missing", true);
  gt_json = nlohmann::json::parse(gt);
  gt_json["camera"].erase("fx");
  ExpectRejected(gt_json.dump(), "camera.fx: missing", true);
  for (const std::size_t cut : {std::size_t{1}, gt.size() / 3, gt.size() - 3}) {
    ExpectRejected(gt.substr(0, cut), "not valid JSON", true);
  }
  const std::string map = MutatedMap([](nlohmann::json&) {});
  ExpectRejected(map.substr(0, map.size() - 1), "not valid JSON");
}

TEST_F(JsonLimitsTest, HugeArraysAreRejected) {
  // More markings than the format allows: refused by count, not by converting them first.
  std::string markings = "[";
  for (std::size_t k = 0; k <= json_limits::kMaxMarkings; ++k) markings += k ? ",0" : "0";
  markings += "]";
  std::string text = MutatedMap([](nlohmann::json& j) { j["markings"] = 0; });
  text.replace(text.find("\"markings\":0"), 12, "\"markings\":" + markings);
  ExpectRejected(text, "markings: 100001 elements, more than the 100000 allowed");
  // One array beyond the container limit is refused by the pre-parse scan.
  std::string big = "{\"format\":[";
  big.reserve(2 * json_limits::kMaxContainerElements + 16);
  for (std::size_t k = 0; k <= json_limits::kMaxContainerElements; ++k) big += k ? ",0" : "0";
  big += "]}";
  ExpectRejected(big, "format: more than 10000000 elements in one array or object");
  // Control points of one lane.
  ExpectRejected(MutatedMap([](nlohmann::json& j) {
                   auto& points = j["lanes"][0]["control_points"];
                   while (points.size() <= json_limits::kMaxControlPointsPerLane) {
                     points.push_back({1.0, 2.0, 0.0});
                   }
                 }),
                 "lanes[0].control_points: 10001 elements, more than the 10000 allowed");
}

TEST_F(JsonLimitsTest, AbsurdCameraSizesInTheGroundTruthAreRejected) {
  nlohmann::json gt = nlohmann::json::parse(GroundTruthText(dir_));
  gt["camera"]["width"] = 2000000000;
  ExpectRejected(gt.dump(), "camera.width: 2000000000 px is outside [1, 16384]", true);
}

TEST(CatmullRomSplineLimits, SamplingAHugeCurveIsBoundedInsteadOfOverflowing) {
  // 3e8 m at 0.1 m would be 3e9 samples: an int overflow before the bound.
  const CatmullRomSpline spline({Eigen::Vector3d(-1e8, 0, 0), Eigen::Vector3d(0, 0, 0),
                                 Eigen::Vector3d(3e8, 0, 0), Eigen::Vector3d(4e8, 0, 0)});
  const auto start = std::chrono::steady_clock::now();
  const std::vector<Eigen::Vector3d> samples = spline.SampleByArcLength(0.1);
  EXPECT_EQ(samples.size(), static_cast<std::size_t>(CatmullRomSpline::kMaxArcLengthSamples) + 1);
  EXPECT_LT((samples.back() - Eigen::Vector3d(3e8, 0, 0)).norm(), 1e-3);
  // About 3 s for the 10^6 samples: bounded (the unbounded loop would never end).
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 30.0);
  const CatmullRomSpline infinite({Eigen::Vector3d(-1e308, 0, 0), Eigen::Vector3d(0, 0, 0),
                                   Eigen::Vector3d(1e308, 0, 0), Eigen::Vector3d(1.7e308, 0, 0)});
  EXPECT_THROW(infinite.SampleByArcLength(0.1), std::invalid_argument);
}

}  // namespace
}  // namespace ipm_road_mapper

// Tests of the option readers: OptionsReader (key paths in every error), the mapper
// options (ipm section, degrees -> radians) and the class table, including loading the
// shipped config/mapper.yaml and config/classes.yaml.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "ipm_road_mapper/core/frontend/class_table.h"
#include "ipm_road_mapper/core/io/yaml_options.h"
#include "ipm_road_mapper/core/mapper/mapper_options.h"

namespace ipm_road_mapper {
namespace {

constexpr double kDeg = M_PI / 180.0;
const std::string kConfigDir = std::string(IRM_SOURCE_DIR) + "/config";

OptionsReader ReaderOf(const std::string& yaml) { return OptionsReader(YAML::Load(yaml), ""); }

// The message of the OptionsError thrown by `f` ("" and a test failure when none is thrown).
std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const OptionsError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected OptionsError, got another exception: " << e.what();
    return e.what();
  }
  ADD_FAILURE() << "expected OptionsError, nothing was thrown";
  return "";
}

bool StartsWith(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

// ---------------------------------------------------------------------------------------
// OptionsReader
// ---------------------------------------------------------------------------------------

TEST(OptionsReader, ReadsValuesAndKeepsDefaultsForAbsentKeys) {
  OptionsReader reader = ReaderOf("a: 2.5\nb: 7\nname: hello\nlist: [1.0, 2.0]\nflag: true");
  double a = 0.0, absent = 42.0;
  int b = 0;
  std::string name;
  std::vector<double> list;
  bool flag = false;
  reader.Read("a", &a);
  reader.Read("b", &b);
  reader.Read("name", &name);
  reader.Read("list", &list);
  reader.Read("flag", &flag);
  reader.Read("absent", &absent);
  EXPECT_EQ(a, 2.5);
  EXPECT_EQ(b, 7);
  EXPECT_EQ(name, "hello");
  EXPECT_EQ(list, (std::vector<double>{1.0, 2.0}));
  EXPECT_TRUE(flag);
  EXPECT_EQ(absent, 42.0);
  EXPECT_TRUE(reader.Has("a"));
  EXPECT_FALSE(reader.Has("absent"));
  reader.RejectUnknownKeys();  // every key was read: no throw
}

TEST(OptionsReader, UnknownKeyErrorNamesTheFullKeyPath) {
  OptionsReader root = ReaderOf("outer:\n  inner:\n    known: 1\n    typo_key: 2\n");
  OptionsReader outer = root.Child("outer");
  OptionsReader inner = outer.Child("inner");
  int known = 0;
  inner.Read("known", &known);
  EXPECT_EQ(ErrorOf([&] { inner.RejectUnknownKeys(); }), "outer.inner.typo_key: unknown key");
  outer.RejectUnknownKeys();
  root.RejectUnknownKeys();

  OptionsReader top = ReaderOf("a: 1\nb: 2");
  int a = 0;
  top.Read("a", &a);
  EXPECT_EQ(ErrorOf([&] { top.RejectUnknownKeys(); }), "b: unknown key");
}

TEST(OptionsReader, WrongTypeNamesTheKeyPath) {
  OptionsReader root = ReaderOf("section: {number: abc, count: 2.5, list: 3, text: [1, 2]}");
  OptionsReader section = root.Child("section");
  double number = 1.0;
  int count = 1;
  std::vector<double> list;
  std::string text;
  EXPECT_TRUE(
      StartsWith(ErrorOf([&] { section.Read("number", &number); }), "section.number: wrong type"));
  EXPECT_EQ(number, 1.0);
  EXPECT_TRUE(
      StartsWith(ErrorOf([&] { section.Read("count", &count); }), "section.count: wrong type"));
  EXPECT_TRUE(
      StartsWith(ErrorOf([&] { section.Read("list", &list); }), "section.list: wrong type"));
  EXPECT_TRUE(
      StartsWith(ErrorOf([&] { section.Read("text", &text); }), "section.text: wrong type"));
}

TEST(OptionsReader, FailedCheckGivesKeyPathAndReason) {
  OptionsReader root = ReaderOf("ipm: {max_range_m: -3}");
  OptionsReader ipm = root.Child("ipm");
  double range = 40.0;
  EXPECT_EQ(ErrorOf([&] { ipm.Read("max_range_m", &range, CheckPositive); }),
            "ipm.max_range_m: must be > 0 (got -3)");
}

TEST(OptionsReader, RequiredKeyMissing) {
  OptionsReader root = ReaderOf("section: {present: 1}");
  OptionsReader section = root.Child("section");
  int value = 0;
  EXPECT_EQ(ErrorOf([&] { section.ReadRequired("missing", &value); }),
            "section.missing: required key is missing");
  section.ReadRequired("present", &value);
  EXPECT_EQ(value, 1);
}

TEST(OptionsReader, ChildMustBeAMapAndMayBeAbsent) {
  OptionsReader root = ReaderOf("scalar: 3\nlist: [1, 2]");
  EXPECT_EQ(ErrorOf([&] { root.Child("scalar"); }), "scalar: must be a map");
  EXPECT_EQ(ErrorOf([&] { root.Child("list"); }), "list: must be a map");
  OptionsReader absent = root.Child("absent");
  double d = 5.0;
  absent.Read("x", &d);
  EXPECT_EQ(d, 5.0);
  absent.RejectUnknownKeys();
  EXPECT_EQ(absent.path(), "absent");
  EXPECT_EQ(ErrorOf([] { ReaderOf("- 1\n- 2"); }), "<root>: must be a map");
}

TEST(OptionsReader, RawMarksKeyUsed) {
  OptionsReader root = ReaderOf("entries: [{a: 1}, {a: 2}]");
  const YAML::Node entries = root.Raw("entries");
  ASSERT_TRUE(entries.IsSequence());
  EXPECT_EQ(entries.size(), 2u);
  root.RejectUnknownKeys();
  const YAML::Node absent = root.Raw("absent");  // absent: an undefined or null node
  EXPECT_TRUE(!absent || absent.IsNull());
}

TEST(OptionsReader, FromFileErrorsNameTheFile) {
  const std::string missing = "/nonexistent/dir/options.yaml";
  const std::string error = ErrorOf([&] { OptionsReader::FromFile(missing); });
  EXPECT_NE(error.find(missing), std::string::npos) << error;
  EXPECT_NE(error.find("cannot open"), std::string::npos) << error;

  const std::string malformed = ::testing::TempDir() + "/irm_malformed.yaml";
  {
    std::FILE* f = std::fopen(malformed.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("ipm: {max_range_m: [1, 2\n", f);
    std::fclose(f);
  }
  const std::string error2 = ErrorOf([&] { OptionsReader::FromFile(malformed); });
  EXPECT_NE(error2.find(malformed), std::string::npos) << error2;
  EXPECT_NE(error2.find("malformed YAML"), std::string::npos) << error2;
  std::remove(malformed.c_str());
}

TEST(OptionsChecks, AcceptAndReject) {
  EXPECT_EQ(CheckPositive(1e-9), "");
  EXPECT_NE(CheckPositive(0.0), "");
  EXPECT_NE(CheckPositive(std::nan("")), "");
  EXPECT_NE(CheckPositive(INFINITY), "");
  EXPECT_EQ(CheckNonNegative(0.0), "");
  EXPECT_NE(CheckNonNegative(-1e-9), "");
  EXPECT_NE(CheckNonNegative(std::nan("")), "");
  EXPECT_EQ(CheckPositiveInt(1), "");
  EXPECT_NE(CheckPositiveInt(0), "");
  EXPECT_EQ(CheckProbability(0.0), "");
  EXPECT_EQ(CheckProbability(1.0), "");
  EXPECT_NE(CheckProbability(1.01), "");
  EXPECT_NE(CheckProbability(-0.01), "");
  EXPECT_NE(CheckProbability(std::nan("")), "");
}

// ---------------------------------------------------------------------------------------
// Mapper options (the `ipm` section; other sections are tested with their modules)
// ---------------------------------------------------------------------------------------

TEST(IpmOptions, DefaultsWhenSectionIsEmpty) {
  const IpmOptions o = LoadIpmOptions(ReaderOf("{}"));
  EXPECT_EQ(o.max_range_m, 40.0);
  EXPECT_EQ(o.error_model.pixel_error_px, Eigen::Vector2d(2.0, 2.0));
  EXPECT_NEAR(o.error_model.pitch_sigma_rad, 0.3 * kDeg, 1e-15);
  EXPECT_EQ(o.error_model.height_sigma_m, 0.05);
}

TEST(IpmOptions, ReadsValuesAndConvertsDegreesToRadians) {
  const IpmOptions o = LoadIpmOptions(
      ReaderOf("max_range_m: 25.5\npixel_error_px: [1.5, 3.0]\npitch_sigma_deg: 0.5\n"
               "height_sigma_m: 0.08"));
  EXPECT_EQ(o.max_range_m, 25.5);
  EXPECT_EQ(o.error_model.pixel_error_px, Eigen::Vector2d(1.5, 3.0));
  EXPECT_NEAR(o.error_model.pitch_sigma_rad, 0.5 * M_PI / 180.0, 1e-15);
  EXPECT_EQ(o.error_model.height_sigma_m, 0.08);
}

TEST(IpmOptions, InvalidValuesNameTheKey) {
  auto load = [](const std::string& yaml) { return [yaml] { LoadMapperOptions(ReaderOf(yaml)); }; };
  EXPECT_EQ(ErrorOf(load("ipm: {max_range_m: 0}")), "ipm.max_range_m: must be > 0 (got 0)");
  EXPECT_EQ(ErrorOf(load("ipm: {pitch_sigma_deg: -1}")),
            "ipm.pitch_sigma_deg: must be >= 0 (got -1)");
  EXPECT_EQ(ErrorOf(load("ipm: {height_sigma_m: -0.1}")),
            "ipm.height_sigma_m: must be >= 0 (got -0.1)");
  EXPECT_EQ(ErrorOf(load("ipm: {pixel_error_px: [1, 2, 3]}")),
            "ipm.pixel_error_px: must be [du, dv]");
  EXPECT_EQ(ErrorOf(load("ipm: {pixel_error_px: [1, .nan]}")),
            "ipm.pixel_error_px: must be finite");
  EXPECT_TRUE(StartsWith(ErrorOf(load("ipm: {max_range_m: far}")), "ipm.max_range_m: wrong type"));
  EXPECT_TRUE(
      StartsWith(ErrorOf(load("ipm: {pixel_error_px: 2}")), "ipm.pixel_error_px: wrong type"));
}

TEST(MapperOptions, UnknownKeysNameTheirPath) {
  EXPECT_EQ(ErrorOf([] { LoadMapperOptions(ReaderOf("ipm: {max_rang_m: 30}")); }),
            "ipm.max_rang_m: unknown key");
  EXPECT_EQ(ErrorOf([] { LoadMapperOptions(ReaderOf("ipmm: {max_range_m: 30}")); }),
            "ipmm: unknown key");
  EXPECT_EQ(ErrorOf([] { LoadMapperOptions(ReaderOf("ipm: 3")); }), "ipm: must be a map");
}

TEST(MapperOptions, ShippedMapperYamlLoads) {
  const std::string path = kConfigDir + "/mapper.yaml";
  MapperOptions o;
  try {
    o = LoadMapperOptions(OptionsReader::FromFile(path));
  } catch (const OptionsError& e) {
    FAIL() << e.what();
  }
  // Compared with the file read independently (so editing the file does not break this).
  const YAML::Node ipm = YAML::LoadFile(path)["ipm"];
  ASSERT_TRUE(ipm.IsMap());
  if (ipm["max_range_m"]) {
    EXPECT_EQ(o.ipm.max_range_m, ipm["max_range_m"].as<double>());
  }
  if (ipm["pitch_sigma_deg"]) {
    EXPECT_NEAR(o.ipm.error_model.pitch_sigma_rad, ipm["pitch_sigma_deg"].as<double>() * kDeg,
                1e-15);
  }
  if (ipm["height_sigma_m"]) {
    EXPECT_EQ(o.ipm.error_model.height_sigma_m, ipm["height_sigma_m"].as<double>());
  }
  if (ipm["pixel_error_px"]) {
    const auto e = ipm["pixel_error_px"].as<std::vector<double>>();
    EXPECT_EQ(o.ipm.error_model.pixel_error_px, Eigen::Vector2d(e[0], e[1]));
  }
  // Sanity: the file's values are the docs/design.md §4 ones, in radians inside the code.
  EXPECT_GT(o.ipm.max_range_m, 0.0);
  EXPECT_LT(o.ipm.error_model.pitch_sigma_rad, 0.1);  // radians, not 0.3 "degrees"
  const std::string dump = ToString(o);
  EXPECT_NE(dump.find("ipm.max_range_m"), std::string::npos);
  EXPECT_NE(dump.find("ipm.pitch_sigma_deg"), std::string::npos);
}

// ---------------------------------------------------------------------------------------
// Hostile config: types, file names and bounds that cannot work
// ---------------------------------------------------------------------------------------

// Writes `yaml` to a fresh temporary file and returns its path.
std::string TempYaml(const std::string& name, const std::string& yaml) {
  const std::string path = ::testing::TempDir() + "/irm_" + name + ".yaml";
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) {
    ADD_FAILURE() << "cannot write " << path;
    return path;
  }
  std::fputs(yaml.c_str(), f);
  std::fclose(f);
  return path;
}

// The error of LoadMapperOptionsFile on a file holding `yaml`, without the "<path>: " prefix
// (which it checks is there).
std::string FileError(const std::string& name, const std::string& yaml) {
  const std::string path = TempYaml(name, yaml);
  const std::string error = ErrorOf([&] { LoadMapperOptionsFile(path); });
  std::remove(path.c_str());
  EXPECT_TRUE(StartsWith(error, path + ": ")) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  return StartsWith(error, path + ": ") ? error.substr(path.size() + 2) : error;
}

TEST(OptionsReader, WrongTypeSaysWhatWasExpectedAndWhatWasFound) {
  OptionsReader root = ReaderOf(
      "s: {number: abc, count: 2.5, list: 3, text: [1, 2], flag: {a: 1}, empty: , big: "
      "99999999999}");
  OptionsReader s = root.Child("s");
  double number = 1.0;
  int count = 1, big = 0;
  std::vector<double> list;
  std::string text;
  bool flag = false;
  EXPECT_EQ(ErrorOf([&] { s.Read("number", &number); }),
            "s.number: wrong type: expected a number, got the scalar 'abc'");
  EXPECT_EQ(ErrorOf([&] { s.Read("count", &count); }),
            "s.count: wrong type: expected an integer, got the scalar '2.5'");
  EXPECT_EQ(ErrorOf([&] { s.Read("big", &big); }),
            "s.big: wrong type: expected an integer, got the scalar '99999999999'");
  EXPECT_EQ(ErrorOf([&] { s.Read("list", &list); }),
            "s.list: wrong type: expected a sequence of numbers, got the scalar '3'");
  EXPECT_EQ(ErrorOf([&] { s.Read("text", &text); }),
            "s.text: wrong type: expected a string, got a sequence");
  EXPECT_EQ(ErrorOf([&] { s.Read("flag", &flag); }),
            "s.flag: wrong type: expected true or false, got a map");
  EXPECT_EQ(ErrorOf([&] { s.Read("empty", &number); }),
            "s.empty: wrong type: expected a number, got null");
  EXPECT_EQ(number, 1.0);
}

TEST(OptionsReader, NonScalarKeysAreOptionsErrors) {
  OptionsReader root = ReaderOf("? [a, b]\n: 1\n");
  EXPECT_EQ(ErrorOf([&] { root.RejectUnknownKeys(); }),
            "<root>: a key is a sequence, expected a name");
  EXPECT_EQ(FileError("base_map", "base: {x: 1}\n"),
            "base: wrong type: expected a string, got a map");
}

TEST(MapperOptions, FileErrorsNameTheFileAndTheKey) {
  EXPECT_EQ(FileError("type_number", "ipm: {max_range_m: far}\n"),
            "ipm.max_range_m: wrong type: expected a number, got the scalar 'far'");
  EXPECT_EQ(FileError("type_map", "ipm: [1, 2]\n"), "ipm: must be a map");
  EXPECT_EQ(FileError("type_list", "backend: {translation_prior_sigma_m: {x: 1}}\n"),
            "backend.translation_prior_sigma_m: wrong type: expected a sequence of numbers, "
            "got a map");
  EXPECT_EQ(FileError("type_string", "input: {base_frame: [base_link]}\n"),
            "input.base_frame: wrong type: expected a string, got a sequence");
  EXPECT_EQ(FileError("chord", "lanes: {chord_spacing_m: 1e-4}\n"),
            "lanes.chord_spacing_m: must be >= 0.5 m (got 0.0001)");
}

TEST(IpmOptions, AllErrorSourcesZeroOrNegativePixelErrorsAreRejected) {
  auto load = [](const std::string& yaml) { return [yaml] { LoadMapperOptions(ReaderOf(yaml)); }; };
  EXPECT_EQ(
      ErrorOf(load("ipm: {pixel_error_px: [0, 0], pitch_sigma_deg: 0, height_sigma_m: 0}")),
      "ipm: pixel_error_px, pitch_sigma_deg and height_sigma_m are all 0: at least one must be "
      "> 0");
  EXPECT_EQ(ErrorOf(load("ipm: {pixel_error_px: [-1, 2]}")), "ipm.pixel_error_px: must be >= 0");
  EXPECT_EQ(ErrorOf(load("ipm: {pixel_error_px: [2, -0.5]}")), "ipm.pixel_error_px: must be >= 0");
  // One source is enough.
  for (const char* one : {"ipm: {pixel_error_px: [0, 0], pitch_sigma_deg: 0.1, height_sigma_m: 0}",
                          "ipm: {pixel_error_px: [0, 0], pitch_sigma_deg: 0, height_sigma_m: 0.1}",
                          "ipm: {pixel_error_px: [0, 1], pitch_sigma_deg: 0, height_sigma_m: 0}"}) {
    EXPECT_NO_THROW(LoadMapperOptions(ReaderOf(one))) << one;
  }
}

TEST(LaneOptions, ChordSpacingHasAFloor) {
  EXPECT_EQ(ErrorOf([] { LoadMapperOptions(ReaderOf("lanes: {chord_spacing_m: 0.49}")); }),
            "lanes.chord_spacing_m: must be >= 0.5 m (got 0.49)");
  EXPECT_EQ(ErrorOf([] { LoadMapperOptions(ReaderOf("lanes: {chord_spacing_m: .inf}")); }),
            "lanes.chord_spacing_m: must be >= 0.5 m (got inf)");
  const MapperOptions o = LoadMapperOptions(ReaderOf("lanes: {chord_spacing_m: 0.5}"));
  EXPECT_EQ(o.lanes.fit.chord_spacing_m, 0.5);
}

TEST(BackendOptions, SolvingLessOftenThanTheWindowIsRejected) {
  EXPECT_EQ(ErrorOf([] {
              LoadMapperOptions(ReaderOf("backend: {window_frames: 10, solve_every_n_frames: 20}"));
            }),
            "backend.solve_every_n_frames: must be <= window_frames (10), got 20");
  EXPECT_NO_THROW(
      LoadMapperOptions(ReaderOf("backend: {window_frames: 10, solve_every_n_frames: 10}")));
}

TEST(OptionLoaders, SizesAndProbabilitiesOutOfRangeNameTheKey) {
  auto error = [](const std::string& yaml) {
    return ErrorOf([yaml] { LoadMapperOptions(ReaderOf(yaml)); });
  };
  EXPECT_EQ(error("extraction: {lane_row_step: 0}"),
            "extraction.lane_row_step: must be > 0 (got 0)");
  EXPECT_EQ(error("extraction: {max_instances_per_frame: -1}"),
            "extraction.max_instances_per_frame: must be > 0 (got -1)");
  EXPECT_EQ(error("association: {lane_min_support: 1.5}"),
            "association.lane_min_support: must be in [0, 1] (got 1.5)");
  EXPECT_EQ(error("association: {marking_merge_overlap: -0.1}"),
            "association.marking_merge_overlap: must be in [0, 1] (got -0.1)");
  EXPECT_EQ(error("extraction: {min_lane_points: 1}"),
            "extraction.min_lane_points: must be >= 2 (got 1)");
  EXPECT_EQ(error("odometry: {buffer_size: 0}"), "odometry.buffer_size: must be > 0 (got 0)");
  EXPECT_EQ(error("backend: {window_frames: 0}"), "backend.window_frames: must be > 0 (got 0)");
  EXPECT_EQ(error("backend: {queue_size: 0}"), "backend.queue_size: must be > 0 (got 0)");
  EXPECT_EQ(error("lanes: {selected_points_per_frame: 0}"),
            "lanes.selected_points_per_frame: must be > 0 (got 0)");
}

TEST(MapperOptions, EveryShippedMapperConfigLoads) {
  std::vector<std::string> paths = {kConfigDir + "/mapper.yaml"};
  for (const auto& entry : std::filesystem::directory_iterator(kConfigDir + "/ablations")) {
    if (entry.path().extension() == ".yaml") paths.push_back(entry.path().string());
  }
  EXPECT_GE(paths.size(), 8u);  // mapper.yaml and the 7 ablations of the benchmark
  for (const std::string& path : paths) {
    try {
      LoadMapperOptionsFile(path);
    } catch (const OptionsError& e) {
      ADD_FAILURE() << e.what();
    }
  }
}

// ---------------------------------------------------------------------------------------
// Class table
// ---------------------------------------------------------------------------------------

TEST(ClassTable, LoadsShippedClassesYaml) {
  const std::string path = kConfigDir + "/classes.yaml";
  ClassTable table;
  try {
    table = ClassTable::LoadFile(path);
  } catch (const OptionsError& e) {
    FAIL() << e.what();
  }
  const YAML::Node raw = YAML::LoadFile(path)["classes"];
  ASSERT_TRUE(raw.IsSequence());
  EXPECT_EQ(table.classes().size(), raw.size());
  int lanes = 0, markings = 0;
  for (const auto& [id, info] : table.classes()) {
    EXPECT_EQ(id, info.id);
    EXPECT_GE(id, 1);
    EXPECT_LE(id, kMaxClassId);
    EXPECT_EQ(table.FindByName(info.name), &info);
    (info.kind == ElementKind::kLane ? lanes : markings)++;
  }
  EXPECT_GT(lanes, 0);
  EXPECT_GT(markings, 0);
  // Each entry of the file is in the table as written.
  for (const YAML::Node& entry : raw) {
    const ClassInfo* info = table.Find(entry["id"].as<int>());
    ASSERT_NE(info, nullptr);
    EXPECT_EQ(info->name, entry["name"].as<std::string>());
    EXPECT_STREQ(ToString(info->kind), entry["kind"].as<std::string>().c_str());
    const std::string style = entry["style"] ? entry["style"].as<std::string>() : "unknown";
    EXPECT_STREQ(ToString(info->style), style.c_str());
  }
  EXPECT_EQ(table.Find(0), nullptr);
  EXPECT_EQ(table.FindByName("no_such_class"), nullptr);
}

TEST(ClassTable, ParsesKindsAndStyles) {
  const ClassTable table =
      ClassTable::Load(ReaderOf("classes:\n"
                                "  - {id: 1, name: solid_lane, kind: lane, style: solid}\n"
                                "  - {id: 2, name: dashed_lane, kind: lane, style: dashed}\n"
                                "  - {id: 3, name: plain_lane, kind: lane}\n"
                                "  - {id: 65, name: arrow, kind: marking}\n"));
  ASSERT_EQ(table.classes().size(), 4u);
  EXPECT_EQ(table.Find(1)->kind, ElementKind::kLane);
  EXPECT_EQ(table.Find(1)->style, LaneStyle::kSolid);
  EXPECT_EQ(table.Find(2)->style, LaneStyle::kDashed);
  EXPECT_EQ(table.Find(3)->style, LaneStyle::kUnknown);
  EXPECT_EQ(table.Find(65)->kind, ElementKind::kMarking);
  EXPECT_EQ(table.FindByName("dashed_lane")->id, 2);
}

TEST(ClassTable, InvalidEntriesNameTheEntry) {
  auto load = [](const std::string& entries) {
    return [entries] { ClassTable::Load(ReaderOf("classes:\n" + entries)); };
  };
  const std::string ok = "  - {id: 1, name: lane_a, kind: lane}\n";

  std::string e = ErrorOf(load(ok + "  - {id: 1, name: lane_b, kind: lane}\n"));
  EXPECT_TRUE(StartsWith(e, "classes[1]")) << e;
  EXPECT_NE(e.find("lane_b"), std::string::npos) << e;
  EXPECT_NE(e.find("duplicate id"), std::string::npos) << e;

  e = ErrorOf(load(ok + "  - {id: 2, name: lane_a, kind: marking}\n"));
  EXPECT_TRUE(StartsWith(e, "classes[1]")) << e;
  EXPECT_NE(e.find("id 2"), std::string::npos) << e;
  EXPECT_NE(e.find("duplicate name"), std::string::npos) << e;

  e = ErrorOf(load(ok + "  - {id: 2, name: blob, kind: polygon}\n"));
  EXPECT_TRUE(StartsWith(e, "classes[1]")) << e;
  EXPECT_NE(e.find("blob"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown kind 'polygon'"), std::string::npos) << e;

  e = ErrorOf(load(ok + "  - {id: 2, name: dotted, kind: lane, style: dotted}\n"));
  EXPECT_TRUE(StartsWith(e, "classes[1]")) << e;
  EXPECT_NE(e.find("unknown style 'dotted'"), std::string::npos) << e;

  for (const char* bad_id : {"0", "66", "-3"}) {
    e = ErrorOf(load(ok + "  - {id: " + bad_id + ", name: x, kind: marking}\n"));
    EXPECT_TRUE(StartsWith(e, "classes[1].id: must be in 1..65")) << e;
  }

  e = ErrorOf(load(ok + "  - {id: 2, kind: marking}\n"));
  EXPECT_EQ(e, "classes[1].name: required key is missing");
  e = ErrorOf(load("  - {name: x, kind: marking}\n"));
  EXPECT_EQ(e, "classes[0].id: required key is missing");
  e = ErrorOf(load(ok + "  - {id: 2, name: x, kind: marking, colour: red}\n"));
  EXPECT_EQ(e, "classes[1].colour: unknown key");
  e = ErrorOf(load(ok + "  - {id: two, name: x, kind: marking}\n"));
  EXPECT_TRUE(StartsWith(e, "classes[1].id: wrong type")) << e;
}

TEST(ClassTable, TableMustBeANonEmptyListAndNothingElse) {
  EXPECT_EQ(ErrorOf([] { ClassTable::Load(ReaderOf("classes: []")); }),
            "classes: must be a non-empty list");
  EXPECT_EQ(ErrorOf([] { ClassTable::Load(ReaderOf("other: 1")); }), "other: unknown key");
  EXPECT_EQ(ErrorOf([] { ClassTable::Load(ReaderOf("{}")); }), "classes: must be a non-empty list");
  EXPECT_EQ(ErrorOf([] { ClassTable::Load(ReaderOf("classes: {id: 1}")); }),
            "classes: must be a non-empty list");
}

TEST(ClassTable, LoadFileErrorsNameTheFile) {
  const std::string path = ::testing::TempDir() + "/irm_bad_classes.yaml";
  {
    std::FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("classes:\n  - {id: 3, name: a, kind: lane, style: wavy}\n", f);
    std::fclose(f);
  }
  const std::string e = ErrorOf([&] { ClassTable::LoadFile(path); });
  EXPECT_TRUE(StartsWith(e, path + ": classes[0]")) << e;
  EXPECT_NE(e.find("wavy"), std::string::npos) << e;
  std::remove(path.c_str());
}

TEST(ClassTable, MaskValueEncoding) {
  EXPECT_EQ(ClassIdOf(0), 0);
  EXPECT_EQ(ClassIdOf(999), 0);
  EXPECT_EQ(ClassIdOf(1000), 1);
  EXPECT_EQ(ClassIdOf(23017), 23);
  EXPECT_EQ(ClassIdOf(65535), kMaxClassId);  // the largest 16-bit value
  EXPECT_LE(kMaxClassId * kInstanceIdFactor, 65535);
}

}  // namespace
}  // namespace ipm_road_mapper

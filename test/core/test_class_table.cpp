// Tests of the mask class table (class_table.h): the shipped classes.yaml, kinds and styles,
// invalid entries named, the table's shape, file errors, the mask value encoding.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "common/options_test_utils.h"
#include "ipm_road_mapper/core/frontend/class_table.h"
#include "ipm_road_mapper/core/io/yaml_options.h"
#include "ipm_road_mapper/core/mapper/mapper_options.h"

namespace ipm_road_mapper {
namespace {

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

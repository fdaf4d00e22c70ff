// Tests of OptionsReader (yaml_options.h): values and defaults, the key path in every error
// (unknown keys, wrong types with what was expected and found, failed checks, required keys,
// children), file errors, the checks. Mapper options: test_mapper_options; the class table:
// test_class_table.
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

}  // namespace
}  // namespace ipm_road_mapper
